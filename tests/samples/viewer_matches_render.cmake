# The viewer and splatfx-render show the same image of the same scene: the
# first frame of a fogged sample (the host fog needs the host depth as a
# texture, which a window's default framebuffer does not have: the viewer
# draws into a framebuffer of its own and copies it to the window), compared
# with OpenImageIO's idiff. Both are RGBA8: every channel within one step of
# 255 (the copy to the window is exact; the tool's PNG is the same bytes).
# With VIEWER_FLAGS=--into-window the viewer draws into the window's default
# framebuffer instead (no depth texture: splatfx copies the window's depth
# buffer once a frame, FrameRendererDesc::copyHostDepth). The window's depth
# is DEPTH24_STENCIL8, which a driver may copy through float (llvmpipe does):
# one step of 2^-24 at most (HostDepthCopyGL), moving the cut by that much, so
# one channel may cross a rounding boundary and a later blend carry it to a
# second step, as in render_depth_conventions.cmake: two steps allowed on at
# most 0.05 % of the pixels (idiff -hardfail 0.0081), never three.
# Inputs: XVFB, VIEWER, RENDER, IDIFF, SCENE, NAME (the scene's output.name), OUT, VIEWER_FLAGS (optional),
# SIZE (optional, default 200x150).
if(NOT SIZE)
  set(SIZE 200x150)
endif()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${XVFB} -a -s "-screen 0 1280x720x24" ${VIEWER} ${SCENE} --size ${SIZE} --hide-ui --auto-quit-after 1 ${VIEWER_FLAGS}
                        --screenshot ${OUT}/viewer.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/viewer.png)
  message(FATAL_ERROR "viewer failed (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${RENDER} ${SCENE} --frames 1 --size ${SIZE} --quiet --out ${OUT}/render
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/render/${NAME}_0000.png)
  message(FATAL_ERROR "splatfx-render failed (${rc}):\n${out}\n${err}")
endif()
if(VIEWER_FLAGS MATCHES "--into-window")
  set(bound -fail 0.004 -failpercent 0.05 -warn 0.004 -warnpercent 0.05 -hardfail 0.0081)
else()
  set(bound -fail 0.004 -failpercent 0)
endif()
execute_process(COMMAND ${IDIFF} ${bound} ${OUT}/viewer.png ${OUT}/render/${NAME}_0000.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the viewer's first frame differs from splatfx-render's (idiff exit ${rc}):\n${out}\n${err}")
endif()
