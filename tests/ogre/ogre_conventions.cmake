# ogre-campfire in an engine's frame (issue 26, item 4), OGRE's own way:
# "Reversed Z-Buffer" (--reverse-z), FSAA 4 on the render texture (--msaa 4)
# and hardware gamma (--srgb), each against the default frame, under Xvfb.
#  - --reverse-z: OGRE's clip control is [0, 1] at the hook and splatfx reads the
#    convention off OGRE's matrix; the frame holds to the default one within one
#    8-bit step, two on at most 0.05 % of the pixels, never three (the bound of
#    tests/samples/render_depth_conventions.cmake: a one-step difference under a
#    splat layer can carry into a second rounding; -hardfail 0.0081).
#  - --msaa 4: splatfx draws per sample (no note), and each sample is the
#    single-sampled frame at a point at most half a pixel from the pixel centre,
#    so the mean |4x - 1x| must stay below the mean |1x shifted by one pixel - 1x|.
#  - --srgb: the stored sRGB codes, converted to linear, are nearer the default
#    (linear) frame than as stored.
# Inputs: XVFB, SAMPLE, IDIFF, OIIOTOOL, PYTHON, OUT.
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
function(ogre name)
  execute_process(COMMAND ${XVFB} -a -s "-screen 0 640x480x24" ${SAMPLE} --frames 2 --size 320x180 ${ARGN} --screenshot ${OUT}/${name}.png
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/${name}.png OR out MATCHES "note:")
    message(FATAL_ERROR "ogre-campfire ${ARGN} failed (${rc}) or noted a fallback:\n${out}\n${err}")
  endif()
  set(${name}_out "${out}" PARENT_SCOPE)
endfunction()
function(mean_error a b var)
  execute_process(COMMAND ${IDIFF} -fail 0 -warn 0 ${a} ${b} OUTPUT_VARIABLE out ERROR_VARIABLE err) # the statistics are printed only for a difference
  if(NOT out MATCHES "Mean error = ([0-9.e+-]+)")
    message(FATAL_ERROR "idiff ${a} ${b} gave no mean error:\n${out}\n${err}")
  endif()
  set(${var} ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()
function(expect_less lo hi what)
  execute_process(COMMAND ${PYTHON} -c "import sys; sys.exit(0 if float('${lo}') < float('${hi}') else 1)" RESULT_VARIABLE less)
  if(NOT less EQUAL 0)
    message(FATAL_ERROR "${what}: ${lo} >= ${hi}")
  endif()
endfunction()

ogre(default)
ogre(reversez --reverse-z)
ogre(msaa4 --msaa 4)
ogre(srgb --srgb)
if(NOT reversez_out MATCHES "clip depth \\[0, 1\\]")
  message(FATAL_ERROR "ogre-campfire --reverse-z: OGRE did not draw with [0, 1] clip depth:\n${reversez_out}")
endif()
if(NOT msaa4_out MATCHES "4x MSAA, drawn per sample")
  message(FATAL_ERROR "ogre-campfire --msaa 4: splatfx did not draw per sample:\n${msaa4_out}")
endif()
execute_process(COMMAND ${IDIFF} -fail 0.004 -failpercent 0.05 -warn 0.004 -warnpercent 0.05 -hardfail 0.0081 ${OUT}/default.png ${OUT}/reversez.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ogre-campfire --reverse-z differs from the default convention (idiff exit ${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${OIIOTOOL} ${OUT}/default.png --cshift +1+0 -o ${OUT}/shifted.png RESULT_VARIABLE rc)
execute_process(COMMAND ${OIIOTOOL} ${OUT}/srgb.png --colorconvert sRGB linear -o ${OUT}/srgb_linear.png RESULT_VARIABLE rc2)
if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0)
  message(FATAL_ERROR "oiiotool failed (${rc}, ${rc2})")
endif()
mean_error(${OUT}/default.png ${OUT}/msaa4.png msaa)
mean_error(${OUT}/default.png ${OUT}/shifted.png shift)
mean_error(${OUT}/default.png ${OUT}/srgb_linear.png srgb_linear)
mean_error(${OUT}/default.png ${OUT}/srgb.png srgb_stored)
message(STATUS "ogre: mean |4x - 1x| ${msaa}, |1x shifted one pixel - 1x| ${shift}; sRGB linearized ${srgb_linear}, as stored ${srgb_stored}")
expect_less(${msaa} ${shift} "ogre-campfire --msaa 4 moves the image more than a one-pixel shift")
expect_less(${srgb_linear} ${srgb_stored} "ogre-campfire --srgb does not store sRGB codes")
