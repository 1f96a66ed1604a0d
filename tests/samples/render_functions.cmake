# Shared by the splatfx-render test scripts: render(ARGS...) runs RENDER with the
# script's ${common} arguments and ARGS, failing on a non-zero exit;
# expect_same(a b what) fails unless the two files are byte for byte the same.
function(render)
  execute_process(COMMAND ${RENDER} ${common} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "splatfx-render ${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
endfunction()

function(expect_same a b what)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${a} ${b} RESULT_VARIABLE differ)
  if(differ)
    message(FATAL_ERROR "${what}: '${a}' and '${b}' differ")
  endif()
endfunction()
