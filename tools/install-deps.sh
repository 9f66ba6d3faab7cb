#!/usr/bin/env bash
# Installs the Debian 12 packages the build, the tools and the tests need.
#   install-deps.sh              everything: programs + tests (tools/run-tests.sh, .ci/run)
#   install-deps.sh --programs   only what building and running the programs needs
#                                (tools/demo.sh; build with -DRESOLVER_BUILD_TESTS=OFF)
#   --list                       print the packages of the set, one a line, install nothing
# Idempotent: runs apt-get only when something is missing. Needs root or sudo.
set -euo pipefail

usage() { echo "usage: $0 [--programs] [--list]" >&2; exit 2; }
only_programs=0
list=0
for arg in "$@"; do
  case "$arg" in
    --programs) only_programs=1 ;;
    --list) list=1 ;;
    -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) usage ;;
  esac
done

# Building and running resolverd, resolver-sim, resolver-echo, resolver-model and
# resolver-accuracy, their man pages and the Python package resolver_lcm.
PROGRAM_PACKAGES=(
  build-essential cmake g++ pkg-config git
  ca-certificates  # the build downloads uPlot over HTTPS (tools/model/web/fetch_locked_package.py)
  liblcm-dev liblcm-bin  # liblcm-bin: lcm-gen, run at build time (proto/, tools/python)
  libeigen3-dev libcli11-dev libtomlplusplus-dev libfmt-dev
  libmuparser-dev  # [[model.custom]] effects: expressions users write (daemon/core/model/custom_effect.h)
  libmatio-dev  # resolver-model export-data --mat (tools/model/export_data.h)
  python3  # the build finds Debian's interpreter for resolver_lcm (tools/python)
  help2man  # man pages from --help (cmake/Packaging.cmake); without it the build makes none
)
# The tests, benchmarks and fuzzers (tests/), resolver-spy's Java types and packaging.
TEST_PACKAGES=(
  libgtest-dev libgmock-dev libbenchmark-dev libsystemd-dev
  can-utils python3-can
  python3-numpy  # tests/independent (benchgen)
  python3-canmatrix  # tests/dbc_peer: an independent DBC reader judges resolverd's decoded values
  qemu-system-x86 iproute2 valgrind clang libclang-rt-14-dev
  # resolver-spy: its types jar is built only where javac and lcm.jar are found (tools/spy)
  default-jdk-headless default-jre liblcm-java libjchart2d-java xvfb xauth
  chromium  # headless: renders, zooms and screenshots the resolver-model HTML report (tests/model)
  python3-scipy  # tests/model/test_export_data.py reads the .mat with scipy.io.loadmat
  python3-distributed  # Dask: resolver_bench.fleet and its test (tests skip without it)
  # packaging (cmake/Packaging.cmake, tests/install): the .deb's shared-library
  # dependencies (dpkg-shlibdeps), systemd-analyze for the installed units, /bin/kill
  # their ExecReload= names
  dpkg-dev systemd procps
)

PACKAGES=("${PROGRAM_PACKAGES[@]}")
[ "$only_programs" = 1 ] || PACKAGES+=("${TEST_PACKAGES[@]}")
if [ "$list" = 1 ]; then
  printf '%s\n' "${PACKAGES[@]}"
  exit 0
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# No Node.js: the build fetches uPlot for the resolver-model report from the npm registry
# with python3 (tools/model/web/fetch_locked_package.py, pinned by package-lock.json's
# SHA-512); Debian's npm would bring ~340 node-* packages to a fresh machine.
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
