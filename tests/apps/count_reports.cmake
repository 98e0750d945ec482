# Checks that a regress run wrote a JSON report for each of COUNT scenarios,
# failing or not.
#
#   cmake -DDIR=<out folder> -DCOUNT=<n> -P count_reports.cmake

file(GLOB reports "${DIR}/*.json")
list(LENGTH reports found)
if(NOT found EQUAL COUNT)
  message(FATAL_ERROR "${DIR}: ${found} reports, expected ${COUNT}")
endif()
foreach(report ${reports})
  file(READ "${report}" text)
  if(NOT text MATCHES "\"outcome\": \"(passed|failed|error)\"")
    message(FATAL_ERROR "${report}: no outcome")
  endif()
endforeach()
