# End-to-end test of `frenetic report` (run by ctest as report_cli):
#   cmake -DFRENETIC=... -DFIXTURE=... -DOUT=... -P tests/report/cli_test.cmake
# Writes synthetic records with frenetic_report_fixture, then checks the command's output,
# exit codes and one-line errors.
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${FIXTURE} ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "fixture failed: ${rc}")
endif()

function(expect_run expected_rc stdout_regex stderr_regex)
  execute_process(COMMAND ${FRENETIC} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL expected_rc)
    message(FATAL_ERROR "frenetic ${ARGN}: exit ${rc}, expected ${expected_rc}\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "${stdout_regex}")
    message(FATAL_ERROR "frenetic ${ARGN}: stdout does not match ${stdout_regex}:\n${out}")
  endif()
  if(NOT err MATCHES "${stderr_regex}")
    message(FATAL_ERROR "frenetic ${ARGN}: stderr does not match ${stderr_regex}:\n${err}")
  endif()
  string(REPLACE ";" " " args "${ARGN}")
  message(STATUS "ok: frenetic ${args}")
endfunction()

file(REMOVE ${OUT}/cli.html)
expect_run(0 "wrote .*cli.html .*300 exchanges" "^$" report ${OUT}/incident.jsonl -o ${OUT}/cli.html)
file(READ ${OUT}/cli.html page LIMIT 200)
if(NOT page MATCHES "^<!doctype html>")
  message(FATAL_ERROR "cli.html is not the page: ${page}")
endif()
expect_run(0 "\"exchanges\":300.*\"incidents\":0" "" report ${OUT}/run.jsonl -o ${OUT}/cli.html
           --json --max-candidates 2)
# The default output sits next to the record.
file(REMOVE ${OUT}/run.html)
expect_run(0 "run.html" "" report ${OUT}/run.jsonl)
if(NOT EXISTS ${OUT}/run.html)
  message(FATAL_ERROR "no default output ${OUT}/run.html")
endif()
expect_run(1 "^$" "^frenetic report: ${OUT}/missing.jsonl: cannot open[^\n]*\n$"
           report ${OUT}/missing.jsonl -o ${OUT}/x.html)
# A record without its header line.
file(STRINGS ${OUT}/run.jsonl lines LIMIT_COUNT 3)
list(GET lines 1 second)
file(WRITE ${OUT}/noheader.jsonl "${second}\n")
expect_run(1 "^$" "noheader.jsonl:1: record has no header" report ${OUT}/noheader.jsonl)
# A malformed line: a warning naming its line, the rest kept.
list(GET lines 0 first)
list(GET lines 2 third)
file(WRITE ${OUT}/broken.jsonl "${first}\n${second}\n{oops\n${third}\n")
expect_run(0 "2 exchanges.*1 lines skipped" "line 3: not a JSON object" report
           ${OUT}/broken.jsonl -o ${OUT}/broken.html)
expect_run(0 "--max-candidates.*default: 8" "" report --help)
expect_run(105 "" "max-candidates" report ${OUT}/run.jsonl --max-candidates 0)
