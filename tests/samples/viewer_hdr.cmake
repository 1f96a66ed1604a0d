# splatfx-viewer --hdr shows what splatfx-render --hdr writes as its PNG: both
# draw the scene into an RGBA16F target with HDR lit colours; the viewer
# copies it to its 8-bit window (GL converts each half float, clamped to
# [0, 1], to the nearest 8-bit step), the tool reads it back and its PNG writer
# does the same. So every channel within one step of 255 (0.004), as
# viewer_matches_render allows for the 8-bit frame.
# Inputs: XVFB, VIEWER, RENDER, IDIFF, SCENE, NAME, OUT.
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${XVFB} -a -s "-screen 0 1280x720x24" ${VIEWER} ${SCENE} --size 200x150 --hide-ui --auto-quit-after 1 --hdr
                        --screenshot ${OUT}/viewer.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/viewer.png)
  message(FATAL_ERROR "viewer --hdr failed (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${RENDER} ${SCENE} --frames 1 --size 200x150 --quiet --hdr --out ${OUT}/render
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/render/${NAME}_0000.png)
  message(FATAL_ERROR "splatfx-render --hdr failed (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${IDIFF} -fail 0.004 -failpercent 0 ${OUT}/viewer.png ${OUT}/render/${NAME}_0000.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the viewer's --hdr frame differs from splatfx-render --hdr's PNG (idiff exit ${rc}):\n${out}\n${err}")
endif()
# Without --hdr the viewer's frame is not that one (the lit colours stop at 1): the comparison can fail.
execute_process(COMMAND ${XVFB} -a -s "-screen 0 1280x720x24" ${VIEWER} ${SCENE} --size 200x150 --hide-ui --auto-quit-after 1
                        --screenshot ${OUT}/viewer_ldr.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
execute_process(COMMAND ${IDIFF} -fail 0.004 -failpercent 0 ${OUT}/viewer_ldr.png ${OUT}/render/${NAME}_0000.png
                RESULT_VARIABLE differ OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR differ EQUAL 0)
  message(FATAL_ERROR "the viewer without --hdr (exit ${rc}) should differ from the --hdr frame, idiff says ${differ}")
endif()
# The window's default framebuffer is 8-bit: --hdr with --into-window is refused before any window opens.
execute_process(COMMAND ${VIEWER} ${SCENE} --hdr --into-window RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT "${out}${err}" MATCHES "excludes")
  message(FATAL_ERROR "viewer --hdr --into-window must be refused (exit 2, CLI11's 'excludes'), got ${rc}:\n${out}\n${err}")
endif()
