# SPLATFX_FUZZ=ON (issue 13, item 7): a clang build in which the SDK itself,
# not only the harness, carries libFuzzer's coverage counters and ASan+UBSan,
# so the fuzzers in tests/fuzz/ see (and are guided by) the parser's branches.
# tools/instrumented-build.sh configures it in build-asan/ for tools/sanitize.sh and
# tools/fuzz.sh alike (debug info from the build type: -O1 -g1 there). Included from the top-level
# CMakeLists before any target is made, so every target is instrumented.
option(SPLATFX_FUZZ "Instrument everything for libFuzzer and build the tests/fuzz targets (needs clang)" OFF)
if(SPLATFX_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "SPLATFX_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++ (tools/fuzz.sh does)")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
