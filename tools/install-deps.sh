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
  qemu-system-x86 iproute2 valgrind clang libclang-rt-14-dev
  default-jdk-headless default-jre liblcm-java libjchart2d-java xvfb xauth
  chromium  # headless, screenshots the resolver-model HTML report (tests/model)
  # packaging (cmake/Packaging.cmake, tests/install): man pages from --help, the
  # .deb's shared-library dependencies (dpkg-shlibdeps), systemd-analyze for the
  # installed units, /bin/kill their ExecReload= names; numpy for resolver_lcm's arrays
  help2man dpkg-dev systemd procps
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
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
