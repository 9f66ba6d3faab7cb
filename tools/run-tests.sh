#!/usr/bin/env bash
# Every test: installs packages, builds with warnings as errors, runs ctest
# (labels: unit, integration, vcan: the SocketCAN suite in a QEMU guest, ~1 min). With RESOLVER_SANITIZE=1 it also builds
# everything with ASan+UBSan into build-asan and runs the unit tests there.
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
  BUILD_DIR=build-asan bash tools/build.sh -DRESOLVER_WERROR=ON -DRESOLVER_BUILD_TESTS=ON -DRESOLVER_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
  ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -L unit
fi
