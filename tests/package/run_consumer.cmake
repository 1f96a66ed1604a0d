# cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DCORE_ONLY=ON] -P run_consumer.cmake
# Installs the SDK into a scratch prefix, configures, builds and runs the
# consumer project in SOURCE_DIR. With CORE_ONLY the consumer asks for the
# core component alone; then the test also requires that configuring found
# none of GL's, EGL's, GLFW's or OpenImageIO's packages, and that the
# consumer's link line names none of them (nor another splatfx library).
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

function(step)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
# Unix Makefiles: the link line is then in one known file (link.txt).
step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -G "Unix Makefiles" -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
set(configure_output "${last_output}")
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
if(CORE_ONLY)
  set(program core_consumer)
else()
  set(program consumer)
endif()
step(${WORK_DIR}/build/${program})
message(STATUS "${last_output}")
if(NOT last_output MATCHES "consumer: ok")
  message(FATAL_ERROR "consumer did not report success:\n${last_output}")
endif()

if(CORE_ONLY)
  # What configuring looked for: a found package leaves <name>_DIR (config
  # packages) or <PREFIX>_FOUND (pkg-config) in the cache.
  file(READ ${WORK_DIR}/build/CMakeCache.txt cache)
  foreach(probe "OpenImageIO_DIR:PATH=[^\n]*[^-\n]" "glfw3_DIR:PATH=[^\n]*[^-\n]" "nlohmann_json_DIR:PATH=[^\n]*[^-\n]"
                "EPOXY_FOUND" "EGL_FOUND" "pkgcfg_lib_EPOXY" "pkgcfg_lib_EGL")
    if(cache MATCHES "${probe}")
      string(REGEX MATCH "[^\n]*${probe}[^\n]*" line "${cache}")
      message(FATAL_ERROR "find_package(splatfx COMPONENTS core) looked for a dependency of another component: ${line}")
    endif()
  endforeach()
  if(NOT cache MATCHES "glm_DIR:PATH=")
    message(FATAL_ERROR "the core consumer's cache has no glm_DIR: did find_package(splatfx COMPONENTS core) run at all?")
  endif()
  set(link_file ${WORK_DIR}/build/CMakeFiles/${program}.dir/link.txt)
  if(NOT EXISTS ${link_file})
    message(FATAL_ERROR "no link line at ${link_file}")
  endif()
  file(READ ${link_file} link_line)
  message(STATUS "core consumer link line: ${link_line}")
  if(NOT link_line MATCHES "libsplatfx_core\\.a")
    message(FATAL_ERROR "the core consumer does not link libsplatfx_core.a: ${link_line}")
  endif()
  string(TOLOWER "${link_line}" lower)
  foreach(forbidden "libgl[.xe_-]" "-lgl( |$)" "opengl" "egl" "glfw" "epoxy" "openimageio" "oiio" "splatfx_io" "splatfx_gl" "splatfx_context")
    if(lower MATCHES "${forbidden}")
      message(FATAL_ERROR "the core consumer's link line matches '${forbidden}': ${link_line}")
    endif()
  endforeach()
endif()
