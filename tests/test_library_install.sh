#!/usr/bin/env bash
# libswim as a user gets it: `make install PREFIX=...`, then examples/run_scene.c built from the
# installed prefix with `cc run_scene.c $(pkg-config --cflags --libs swim)` alone, run from
# another folder: its final state equals swim run's summary.json to the last digit, on Example 3
# and on a scene with a barrier; pkg-config's version is swim's; `make uninstall` removes the
# library, its header and swim.pc; the installed swim --version says the same version.
set -u
cd "$(dirname "$0")/.."
pass=0; fail=0
ok() { pass=$((pass+1)); }
bad() { echo "FAIL: $*"; fail=$((fail+1)); }
top=$(mktemp -d /tmp/swim-lib-XXXXXX)
prefix="$top/prefix"
trap 'rm -rf "$top"' EXIT
export SWIM_CACHE=${SWIM_CACHE:-$PWD/build/cache}
SWIM=${SWIM_BIN:-$PWD/bin/swim}

# the whole install: the library finds the generator and the kernel headers in PREFIX/share/swim
if make --no-print-directory -s install PREFIX="$prefix" >"$top/install.log" 2>&1; then ok; else
    bad "make install failed: $(tail -3 "$top/install.log")"; fi
for f in lib/libswim.so lib/libswim.a include/swim.h lib/pkgconfig/swim.pc; do
    [ -e "$prefix/$f" ] && ok || bad "not installed: $f"
done
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
[ "$(pkg-config --modversion swim)" = "$(cat VERSION)" ] && ok || bad "pkg-config --modversion swim: $(pkg-config --modversion swim 2>&1)"
# one version: VERSION's, as the installed swim --version says it
[ "$("$prefix/bin/swim" --version)" = "swim $(pkg-config --modversion swim)" ] && ok \
    || bad "swim --version '$("$prefix/bin/swim" --version 2>&1)' vs pkg-config '$(pkg-config --modversion swim)'"
# CITATION.cff cites this version, not another
[ "$(sed -n 's/^version: "\(.*\)"$/\1/p' CITATION.cff)" = "$(cat VERSION)" ] && ok || bad "CITATION.cff's version is not VERSION's"
# only swim.h's functions (its SWIM_API declarations) are exported by the shared library
declared=$(grep -o 'SWIM_API [^(]*(' runtime/lib/swim.h | sed 's/.*[ *]\(swim_[a-z0-9_]*\)($/\1/' | sort -u)
others=$(nm -D --defined-only "$prefix/lib/libswim.so" | awk '$2 == "T" {print $3}' | grep -vxF "$declared" | head -5 | tr '\n' ' ')
[ "$(wc -l <<<"$declared")" -ge 30 ] && [ -z "$others" ] && ok || bad "libswim.so exports more than swim.h: $others"
for f in swim_strerror swim_model_set swim_struct_size swim_sim_state_at swim_sim_sensitivity swim_sim_lyapunov \
         swim_periodic_orbit swim_floquet_multipliers swim_continuation swim_orbit_branch swim_model_run_member; do
    nm -D --defined-only "$prefix/lib/libswim.so" | grep -q " T $f\$" && ok || bad "libswim.so does not export $f"
done
# one ABI number: swim.h's SWIM_ABI is the SONAME's, the installed symlink's and the Python package's
abi=$(sed -n 's/^#define SWIM_ABI \([0-9][0-9]*\)$/\1/p' runtime/lib/swim.h)
[ -n "$abi" ] && readelf -d "$prefix/lib/libswim.so" | grep -q "SONAME.*\[libswim.so.$abi\]" && [ -e "$prefix/lib/libswim.so.$abi" ] && ok \
    || bad "no SONAME libswim.so.$abi (swim.h's SWIM_ABI) or no lib/libswim.so.$abi"
grep -q "^ABI = $abi\$" python/swim/_lib.py && ok || bad "python/swim/_lib.py's ABI is not swim.h's SWIM_ABI $abi"

cp examples/run_scene.c "$top/"
# shellcheck disable=SC2046
( cd "$top" && cc run_scene.c $(pkg-config --cflags --libs swim) -o run_scene ) >"$top/cc.log" 2>&1 && ok \
    || bad "cc run_scene.c \$(pkg-config --cflags --libs swim): $(tail -3 "$top/cc.log")"

for c in "models/example3.toml 5" "models/hard/near_boundary_a05.toml 1"; do
    read -r scene tend <<<"$c"
    got=$( cd "$top" && env -u SWIM_SHARE ./run_scene "$OLDPWD/$scene" "$tend" 2>"$top/run.err" | tail -1 )
    "$SWIM" run "$scene" --out "$top/ref" --t-end "$tend" --quiet >/dev/null 2>&1
    want=$(/usr/bin/python3 -c "import json,sys; s=json.load(open(sys.argv[1])); f=s['final_state']; print('%.17g %.17g %.17g %.17g' % (f['t'], f['x'], f['y'], f['theta']))" "$top/ref/summary.json")
    [ -n "$got" ] && [ "$got" = "$want" ] && ok || bad "$scene: run_scene '$got' vs swim run '$want' ($(cat "$top/run.err"))"
done
# a bad scene: one line naming the key, exit 2, from the example's error struct
sed 's/^rho0 = 1.0/rho0 = -1.0/' models/example3.toml >"$top/bad.toml"
out=$( cd "$top" && ./run_scene bad.toml 1 2>&1 ); rc=$?
[ $rc -eq 2 ] && grep -q "key model.rho0" <<<"$out" && ok || bad "bad scene: exit $rc, '$out'"

make --no-print-directory -s uninstall-lib PREFIX="$prefix" >"$top/uninstall.log" 2>&1 && ok || bad "make uninstall-lib failed"
# what uninstall-lib owns (the Python package and bin/ have their own uninstall rules)
left=$(cd "$prefix" 2>/dev/null && find lib/libswim* lib/pkgconfig include -type f -o -type l 2>/dev/null | sort | tr '\n' ' ')
[ -z "$left" ] && ok || bad "left after uninstall-lib: $left"
echo "test_library_install: $pass passed, $fail failed"
[ $fail -eq 0 ]
