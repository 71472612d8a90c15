#!/usr/bin/env bash
# Build the libFuzzer target over the core (test/fuzz/fuzz_core.cpp) with clang, address and
# undefined-behaviour sanitizers, and run it for a bounded number of inputs from a fixed seed.
#   [FUZZ_WORKERS=N] [FUZZ_SEED=S] [FUZZ_RUNS=R] dev/fuzz.sh [SECONDS] [JUNIT_XML]
# Reproducible: every run starts from the committed corpus (test/fuzz/corpus, inputs of past
# findings) and an empty working corpus, with libFuzzer's -seed fixed (FUZZ_SEED, default 1;
# worker k uses FUZZ_SEED + k - 1). FUZZ_RUNS (default 0 = unbounded) caps the executed inputs
# per worker: with it the run is the same on every machine as long as SECONDS does not end it
# first. SECONDS: the time limit (default 60), a backstop for FUZZ_RUNS or, without it, the length.
# JUNIT_XML: if given, the verdict is also written there as a one-test JUnit file.
# FUZZ_WORKERS (default 1): that many fuzzing processes side by side, for long runs; the printed
# execution count is their sum. FUZZ_OUT (default .ws/fuzz): the folder of the binary, the
# working corpus and the logs (a long run in its own folder does not collide with the suite's).
# FUZZ_KEEP_CORPUS=1 keeps the working corpus of earlier runs (long exploratory runs); by default
# it is emptied first, so a run's inputs do not depend on the runs before it.
# Exit 0 = clean; 1 = a crash, a sanitizer report or a finding of the target (non-finite /
# over-limit action, ...), or the target failed to build; 2 = clang or libFuzzer missing
# (reported as a skipped test). dev/run_tests.sh takes its verdict from this exit code.
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
seconds="${1:-60}"
xml="${2:-}"
out="${FUZZ_OUT:-$repo/.ws/fuzz}"
seed="${FUZZ_SEED:-1}"
runs="${FUZZ_RUNS:-0}"
runs_arg="$runs"; [ "$runs" -gt 0 ] || runs_arg=-1  # libFuzzer: -1 = unbounded
[ "${FUZZ_KEEP_CORPUS:-0}" = 1 ] || rm -rf "$out/corpus"
mkdir -p "$out/corpus"
rm -f "$out"/crash-* "$out"/timeout-* "$out"/oom-* "$out"/leak-*
log="$out/fuzz_core.log"

junit() {  # junit STATUS(pass|fail|skip) MESSAGE
  [ -n "$xml" ] || return 0
  mkdir -p "$(dirname "$xml")"
  local failures=0 skipped=0 body=""
  local msg
  msg="$(printf '%s' "$2" | sed -e 's/&/\&amp;/g' -e 's/</\&lt;/g' -e 's/>/\&gt;/g' -e 's/"/\&quot;/g')"
  case "$1" in
    fail) failures=1; body="<failure message=\"${msg}\"/>" ;;
    skip) skipped=1; body="<skipped message=\"${msg}\"/>" ;;
  esac
  cat > "$xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<testsuite name="fuzz_core" tests="1" failures="${failures}" errors="0" skipped="${skipped}">
  <testcase classname="jackal_aic.fuzz" name="fuzz_core_${seconds}s">${body}</testcase>
</testsuite>
XML
}

cxx="$(command -v clang++ || true)"
if [ -z "$cxx" ]; then
  echo "fuzz: clang++ not found (apt-get install clang); skipped"
  junit skip "clang++ not found"
  exit 2
fi
# Coverage feedback from jackal_aic's code only, not from Eigen's kernels, and no UBSan checks
# inside Eigen (the two lists say why); AddressSanitizer covers Eigen as well.
flags=(-std=c++17 -g -O2 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
       -fsanitize-coverage-ignorelist="$repo/test/fuzz/coverage_ignorelist.txt"
       -fsanitize-ignorelist="$repo/test/fuzz/ubsan_ignorelist.txt"
       -I"$repo/include" -I/usr/include/eigen3)
