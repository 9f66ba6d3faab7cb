#!/usr/bin/env bash
# cmake/WriteVersionInfo.cmake, the source of every --version line:
#   - in this checkout it writes `git describe --always --dirty`;
#   - for a source folder that is not a checkout (a tarball) it writes "unknown";
#   - for a folder inside some other checkout (a tarball unpacked in another
#     repository) it also writes "unknown", not that repository's description;
#   - a second run with nothing changed leaves the files untouched (no rebuild).
# Exit 0 = pass, 1 = fail, 77 = skipped (no git, or the source is not a checkout).
set -u
script=${1:?usage: test_version_info.sh WriteVersionInfo.cmake SOURCE_DIR}
source_dir=${2:?}
fail=0
bad() { printf 'FAIL: %s\n' "$*"; fail=1; }
expect() {  # expect WHAT GOT WANT
  if [[ $2 == "$3" ]]; then echo "ok: $1: $2"; else bad "$1: '$2', expected '$3'"; fi
}
command -v git >/dev/null || { echo "SKIP: no git"; exit 77; }
git -C "$source_dir" rev-parse --show-toplevel >/dev/null 2>&1 || { echo "SKIP: $source_dir is not a git checkout"; exit 77; }

work=$(mktemp -d "${TMPDIR:-/tmp}/resolver-version.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT
git_exe=$(command -v git)
write() {  # write SOURCE_DIR OUT_PREFIX
  cmake -DPROJECT_VERSION=9.8.7 "-DSOURCE_DIR=$1" "-DGIT_EXECUTABLE=$git_exe" \
    "-DHEADER=$2.h" "-DTEXT=$2.txt" -P "$script" || bad "cmake -P $script failed for $1"
}

write "$source_dir" "$work/here"
want="9.8.7 (git $(git -C "$source_dir" describe --always --dirty))"
got=$(cat "$work/here.txt")
expect "checkout" "$got" "$want"
grep -qF "kGitDescription = \"$(git -C "$source_dir" describe --always --dirty)\"" "$work/here.h" ||
  bad "the header does not carry the description: $(cat "$work/here.h")"

mkdir -p "$work/tarball"
write "$work/tarball" "$work/tarball_out"
got=$(cat "$work/tarball_out.txt")
expect "not a checkout" "$got" "9.8.7 (git unknown)"

write "$source_dir/cmake" "$work/nested"
got=$(cat "$work/nested.txt")
expect "inside another checkout" "$got" "9.8.7 (git unknown)"

touch -d '2000-01-01' "$work/here.h" "$work/here.txt"
write "$source_dir" "$work/here"
if [[ $(stat -c %Y "$work/here.h") == $(date -d 2000-01-01 +%s) && $(stat -c %Y "$work/here.txt") == $(date -d 2000-01-01 +%s) ]]; then
  echo "ok: an unchanged description rewrites nothing"
else
  bad "the files were rewritten although nothing changed (every build would relink every program)"
fi
((fail)) && exit 1
echo PASS
