# The viewer and splatfx-render in an engine's frame (issue 26, item 4): for
# each of --reverse-z (reverse-Z, [0, 1] clip depth, float depth), --msaa 4
# and --srgb, the viewer's first frame must be the tool's frame with the same
# flag, and both must hold to the default convention's frame.
#  - viewer against tool, same flag: the same target (Framebuffer of the same
#    desc), the same passes, the same resolve (a blit, GL_FRAMEBUFFER_SRGB as
#    while drawing) and a copy of the stored codes: every channel within one
#    8-bit step (idiff -fail 0.004, no pixel beyond), as viewer_matches_render.
#  - --reverse-z against the default: the bound of render_depth_conventions.cmake
#    (one step; two on at most 0.05 % of the pixels, where a carry meets a
#    second rounding under a splat layer; never three: -hardfail 0.0081).
#  - --msaa 4 against the default: each sample is the single-sampled frame at a
#    point at most half a pixel from the pixel centre, so the mean |4x - 1x|
#    must stay below the mean |1x shifted by one pixel - 1x| (as
#    render_msaa_srgb.cmake), and no fallback note is printed.
#  - --srgb against the default: the stored sRGB codes, converted to linear
#    (oiiotool), must be nearer the default (linear) frame than as stored.
# Inputs: XVFB, VIEWER, RENDER, IDIFF, OIIOTOOL, PYTHON, SCENE, NAME (the scene's output.name), OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(common ${SCENE} --frames 1 --size 200x150 --quiet)

function(viewer dir)
  file(MAKE_DIRECTORY ${OUT}/${dir})
  execute_process(COMMAND ${XVFB} -a -s "-screen 0 1280x720x24" ${VIEWER} ${SCENE} --size 200x150 --hide-ui --auto-quit-after 1 ${ARGN}
                          --screenshot ${OUT}/${dir}/viewer.png
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/${dir}/viewer.png)
    message(FATAL_ERROR "splatfx-viewer ${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
endfunction()
function(within_steps a b bound what)
  execute_process(COMMAND ${IDIFF} ${bound} ${a} ${b} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} (idiff exit ${rc}):\n${out}\n${err}")
  endif()
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

set(one_step -fail 0.004 -failpercent 0)
render(--out ${OUT}/default)
set(default ${OUT}/default/${NAME}_0000.png)
foreach(variant "reversez;--reverse-z" "msaa4;--msaa;4" "srgb;--srgb")
  list(GET variant 0 dir)
  list(SUBLIST variant 1 -1 flags)
  viewer(${dir} ${flags})
  execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/${dir} ${flags} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR out MATCHES "note:")
    message(FATAL_ERROR "splatfx-render ${flags} (${rc}) failed or fell back:\n${out}\n${err}")
  endif()
  within_steps(${OUT}/${dir}/viewer.png ${OUT}/${dir}/${NAME}_0000.png "${one_step}"
               "the viewer's first frame with ${flags} differs from splatfx-render's with ${flags}")
endforeach()

within_steps(${default} ${OUT}/reversez/viewer.png "-fail;0.004;-failpercent;0.05;-warn;0.004;-warnpercent;0.05;-hardfail;0.0081"
             "the viewer with --reverse-z differs from the default convention")

execute_process(COMMAND ${OIIOTOOL} ${default} --cshift +1+0 -o ${OUT}/shifted.png RESULT_VARIABLE rc)
execute_process(COMMAND ${OIIOTOOL} ${OUT}/srgb/viewer.png --colorconvert sRGB linear -o ${OUT}/srgb_linear.png RESULT_VARIABLE rc2)
if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0)
  message(FATAL_ERROR "oiiotool failed (${rc}, ${rc2})")
endif()
mean_error(${default} ${OUT}/msaa4/viewer.png msaa)
mean_error(${default} ${OUT}/shifted.png shift)
mean_error(${default} ${OUT}/srgb_linear.png srgb_linear)
mean_error(${default} ${OUT}/srgb/viewer.png srgb_stored)
message(STATUS "viewer: mean |4x - 1x| ${msaa}, |1x shifted one pixel - 1x| ${shift}; sRGB linearized ${srgb_linear}, as stored ${srgb_stored}")
expect_less(${msaa} ${shift} "the viewer's --msaa 4 moves the image more than a one-pixel shift")
expect_less(${srgb_linear} ${srgb_stored} "the viewer's --srgb does not show the sRGB codes")
