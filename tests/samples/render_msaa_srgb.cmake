# splatfx-render into an engine's colour targets (issue 26): --msaa 4 and --srgb.
# --msaa 1 is the default run byte for byte (a single-sampled target). With
# --msaa 4 nothing falls back (no "note:" line; "4x MSAA" is said) and every
# sample is the single-sampled frame at a point at most half a pixel from the
# pixel centre, so the mean |4x - 1x| cannot exceed the mean |1x shifted by
# one pixel - 1x| (idiff's mean error): each sample moves less than the whole
# pixel the shift moves. --srgb stores sRGB codes: converted back to linear
# (oiiotool) its frame is nearer the default (linear) one than as stored.
# Inputs: RENDER, IDIFF, OIIOTOOL, PYTHON, SCENE, NAME, OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
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

function(mean_error a b var)
  execute_process(COMMAND ${IDIFF} -fail 0 -warn 0 ${a} ${b} OUTPUT_VARIABLE out ERROR_VARIABLE err) # the statistics are printed only for a difference
  if(NOT out MATCHES "Mean error = ([0-9.e+-]+)")
    message(FATAL_ERROR "idiff ${a} ${b} gave no mean error:\n${out}\n${err}")
  endif()
  set(${var} ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()
execute_process(COMMAND ${OIIOTOOL} ${OUT}/default/${NAME}_0000.png --cshift +1+0 -o ${OUT}/shifted.png RESULT_VARIABLE rc)
execute_process(COMMAND ${OIIOTOOL} ${OUT}/srgb/${NAME}_0000.png --colorconvert sRGB linear -o ${OUT}/srgb_linear.png RESULT_VARIABLE rc2)
if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0)
  message(FATAL_ERROR "oiiotool failed (${rc}, ${rc2})")
endif()
mean_error(${OUT}/default/${NAME}_0000.png ${OUT}/msaa4/${NAME}_0000.png msaa)
mean_error(${OUT}/default/${NAME}_0000.png ${OUT}/shifted.png shift)
mean_error(${OUT}/default/${NAME}_0000.png ${OUT}/srgb_linear.png srgb_linear)
mean_error(${OUT}/default/${NAME}_0000.png ${OUT}/srgb/${NAME}_0000.png srgb_stored)
message(STATUS "mean |4x - 1x| ${msaa}, |1x shifted one pixel - 1x| ${shift}; sRGB linearized ${srgb_linear}, as stored ${srgb_stored}")
# CMake compares only integers: the floats through python3 (a test dependency already, capi.ctypes).
foreach(pair "msaa;shift;--msaa 4 moves the image more than a one-pixel shift" "srgb_linear;srgb_stored;--srgb does not store sRGB codes")
  list(GET pair 0 lo)
  list(GET pair 1 hi)
  list(GET pair 2 what)
  execute_process(COMMAND ${PYTHON} -c "import sys; sys.exit(0 if float('${${lo}}') < float('${${hi}}') else 1)" RESULT_VARIABLE less)
  if(NOT less EQUAL 0)
    message(FATAL_ERROR "${what}: ${lo} ${${lo}} >= ${hi} ${${hi}}")
  endif()
endforeach()
