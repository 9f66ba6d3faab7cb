#!/usr/bin/env bash
# Debian packages the vcan suite needs on the host (as root): QEMU to boot the
# guest, and the programs make_guest.sh copies into it. The kernel and busybox
# are not installed: make_guest.sh fetches them with apt-get download.
set -euo pipefail
pkgs=(qemu-system-x86 can-utils liblcm-bin iproute2 python3)
missing=()
for p in "${pkgs[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi
