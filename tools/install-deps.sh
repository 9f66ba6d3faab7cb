#!/usr/bin/env bash
# Installs the Debian 12 packages the build, the tools and the tests need.
# Idempotent: runs apt-get only when something is missing. Needs root or sudo.
set -euo pipefail

PACKAGES=(
  build-essential cmake g++ pkg-config git
  libgtest-dev libgmock-dev libbenchmark-dev
  liblcm-dev liblcm-bin
  libeigen3-dev libcli11-dev libtomlplusplus-dev libfmt-dev libsystemd-dev
  libmuparser-dev  # [[model.custom]] effects: expressions users write (daemon/core/model/custom_effect.h)
  can-utils python3 python3-can
  python3-numpy  # tests/independent (benchgen)
  python3-canmatrix  # tests/dbc_peer: an independent DBC reader judges resolverd's decoded values
  qemu-system-x86 iproute2 valgrind clang libclang-rt-14-dev
  default-jdk-headless default-jre liblcm-java libjchart2d-java xvfb xauth
  chromium  # headless: renders, zooms and screenshots the resolver-model HTML report (tests/model)
  libmatio-dev  # resolver-model export-data --mat (tools/model/export_data.h)
  python3-scipy  # tests/model/test_export_data.py reads the .mat with scipy.io.loadmat
  # packaging (cmake/Packaging.cmake, tests/install): man pages from --help, the
  # .deb's shared-library dependencies (dpkg-shlibdeps), systemd-analyze for the
  # installed units, /bin/kill their ExecReload= names; numpy for resolver_lcm's arrays
  help2man dpkg-dev systemd procps
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm: the build installs uPlot for the resolver-model report from the npm registry
# (tools/model/web/package-lock.json). The machine images ship Node.js with npm; where
# there is no npm at all, Debian's nodejs and npm packages provide it.
command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages and npm present"
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
