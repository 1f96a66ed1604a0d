# splatfx-render --assemble takes only frames a run of this sequence wrote:
# each run records its settings and every frame's hash (DIR/.<set>.run), and
# a frame from another --seed, a frame replaced since, or a PNG no run wrote
# is refused, named, with no GIF written or replaced.
# Inputs: RENDER, SCENE (Fig. 1, output.name "figure1", seed 1), OUT.
file(REMOVE_RECURSE ${OUT})
set(common ${SCENE} --frames 4 --size 48x32 --quiet)

include(${CMAKE_CURRENT_LIST_DIR}/render_functions.cmake)

# --assemble in DIR must fail matching REGEX and leave DIR/figure1.gif as it was (or absent).
function(assemble_refused dir regex)
  set(before "")
  if(EXISTS ${dir}/figure1.gif)
    file(SHA256 ${dir}/figure1.gif before)
  endif()
  execute_process(COMMAND ${RENDER} ${common} --out ${dir} --assemble RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "${regex}")
    message(FATAL_ERROR "--assemble in ${dir}: expected a refusal matching '${regex}' (rc ${rc}):\n${out}\n${err}")
  endif()
  set(after "")
  if(EXISTS ${dir}/figure1.gif)
    file(SHA256 ${dir}/figure1.gif after)
  endif()
  if(NOT before STREQUAL after)
    message(FATAL_ERROR "a refused --assemble changed ${dir}/figure1.gif")
  endif()
endfunction()

render(--out ${OUT}/full)
render(--out ${OUT}/farm --range 0-1)
render(--out ${OUT}/farm --range 2-3)
render(--out ${OUT}/farm --assemble)
expect_same(${OUT}/full/figure1.gif ${OUT}/farm/figure1.gif "the assembled GIF vs the full run's")

# A task rendered with another seed: its frames are named with the setting.
render(--out ${OUT}/farm --range 2-3 --seed 7)
assemble_refused(${OUT}/farm
  "--assemble: 2 of the 4 frames are not from this sequence: '${OUT}/farm/figure1_0002.png': rendered with seed 7 \\(this sequence: 1\\); '${OUT}/farm/figure1_0003.png': rendered with seed 7 \\(this sequence: 1\\); render them again with this sequence's options \\(--range\\)")

# The task again with the sequence's seed, then a frame replaced by another
# PNG of the right size (a copy of frame 0).
render(--out ${OUT}/farm --range 2-3)
render(--out ${OUT}/farm --assemble)
configure_file(${OUT}/farm/figure1_0000.png ${OUT}/farm/figure1_0003.png COPYONLY)
assemble_refused(${OUT}/farm
  "--assemble: 1 of the 4 frames are not from this sequence: '${OUT}/farm/figure1_0003.png': it is not the file its run wrote \\(replaced or changed since\\)")

# The full run's frames copied without their records: no run wrote them here.
file(MAKE_DIRECTORY ${OUT}/copied)
file(GLOB pngs ${OUT}/full/*.png)
file(COPY ${pngs} DESTINATION ${OUT}/copied)
assemble_refused(${OUT}/copied
  "--assemble: 4 of the 4 frames are not from this sequence: '${OUT}/copied/figure1_0000.png': no run record in '${OUT}/copied' lists it \\(not written by splatfx-render\\)")
message(STATUS "render tool assemble: ok")
