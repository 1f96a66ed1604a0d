# splatfx-render: a good run leaves every frame and the GIF; a failed run
# (--abort-after, or a bad scene file) leaves no GIF and no staging folder.
file(REMOVE_RECURSE ${OUT})

execute_process(COMMAND ${RENDER} ${SCENE} --out ${OUT}/good --frames 3 --size 96x64 --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "render failed (${rc}):\n${out}\n${err}")
endif()
foreach(f figure1_0000.png figure1_0001.png figure1_0002.png figure1.gif)
  if(NOT EXISTS ${OUT}/good/${f})
    message(FATAL_ERROR "missing ${OUT}/good/${f}")
  endif()
endforeach()
foreach(word "summary" "splats per frame" "effects           2 declared")
  string(FIND "${out}" "${word}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "summary lacks '${word}':\n${out}")
  endif()
endforeach()
file(GLOB leftovers ${OUT}/good/.figure1.partial)
if(leftovers)
  message(FATAL_ERROR "staging folder left behind: ${leftovers}")
endif()

# A second run with fewer frames replaces the set it wrote (the third frame
# goes) and never touches files it did not write, even ones named like its own.
file(WRITE ${OUT}/good/figure1_9999.png "not a frame splatfx-render wrote")
file(WRITE ${OUT}/good/t_logo.png "the user's")
execute_process(COMMAND ${RENDER} ${SCENE} --out ${OUT}/good --frames 2 --size 96x64 --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "second render failed (${rc}):\n${out}\n${err}")
endif()
if(EXISTS ${OUT}/good/figure1_0002.png)
  message(FATAL_ERROR "the previous set's third frame should be gone after a 2-frame run")
endif()
foreach(f figure1_9999.png t_logo.png figure1_0000.png figure1_0001.png figure1.gif)
  if(NOT EXISTS ${OUT}/good/${f})
    message(FATAL_ERROR "missing ${OUT}/good/${f} after the second run")
  endif()
endforeach()

execute_process(COMMAND ${RENDER} ${SCENE} --out ${OUT}/failed --frames 3 --size 96x64 --quiet --abort-after 2
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "--abort-after 2 should fail")
endif()
file(GLOB_RECURSE anything ${OUT}/failed/*)
file(GLOB staging ${OUT}/failed/.figure1.partial)
if(anything OR staging OR EXISTS ${OUT}/failed/figure1.gif)
  message(FATAL_ERROR "a failed run left files: ${anything} ${staging}")
endif()

file(WRITE ${OUT}/bad/scene.json "{\"format\": \"splatfx-scene\", \"version\": 1, \"effects\": [{\"kind\": \"fire\", \"dims\": [7, 20]}]}")
execute_process(COMMAND ${RENDER} ${OUT}/bad/scene.json --out ${OUT}/bad/out --frames 2 --size 96x64
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(FIND "${err}" "effects[0].dims: expected an array of 3 integers" at)
if(rc EQUAL 0 OR at EQUAL -1 OR EXISTS ${OUT}/bad/out/bad.gif)
  message(FATAL_ERROR "a bad scene must fail with a message naming the field (rc ${rc}):\n${err}")
endif()
message(STATUS "render tool outputs: ok")
