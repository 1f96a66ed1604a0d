# ogre-campfire in an engine's frame (issue 26, item 4), OGRE's own way:
# "Reversed Z-Buffer" (--reverse-z), FSAA 4 on the render texture (--msaa 4)
# and hardware gamma (--srgb), each against the default frame, under Xvfb.
#  - --reverse-z: OGRE's clip control is [0, 1] at the hook and splatfx reads the
#    convention off OGRE's matrix; the frame holds to the default one within one
#    8-bit step, two on at most 0.05 % of the pixels, never three (the bound of
#    tests/samples/render_depth_conventions.cmake: a one-step difference under a
#    splat layer can carry into a second rounding; -hardfail 0.0081).
#  - --msaa 4: splatfx draws per sample (no note); --msaa 4 and --srgb held to
#    the default frame by expect_msaa_srgb (tests/samples/host_targets.cmake:
#    the one-pixel-shift bound, the sRGB codes).
# Inputs: XVFB, SAMPLE, IDIFF, OIIOTOOL, PYTHON, OUT.
include(${CMAKE_CURRENT_LIST_DIR}/../samples/host_targets.cmake)
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
within_steps(${OUT}/default.png ${OUT}/reversez.png "-fail;0.004;-failpercent;0.05;-warn;0.004;-warnpercent;0.05;-hardfail;0.0081"
             "ogre-campfire --reverse-z differs from the default convention")
expect_msaa_srgb(${OUT}/default.png ${OUT}/msaa4.png ${OUT}/srgb.png ogre-campfire)
