#!/usr/bin/env bash
# The .deb as a bench engineer gets it (ctest install_deb, label install):
#   1. cpack builds resolver-bench_<version>_<arch>.deb from the build tree;
#   2. its Depends: names the package of every shared library an installed
#      program links directly (readelf NEEDED -> ldd path -> dpkg -S), and python3;
#   3. dpkg installs it into a fresh root (dpkg --root, no container, no chroot:
#      --force-script-chrootless, and the maintainer scripts do nothing under
#      DPKG_ROOT). The root's dpkg database is a copy of this machine's, so
#      dpkg's own dependency check runs against the packages really installed
#      here. Control: with liblcm1 taken out of that database dpkg must refuse;
#   4. from the root only: every program's --version (the build's own line),
#      resolver-model --help, a man page per program, no RUNPATH into the build;
#   5. the demo from installed files: resolver-sim with the installed demo config
#      -> resolverd --replay --once --fast with the installed DBC -> resolver-echo
#      --log; the installed Python example reads the same log and agrees;
#   6. systemd-analyze verify --root=ROOT on the installed units: clean. verify
#      resolves ExecStart=, ExecReload= and the units' dependencies inside the
#      root, so the root also gets this machine's systemd units and kill (what
#      any systemd host has; no-clobber, so the installed units win). Control:
#      without the installed resolverd, verify complains about ExecStart;
#   7. dpkg --root -r removes every file it installed.
# Exit 0 = pass, 1 = fail, 77 = skipped (no dpkg: not a Debian machine).
# RESOLVER_REQUIRE_SYSTEMD_ANALYZE=1 makes a missing systemd-analyze a failure.
set -u

build="" cpack="" version="" lcm_dir="" work=""
while (($# > 0)); do
  case $1 in
    --build) build=$2 ;;
    --cpack) cpack=$2 ;;
    --version) version=$2 ;;
    --lcm-dir) lcm_dir=$2 ;;
    --work) work=$2 ;;
    *) echo "usage: $0 --build DIR --cpack CPACK --version X.Y.Z --lcm-dir DIR --work DIR" >&2; exit 2 ;;
  esac
  shift 2
done
[[ -n $build && -n $cpack && -n $version && -n $lcm_dir && -n $work ]] || { echo "missing arguments" >&2; exit 2; }

fail=0
note() { printf '%s\n' "$*"; }
bad() { printf 'FAIL: %s\n' "$*"; fail=1; }
die() { printf 'FAIL: %s\n' "$*"; exit 1; }

for tool in dpkg dpkg-deb; do
  command -v "$tool" >/dev/null || { note "SKIP: $tool not found (the .deb test needs Debian's dpkg)"; exit 77; }
done

rm -rf "$work"
mkdir -p "$work/pkg"
root="$work/root"
arch=$(dpkg --print-architecture)

# --- 1. the package ------------------------------------------------------------
note "== cpack -G DEB"
"$cpack" -G DEB --config "$build/CPackConfig.cmake" -B "$work/pkg" >"$work/cpack.log" 2>&1 ||
  { cat "$work/cpack.log"; die "cpack failed"; }
deb="$work/pkg/resolver-bench_${version}_${arch}.deb"
[[ -f $deb ]] || { ls "$work/pkg"; die "expected $deb"; }
note "ok: $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB)"
field() { dpkg-deb -f "$deb" "$1"; }
[[ $(field Package) == resolver-bench && $(field Version) == "$version" && $(field Architecture) == "$arch" ]] ||
  bad "control fields: Package=$(field Package) Version=$(field Version) Architecture=$(field Architecture)"
depends=$(field Depends)
note "   Depends: $depends"
note "   Recommends: $(field Recommends)"

# --- 3. install into a fresh root (before 2: the checks read the installed files) ----
# make_root DIR [PACKAGE_TO_DROP]: an empty root whose dpkg database says this
# machine's packages are installed (status copied; empty file lists so dpkg
# does not warn about each), optionally without one package.
make_root() {
  local dir=$1 drop=${2:-}
  mkdir -p "$dir/var/lib/dpkg/info" "$dir/var/lib/dpkg/updates" "$dir/var/lib/dpkg/triggers" "$dir/var/log"
  touch "$dir/var/lib/dpkg/available"
  if [[ -n $drop ]]; then
    # Paragraph mode: every stanza but the one of $drop.
    awk -v drop="$drop" 'BEGIN { RS = ""; ORS = "\n\n" } $0 !~ ("(^|\n)Package: " drop "\n")' \
      /var/lib/dpkg/status >"$dir/var/lib/dpkg/status"
  else
    cp /var/lib/dpkg/status "$dir/var/lib/dpkg/status"
  fi
  dpkg-query -W -f '${binary:Package}\n' | while read -r p; do : >"$dir/var/lib/dpkg/info/$p.list"; done
}
dpkg_root() {  # dpkg_root ROOT ARGS...
  local r=$1
  shift
  dpkg --root="$r" --force-script-chrootless --force-not-root "$@"
}

