# run_fuzz.cmake -- one harness's CTest run (fuzz/CMakeLists.txt):
#   cmake -DHARNESS=exe -DSEEDS=dir -DDICT=file -DWORK=dir -DSECONDS=n -DMAX_LEN=n -P run_fuzz.cmake
# Runs every seed, then fuzzes for SECONDS. The seed folder is only read: new
# inputs go to WORK/new, crashes, hangs and leaks to WORK/artifacts/ (named in
# the log), both emptied first.
#
# libFuzzer's -timeout is wall-clock time: on a loaded machine a quick input
# can be descheduled past it. A timeout therefore fails the test only when its
# input, run again alone, times out again (a real hang); otherwise the run is
# started again, at most three times in all.
foreach(var HARNESS SEEDS DICT WORK SECONDS MAX_LEN)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_fuzz.cmake: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/new)
set(dict_option "")
if(EXISTS ${DICT})
  set(dict_option -dict=${DICT})
endif()
foreach(attempt 1 2 3)
  set(artifacts ${WORK}/artifacts-${attempt})
  file(MAKE_DIRECTORY ${artifacts})
  execute_process(
    COMMAND ${HARNESS} -max_total_time=${SECONDS} -timeout=2 -rss_limit_mb=2048
            -max_len=${MAX_LEN} -print_final_stats=1 ${dict_option}
            -artifact_prefix=${artifacts}/ ${WORK}/new ${SEEDS}
    RESULT_VARIABLE status)
  if(status EQUAL 0)
    return()
  endif()
  file(GLOB found ${artifacts}/*)
  file(GLOB timeouts ${artifacts}/timeout-*)
  list(LENGTH found n_found)
  list(LENGTH timeouts n_timeouts)
  if(NOT (n_found EQUAL 1 AND n_timeouts EQUAL 1))
    message(FATAL_ERROR "${HARNESS}: exit status ${status}; the input that failed: ${found} "
                        "(replay: ${HARNESS} <input>; save it under ${SEEDS}/ once fixed)")
  endif()
  execute_process(COMMAND ${HARNESS} -timeout=2 -runs=3 ${timeouts} RESULT_VARIABLE replay)
  if(NOT replay EQUAL 0)
    message(FATAL_ERROR "${HARNESS}: a hang (over 2 s, again when replayed alone): ${timeouts} "
                        "(replay: ${HARNESS} <input>; save it under ${SEEDS}/ once fixed)")
  endif()
  message(WARNING "${HARNESS}: ${timeouts} timed out but runs in time alone (machine busy?); "
                  "fuzzing again")
endforeach()
message(WARNING "${HARNESS}: three timeouts that did not repeat alone: the machine is too busy "
                "for this fuzzing budget; passing")
