# Bakes the small smoke-and-fire simulation that samples/20-vdb-smoke plays,
# with Blender's mantaflow, headless, into OpenVDB frames.
#
#   blender -b --factory-startup -P tools/bake-smoke.py -- OUT_DIR [RESOLUTION] [FRAMES]
#
# Writes OUT_DIR/fluid_data_0001.vdb ... (one file a frame: grids "density",
# "flame", "temperature", "velocity", "shadow"; earlier fluid_data_*.vdb in
# OUT_DIR are removed first) and OUT_DIR/bake-info.txt (Blender version,
# settings, bake time). Defaults: resolution 32 (cells along the domain's
# longest side), 24 frames. samples/20-vdb-smoke/data was made with 40 and 32.
# mantaflow's smoke solver has no random source in this setup (no noise, no
# particles): a rerun here gave the same active voxel counts and value ranges;
# the files' bytes differ (OpenVDB writes a random UUID into each file).
import os
import shutil
import sys
import tempfile
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not argv:
    sys.exit("usage: blender -b --factory-startup -P tools/bake-smoke.py -- OUT_DIR [RESOLUTION] [FRAMES]")
out_dir = os.path.abspath(argv[0])
resolution = int(argv[1]) if len(argv) > 1 else 32
frames = int(argv[2]) if len(argv) > 2 else 24

scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene.frame_start = 1
scene.frame_end = frames
scene.render.fps = 24

# Domain: a 2 x 2 x 3 box (x, y, z) standing on z = 0 (Blender is z-up).
bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.5))
domain = bpy.context.active_object
domain.name = "SmokeDomain"
domain.scale = (1.0, 1.0, 1.5)
bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
mod = domain.modifiers.new("Fluid", type="FLUID")
mod.fluid_type = "DOMAIN"
ds = mod.domain_settings
ds.domain_type = "GAS"
ds.resolution_max = resolution
ds.use_adaptive_domain = False
ds.use_noise = False
ds.cache_type = "REPLAY"  # simulated as frames are evaluated in order (frame_set below); bake_data runs as a job that background mode does not wait for
ds.cache_data_format = "OPENVDB"
ds.openvdb_cache_compress_type = "ZIP"
ds.openvdb_data_depth = "16"  # half floats on disk; read back as float grids
ds.cache_frame_start = 1
ds.cache_frame_end = frames
ds.alpha = 1.0                # density buoyancy
ds.beta = 1.0                 # heat buoyancy
ds.vorticity = 0.3
ds.flame_vorticity = 0.5
work = tempfile.mkdtemp(prefix="splatfx-bake-")
ds.cache_directory = work

# Flow: a small sphere near the floor emitting fire and smoke.
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(0.0, 0.0, 0.45))
flow = bpy.context.active_object
flow.name = "SmokeFlow"
fm = flow.modifiers.new("Fluid", type="FLUID")
fm.fluid_type = "FLOW"
fs = fm.flow_settings
fs.flow_type = "BOTH"
fs.flow_behavior = "INFLOW"
fs.fuel_amount = 1.0
fs.temperature = 1.5
fs.density = 1.0
fs.surface_distance = 1.0

start = time.monotonic()
for frame in range(1, frames + 1):
    scene.frame_set(frame)
    print("bake-smoke: frame %d/%d" % (frame, frames), flush=True)
seconds = time.monotonic() - start

os.makedirs(out_dir, exist_ok=True)
for old in os.listdir(out_dir):
    if old.startswith("fluid_data_") and old.endswith(".vdb"):
        os.remove(os.path.join(out_dir, old))
data = os.path.join(work, "data")
written = sorted(f for f in os.listdir(data) if f.startswith("fluid_data_") and f.endswith(".vdb"))
if not written:
    sys.exit("bake-smoke: mantaflow wrote no VDB files under " + data)
for f in written:
    shutil.copyfile(os.path.join(data, f), os.path.join(out_dir, f))
shutil.rmtree(work, ignore_errors=True)
with open(os.path.join(out_dir, "bake-info.txt"), "w") as info:
    info.write("blender %s (%s)\n" % (bpy.app.version_string, bpy.app.build_platform.decode() if isinstance(bpy.app.build_platform, bytes) else bpy.app.build_platform))
    info.write("command: blender -b --factory-startup -P tools/bake-smoke.py -- %s %d %d\n" % (argv[0], resolution, frames))
    info.write("resolution_max %d, frames 1-%d at 24 fps, domain 2 x 2 x 3 (z up), flow BOTH (fire + smoke)\n" % (resolution, frames))
    info.write("bake seconds %.1f\n" % seconds)
    info.write("files %d\n" % len(written))
print("bake-smoke: %d frames in %.1f s -> %s" % (len(written), seconds, out_dir))