note "== dpkg --root $root -i"
make_root "$root"
dpkg_root "$root" -i "$deb" >"$work/dpkg-install.log" 2>&1 || { cat "$work/dpkg-install.log"; die "dpkg -i into the fresh root failed"; }
status=$(dpkg --root="$root" -s resolver-bench 2>/dev/null | sed -n 's/^Status: //p')
if [[ $status == "install ok installed" ]]; then note "ok: installed ($status)"; else bad "dpkg status after install: '$status'"; fi

note "== control: the same root without liblcm1"
make_root "$work/root-no-lcm" liblcm1
if dpkg_root "$work/root-no-lcm" -i "$deb" >"$work/dpkg-no-lcm.log" 2>&1; then
  bad "dpkg installed the package although liblcm1 is missing: the dependency check proves nothing"
elif grep -q "depends on liblcm1" "$work/dpkg-no-lcm.log"; then
  note "ok: refused ($(grep -m1 'depends on liblcm1' "$work/dpkg-no-lcm.log" | sed 's/^ *//'))"
else
  cat "$work/dpkg-no-lcm.log"
  bad "dpkg refused, but not for liblcm1"
fi
rm -rf "$work/root-no-lcm"

# --- 2. Depends covers what the programs link ---------------------------------
note "== Depends vs the libraries the installed programs link"
depends_names=" $(tr ',|' '\n' <<<"$depends" | sed 's/(.*)//; s/ //g; s/:.*//' | tr '\n' ' ') "
# unlisted_libraries " NAME NAME ... ": prints "program: soname from package" for
# every library an installed program links directly whose package is not a NAME.
unlisted_libraries() {
  local names=$1 exe ldd_out soname path pkg p
  for exe in "$root"/usr/bin/*; do
    readelf -h "$exe" >/dev/null 2>&1 || continue # ELF programs only (resolver-spy is bash)
    ldd_out=$(ldd "$exe")
    for soname in $(readelf -d "$exe" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
      path=$(awk -v so="$soname" '$1 == so && $2 == "=>" { print $3 }' <<<"$ldd_out")
      [[ -n $path ]] || { echo "$(basename "$exe"): $soname not found by the loader"; continue; }
      # Debian 12 merges /lib into /usr/lib; dpkg knows a file under one of the two names.
      pkg=""
      for p in "$path" "$(readlink -f "$path")" "/usr${path}" "${path#/usr}"; do
        pkg=$(dpkg -S "$p" 2>/dev/null | head -1 | sed 's/:.*//')
        [[ -n $pkg ]] && break
      done
      [[ -n $pkg && $names == *" $pkg "* ]] || echo "$(basename "$exe"): $soname from ${pkg:-no package}"
    done
  done
}
unlisted=$(unlisted_libraries "$depends_names")
if [[ -n $unlisted ]]; then
  bad "libraries whose package Depends does not name:"
  printf '  %s\n' "$unlisted"
else
  note "ok: every directly linked library's package is in Depends"
fi
# Control: the same check with liblcm1 left out of Depends must object.
if unlisted_libraries "${depends_names/ liblcm1 / }" | grep -q "liblcm.so"; then
  note "ok: control: without liblcm1 in Depends the check names liblcm.so"
else
  bad "control: the check did not notice liblcm1 missing from Depends"
fi
[[ $depends_names == *" python3 "* ]] || bad "Depends lacks python3 (the resolver_lcm package)"

