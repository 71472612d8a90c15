#!/usr/bin/env bash
# The test command (README quick start, and CI through .ci/run): install what is missing,
# build into the git-ignored workspace, run every gtest and rostest, print
# "N passed, N failed, N skipped" and exit non-zero on any failure.
# `catkin_make run_tests` exits 0 even when tests fail: the verdict is catkin_test_results.
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$here/ws_env.sh"

bash "$here/setup_deps.sh" || { echo "run_tests: installing dependencies failed"; echo "0 passed, 1 failed"; exit 1; }
bash "$here/build.sh" || { echo "run_tests: build failed"; echo "0 passed, 1 failed"; exit 1; }
bash "$here/build.sh" tests || { echo "run_tests: building the tests failed"; echo "0 passed, 1 failed"; exit 1; }
# The fuzz target is a test binary too: built here (when its inputs changed), run below. A
# failed build is reported by the run below, with its verdict.
FUZZ_BUILD_ONLY=1 bash "$here/fuzz.sh" > /dev/null 2>&1 || true

# The tests' Python nodes import this workspace's message and tool modules (jackal_msgs,
# jackal_aic, jackal_aic_tools): run them in the workspace's environment.
set +u  # the catkin setup scripts read unset variables
source_ws
set -u
results="$ws/build/test_results"
rm -rf "$results"
cd "$ws"
# -j1: the rostests run the nodes on the wall clock; side by side on a 2-core machine they
# would measure the machine. Each runs once: no retries.
catkin_make "${catkin_args[@]}" run_tests -j1 2>&1 | tee "$ws/run_tests.log" | grep -E "^\[ *(RUN|OK|FAILED|PASSED) *\]|^\[ROSTEST\]|^\[Testcase|FAILURE|Error|error:" || true

# The libFuzzer target over the core (clang, sanitizers) from a fixed seed over the committed
# corpus, a fixed number of inputs (the time limit is a backstop): one more result, judged by
# its exit code (0 clean, 1 failed, 2 no clang/libFuzzer: skipped).
FUZZ_SEED="${FUZZ_SEED:-1}" FUZZ_RUNS="${FUZZ_RUNS:-60000}" bash "$here/fuzz.sh" "${FUZZ_SECONDS:-120}"
fuzz_rc=$?

# The benchmark of the controller's update steps: its figures in the log, no bound judged; it
# must run (a crash fails the suite). Short: a few milliseconds per benchmark.
bench="$ws/devel/lib/jackal_aic/bench_controller"
if [ -x "$bench" ]; then
  echo "run_tests: bench_controller (figures only, not judged)"
  "$bench" --benchmark_min_time="${BENCH_MIN_TIME:-0.05}"
  bench_rc=$?
else
  echo "run_tests: bench_controller not built (Google Benchmark missing): skipped"
  bench_rc=skip
fi

summary="$(catkin_test_results --verbose "$results" 2>&1)"
verdict=$?
echo "$summary" | grep -v "^Skipping" | tail -40
line="$(echo "$summary" | grep -E '^Summary:' | tail -1)"
tests=$(echo "$line" | sed -nE 's/.* ([0-9]+) tests.*/\1/p')
errors=$(echo "$line" | sed -nE 's/.* ([0-9]+) errors.*/\1/p')
failures=$(echo "$line" | sed -nE 's/.* ([0-9]+) failures.*/\1/p')
skipped=$(echo "$line" | sed -nE 's/.* ([0-9]+) skipped.*/\1/p')
tests=${tests:-0}; errors=${errors:-0}; failures=${failures:-0}; skipped=${skipped:-0}
failed=$((errors + failures))
passed=$((tests - failed - skipped))
if [ "$tests" -eq 0 ]; then
  echo "run_tests: no test results found under $results"
  failed=$((failed + 1))
fi
[ "$verdict" -ne 0 ] && [ "$failed" -eq 0 ] && failed=1
case "$fuzz_rc" in
  0) passed=$((passed + 1)) ;;
  2) skipped=$((skipped + 1)) ;;
  *) echo "run_tests: FAILURE: the fuzz run failed (exit $fuzz_rc; dev/fuzz.sh, log in .ws/fuzz)"
     failed=$((failed + 1)) ;;
esac
case "$bench_rc" in
  0) passed=$((passed + 1)) ;;
  skip) skipped=$((skipped + 1)) ;;
  *) echo "run_tests: FAILURE: bench_controller exited $bench_rc"
     failed=$((failed + 1)) ;;
esac
# The installed package (catkin_make install) runs the demo launch: dev/check_install.sh.
if bash "$here/check_install.sh"; then
  passed=$((passed + 1))
else
  echo "run_tests: FAILURE: the installed package does not run the demo launch (dev/check_install.sh)"
  failed=$((failed + 1))
fi
# Every failure's message, one short block each, last: a log cut to its tail still says why.
python3 "$here/failure_summary.py" "$results" || true
echo "${passed} passed, ${failed} failed, ${skipped} skipped"
[ "$failed" -eq 0 ]
