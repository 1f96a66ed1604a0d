# cmake -DBUILD_DIR=... -DPROBES=control,epoxy,... -P check_core_guard.cmake
# Builds each core probe (tests/package/CMakeLists.txt). The control must
# build; every other probe must fail, and fail because of core_guard's #error,
# so that a probe broken for another reason (a typo, a missing file) cannot
# pass this test.
string(REPLACE "," ";" probes "${PROBES}")
set(failures "")
foreach(probe ${probes})
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target splatfx_core_probe_${probe}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(probe STREQUAL "control")
    if(NOT rc EQUAL 0)
      string(APPEND failures "control probe (core header only) did not build:\n${out}\n${err}\n")
    endif()
  elseif(rc EQUAL 0)
    string(APPEND failures "probe '${probe}': a core source including a forbidden header BUILT\n")
  elseif(NOT "${out}${err}" MATCHES "splatfx::core is GL-free and image-file-free")
    string(APPEND failures "probe '${probe}' failed, but not with the core_guard message:\n${out}\n${err}\n")
  else()
    message(STATUS "probe '${probe}': fails to build, as it must")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "${failures}")
endif()
