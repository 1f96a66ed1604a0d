# splatfx-render --hdr (issue 26 item 3, issue 27 item 5): an RGBA16F target
# with HDR lit colours. A smoke under a sun of intensity 6 (lit colours up to
# about 4): the EXR beside the PNG is half float and holds values above 1 (the
# run without --hdr cannot: its lit colours stop at 1), the PNG is that EXR
# clamped at 1 and rounded to 8 bits (byte for byte what oiiotool makes of
# it), and --hdr with --srgb (an 8-bit target) is refused.
# The values against the double-precision references: HdrLitGL.* (test_lighting_gl).
# Inputs: RENDER, OIIOTOOL, IDIFF, PYTHON, SCENE, OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
file(REMOVE_RECURSE ${OUT})
set(common ${SCENE} --quiet)
execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/hdr --hdr RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "RGBA16F")
  message(FATAL_ERROR "splatfx-render --hdr (${rc}) failed or did not say so:\n${out}\n${err}")
endif()
render(--out ${OUT}/ldr)
foreach(f ${OUT}/hdr/hdr-smoke_0000.exr ${OUT}/hdr/hdr-smoke_0000.png ${OUT}/ldr/hdr-smoke_0000.png)
  if(NOT EXISTS ${f})
    message(FATAL_ERROR "missing ${f}")
  endif()
endforeach()
if(EXISTS ${OUT}/ldr/hdr-smoke_0000.exr)
  message(FATAL_ERROR "a run without --hdr wrote an EXR")
endif()

function(max_rgb file var)
  execute_process(COMMAND ${OIIOTOOL} --stats ${file} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "Stats Max: ([0-9.e+-]+) ([0-9.e+-]+) ([0-9.e+-]+)")
    message(FATAL_ERROR "oiiotool --stats ${file} (${rc}):\n${out}")
  endif()
  execute_process(COMMAND ${PYTHON} -c "print(max(${CMAKE_MATCH_1}, ${CMAKE_MATCH_2}, ${CMAKE_MATCH_3}))" OUTPUT_VARIABLE m OUTPUT_STRIP_TRAILING_WHITESPACE)
  set(${var} ${m} PARENT_SCOPE)
  if(out MATCHES "NanCount: [0-9 ]*[1-9]" OR out MATCHES "InfCount: [0-9 ]*[1-9]")
    message(FATAL_ERROR "${file} holds NaN or inf:\n${out}")
  endif()
endfunction()
max_rgb(${OUT}/hdr/hdr-smoke_0000.exr hdr)
message(STATUS "brightest channel of the --hdr EXR: ${hdr}")
execute_process(COMMAND ${PYTHON} -c "import sys; sys.exit(0 if float('${hdr}') > 1.5 else 1)" RESULT_VARIABLE above)
if(NOT above EQUAL 0)
  message(FATAL_ERROR "--hdr kept no value above 1.5 (brightest ${hdr}): the lit colours were clamped")
endif()

# The PNG of an --hdr run is its EXR clamped to [0, 1] at 8 bits.
execute_process(COMMAND ${OIIOTOOL} ${OUT}/hdr/hdr-smoke_0000.exr --clamp:min=0:max=1 -d uint8 -o ${OUT}/clamped.png RESULT_VARIABLE rc)
execute_process(COMMAND ${IDIFF} -fail 0.5e-3 -warn 0.5e-3 ${OUT}/clamped.png ${OUT}/hdr/hdr-smoke_0000.png RESULT_VARIABLE differ OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT differ EQUAL 0)
  message(FATAL_ERROR "the --hdr PNG is not its EXR clamped at 1 (${rc}, ${differ}):\n${out}")
endif()

execute_process(COMMAND ${RENDER} ${common} --out ${OUT}/both --hdr --srgb RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT "${out}${err}" MATCHES "excludes")
  message(FATAL_ERROR "--hdr --srgb must be refused (exit 2, CLI11's 'excludes'), got ${rc}:\n${out}\n${err}")
endif()
