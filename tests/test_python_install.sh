#!/usr/bin/env bash
# The Python package as a user gets it: `make install PREFIX=...` (a PREFIX with a space and a
# quote), then from another folder Debian's python3 with PYTHONPATH=PREFIX/lib/python3/dist-packages
# imports swim from the prefix, which loads PREFIX/lib/libswim.so.ABI (not the build tree's), runs
# Example 3 to t = 5 with the final state of `swim run` to the last bit, and says VERSION's
# version; the import may write bytecode (PYTHONDONTWRITEBYTECODE unset, as for most users).
# `make uninstall` removes the package and that bytecode but not another package beside it, and
# leaves no folder of its own behind (and none that was there before install).
set -u
cd "$(dirname "$0")/.."
. tests/python_final_state.sh
top=$(mktemp -d /tmp/swim-py-XXXXXX)
prefix="$top/pre fix'q"
pkg="$prefix/lib/python3/dist-packages"
trap 'rm -rf "$top"' EXIT
export SWIM_CACHE=${SWIM_CACHE:-$PWD/build/cache}
SWIM=${SWIM_BIN:-$PWD/bin/swim}
mkdir -p "$top/elsewhere"

if make --no-print-directory -s install PREFIX="$prefix" >"$top/install.log" 2>&1; then ok; else
    bad "make install failed: $(tail -3 "$top/install.log")"; fi
for f in __init__.py _lib.py; do [ -f "$pkg/swim/$f" ] && ok || bad "not installed: $pkg/swim/$f"; done

want=$(python_reference "$top")
out=$(cd "$top/elsewhere" && env -u SWIM_LIB -u SWIM_SHARE -u PYTHONDONTWRITEBYTECODE PYTHONPATH="$pkg" /usr/bin/python3 -c "$PYTHON_RUN" \
      "$OLDPWD/models/example3.toml" 2>"$top/py.err")
[ "$(sed -n 1p <<<"$out")" = "$pkg/swim/__init__.py" ] && ok || bad "swim imported from '$(sed -n 1p <<<"$out")' ($(cat "$top/py.err"))"
abi=$(sed -n 's/^#define SWIM_ABI \([0-9][0-9]*\)$/\1/p' runtime/lib/swim.h)
[ "$(sed -n 2p <<<"$out")" = "$prefix/lib/libswim.so.$abi" ] && ok || bad "libswim loaded from '$(sed -n 2p <<<"$out")'"
[ "$(sed -n 3p <<<"$out")" = "$(cat VERSION)" ] && ok || bad "swim.__version__ '$(sed -n 3p <<<"$out")' vs VERSION $(cat VERSION)"
[ -n "$want" ] && [ "$(sed -n 4p <<<"$out")" = "$want" ] && ok || bad "final state '$(sed -n 4p <<<"$out")' vs swim run '$want'"
[ -d "$pkg/swim/__pycache__" ] && ok || bad "the import wrote no bytecode (the uninstall check below tests nothing)"

echo "# another package" >"$pkg/other.py"
make --no-print-directory -s uninstall PREFIX="$prefix" >"$top/uninstall.log" 2>&1 && ok || bad "make uninstall failed"
[ ! -e "$pkg/swim" ] && ok || bad "left after uninstall: $(find "$pkg/swim" | tr '\n' ' ')"
[ -f "$pkg/other.py" ] && ok || bad "make uninstall removed another package's file"
rm -f "$pkg/other.py"
make --no-print-directory -s install-python PREFIX="$prefix" >>"$top/install.log" 2>&1 && ok || bad "make install-python failed"
make --no-print-directory -s uninstall-python PREFIX="$prefix" >>"$top/uninstall.log" 2>&1 && ok || bad "make uninstall-python failed"
# the package's folder goes; lib/python3/dist-packages was there before this install (kept by
# other.py at the uninstall above), so it stays: uninstall removes only the folders install made
[ ! -e "$pkg/swim" ] && [ -d "$pkg" ] && ok || bad "after uninstall-python: $(find "$prefix/lib/python3" | tr '\n' ' ')"
echo "test_python_install: $pass passed, $fail failed"
[ $fail -eq 0 ]
