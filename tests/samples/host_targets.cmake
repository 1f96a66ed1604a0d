# Shared by the scripts that draw in an engine's frame (issue 26): splatfx-render's
# (render_msaa_srgb), the viewer's (viewer_conventions), OGRE's (ogre_conventions)
# and the sample host's (sample_targets). Needs IDIFF, OIIOTOOL, PYTHON and OUT.
#
# expect_msaa_srgb(DEFAULT MSAA4 SRGB WHO), the bounds every host is held to:
#  - MSAA: each sample is the single-sampled frame at a point at most half a
#    pixel from the pixel centre, so the mean |4x - 1x| cannot exceed the mean
#    |1x shifted by one pixel - 1x| (idiff's mean error): each sample moves less
#    than the whole pixel the shift moves.
#  - sRGB: the stored sRGB codes, converted back to linear (oiiotool), are
#    nearer the default (linear) frame than as stored.

# The mean |a - b| over every channel (idiff prints its statistics only for a difference).
function(mean_error a b var)
  execute_process(COMMAND ${IDIFF} -fail 0 -warn 0 ${a} ${b} OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT out MATCHES "Mean error = ([0-9.e+-]+)")
    message(FATAL_ERROR "idiff ${a} ${b} gave no mean error:\n${out}\n${err}")
  endif()
  set(${var} ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()

# Fails unless lo < hi as floats (CMake compares only integers: python3, a test dependency already).
function(expect_less lo hi what)
  execute_process(COMMAND ${PYTHON} -c "import sys; sys.exit(0 if float('${lo}') < float('${hi}') else 1)" RESULT_VARIABLE less)
  if(NOT less EQUAL 0)
    message(FATAL_ERROR "${what}: ${lo} >= ${hi}")
  endif()
endfunction()

# Fails unless idiff with the given bound (a list: -fail 0.004 -failpercent 0 ...) passes.
function(within_steps a b bound what)
  execute_process(COMMAND ${IDIFF} ${bound} ${a} ${b} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} (idiff exit ${rc}):\n${out}\n${err}")
  endif()
endfunction()

function(expect_msaa_srgb default msaa srgb who)
  string(MAKE_C_IDENTIFIER "${who}" who_id)
  set(shifted ${OUT}/${who_id}_shifted.png)
  set(linear ${OUT}/${who_id}_srgb_linear.png)
  execute_process(COMMAND ${OIIOTOOL} ${default} --cshift +1+0 -o ${shifted} RESULT_VARIABLE rc)
  execute_process(COMMAND ${OIIOTOOL} ${srgb} --colorconvert sRGB linear -o ${linear} RESULT_VARIABLE rc2)
  if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0)
    message(FATAL_ERROR "oiiotool failed (${rc}, ${rc2})")
  endif()
  mean_error(${default} ${msaa} msaa_error)
  mean_error(${default} ${shifted} shift_error)
  mean_error(${default} ${linear} srgb_linear)
  mean_error(${default} ${srgb} srgb_stored)
  message(STATUS "${who}: mean |4x - 1x| ${msaa_error}, |1x shifted one pixel - 1x| ${shift_error}; sRGB linearized ${srgb_linear}, as stored ${srgb_stored}")
  expect_less(${msaa_error} ${shift_error} "${who} --msaa 4 moves the image more than a one-pixel shift")
  expect_less(${srgb_linear} ${srgb_stored} "${who} --srgb does not store sRGB codes")
endfunction()
