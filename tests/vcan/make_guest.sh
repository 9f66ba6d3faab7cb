#!/usr/bin/env bash
# Builds a tiny QEMU guest that has real SocketCAN (vcan) for the vcan suite:
#   OUT/vmlinuz             Debian's stock amd64 kernel (linux-image-<ver>-amd64)
#   OUT/initramfs.cpio.gz   busybox-static + CAN/vcan/9p modules + can-utils +
#                           lcm-logger + iproute2's ip + the given binaries and
#                           every shared library they need (ldd), + /init
#   OUT/guest.env           KERNEL_VERSION=..., what was packed
#
# Usage: make_guest.sh --out DIR [--kernel-version 6.1.0-56-amd64] [--file SRC:DEST]... BINARY...
#   BINARY   project programs to put in the guest's /opt/resolver/bin (resolverd, ...)
#   --file   also copy the host file SRC to DEST in the guest (e.g. the DBC file
#            resolverd opens by its compiled-in absolute path)
#   --kernel-version   pin the kernel (also env RESOLVER_VCAN_KERNEL); default: the
#            one already cached in DIR/debs, else the one Debian's linux-image-amd64
#            meta-package depends on today.
#
# Downloads with `apt-get download` into DIR/debs (cached: a second run is offline)
# and unpacks with dpkg-deb -x; nothing is installed on the host. Host needs: apt,
# dpkg-deb, python3, ldd, and the packages can-utils, liblcm-bin, iproute2
# (tests/vcan/install-deps.sh installs them and qemu-system-x86).
#
# What /init does in the guest (see write_init below): mounts proc/sys/dev, loads
# the modules, brings up lo with the multicast route LCM's udpm needs, creates
# vcan0 (classic MTU 16) and vcan1 (FD, MTU 72), mounts the host's 9p share
# (mount tag "vcanshare") on /share, runs each scenario named by the kernel
# argument resolver_vcan=NAME[,NAME...] from /scenarios/NAME.sh with
# IN=/tmp/in OUT=/tmp/out/NAME (tmpfs; copied from /share/in and to /share/out/NAME,
# so no 9p I/O happens while frames fly), prints markers on the serial console
# (@@VCAN READY / BEGIN / END rc=N / DONE) and powers off.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
out=""
kver="${RESOLVER_VCAN_KERNEL:-}"
bins=()
files=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --kernel-version) kver="$2"; shift 2 ;;
    --file) files+=("$2"); shift 2 ;;
    -h|--help) sed -n '2,29p' "$0"; exit 0 ;;
    -*) echo "make_guest.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) bins+=("$(realpath -- "$1")"); shift ;;
  esac
done
[ -n "$out" ] || { echo "make_guest.sh: --out DIR is required (see --help)" >&2; exit 2; }
mkdir -p "$out/debs"
out="$(cd "$out" && pwd)"

die() { echo "make_guest.sh: $*" >&2; exit 1; }
for tool in apt-get dpkg-deb ldd python3; do
  command -v "$tool" >/dev/null || die "'$tool' not found; this script needs a Debian host"
done
# Guest programs taken from the host's own packages.
host_progs=(/usr/bin/candump /usr/bin/canplayer /usr/bin/cansend /usr/bin/cangen /usr/bin/lcm-logger /usr/sbin/ip)
for p in "${host_progs[@]}"; do
  [ -x "$p" ] || die "$p missing; run: apt-get install can-utils liblcm-bin iproute2 (or tests/vcan/install-deps.sh)"
done
for b in "${bins[@]}"; do [ -x "$b" ] || die "binary '$b' does not exist or is not executable"; done

# ---- 1. kernel and busybox packages (cached) --------------------------------
cd "$out/debs"
if [ -z "$kver" ]; then
  cached=$(ls linux-image-*-amd64_*.deb 2>/dev/null | sed -n 's/^linux-image-\(.*-amd64\)_.*/\1/p' | sort -V | tail -1 || true)
  if [ -n "$cached" ]; then
    kver="$cached"
  else
    kver=$(apt-cache depends linux-image-amd64 2>/dev/null | sed -n 's/.*Depends: linux-image-\(.*-amd64\)$/\1/p' | sort -V | tail -1)
    [ -n "$kver" ] || die "cannot tell the newest kernel: 'apt-cache depends linux-image-amd64' found none (run apt-get update, or pass --kernel-version)"
  fi
fi
fetch() {  # fetch PACKAGE: apt-get download unless a .deb of it is cached
  local pkg="$1"
  if ! ls "${pkg}"_*.deb >/dev/null 2>&1; then
    echo "make_guest.sh: downloading $pkg" >&2
    apt-get download "$pkg" >/dev/null 2>apt-download.err || { cat apt-download.err >&2; die "apt-get download $pkg failed (apt-get update? package name?)"; }
  fi
  ls "${pkg}"_*.deb | sort -V | tail -1
}
kdeb=$(fetch "linux-image-$kver")
bdeb=$(fetch busybox-static)
if [ ! -f "$out/kpkg/.unpacked-$kdeb" ]; then
  rm -rf "$out/kpkg"; mkdir -p "$out/kpkg"
  dpkg-deb -x "$kdeb" "$out/kpkg"; touch "$out/kpkg/.unpacked-$kdeb"
