# Opens the regress HTML report in headless Chromium, which must load it and
# write a screenshot (kept for a look by eye); the page's summary must be in
# the DOM the browser built.
#
#   cmake -DCHROMIUM=<chromium> -DHTML=<report.html> -DSHOT=<png> -P html_in_browser.cmake

if(NOT EXISTS "${HTML}")
  message(FATAL_ERROR "${HTML} was not written")
endif()
file(REMOVE "${SHOT}")
set(flags --headless --no-sandbox --disable-gpu --hide-scrollbars --no-first-run
          --user-data-dir=${SHOT}.profile)
execute_process(COMMAND "${CHROMIUM}" ${flags} --window-size=1200,1600 --screenshot=${SHOT} "file://${HTML}"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 240)
if(NOT code EQUAL 0 OR NOT EXISTS "${SHOT}")
  message(FATAL_ERROR "chromium could not screenshot ${HTML} (exit ${code}):\n${err}")
endif()
file(SIZE "${SHOT}" size)
if(size LESS 20000)
  message(FATAL_ERROR "${SHOT} is only ${size} bytes: the page did not render")
endif()
execute_process(COMMAND "${CHROMIUM}" ${flags} --dump-dom "file://${HTML}"
                RESULT_VARIABLE code OUTPUT_VARIABLE dom ERROR_VARIABLE err TIMEOUT 240)
if(NOT dom MATCHES "id=\"summary\">[0-9]+ of [0-9]+ scenarios passed")
  message(FATAL_ERROR "the browser's DOM has no summary:\n${err}")
endif()
file(REMOVE_RECURSE "${SHOT}.profile")
message(STATUS "screenshot: ${SHOT} (${size} bytes)")
