#!/usr/bin/env bash
# Every test: installs packages, builds with warnings as errors, runs ctest
# (labels: unit, integration, vcan: the SocketCAN suite in a QEMU guest, ~1 min). With RESOLVER_SANITIZE=1 it also builds
# everything with ASan+UBSan into build-asan and runs the unit tests there: Debug (asserts on)
# at -O1, as ASan's own documentation advises; at -O0 the discovery unit tests took 1-6 min
# each there (Eigen uninlined) and the stage over 40 min, at -O1 a quarter of that.
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
  BUILD_DIR=build-asan bash tools/build.sh -DRESOLVER_WERROR=ON -DRESOLVER_BUILD_TESTS=ON -DRESOLVER_SANITIZE=ON \
    -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-g -O1" "-DCMAKE_C_FLAGS_DEBUG=-g -O1"
  # Not ALightlyDampedLoopAsksForItsZeta: the harmonic balance of a zeta 0.05 loop
  # (loop_correction.cpp, an FFT per node per row) takes 56 s optimised and 7 min here,
  # alone at the stage's end; its code runs under the sanitizers in loop_correction_test and
  # the other tracking-loop tests, and the test itself in the ctest above.
  ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -L unit \
    -E '^ModelDiscovery[.]ALightlyDampedLoopAsksForItsZeta$'
fi
