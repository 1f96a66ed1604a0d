# splatfx-render: a good run leaves every frame and the GIF; a failed run
# (--abort-after, or a bad scene file) leaves no GIF and no staging folder;
# a second writer of the set, a user's file named like an output and an
# empty --out are refused with a message, and nothing is lost.
# Inputs: RENDER, SCENE (Fig. 1, output.name "figure1"), OUT, FLOCK (util-linux flock, may be empty).
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

# A file hash of every file in a folder, hidden ones included, to show that a refused run changed nothing.
function(folder_state var dir)
  file(GLOB files LIST_DIRECTORIES false ${dir}/* ${dir}/.*)
  list(SORT files)
  set(state "")
  foreach(f ${files})
    file(SHA256 ${f} h)
    list(APPEND state "${f}=${h}")
  endforeach()
  set(${var} "${state}" PARENT_SCOPE)
endfunction()

function(expect_refused what regex)
  if(rc EQUAL 0 OR NOT err MATCHES "${regex}")
    message(FATAL_ERROR "${what}: expected a refusal matching '${regex}' (rc ${rc}):\n${out}\n${err}")
  endif()
endfunction()

# A user's own files named like the outputs, in no record (the first run into
# a folder): refused before rendering, naming them; they keep their bytes.
file(MAKE_DIRECTORY ${OUT}/users)
file(WRITE ${OUT}/users/figure1_0001.png "the user's frame")
file(WRITE ${OUT}/users/figure1.gif "the user's GIF")
folder_state(before ${OUT}/users)
execute_process(COMMAND ${RENDER} ${SCENE} --out ${OUT}/users --frames 3 --size 96x64 --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
expect_refused("a user's files in the way"
  "refusing to overwrite '${OUT}/users/figure1_0001.png', '${OUT}/users/figure1.gif': no output record in '${OUT}/users' lists them, so splatfx did not write them; move them away or choose another output folder")
folder_state(after ${OUT}/users)
if(NOT before STREQUAL after)
  message(FATAL_ERROR "a refused run changed the folder:\nbefore ${before}\nafter  ${after}")
endif()
string(FIND "${out}" "frame 0" rendered)
if(NOT rendered EQUAL -1)
  message(FATAL_ERROR "the refusal must come before any frame is rendered:\n${out}")
endif()

# A second writer of a set another process holds (flock stands in for a
# render still running, deterministically): refused at once, naming the
# folder; the published set is untouched.
if(FLOCK)
  folder_state(before ${OUT}/good)
  execute_process(COMMAND ${FLOCK} ${OUT}/good/.figure1.lock ${RENDER} ${SCENE} --out ${OUT}/good --frames 3 --size 96x64 --quiet
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  expect_refused("a second writer"
    "splatfx-render: output folder '${OUT}/good' is in use: another render is writing the set 'figure1' there; wait for it to finish or give this run another output folder")
  file(REMOVE ${OUT}/good/.figure1.lock) # flock's own file
  folder_state(after ${OUT}/good)
  if(NOT before STREQUAL after)
    message(FATAL_ERROR "a refused second writer changed the folder:\nbefore ${before}\nafter  ${after}")
  endif()
endif()

# An empty --out (it wrote into the current folder): refused, the current folder untouched.
file(MAKE_DIRECTORY ${OUT}/cwd)
execute_process(COMMAND ${RENDER} ${SCENE} --out "" --frames 1 --size 96x64 --quiet WORKING_DIRECTORY ${OUT}/cwd
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
expect_refused("an empty --out" "splatfx-render: --out is empty: name the output folder \\('\\.' for the current one\\)")
file(GLOB written ${OUT}/cwd/* ${OUT}/cwd/.*)
if(written)
  message(FATAL_ERROR "--out \"\" wrote into the current folder: ${written}")
endif()
message(STATUS "render tool outputs: ok")
