# splatfx-viewer under Xvfb: runs 20 frames and writes a screenshot that is not blank.
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${XVFB} -a -s "-screen 0 1280x720x24" ${VIEWER} ${SCENE} --size 480x320 --auto-quit-after 20
                        --screenshot ${OUT}/viewer.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${OUT}/viewer.png)
  message(FATAL_ERROR "viewer failed (${rc}):\n${out}\n${err}")
endif()
string(FIND "${out}" "1 effects declared / 1 simulated / 1 visible" at)
if(at EQUAL -1)
  message(FATAL_ERROR "viewer summary unexpected:\n${out}")
endif()
file(SIZE ${OUT}/viewer.png size)
if(size LESS 5000)
  message(FATAL_ERROR "screenshot suspiciously small (${size} bytes): blank?")
endif()
