"""The C API from another language with no compiler: Python's ctypes loads libsplatfx_c.so, lays out
the header's structs itself (a desc with pointers and padding, the camera, the frame stats), builds a
fire, prepares a frame and reads the error paths. What a C#, Rust or Lua binding does, in miniature.

usage: python3 ctypes_test.py path/to/libsplatfx_c.so
"""
import ctypes as C
import math
import sys

fx = C.CDLL(sys.argv[1])
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAILED:", what, file=sys.stderr)


class Camera(C.Structure):
    _fields_ = [("view", C.c_float * 16), ("proj", C.c_float * 16), ("viewport", C.c_int32 * 2)]


class FrameStats(C.Structure):
    _fields_ = [("declared", C.c_uint64), ("needed", C.c_uint64), ("simulated", C.c_uint64),
                ("drawn", C.c_uint64), ("splats", C.c_uint64), ("time_sec", C.c_double)]


class FireDesc(C.Structure):
    _fields_ = [("dims", C.c_int32 * 3), ("spacing", C.c_float * 3), ("position", C.c_float * 3),
                ("texture_set", C.c_void_p), ("texture_count", C.c_int32), ("opacity", C.c_float),
                ("propagation_steps_per_sec", C.c_float), ("textures_per_sec", C.c_float), ("crossfade", C.c_int),
                ("motion_keys", C.c_void_p), ("motion_key_count", C.c_uint32), ("seed", C.c_uint32),
                ("texture_seed", C.c_uint32)]


P = C.c_void_p
fx.splatfx_c_api_version.restype = C.c_uint32
fx.splatfx_error_create.restype = P
fx.splatfx_error_message.restype = C.c_char_p
fx.splatfx_error_message.argtypes = [P]
fx.splatfx_error_status.argtypes = [P]
fx.splatfx_error_destroy.argtypes = [P]
for name in ("materials", "scene", "frame"):
    getattr(fx, f"splatfx_{name}_destroy").argtypes = [P]
fx.splatfx_materials_create.argtypes = [P, C.POINTER(P), P]
fx.splatfx_scene_create.argtypes = [C.POINTER(P), P]
fx.splatfx_frame_create.argtypes = [C.POINTER(P), P]
fx.splatfx_fire_desc_init.argtypes = [C.POINTER(FireDesc)]
fx.splatfx_scene_add_fire.argtypes = [P, P, C.POINTER(FireDesc), P, C.POINTER(C.c_uint32), P]
fx.splatfx_camera_look_at.argtypes = [C.c_float * 3] * 3 + [C.c_float, C.c_int32, C.c_int32, C.c_float, C.c_float,
                                                           C.POINTER(Camera), P]
fx.splatfx_scene_prepare.argtypes = [P, C.c_double, C.POINTER(Camera), P, P, P]
fx.splatfx_frame_get_stats.argtypes = [P, C.POINTER(FrameStats), P]
fx.splatfx_scene_set_hdr_lit.argtypes = [P, C.c_int, P]
fx.splatfx_scene_hdr_lit.argtypes = [P]

SPLATFX_OK, INVALID_ARGUMENT = 0, 1
check(fx.splatfx_c_api_version() == 4, "API version")
err = fx.splatfx_error_create()
m, scene, frame = P(), P(), P()
check(fx.splatfx_materials_create(None, C.byref(m), err) == SPLATFX_OK, "materials")
check(fx.splatfx_scene_create(C.byref(scene), err) == SPLATFX_OK, "scene")
check(fx.splatfx_frame_create(C.byref(frame), err) == SPLATFX_OK, "frame")

desc = FireDesc()
fx.splatfx_fire_desc_init(C.byref(desc))
check(list(desc.dims) == [7, 20, 5] and abs(desc.opacity - 0.55) < 1e-6 and desc.seed == 1 and desc.texture_seed == 1,
      f"fire desc defaults as ctypes lays them out: dims {list(desc.dims)}, opacity {desc.opacity}, seeds "
      f"{desc.seed} {desc.texture_seed}")
desc.dims[0], desc.dims[1], desc.dims[2] = 3, 4, 2
fid = C.c_uint32(99)
rc = fx.splatfx_scene_add_fire(scene, m, C.byref(desc), None, C.byref(fid), err)
check(rc == SPLATFX_OK and fid.value == 0, f"add fire: {rc} {fx.splatfx_error_message(err)}")

V3 = C.c_float * 3
cam = Camera()
rc = fx.splatfx_camera_look_at(V3(0, 1, 12), V3(0, 1, 0), V3(0, 1, 0), 0.9, 64, 48, 0.1, 100.0, C.byref(cam), err)
check(rc == SPLATFX_OK and list(cam.viewport) == [64, 48], f"camera: {fx.splatfx_error_message(err)}")
check(fx.splatfx_scene_prepare(scene, 0.5, C.byref(cam), m, frame, err) == SPLATFX_OK,
      f"prepare: {fx.splatfx_error_message(err)}")
st = FrameStats()
check(fx.splatfx_frame_get_stats(frame, C.byref(st), err) == SPLATFX_OK, "stats")
# The 3x4x2 dims reached the preset through ctypes' layout: at most one splat per voxel.
check(st.declared == 1 and st.needed == 1 and 0 < st.splats <= 24 and st.time_sec == 0.5,
      f"stats: declared {st.declared} needed {st.needed} splats {st.splats} time {st.time_sec}")

# HDR lit colour: a host switch, an int on both sides.
check(fx.splatfx_scene_hdr_lit(scene) == 0, "HDR lit colour off by default")
check(fx.splatfx_scene_set_hdr_lit(scene, 1, err) == SPLATFX_OK and fx.splatfx_scene_hdr_lit(scene) == 1, "HDR lit colour on")
rc = fx.splatfx_scene_set_hdr_lit(m, 1, err)  # materials passed as the scene
msg = fx.splatfx_error_message(err).decode()
check(rc == INVALID_ARGUMENT and "scene is not a splatfx_scene (it is a splatfx_materials)" in msg, f"HDR on a wrong handle: {rc} {msg}")

rc = fx.splatfx_scene_prepare(scene, math.nan, C.byref(cam), m, frame, err)
msg = fx.splatfx_error_message(err).decode()
check(rc == INVALID_ARGUMENT and "time_sec is nan" in msg, f"NaN time: {rc} {msg}")
rc = fx.splatfx_scene_prepare(None, 0.0, C.byref(cam), m, frame, err)
msg = fx.splatfx_error_message(err).decode()
check(rc == INVALID_ARGUMENT and "scene is NULL" in msg, f"NULL scene: {rc} {msg}")
rc = fx.splatfx_scene_prepare(m, 0.0, C.byref(cam), m, frame, err)  # materials passed as the scene
msg = fx.splatfx_error_message(err).decode()
check(rc == INVALID_ARGUMENT and "scene is not a splatfx_scene (it is a splatfx_materials)" in msg, f"wrong handle: {rc} {msg}")

# Handles destroyed twice (a binding's finalizer and an explicit close both running): ignored.
for name, h in (("frame", frame), ("scene", scene), ("materials", m)):
    getattr(fx, f"splatfx_{name}_destroy")(h)
    getattr(fx, f"splatfx_{name}_destroy")(h)
fx.splatfx_error_destroy(err)
fx.splatfx_error_destroy(err)
check(fx.splatfx_error_status(err) == INVALID_ARGUMENT, "a destroyed error object's status")
if failures:
    sys.exit(f"ctypes_test: {len(failures)} check(s) failed")
print(f"ctypes_test: all checks passed ({st.splats} splats; NaN time -> an error message)")
