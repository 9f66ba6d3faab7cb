#!/usr/bin/env bash
# The first run (tools/demo.sh) builds and installs only the programs (issue 26):
#   - configured with -DRESOLVER_BUILD_TESTS=OFF, and GoogleTest made unfindable
#     (CMAKE_DISABLE_FIND_PACKAGE_GTest), the project configures;
#   - that build has every program target and no test, benchmark or fuzzer target,
#     no compile unit under tests/ and no ctest test;
#   - tools/install-deps.sh --programs lists the build's packages and none of the
#     tests' (QEMU, Chromium, a JDK, valgrind, clang, scipy, GoogleTest ...), the
#     default set lists both;
#   - tools/demo.sh asks for exactly that; run-tests.sh, the sanitizer build and
#     run_fuzzers.sh turn the tests back on explicitly (build/ is shared).
# Usage: test_programs_only.sh SOURCE_DIR WORK_DIR
set -euo pipefail
src=$1
work=$2
fail=0
bad() { echo "FAIL: $*" >&2; fail=1; }

rm -rf "$work"
mkdir -p "$work"
if ! cmake -S "$src" -B "$work/build" -DRESOLVER_BUILD_TESTS=OFF -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON \
     -DRESOLVER_MAN_PAGES=OFF >"$work/configure.log" 2>&1; then
  cat "$work/configure.log" >&2
  echo "FAIL: configuring with RESOLVER_BUILD_TESTS=OFF and no GoogleTest failed" >&2
  exit 1
fi

targets=$(cmake --build "$work/build" --target help | sed -n 's/^\.\.\. \([^ ]*\).*/\1/p')
for t in resolverd resolver_sim_cli resolver_echo resolver_model_cli resolver_accuracy; do
  grep -qx "$t" <<<"$targets" || bad "program target $t missing"
done
extra=$(grep -E '^(test_|bench_|fuzz_)|_test$' <<<"$targets" || true)
[ -z "$extra" ] || bad "test, benchmark or fuzzer targets built with the tests off: $(echo $extra)"

units=$(grep -c '"file":' "$work/build/compile_commands.json")
in_tests=$(grep -c '"file": *"[^"]*/tests/' "$work/build/compile_commands.json" || true)
[ "$in_tests" = 0 ] || bad "$in_tests compile units under tests/"
echo "programs-only build: $units compile units"

n_tests=$(cd "$work/build" && ctest -N 2>/dev/null | sed -n 's/^Total Tests: //p')
[ "${n_tests:-0}" = 0 ] || bad "ctest lists $n_tests tests with the tests off"

programs=$(bash "$src/tools/install-deps.sh" --programs --list)
everything=$(bash "$src/tools/install-deps.sh" --list)
for p in liblcm-dev liblcm-bin libeigen3-dev libcli11-dev libtomlplusplus-dev libfmt-dev libmuparser-dev libmatio-dev \
         cmake g++; do
  grep -qx "$p" <<<"$programs" || bad "install-deps.sh --programs lacks $p (the build needs it)"
done
for p in qemu-system-x86 chromium default-jdk-headless valgrind clang python3-scipy libgtest-dev libbenchmark-dev; do
  grep -qx "$p" <<<"$programs" && bad "install-deps.sh --programs installs $p (a test's)"
  grep -qx "$p" <<<"$everything" || bad "install-deps.sh (everything) lacks $p"
done

grep -q 'install-deps.sh --programs' "$src/tools/demo.sh" || bad "demo.sh does not install the programs' set"
grep -q -- '-DRESOLVER_BUILD_TESTS=OFF' "$src/tools/demo.sh" || bad "demo.sh does not turn the tests off"
grep -Eq '^bash tools/install-deps.sh$' "$src/tools/run-tests.sh" || bad "run-tests.sh does not install everything"
[ "$(grep -c -- '-DRESOLVER_BUILD_TESTS=ON' "$src/tools/run-tests.sh")" = 2 ] ||
  bad "run-tests.sh must turn the tests on in both of its builds (demo.sh leaves build/ with them off)"
grep -q -- '-DRESOLVER_BUILD_TESTS=ON' "$src/tests/fuzz/run_fuzzers.sh" || bad "run_fuzzers.sh does not turn the tests on"

((fail)) && exit 1
echo "ok"
