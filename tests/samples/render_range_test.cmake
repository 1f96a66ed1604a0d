# splatfx-render --range (issue 18, item 3): a sequence rendered whole and as
# farm tasks 0-7, 8-15, 16-23 gives the same bytes in every frame (the scene's
# solver effects included: a task replays the frames before its range), a
# task never removes another task's frames, a stepped range writes exactly
# its frames, and --assemble writes the GIF the full run wrote, byte for byte.
# Inputs: RENDER, SCENE, NAME (the scene's output.name), OUT.
file(REMOVE_RECURSE ${OUT})
set(common ${SCENE} --frames 24 --size 96x64 --quiet)

include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)

function(frame_file var dir i)
  string(LENGTH "${i}" n)
  set(pad "${i}")
  while(n LESS 4)
    set(pad "0${pad}")
    math(EXPR n "${n} + 1")
  endwhile()
  set(${var} ${dir}/${NAME}_${pad}.png PARENT_SCOPE)
endfunction()

render(--out ${OUT}/full)

# The tasks, each followed by a check that the earlier tasks' frames are all
# still there: publishing a task's set must not remove them.
set(done "")
foreach(task 0-7 8-15 16-23 8-15)  # the last: a retried task
  render(--out ${OUT}/split --range ${task})
  string(REPLACE "-" ";" ends ${task})
  list(GET ends 0 a)
  list(GET ends 1 b)
  foreach(i RANGE ${a} ${b})
    list(APPEND done ${i})
  endforeach()
  foreach(i ${done})
    frame_file(f ${OUT}/split ${i})
    if(NOT EXISTS ${f})
      message(FATAL_ERROR "after task ${task}: frame ${i} is gone (${f})")
    endif()
  endforeach()
endforeach()
if(EXISTS ${OUT}/split/${NAME}.gif)
  message(FATAL_ERROR "a range task wrote the sequence's GIF; only a full run or --assemble may")
endif()
file(GLOB staging ${OUT}/split/.*.partial)
if(staging)
  message(FATAL_ERROR "staging folders left behind: ${staging}")
endif()
foreach(i RANGE 0 23)
  frame_file(whole ${OUT}/full ${i})
  frame_file(part ${OUT}/split ${i})
  expect_same(${whole} ${part} "frame ${i}, whole run vs tasks 0-7/8-15/16-23")
endforeach()

# A stepped task writes exactly its frames, each the full run's.
render(--out ${OUT}/step --range 2-23:7)
foreach(i RANGE 0 23)
  frame_file(f ${OUT}/step ${i})
  if(i EQUAL 2 OR i EQUAL 9 OR i EQUAL 16 OR i EQUAL 23)
    frame_file(whole ${OUT}/full ${i})
    expect_same(${whole} ${f} "frame ${i} of --range 2-23:7")
  elseif(EXISTS ${f})
    message(FATAL_ERROR "--range 2-23:7 wrote frame ${i}")
  endif()
endforeach()

# Assembling a sequence with a frame missing names it and writes no GIF.
execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/step --assemble RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(FIND "${err}" "20 of the 24 frames are missing" at)
if(rc EQUAL 0 OR at EQUAL -1 OR EXISTS ${OUT}/step/${NAME}.gif)
  message(FATAL_ERROR "--assemble with missing frames must fail naming them (rc ${rc}):\n${err}")
endif()

render(--out ${OUT}/split --assemble)
expect_same(${OUT}/full/${NAME}.gif ${OUT}/split/${NAME}.gif "the assembled GIF vs the full run's")
message(STATUS "render ranges (${NAME}): ok")