fi
if [ ! -f "$out/bbpkg/.unpacked-$bdeb" ]; then
  rm -rf "$out/bbpkg"; mkdir -p "$out/bbpkg"
  dpkg-deb -x "$bdeb" "$out/bbpkg"; touch "$out/bbpkg/.unpacked-$bdeb"
fi
vmlinuz="$out/kpkg/boot/vmlinuz-$kver"
moddir="$out/kpkg/lib/modules/$kver"
[ -f "$vmlinuz" ] || die "$kdeb has no boot/vmlinuz-$kver"
cp "$vmlinuz" "$out/vmlinuz"

# ---- 2. the root tree ---------------------------------------------------------
root="$out/root"
rm -rf "$root"
mkdir -p "$root"/{bin,sbin,usr/bin,usr/sbin,lib/x86_64-linux-gnu,lib64,lib/modules,proc,sys,dev,tmp,run,share,etc,scenarios,opt/resolver/bin,var/log}
cp "$out/bbpkg/bin/busybox" "$root/bin/busybox"
for applet in $("$root/bin/busybox" --list); do
  [ -e "$root/bin/$applet" ] || ln -s busybox "$root/bin/$applet"
done
echo "root:x:0:0:root:/:/bin/sh" > "$root/etc/passwd"
echo "root:x:0:" > "$root/etc/group"

# Kernel modules, in load order: the wanted ones preceded by what they depend on
# (read from each .ko's .modinfo "depends=" string; Debian ships no modules.dep,
# depmod writes it at install time). Debian 12's modules are not compressed; .ko.xz
# would be unpacked here with xz -d.
python3 - "$moddir" "$root/lib/modules" can can-raw can-dev vcan 9p 9pnet_virtio virtio_pci <<'EOF'
import lzma, os, re, shutil, sys
moddir, dest, wanted = sys.argv[1], sys.argv[2], sys.argv[3:]
index = {}
for d, _, files in os.walk(moddir):
    for f in files:
        m = re.match(r"(.+)\.ko(\.xz)?$", f)
        if m:
            index[m.group(1).replace("-", "_")] = os.path.join(d, f)
def data(name):
    p = index[name.replace("-", "_")]
    raw = open(p, "rb").read()
    return lzma.decompress(raw) if p.endswith(".xz") else raw
order = []
def visit(name):
    key = name.replace("-", "_")
    if key in (n.replace("-", "_") for n in order):
        return
    if key not in index:
        sys.exit(f"make_guest.sh: module {name} not in {moddir} (built into this kernel? then drop it)")
    m = re.search(rb"depends=([^\0]*)\0", data(name))
    for dep in (m.group(1).decode().split(",") if m and m.group(1) else []):
        visit(dep)
    order.append(name)
for w in wanted:
    visit(w)
for n in order:
    with open(os.path.join(dest, n + ".ko"), "wb") as f:
        f.write(data(n))
with open(os.path.join(dest, "load-order"), "w") as f:
    f.write("\n".join(order) + "\n")
EOF

# Programs and their shared libraries (ldd), placed at the paths ldd names.
copy_libs() {
  ldd "$1" | awk '/=> \//{print $3} /^\t\/lib/{print $1}' | while read -r lib; do
    case "$lib" in
      */ld-linux-x86-64.so.2) cp -L "$lib" "$root/lib64/ld-linux-x86-64.so.2" ;;
      *) mkdir -p "$root$(dirname "$lib")"; [ -e "$root$lib" ] || cp -L "$lib" "$root$lib" ;;
    esac
  done
}
for p in "${host_progs[@]}"; do cp -L "$p" "$root$p"; copy_libs "$p"; done
# Without their debug information: the guest unpacks the initramfs into its 512 MiB
# of RAM, and RelWithDebInfo programs are ~90 MB each.
for b in "${bins[@]}"; do
  cp -L "$b" "$root/opt/resolver/bin/"
  strip --strip-debug "$root/opt/resolver/bin/$(basename "$b")" 2>/dev/null || true
  copy_libs "$b"
done
# Bookworm is merged-/usr: a program may ask ldd's /usr/lib path or /lib path.
if [ -d "$root/usr/lib/x86_64-linux-gnu" ]; then
  cp -an "$root/usr/lib/x86_64-linux-gnu/." "$root/lib/x86_64-linux-gnu/" && rm -rf "$root/usr/lib"
fi
ln -s ../lib "$root/usr/lib"

for spec in "${files[@]}"; do
  src="${spec%%:*}"; dest="${spec#*:}"
  [ -f "$src" ] && [ "${dest#/}" != "$dest" ] || die "--file $spec: want an existing SRC and an absolute DEST"
  mkdir -p "$root$(dirname "$dest")"; cp -L "$src" "$root$dest"
