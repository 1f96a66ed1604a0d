# splatfx-bench accuracy --replot on a folder named like a shell injection
# (issue 13): gnuplot runs inside that folder (its print lands there) and the
# name's "touch" never runs.
# cmake -DBENCH=<splatfx-bench> -DWORK=<scratch folder> -P plot_no_shell.cmake
file(REMOVE_RECURSE "${WORK}")
set(hostile "${WORK}/o'; touch INJECTED; echo '")
file(MAKE_DIRECTORY "${hostile}")
file(WRITE "${hostile}/accuracy.gp" "set print 'printed.txt'\nprint 'gnuplot ran here'\n")
execute_process(COMMAND "${BENCH}" accuracy --replot --out "${hostile}" WORKING_DIRECTORY "${WORK}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(GLOB_RECURSE injected "${WORK}/INJECTED" "${WORK}/*/INJECTED")
if(EXISTS "${WORK}/INJECTED" OR injected)
  message(FATAL_ERROR "the folder name ran as a shell command (INJECTED was created)\n${out}${err}")
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "replot failed (${rc}):\n${out}${err}")
endif()
if(NOT EXISTS "${hostile}/printed.txt")
  message(FATAL_ERROR "gnuplot did not run inside '${hostile}'\n${out}${err}")
endif()
