#!/usr/bin/env python3
"""Fetches one npm package exactly as package-lock.json pins it, without Node.js.

The report page embeds uPlot (tools/model/web/package-lock.json). `npm ci` did this before,
but Debian's npm package brings ~340 node-* packages, more than half of what a fresh
machine installs to build the programs (issue 26: the first run in minutes). The lock's
integrity (SHA-512) pins the tarball; this reads it, downloads
REGISTRY/NAME/-/NAME-VERSION.tgz (REGISTRY: $npm_config_registry, else registry.npmjs.org),
refuses it unless the hash matches, and unpacks its `package/` folder into OUT/NAME.

Offline: --tarball FILE (or $RESOLVER_NPM_TARBALLS, a folder of NAME-VERSION.tgz) is
checked against the same hash instead of downloading.

  fetch_locked_package.py --lock package-lock.json --name uplot --out DIR [--tarball FILE]
"""
import argparse
import base64
import hashlib
import io
import json
import os
import shutil
import sys
import tarfile
import urllib.request


def fail(message):
    print(f"fetch_locked_package: {message}", file=sys.stderr)
    sys.exit(1)


def pinned(lock_path, name):
    with open(lock_path, encoding="utf-8") as f:
        lock = json.load(f)
    entry = lock.get("packages", {}).get(f"node_modules/{name}")
    if not entry or "version" not in entry or not entry.get("integrity", "").startswith("sha512-"):
        fail(f"{lock_path}: no node_modules/{name} with a version and a sha512 integrity")
    return entry["version"], base64.b64decode(entry["integrity"][len("sha512-"):])


def tarball_bytes(name, version, local):
    if local:
        with open(local, "rb") as f:
            return f.read(), local
    folder = os.environ.get("RESOLVER_NPM_TARBALLS")
    if folder and os.path.exists(os.path.join(folder, f"{name}-{version}.tgz")):
        path = os.path.join(folder, f"{name}-{version}.tgz")
        with open(path, "rb") as f:
            return f.read(), path
    registry = os.environ.get("npm_config_registry", "https://registry.npmjs.org").rstrip("/")
    url = f"{registry}/{name}/-/{name}-{version}.tgz"
    try:
        with urllib.request.urlopen(url, timeout=60) as r:
            return r.read(), url
    except OSError as e:
        fail(f"cannot download {url}: {e}; offline, put {name}-{version}.tgz in a folder named by "
             f"$RESOLVER_NPM_TARBALLS")


def unpack(data, out):
    """The tarball's package/ folder into `out`, refusing paths that leave it."""
    if os.path.exists(out):
        shutil.rmtree(out)
    os.makedirs(out)
    root = os.path.realpath(out)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        for member in tar.getmembers():
            if not member.name.startswith("package/") or not (member.isfile() or member.isdir()):
                continue
            target = os.path.realpath(os.path.join(out, member.name[len("package/"):]))
            if not target.startswith(root + os.sep):
                fail(f"refusing {member.name}: outside the package")
            if member.isdir():
                os.makedirs(target, exist_ok=True)
                continue
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with tar.extractfile(member) as src, open(target, "wb") as dst:
                dst.write(src.read())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lock", required=True)
    ap.add_argument("--name", required=True)
    ap.add_argument("--out", required=True, help="the package goes to OUT/NAME")
    ap.add_argument("--tarball", help="a local NAME-VERSION.tgz instead of the registry")
    args = ap.parse_args()
    version, digest = pinned(args.lock, args.name)
    data, source = tarball_bytes(args.name, version, args.tarball)
    if hashlib.sha512(data).digest() != digest:
        fail(f"{source}: SHA-512 differs from {args.lock}'s integrity for {args.name} {version}: not the pinned "
             f"tarball, refused")
    unpack(data, os.path.join(args.out, args.name))
    print(f"fetch_locked_package: {args.name} {version} from {source} (SHA-512 as pinned)")


if __name__ == "__main__":
    main()