done

# Scenarios (the same scripts run natively on a bench PC with vcan0).
cp "$here"/scenarios/*.sh "$root/scenarios/"

# ---- 3. /init -----------------------------------------------------------------
cat > "$root/init" <<'EOF'
#!/bin/busybox sh
# resolver vcan guest init: set up SocketCAN, run the scenarios, power off.
export PATH=/opt/resolver/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/ TERM=dumb
# busybox's shell runs its own applets before PATH: name iproute2's ip explicitly
# (busybox ip knows neither "type vcan" on every build nor "-d").
export IP=/usr/sbin/ip
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs dev /dev 2>/dev/null
mount -t tmpfs tmp /tmp
exec 0</dev/null 1>/dev/console 2>&1
up() { cut -d' ' -f1 /proc/uptime; }
fail() { echo "@@VCAN SETUP-FAILED $*"; poweroff -f; sleep 5; }
for m in $(cat /lib/modules/load-order); do
  insmod /lib/modules/$m.ko || fail "insmod $m"
done
# Socket receive buffers: 8 MiB instead of Linux's ~208 KiB default (~270 CAN
# frames, 45 ms at the demo's 6000 frames/s). Emulated without KVM the guest can
# stall longer than that and the kernel would drop frames that real hardware
# keeps (measured: 411 of 30050 dropped with the default). resolverd sets no
# SO_RCVBUF itself, so rmem_default is what it gets. resolver_vcan_rmem=BYTES on
# the kernel command line overrides (e.g. 212992 to see the drops).
rmem=$(tr ' ' '\n' < /proc/cmdline | sed -n 's/^resolver_vcan_rmem=//p')
echo "${rmem:-8388608}" > /proc/sys/net/core/rmem_max
echo "${rmem:-8388608}" > /proc/sys/net/core/rmem_default
$IP link set lo up || fail "lo up"
$IP route add 224.0.0.0/4 dev lo || fail "multicast route"
$IP link add dev vcan0 type vcan || fail "vcan0"
$IP link set vcan0 mtu 16 || fail "vcan0 mtu 16 (classic CAN; vcan's default is the FD MTU 72)"
$IP link set vcan0 up || fail "vcan0 up"
$IP link add dev vcan1 type vcan || fail "vcan1"
$IP link set vcan1 mtu 72 || fail "vcan1 mtu 72 (CAN FD)"
$IP link set vcan1 up || fail "vcan1 up"
mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144 vcanshare /share || fail "9p mount of tag vcanshare on /share"
cp -r /share/in /tmp/in || fail "copy of the inputs from /share/in"
gap=$(tr ' ' '\n' < /proc/cmdline | sed -n 's/^resolver_vcan_gap=//p')
export CANPLAYER_GAP_MS=${gap:-1}
scenarios=$(tr ' ' '\n' < /proc/cmdline | sed -n 's/^resolver_vcan=//p' | tr ',' ' ')
echo
echo "@@VCAN READY uptime=$(up) kernel=$(uname -r) rmem_default=$(cat /proc/sys/net/core/rmem_default) canplayer_gap_ms=$CANPLAYER_GAP_MS scenarios=$scenarios"
$IP -d link show vcan0 | head -3
$IP -d link show vcan1 | head -3
for s in $scenarios; do
  # Work on tmpfs, copy to the share afterwards: writing through 9p while frames
  # arrive would stall the readers (resolverd, candump) and make the kernel drop.
  o=/tmp/out/$s
  mkdir -p $o /share/out/$s
  echo "@@VCAN BEGIN $s uptime=$(up)"
  if [ -f /scenarios/$s.sh ]; then
    IN=/tmp/in OUT=$o IFACE=vcan0 FD_IFACE=vcan1 IP=$IP sh /scenarios/$s.sh > $o/scenario.txt 2>&1
    rc=$?
  else
    echo "no scenario /scenarios/$s.sh" > $o/scenario.txt; rc=127
  fi
  echo "$rc" > $o/rc
  cp -r $o/. /share/out/$s/ || echo "@@VCAN COPY-FAILED $s"
  sed 's/^/  | /' $o/scenario.txt | tail -40
  echo "@@VCAN END $s rc=$rc uptime=$(up)"
done
sync
umount /share
echo "@@VCAN DONE uptime=$(up)"
poweroff -f
sleep 10
EOF
chmod 755 "$root/init"

python3 "$here/mkcpio.py" "$root" "$out/initramfs.cpio.gz"
{
  echo "KERNEL_VERSION=$kver"
  echo "KERNEL_DEB=$kdeb"
  echo "BUSYBOX_DEB=$bdeb"
  echo "MODULES=\"$(tr '\n' ' ' < "$root/lib/modules/load-order")\""
  echo "BINARIES=\"${bins[*]}\""
} > "$out/guest.env"
echo "make_guest.sh: $out/vmlinuz ($kver) + $out/initramfs.cpio.gz ($(du -h "$out/initramfs.cpio.gz" | cut -f1))" >&2
