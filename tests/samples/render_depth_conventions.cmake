# splatfx-render (or a samples/common sample: no SCENE) in the engines' depth
# conventions (issue 26): --clip-01 and
# --reverse-z (reverse-Z, [0, 1] clip depth, float depth) must give the
# default run's frame within one 8-bit step per channel (idiff -fail 0.004):
# the PNGs are RGBA8, and the conventions compute the same float values up
# to a few roundings, which can move a channel across a rounding boundary by
# one step. The host target is RGBA8 too, and every splat layer over a pixel
# is blended into it and rounded there, so a one-step difference under a
# layer can carry and meet a second rounding: two steps are allowed on at
# most 0.05 % of the pixels (measured: 1 pixel of 19200 on the cow with the
# presets' splat variation; idiff -hardfail 0.0081), never three.
# Inputs: RENDER, IDIFF, SCENE (splatfx-render only), NAME (the frames' name), OUT.
include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)
file(REMOVE_RECURSE ${OUT})
if(SCENE)
  set(common ${SCENE} --frames 1 --size 160x120 --quiet)
else()
  set(common --frames 1 --size 160x120)
endif()
render(--out ${OUT}/default)
foreach(variant "clip01;--clip-01" "reversez;--reverse-z")
  list(GET variant 0 dir)
  list(SUBLIST variant 1 -1 flags)
  render(--out ${OUT}/${dir} ${flags})
  execute_process(COMMAND ${IDIFF} -fail 0.004 -failpercent 0.05 -warn 0.004 -warnpercent 0.05 -hardfail 0.0081 ${OUT}/default/${NAME}_0000.png ${OUT}/${dir}/${NAME}_0000.png
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "splatfx-render ${flags} differs from the default convention (idiff exit ${rc}):\n${out}\n${err}")
  endif()
endforeach()
