#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang (ASan + UBSan) in their
# own build folder and runs each for a bounded time. Exits non-zero when a
# target crashes, trips a sanitizer, breaks a FUZZ_CHECK property, times out or
# runs out of memory; the reproducer is saved and its path printed. CI calls this.
#
#   tests/fuzz/run_fuzzers.sh [SECONDS_PER_TARGET] [TARGET...]
#       SECONDS_PER_TARGET  default 20 (or $FUZZ_SECONDS)
#       TARGET              candump_line candump_reader dbc_parser frame_intake
#                           daemon_config asc_reader csv_reader (default: all)
#   environment:
#       FUZZ_BUILD_DIR  build folder (default <repo>/build-fuzz)
#       FUZZ_USE_BUILD  1: FUZZ_BUILD_DIR is an existing clang sanitizer build configured
#                       with -DRESOLVER_FUZZ_COVERAGE=ON (CI's build-asan); only the fuzz
#                       targets are built in it, it is not configured again
#       FUZZ_JOBS       parallel compile jobs (default: nproc)
#       FUZZ_RUNS       also stop after this many executions per target
#       FUZZ_ARGS       extra libFuzzer flags, e.g. "-jobs=2 -workers=2"
#
# Needs clang and its sanitizer/libFuzzer runtimes (Debian 12:
# apt-get install -y clang libclang-rt-14-dev) besides the project's own
# build dependencies (tools/install-deps.sh).
#
# The corpus each target grows is kept in <build>/fuzz/corpus/<target> and
# reused by the next run; inputs worth keeping as regression tests go to
# tests/fuzz/corpus/<target>/ (replayed by ctest, label unit).
# Reproduce a saved crash: <build>/fuzz/fuzz_<target> <artifact file>
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seconds=${1:-${FUZZ_SECONDS:-20}}
shift $(( $# > 0 ? 1 : 0 ))
all_targets=(candump_line candump_reader dbc_parser frame_intake daemon_config asc_reader csv_reader)
if (( $# > 0 )); then targets=("$@"); else targets=("${all_targets[@]}"); fi
build=${FUZZ_BUILD_DIR:-$repo/build-fuzz}
jobs=${FUZZ_JOBS:-$(nproc)}
shared=$repo/../shared/corpus/savvycan

if ! [[ $seconds =~ ^[0-9]+$ ]] || (( seconds < 1 )); then
  echo "run_fuzzers.sh: SECONDS_PER_TARGET must be a positive integer, got '$seconds'" >&2
  exit 2
fi
for t in "${targets[@]}"; do
  if [[ " ${all_targets[*]} " != *" $t "* ]]; then
    echo "run_fuzzers.sh: unknown target '$t'; known: ${all_targets[*]}" >&2
    exit 2
  fi
done
if ! command -v clang++ >/dev/null || ! command -v clang >/dev/null; then
  echo "run_fuzzers.sh: clang++ not found; install it: apt-get install -y clang libclang-rt-14-dev" >&2
  exit 2
fi

# Instrument the libraries too (coverage feedback + ASan inside the parsers);
# the fuzz executables add -fsanitize=fuzzer themselves (tests/fuzz/CMakeLists.txt).
san="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake_args=(-S "$repo" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++
            -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRESOLVER_BUILD_TESTS=ON "-DCMAKE_C_FLAGS=$san" "-DCMAKE_CXX_FLAGS=$san")
if [[ ${FUZZ_USE_BUILD:-0} == 1 ]]; then
  cache=$build/CMakeCache.txt
  if ! grep -q '^RESOLVER_FUZZ_COVERAGE:BOOL=ON' "$cache" 2>/dev/null ||
     ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang++' "$cache"; then
    echo "run_fuzzers.sh: FUZZ_USE_BUILD=1 needs $build configured by clang with -DRESOLVER_FUZZ_COVERAGE=ON" \
         "and sanitizers (see tools/run-tests.sh); $cache is not" >&2
    exit 2
  fi
  echo "== using $build (configured with RESOLVER_FUZZ_COVERAGE)"
else
  echo "== configuring $build (clang, ASan + UBSan + libFuzzer)"
  cmake "${cmake_args[@]}" >"$build.configure.log" 2>&1 || { cat "$build.configure.log" >&2; exit 2; }
fi
echo "== building ${targets[*]}"
build_targets=()
for t in "${targets[@]}"; do build_targets+=(--target "fuzz_$t"); done
cmake --build "$build" -j "$jobs" "${build_targets[@]}"

dict_for() {
  case $1 in
    candump_line|candump_reader|frame_intake) echo "$repo/tests/fuzz/dict/candump.dict" ;;
    dbc_parser) echo "$repo/tests/fuzz/dict/dbc.dict" ;;
    daemon_config) echo "$repo/tests/fuzz/dict/toml.dict" ;;
    asc_reader) echo "$repo/tests/fuzz/dict/asc.dict" ;;
    csv_reader) echo "$repo/tests/fuzz/dict/csv.dict" ;;
  esac
}

# Extra seeds from the shared SavvyCAN corpus, cut to a size libFuzzer mutates quickly.
seed_extra() {
  local t=$1 dir=$build/fuzz/seeds/$1
  rm -rf "$dir"
  mkdir -p "$dir"
  case $t in
    candump_line|candump_reader|frame_intake)
      [[ -f $shared/candump.log ]] && head -n 100 "$shared/candump.log" >"$dir/savvycan_head.log" ;;
    dbc_parser)
      cp "$repo/proto/resolver_bench.dbc" "$dir/"
      [[ -f $shared/LeafPowertrainBus.dbc ]] && cp "$shared/LeafPowertrainBus.dbc" "$dir/" ;;
  esac
  echo "$dir"
}

status=0
summary=()
for t in "${targets[@]}"; do
  corpus=$build/fuzz/corpus/$t
  artifacts=$build/fuzz/artifacts/$t/
  log=$build/fuzz/$t.log
  mkdir -p "$corpus" "$artifacts"
  extra=$(seed_extra "$t")
  args=(-max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
        -artifact_prefix="$artifacts" -dict="$(dict_for "$t")")
  [[ -n ${FUZZ_RUNS:-} ]] && args+=(-runs="$FUZZ_RUNS")
  # shellcheck disable=SC2206  # FUZZ_ARGS is a list of flags on purpose
  [[ -n ${FUZZ_ARGS:-} ]] && args+=($FUZZ_ARGS)
  echo "== fuzz_$t for ${seconds} s (log: $log)"
  rc=0
  "$build/fuzz/fuzz_$t" "${args[@]}" "$corpus" "$repo/tests/fuzz/corpus/$t" "$extra" >"$log" 2>&1 || rc=$?
  execs=$(grep -ho 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | awk '{s+=$1} END {print s+0}')
  rate=$(grep -ho 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -n 1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | grep -o '[0-9]*' || true)
  if (( rc != 0 )); then
    status=1
    summary+=("FAIL fuzz_$t: exit $rc after $execs executions; reproducer(s): $(ls -1 "$artifacts" 2>/dev/null | sed "s|^|$artifacts|" | tr '\n' ' ')")
    echo "---- fuzz_$t failed (exit $rc); last lines of $log:" >&2
    grep -v '^#[0-9]' "$log" | tail -n 40 >&2
  else
    summary+=("ok   fuzz_$t: $execs executions (${rate:-?}/s), coverage ${cov:-?} edges, corpus $(ls -1 "$corpus" | wc -l) inputs")
  fi
done

echo "== summary"
printf '%s\n' "${summary[@]}"
exit "$status"