sources=("$repo"/src/params/{aic_params,param_violation,param_spec,param_schema,node_params,fdi_params,diff_drive_params}.cpp
         "$repo"/src/aic/{generalizer,skid_steer_model,goal_rate,reference_model,action_delay_line,action_prior,rest_release,goal_response,anti_windup,action_slew_limit,wheel_loop_model,robot_belief,latency_action,latency_learner,controller,separation_learner,precision_learner}.cpp
         "$repo"/src/safety/fault_monitor.cpp "$repo"/src/loop/{diff_drive,fault_test}.cpp
         "$repo/test/fuzz/fuzz_core.cpp")
# The binary is rebuilt only when its inputs change: a stamp holds the SHA-256 of the compiler's
# version, the flags and every source and header it can include (the core's headers, the
# sources, the two lists). dev/run_tests.sh builds it with the other tests (FUZZ_BUILD_ONLY=1)
# so that the suite's run is the fuzzing alone.
stamp="$out/fuzz_core.inputs"
inputs="$( { "$cxx" --version; printf '%s\n' "${flags[@]}";
             cat "${sources[@]}" "$repo"/test/fuzz/*.txt;
             find "$repo/include" -type f -name '*.hpp' | LC_ALL=C sort | xargs cat; } | sha256sum | cut -d' ' -f1)"
if [ -x "$out/fuzz_core" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$inputs" ]; then
  echo "fuzz: fuzz_core is up to date"
elif ! { rm -f "$stamp"; "$cxx" "${flags[@]}" "${sources[@]}" -o "$out/fuzz_core" > "$out/build.log" 2>&1; }; then
  if grep -q -- "-fsanitize=fuzzer\|libclang_rt.fuzzer\|FuzzedDataProvider" "$out/build.log"; then
    echo "fuzz: this clang has no libFuzzer; skipped"; tail -5 "$out/build.log"
    junit skip "clang without libFuzzer"
    exit 2
  fi
  echo "fuzz: build failed:"; tail -20 "$out/build.log"
  junit fail "fuzz target build failed"
  exit 1
fi
[ -f "$stamp" ] || echo "$inputs" > "$stamp"
if [ "${FUZZ_BUILD_ONLY:-0}" = 1 ]; then
  echo "fuzz: built $out/fuzz_core (FUZZ_BUILD_ONLY: not run)"
  exit 0
fi
workers="${FUZZ_WORKERS:-1}"
echo "fuzz: running fuzz_core, seed ${seed}, ${runs} runs per worker (0: unbounded), at most ${seconds} s, ${workers} worker(s) (log: $log)"
# Each worker is an independent libFuzzer process on the shared corpus folder (libFuzzer reloads
# it, so the workers see each other's finds); worker k logs to fuzz_core.log (k = 1) or
# fuzz_core.k.log.
pids=()
for k in $(seq 1 "$workers"); do
  wlog="$log"; [ "$k" -gt 1 ] && wlog="${log%.log}.$k.log"
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1 \
    "$out/fuzz_core" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -seed="$((seed + k - 1))" -runs="$runs_arg" -artifact_prefix="$out/" "$out/corpus" "$repo/test/fuzz/corpus" > "$wlog" 2>&1 &
  pids+=("$!")
done
rc=0
for pid in "${pids[@]}"; do wait "$pid" || rc=$?; done
logs=("$log"); for k in $(seq 2 "$workers"); do logs+=("${log%.log}.$k.log"); done
execs=0
for l in "${logs[@]}"; do
  n="$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+).*/\1/p' "$l" | tail -1)"
  execs=$((execs + ${n:-0}))
done
if [ "$rc" -ne 0 ] || grep -q "ERROR: AddressSanitizer\|runtime error:\|FINDING\|deadly signal" "${logs[@]}"; then
  echo "fuzz: FAILED after ${execs} executions (exit $rc):"
  grep -h -m5 -E "ERROR|runtime error|FINDING|deadly|SUMMARY" "${logs[@]}"
  ls "$out"/crash-* "$out"/timeout-* "$out"/oom-* 2>/dev/null | head -3
  junit fail "fuzz_core: crash, sanitizer report or finding after ${execs} executions; see ${logs[*]}"
  exit 1
fi
echo "fuzz: clean, ${execs} executions (seed ${seed}, ${workers} worker(s))"
junit pass ""
exit 0
