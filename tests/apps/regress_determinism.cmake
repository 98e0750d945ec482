# Runs `dovetail regress` on the shipped scenarios at 1, 2 and 8 collision
# threads, and at 1 thread a second time: every run must pass, and every
# scenario's JSON report must be byte-identical across the four runs. The
# first run also writes JUnit XML and the HTML report.
#
#   cmake -DPROGRAM=<dovetail> -DSCENARIOS=<folder> -DOUT=<folder> -P regress_determinism.cmake

foreach(run 1:1 2:2 3:8 4:1)
  string(REPLACE ":" ";" run "${run}")
  list(GET run 0 index)
  list(GET run 1 threads)
  file(REMOVE_RECURSE "${OUT}/${index}")
  set(extra)
  if(index EQUAL 1)
    set(extra --junit "${OUT}/1/junit.xml" --html "${OUT}/1/report.html")
  endif()
  execute_process(COMMAND "${PROGRAM}" regress "${SCENARIOS}" --out "${OUT}/${index}" --threads ${threads}
                          -j 2 ${extra}
                  RESULT_VARIABLE code OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  message(STATUS "run ${index} (${threads} threads):\n${stdout}${stderr}")
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "regress at ${threads} threads exited with ${code}")
  endif()
endforeach()
file(GLOB reports RELATIVE "${OUT}/1" "${OUT}/1/*.json")
list(LENGTH reports count)
if(count EQUAL 0)
  message(FATAL_ERROR "no reports in ${OUT}/1")
endif()
foreach(report ${reports})
  foreach(index 2 3 4)
    execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files "${OUT}/1/${report}" "${OUT}/${index}/${report}"
                    RESULT_VARIABLE differ)
    if(NOT differ EQUAL 0)
      message(FATAL_ERROR "${report} differs between run 1 and run ${index}")
    endif()
  endforeach()
endforeach()
message(STATUS "${count} reports identical over four runs")
