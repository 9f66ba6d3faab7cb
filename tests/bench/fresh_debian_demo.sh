#!/usr/bin/env bash
# README's "How long the first run takes", measured from nothing: a fresh Debian 12 base
# image (debootstrap --variant=minbase bookworm) and a fresh clone of this repository's
# HEAD, then `time bash tools/install-deps.sh --programs` and `time bash tools/demo.sh`
# inside it. Not in ctest (it downloads ~150 packages and builds the programs: minutes).
# Needs root, debootstrap (apt-get install debootstrap) and Debian's mirror. A machine whose
# HTTPS goes through a proxy with its own CA: that CA (*.crt in
# /usr/local/share/ca-certificates) is copied in, as such a machine's admin installs it.
#   sudo bash tests/bench/fresh_debian_demo.sh [ROOT_DIR]     (default /var/tmp/fresh-debian)
set -euo pipefail
REPO="$(cd "$(dirname "$0")/../.." && pwd)"
ROOT="${1:-/var/tmp/fresh-debian}"
cleanup() { for m in proc dev sys; do umount "$ROOT/$m" 2>/dev/null || true; done; }
trap cleanup EXIT
cleanup
rm -rf "$ROOT"
debootstrap --variant=minbase bookworm "$ROOT" http://deb.debian.org/debian > "$ROOT.debootstrap.log" 2>&1
cp /etc/resolv.conf "$ROOT/etc/resolv.conf"
mkdir -p "$ROOT/usr/local/share/ca-certificates"
cp /usr/local/share/ca-certificates/*.crt "$ROOT/usr/local/share/ca-certificates/" 2>/dev/null || true
mount -t proc proc "$ROOT/proc"; mount --bind /dev "$ROOT/dev"; mount --bind /sys "$ROOT/sys"
git clone -q "$REPO" "$ROOT/src/repo"
echo "load before: $(cat /proc/loadavg)"
chroot "$ROOT" /bin/bash -c 'cd /src/repo && export DEBIAN_FRONTEND=noninteractive &&
  time bash tools/install-deps.sh --programs && time bash tools/demo.sh' 2>&1 | tee "$ROOT.demo.log" |
  grep -E '^(real|user|sys)|^install-deps|^== |rc='
echo "load after: $(cat /proc/loadavg); packages set up: $(grep -c '^Setting up' "$ROOT.demo.log")"