# --- 4. the installed programs --------------------------------------------------
note "== the installed programs"
run_env=(env -i "PATH=/usr/bin:/bin" "HOME=$work" "LC_ALL=C.UTF-8")
programs=(resolverd resolver-sim resolver-echo resolver-model resolver-accuracy resolver-spy)
for p in "${programs[@]}"; do
  exe=$root/usr/bin/$p
  [[ -x $exe ]] || { bad "$exe missing"; continue; }
  got=$("${run_env[@]}" "$exe" --version 2>&1) || bad "$p --version exited $?: $got"
  want=$("$build/bin/$p" --version 2>&1)
  if [[ ! $got =~ ^$p\ ${version//./\\.}\ \(git\ [^\)]+\)$ ]]; then
    bad "$p --version: '$got' (expected '$p $version (git DESCRIPTION)')"
  elif [[ $got != "$want" ]]; then
    bad "$p --version: installed '$got' but the build says '$want'"
  fi
  page=$root/usr/share/man/man1/$p.1.gz
  if [[ ! -f $page ]]; then
    bad "no man page $page"
  elif ! zcat "$page" | grep -q "^\.TH \"\?${p^^}"; then
    bad "$page has no .TH ${p^^} header"
  fi
  if readelf -h "$exe" >/dev/null 2>&1 && readelf -d "$exe" | grep -qE 'RPATH|RUNPATH'; then
    bad "$p has an RPATH/RUNPATH: $(readelf -d "$exe" | grep -E 'RPATH|RUNPATH')"
  fi
done
((fail)) || note "ok: ${#programs[@]} programs: --version '$("$root/usr/bin/resolverd" --version)', man pages, no RUNPATH"
help=$("${run_env[@]}" "$root/usr/bin/resolver-model" --help 2>&1) || bad "resolver-model --help exited $?"
grep -q "explain" <<<"$help" || bad "resolver-model --help does not list explain"
zcat "$root/usr/share/man/man1/resolver-model.1.gz" | grep -q '^\.SS "resolver-model fit"' ||
  bad "resolver-model.1 lacks the fit subcommand's section"

share=$root/usr/share/resolver-bench
for f in "$share/resolver_bench.dbc" "$share/demo/demo_bench.toml" "$root/usr/lib/systemd/system/resolverd.service" \
  "$root/usr/lib/systemd/system/resolverd@.service" "$share/systemd-network/can0.network" \
  "$root/usr/lib/python3/dist-packages/resolver_lcm/resolver/angle_t.py" \
  "$root/usr/lib/python3/dist-packages/resolver_bench/fleet.py" \
  "$root/usr/share/doc/resolver-bench/examples/lcmlog_to_arrays.py"; do
  [[ -f $f ]] || bad "not installed: ${f#"$root"}"
done
for lcm in "$lcm_dir"/*.lcm; do
  name=$(basename "$lcm" .lcm)
  cmp -s "$lcm" "$share/lcm/resolver/$name.lcm" || bad "not installed (or different): share/resolver-bench/lcm/resolver/$name.lcm"
  [[ -f $root/usr/include/resolver/$name.hpp ]] || bad "not installed: include/resolver/$name.hpp"
done
if [[ -f $build/share/resolver-types.jar && ! -f $root/usr/share/java/resolver-types.jar ]]; then
  bad "the build made resolver-types.jar but the package lacks share/java/resolver-types.jar"
fi

# --- 5. the demo from the installed files ---------------------------------------
note "== the demo from installed files"
demo=$work/demo
mkdir -p "$demo"
# The installed DBC instead of the compiled-in copy: the file must decode the log.
printf '[layout]\ndbc = "%s"\n' "$share/resolver_bench.dbc" >"$demo/installed_dbc.toml"
duration_s=2
sample_rate_hz=2000 # resolver-sim's default; the demo config does not change it
if "${run_env[@]}" "$root/usr/bin/resolver-sim" --config "$share/demo/demo_bench.toml" --duration "$duration_s" \
  --out "$demo/demo.log" >"$demo/sim.out" 2>&1 &&
  "${run_env[@]}" "$root/usr/bin/resolverd" --replay "$demo/demo.log" --once --fast --quiet \
    --config "$demo/installed_dbc.toml" --report "$demo/report.json" \
    --lcm "file://$demo/demo.lcmlog?mode=w" >"$demo/resolverd.out" 2>&1 &&
  "${run_env[@]}" "$root/usr/bin/resolver-echo" --log "$demo/demo.lcmlog" >"$demo/echo.jsonl" 2>"$demo/echo.err"; then
  if counts=$(/usr/bin/python3 - "$demo/echo.jsonl" "$demo/report.json" "$((duration_s * sample_rate_hz))" <<'PY'
import collections, json, sys
counts = collections.Counter(json.loads(line)["channel"] for line in open(sys.argv[1]))
report = json.load(open(sys.argv[2]))
samples = int(sys.argv[3])
problems = []
if report["samples_complete"] != samples:
    problems.append(f"{report['samples_complete']} samples decoded, expected {samples}")
if not report["converged"]:
    problems.append("the alpha estimate did not converge")
if counts["RESOLVER_ANGLE"] != samples:  # angle_decimation = 1: one angle_t per sample
    problems.append(f"{counts['RESOLVER_ANGLE']} RESOLVER_ANGLE messages, expected {samples}")
for ch in ("RESOLVER_DQ", "RESOLVER_ESTIMATE", "RESOLVER_HEALTH", "RESOLVER_MODEL_FIT"):
    if counts[ch] == 0:
        problems.append(f"no {ch} message")
print(json.dumps(dict(sorted(counts.items()))))
sys.exit("; ".join(problems) if problems else 0)
PY
  ); then
    note "ok: sim -> resolverd -> echo from the root: $counts"
  else
    bad "demo output: $counts"
  fi
else
  cat "$demo"/*.out "$demo/echo.err" 2>/dev/null
  bad "the demo failed with the installed programs"
fi

# The installed Python package and example on the same log agree with resolver-echo.
pythonpath=$root/usr/lib/python3/dist-packages
if [[ -f $demo/echo.jsonl ]]; then
  where=$("${run_env[@]}" "PYTHONPATH=$pythonpath" /usr/bin/python3 -c 'import resolver_lcm; print(resolver_lcm.__file__)' 2>&1)
  [[ $where == "$pythonpath/"* ]] || bad "resolver_lcm imported from '$where', not from the root"
  if "${run_env[@]}" "PYTHONPATH=$pythonpath" PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 \
    "$root/usr/share/doc/resolver-bench/examples/lcmlog_to_arrays.py" "$demo/demo.lcmlog" --json >"$demo/example.json" 2>"$demo/example.err"; then
    if /usr/bin/python3 - "$demo/echo.jsonl" "$demo/example.json" <<'PY'; then
import collections, json, sys
echo = collections.Counter(json.loads(line)["channel"] for line in open(sys.argv[1]))
example = {name: ch["count"] for name, ch in json.load(open(sys.argv[2]))["channels"].items()}
if dict(echo) != example:
    sys.exit(f"resolver-echo {dict(echo)} != example {example}")
PY
      note "ok: the installed Python example counts what resolver-echo counts"
    else
      bad "Python example vs resolver-echo"
    fi
  else
    cat "$demo/example.err"
    bad "the installed lcmlog_to_arrays.py failed"
  fi
fi

# --- 6. systemd-analyze verify on the installed units ---------------------------
if ! command -v systemd-analyze >/dev/null; then
  if [[ ${RESOLVER_REQUIRE_SYSTEMD_ANALYZE:-0} == 1 ]]; then
    bad "systemd-analyze not found but RESOLVER_REQUIRE_SYSTEMD_ANALYZE=1"
  else
    note "note: systemd-analyze not found; installed units not verified"
  fi
else
  note "== systemd-analyze verify --root"
  units=$root/usr/lib/systemd/system
  grep -q "^ExecStart=/usr/bin/resolverd " "$units/resolverd.service" ||
    bad "installed resolverd.service: $(grep '^ExecStart=' "$units/resolverd.service")"
  # What a systemd host has that the units refer to: its units (sysinit.target,
  # network-online.target, ...) and /bin/kill for ExecReload=. Debian 12 merges /usr.
  for dir in /usr/lib/systemd/system /lib/systemd/system; do
    [[ -d $dir ]] && cp -an "$dir/." "$units/"
  done
  [[ -e $root/bin ]] || ln -s usr/bin "$root/bin"
  # /bin/kill, not the shell builtin: ExecReload= runs the program (procps).
  if [[ ! -e $root/usr/bin/kill ]]; then
    cp "$(readlink -f /bin/kill)" "$root/usr/bin/kill" || bad "/bin/kill not found on this machine (Debian: procps)"
  fi
  verify_root() { (cd "$work" && systemd-analyze verify --man=no --root="$root" "$@" 2>&1); }
  if out=$(verify_root resolverd.service resolverd@can0.service) && [[ -z $out ]]; then
    note "ok: verify --root: resolverd.service, resolverd@can0.service clean"
  else
    bad "systemd-analyze verify --root on the installed units:"
    printf '%s\n' "$out"
  fi
  mv "$root/usr/bin/resolverd" "$root/usr/bin/resolverd.moved"
  out=$(verify_root resolverd.service)
  mv "$root/usr/bin/resolverd.moved" "$root/usr/bin/resolverd"
  if grep -q "/usr/bin/resolverd is not executable" <<<"$out"; then
    note "ok: control: without the installed resolverd, verify says: $(grep -m1 'not executable' <<<"$out")"
  else
    bad "control: verify did not notice the missing /usr/bin/resolverd ($out); it checks nothing in the root"
  fi
fi

# --- 7. removal -------------------------------------------------------------------
note "== dpkg --root -r"
dpkg -c "$deb" | awk '{ print $NF }' | grep -v '/$' | sed 's#^\./#/#' >"$work/files.txt"
if dpkg_root "$root" -r resolver-bench >"$work/dpkg-remove.log" 2>&1; then
  left=0
  while read -r f; do [[ -e $root$f ]] && { bad "left after removal: $f"; left=1; }; done <"$work/files.txt"
  ((left)) || note "ok: removed; none of its $(wc -l <"$work/files.txt") files is left"
else
  cat "$work/dpkg-remove.log"
  bad "dpkg -r failed"
fi

if ((fail)); then exit 1; fi
note "PASS"
