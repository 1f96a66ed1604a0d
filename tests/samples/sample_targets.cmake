# The shared sample host (samples/common) in an engine's colour targets (issue
# 26), through sample 01 headless: --msaa 4, --srgb and --hdr.
#  - --msaa 1 is the default run byte for byte (a single-sampled target); --msaa 4
#    and --srgb say so and are held to the default frame by expect_msaa_srgb
#    (host_targets.cmake: the one-pixel-shift bound, the sRGB codes).
#  - --hdr writes an EXR beside each PNG; the PNG is that EXR clamped at 1 and
#    rounded to 8 bits (what oiiotool makes of it: within half a step, as
#    render_hdr.cmake), and the EXR holds no NaN or inf.
#  - --hdr draws into RGBA16F, not 8 bits: its EXR is not on the 8-bit grid
#    (an RGBA8 target can hold only multiples of 1/255: the EXR rounded to
#    8 bits must differ from it somewhere by more than half float's rounding).
#  - --hdr against the default (RGBA8) frame, the same picture: the RGBA8
#    target rounds each splat layer's blend to 8 bits (half a step each, 4.2
#    steps at most and 0.26 on average measured at 160x120, growing with the
#    layers over a pixel, a count this test cannot see), so no per-pixel bound
#    is derived here; the mean |HDR - 8 bit| must stay below the mean |1x shifted
#    by one pixel - 1x|, the bound the MSAA frames are held to.
#  - --hdr --srgb is refused (an 8-bit target), and --scale 3 (1, 2 or 4).
#  - The frame renderer's notes are printed: none for the runs above; --msaa 4
#    --scale 2 prints the reduced layer's (once as it happens, once in the summary).
# Inputs: RENDER (the sample), IDIFF, OIIOTOOL, PYTHON, NAME (the frames' name), OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/host_targets.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(common --frames 1 --size 160x120)
render(--out ${OUT}/default)
render(--out ${OUT}/msaa1 --msaa 1)
expect_same(${OUT}/default/${NAME}_0000.png ${OUT}/msaa1/${NAME}_0000.png "--msaa 1 against the default")
foreach(variant "msaa4;4x MSAA;--msaa;4" "srgb;sRGB;--srgb" "hdr;RGBA16F;--hdr")
  list(GET variant 0 dir)
  list(GET variant 1 said)
  list(SUBLIST variant 2 -1 flags)
  execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/${dir} ${flags} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "${said}")
    message(FATAL_ERROR "${NAME} ${flags} (${rc}) failed or did not say '${said}':\n${out}\n${err}")
  endif()
  if(out MATCHES "note")
    message(FATAL_ERROR "${NAME} ${flags}: the frame renderer noted a fallback where none is expected:\n${out}")
  endif()
endforeach()
# The frame renderer's notes are printed (once, and under the summary): --scale 2 on --msaa 4 draws
# the reduced layer unshifted in every sample's run, and says so.
execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/msaa4_scale2 --msaa 4 --scale 2 RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCHALL "note:? reduced resolution \\(resolutionScale 2\\) on a multisampled host" said "${out}")
list(LENGTH said count)
if(NOT rc EQUAL 0 OR NOT count EQUAL 2)
  message(FATAL_ERROR "${NAME} --msaa 4 --scale 2 (${rc}) must print its reduced-layer note once and under the summary (${count} times):\n${out}\n${err}")
endif()
set(default ${OUT}/default/${NAME}_0000.png)
expect_msaa_srgb(${default} ${OUT}/msaa4/${NAME}_0000.png ${OUT}/srgb/${NAME}_0000.png ${NAME})

set(exr ${OUT}/hdr/${NAME}_0000.exr)
if(NOT EXISTS ${exr} OR EXISTS ${OUT}/default/${NAME}_0000.exr)
  message(FATAL_ERROR "--hdr must write ${exr}, and only --hdr an EXR")
endif()
execute_process(COMMAND ${OIIOTOOL} --stats ${exr} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR out MATCHES "NanCount: [0-9 ]*[1-9]" OR out MATCHES "InfCount: [0-9 ]*[1-9]")
  message(FATAL_ERROR "oiiotool --stats ${exr} (${rc}) failed or found NaN or inf:\n${out}")
endif()
execute_process(COMMAND ${OIIOTOOL} ${exr} --clamp:min=0:max=1 -d uint8 -o ${OUT}/clamped.png RESULT_VARIABLE rc)
within_steps(${OUT}/clamped.png ${OUT}/hdr/${NAME}_0000.png "-fail;0.5e-3;-warn;0.5e-3" "the --hdr PNG is not its EXR clamped at 1")
execute_process(COMMAND ${OIIOTOOL} ${exr} -d uint8 -o ${OUT}/hdr_as_8bit.png RESULT_VARIABLE rc)
execute_process(COMMAND ${IDIFF} -fail 1e-3 -warn 1e-3 ${exr} ${OUT}/hdr_as_8bit.png RESULT_VARIABLE on_grid OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR on_grid EQUAL 0)
  message(FATAL_ERROR "--hdr's EXR is on the 8-bit grid (${rc}, idiff ${on_grid}): the target was not RGBA16F:\n${out}")
endif()
mean_error(${default} ${OUT}/hdr/${NAME}_0000.exr hdr_error)
mean_error(${default} ${OUT}/${NAME}_shifted.png shift_error) # written by expect_msaa_srgb
message(STATUS "${NAME}: mean |HDR - 8 bit| ${hdr_error}, |1x shifted one pixel - 1x| ${shift_error}")
expect_less(${hdr_error} ${shift_error} "${NAME} --hdr is not the default picture")

execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/both --hdr --srgb RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT "${out}${err}" MATCHES "excludes")
  message(FATAL_ERROR "--hdr --srgb must be refused (exit 2, CLI11's 'excludes'), got ${rc}:\n${out}\n${err}")
endif()
execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/scale3 --scale 3 RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT "${out}${err}" MATCHES "--scale: 3 not in" OR EXISTS ${OUT}/scale3)
  message(FATAL_ERROR "--scale 3 must be refused (exit 2, naming --scale) with nothing written, got ${rc}:\n${out}\n${err}")
endif()
