#!/usr/bin/python3
"""Pack a directory tree into a gzip-compressed cpio archive ("newc" format),
the format the Linux kernel unpacks as an initramfs.

Usage: mkcpio.py ROOT_DIR OUT.cpio.gz

Written here (Python standard library only) so the suite needs no `cpio` package.
Every entry is owned by root (uid/gid 0) whatever the host owner was; file modes
and symlinks are kept. Entries are sorted, and mtimes are zeroed, so the same tree
gives the same bytes (handy for caching and for comparing two builds).
Format reference: the kernel's Documentation/driver-api/early-userspace/buffer-format.rst.
"""
import gzip
import os
import stat
import sys

NEWC_MAGIC = b"070701"


def _pad4(n):
    return (4 - n % 4) % 4


def _header(ino, mode, nlink, size, name_len):
    # 13 fields of 8 hex digits after the magic: ino mode uid gid nlink mtime
    # filesize devmajor devminor rdevmajor rdevminor namesize check.
    fields = [ino, mode, 0, 0, nlink, 0, size, 0, 0, 0, 0, name_len, 0]
    return NEWC_MAGIC + b"".join(b"%08X" % f for f in fields)


def _entry(out, ino, name, mode, data, nlink=1):
    bname = name.encode() + b"\0"
    hdr = _header(ino, mode, nlink, len(data), len(bname))
    out.write(hdr + bname + b"\0" * _pad4(len(hdr) + len(bname)))
    out.write(data + b"\0" * _pad4(len(data)))


def pack(root, out_path):
    paths = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames.sort()
        for n in sorted(dirnames + filenames):
            paths.append(os.path.join(dirpath, n))
    paths.sort()
    with gzip.GzipFile(out_path, "wb", compresslevel=6, mtime=0) as out:
        ino = 1
        for p in paths:
            rel = os.path.relpath(p, root)
            st = os.lstat(p)
            if stat.S_ISLNK(st.st_mode):
                _entry(out, ino, rel, stat.S_IFLNK | 0o777, os.readlink(p).encode())
            elif stat.S_ISDIR(st.st_mode):
                _entry(out, ino, rel, stat.S_IFDIR | stat.S_IMODE(st.st_mode), b"", nlink=2)
            elif stat.S_ISREG(st.st_mode):
                with open(p, "rb") as f:
                    _entry(out, ino, rel, stat.S_IFREG | stat.S_IMODE(st.st_mode), f.read())
            else:
                raise SystemExit(f"mkcpio: {p}: only files, directories and symlinks are packed")
            ino += 1
        _entry(out, ino, "TRAILER!!!", 0, b"")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    pack(sys.argv[1], sys.argv[2])
