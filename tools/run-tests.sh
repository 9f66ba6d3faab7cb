#!/usr/bin/env bash
# Every test: installs packages, builds with warnings as errors, runs ctest
# (labels: unit, integration, vcan: the SocketCAN suite in a QEMU guest, ~1 min). With RESOLVER_SANITIZE=1 it also builds
# what the unit tests need with ASan+UBSan into build-asan and runs them there: Debug (asserts
# on) at -O1, as ASan's own documentation advises (at -O0 the discovery unit tests took 1-6 min
# each, Eigen uninlined). Built by clang with line tables only: clang's own sanitizers, and the
# heaviest file (ranking.cpp) compiles in 14 s there against 32 s with g++ -g -O1; the -Werror
# build above is g++'s, so both compilers' warnings stay errors.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
# Tests that talk to python-can must not skip where it was just installed.
export RESOLVER_REQUIRE_PYCAN=${RESOLVER_REQUIRE_PYCAN:-1}
# Tests ON explicitly: tools/demo.sh leaves build/ configured with them OFF (and as
# Release; tools/build.sh sets RelWithDebInfo again).
bash tools/build.sh -DRESOLVER_WERROR=ON -DRESOLVER_BUILD_TESTS=ON
ctest --test-dir build --output-on-failure -j"$(nproc)"
if [ "${RESOLVER_SANITIZE:-0}" = "1" ]; then
  echo "== sanitizer build (ASan + UBSan)"
  # RESOLVER_FUZZ_COVERAGE: the fuzzers can be built here too (.ci/run fuzzes in this tree).
  cmake -S . -B build-asan -DRESOLVER_WERROR=ON -DRESOLVER_BUILD_TESTS=ON -DRESOLVER_SANITIZE=ON -DRESOLVER_FUZZ_COVERAGE=ON \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
    "-DCMAKE_CXX_FLAGS_DEBUG=-gline-tables-only -O1" "-DCMAKE_C_FLAGS_DEBUG=-gline-tables-only -O1" >/dev/null
  cmake --build build-asan -j"$(nproc)" --target unit_tests
  # Not ALightlyDampedLoopAsksForItsZeta: the harmonic balance of a zeta 0.05 loop
  # (loop_correction.cpp, an FFT per node per row) takes 56 s optimised and over 10 min here,
  # alone at the stage's end; its code runs under the sanitizers in loop_correction_test and
  # the other tracking-loop tests, and the test itself in the ctest above.
  ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -L unit \
    -E '^ModelDiscovery[.]ALightlyDampedLoopAsksForItsZeta$'
fi
