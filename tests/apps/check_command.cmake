# Runs one `dovetail` command line and checks its exit code, output and files.
#
#   cmake -DPROGRAM=<exe> -DARGS=<arg|arg|...> -DEXPECT_EXIT=<code>
#         [-DEXPECT_STDOUT=<regex>] [-DEXPECT_STDERR=<regex>] [-DREJECT_STDOUT=<regex>]
#         [-DEXPECT_FILE=<path> -DEXPECT_FILE_CONTENT=<exact text>]
#         [-DEXPECT_FILE=<path> -DEXPECT_FILE_MATCHES=<regex>]
#         [-DREMOVE_FIRST=<path>] [-DKEEP=<path>] -P check_command.cmake
#
# KEEP writes <path> with a known text before the run; the run must leave it as it was
# (a command that fails on its inputs does not touch an existing output).
#
# Arguments are separated by `|`. EXPECT_STDOUT / EXPECT_STDERR / EXPECT_FILE_MATCHES
# may hold several regexes, all required, separated by `&&` (they become a CMake list, so a
# regex must not contain an unbalanced `[`).

if(NOT DEFINED PROGRAM OR NOT DEFINED EXPECT_EXIT)
  message(FATAL_ERROR "check_command.cmake needs PROGRAM and EXPECT_EXIT")
endif()
string(REPLACE "|" ";" argv "${ARGS}")
if(DEFINED REMOVE_FIRST)
  file(REMOVE_RECURSE "${REMOVE_FIRST}")
endif()

set(keep_text "written before the run; must be kept\n")
if(DEFINED KEEP)
  file(WRITE "${KEEP}" "${keep_text}")
endif()

execute_process(COMMAND "${PROGRAM}" ${argv}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)

set(problems "")
if(NOT "${code}" STREQUAL "${EXPECT_EXIT}")
  string(APPEND problems "exit code ${code}, expected ${EXPECT_EXIT}\n")
endif()
foreach(stream stdout stderr)
  string(TOUPPER ${stream} upper)
  if(stream STREQUAL "stdout")
    set(text "${out}")
  else()
    set(text "${err}")
  endif()
  if(DEFINED EXPECT_${upper})
    string(REPLACE "&&" ";" wanted "${EXPECT_${upper}}")
    foreach(regex IN LISTS wanted)
      if(NOT text MATCHES "${regex}")
        string(APPEND problems "${stream} does not match '${regex}'\n")
      endif()
    endforeach()
  endif()
endforeach()
if(DEFINED KEEP)
  file(READ "${KEEP}" kept)
  if(NOT kept STREQUAL keep_text)
    string(APPEND problems "${KEEP} was changed; it holds:\n${kept}\n")
  endif()
endif()
if(DEFINED REJECT_STDOUT AND out MATCHES "${REJECT_STDOUT}")
  string(APPEND problems "stdout matches '${REJECT_STDOUT}', which it must not\n")
endif()
if(DEFINED EXPECT_FILE)
  if(NOT EXISTS "${EXPECT_FILE}")
    string(APPEND problems "${EXPECT_FILE} was not written\n")
  else()
    file(READ "${EXPECT_FILE}" content)
    if(DEFINED EXPECT_FILE_CONTENT AND NOT content STREQUAL "${EXPECT_FILE_CONTENT}")
      string(APPEND problems "${EXPECT_FILE} holds:\n${content}\nexpected:\n${EXPECT_FILE_CONTENT}\n")
    endif()
    if(DEFINED EXPECT_FILE_MATCHES)
      string(REPLACE "&&" ";" wanted "${EXPECT_FILE_MATCHES}")
      foreach(regex IN LISTS wanted)
        if(NOT content MATCHES "${regex}")
          string(APPEND problems "${EXPECT_FILE} does not match '${regex}'; it holds:\n${content}\n")
        endif()
      endforeach()
    endif()
  endif()
endif()

if(problems)
  string(REPLACE ";" " " shown "${argv}")
  message(FATAL_ERROR "dovetail ${shown}\n${problems}--- stdout:\n${out}\n--- stderr:\n${err}")
endif()
