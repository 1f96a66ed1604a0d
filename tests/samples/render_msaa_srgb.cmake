# splatfx-render into an engine's colour targets (issue 26): --msaa 4 and --srgb.
# --msaa 1 is the default run byte for byte (a single-sampled target). With
# --msaa 4 nothing falls back (no "note:" line; "4x MSAA" is said); the 4x and
# --srgb frames are held to the default one by expect_msaa_srgb
# (host_targets.cmake: the one-pixel-shift bound and the sRGB codes).
# Inputs: RENDER, IDIFF, OIIOTOOL, PYTHON, SCENE, NAME, OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/host_targets.cmake)
file(REMOVE_RECURSE ${OUT})
set(common ${SCENE} --frames 1 --size 160x120 --quiet)
render(--out ${OUT}/default)
render(--out ${OUT}/msaa1 --msaa 1)
expect_same(${OUT}/default/${NAME}_0000.png ${OUT}/msaa1/${NAME}_0000.png "--msaa 1 against the default")
execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/msaa4 --msaa 4 RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "4x MSAA" OR out MATCHES "note:")
  message(FATAL_ERROR "splatfx-render --msaa 4 (${rc}) failed, did not say so or fell back:\n${out}\n${err}")
endif()
render(--out ${OUT}/srgb --srgb)
expect_msaa_srgb(${OUT}/default/${NAME}_0000.png ${OUT}/msaa4/${NAME}_0000.png ${OUT}/srgb/${NAME}_0000.png splatfx-render)
