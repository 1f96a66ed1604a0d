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
#  - --msaa 4 and --srgb against the default: expect_msaa_srgb
#    (host_targets.cmake: the one-pixel-shift bound, the sRGB codes), and no
#    fallback note is printed.
# Inputs: XVFB, VIEWER, RENDER, IDIFF, OIIOTOOL, PYTHON, SCENE, NAME (the scene's output.name), OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/host_targets.cmake)
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

expect_msaa_srgb(${default} ${OUT}/msaa4/viewer.png ${OUT}/srgb/viewer.png viewer)
