#!/usr/bin/env bash
# The Python package as a pip user gets it: a fresh virtual environment made by Debian's python3
# with --system-site-packages (numpy, setuptools and wheel from Debian), then
# `python3 -m pip install --no-index --no-build-isolation python/` with no package index. From
# another folder that environment imports swim from its own site-packages (not the source tree),
# which finds this checkout's `make lib` build (recorded at build time), and runs Example 3 to
# t = 5 with the final state of `swim run` to the last bit. With SWIM_LIB naming a missing file the
# import fails saying how to get the library. pip uninstall removes the package. The source
# folder is left as it was (pip builds in a copy, so no build/ or egg-info appears in python/).
set -u
cd "$(dirname "$0")/.."
. tests/python_final_state.sh
top=$(mktemp -d /tmp/swim-pip-XXXXXX)
trap 'rm -rf "$top"' EXIT
export SWIM_CACHE=${SWIM_CACHE:-$PWD/build/cache}
SWIM=${SWIM_BIN:-$PWD/bin/swim}
mkdir -p "$top/elsewhere"
src=$(mktemp -d "$top/src-XXXX")
# pip writes build/ and egg-info beside the sources: a copy of python/ keeps this one clean; the
# rest of the copy's checkout is this one (its generator and its `make lib`)
cp -a python VERSION "$src/"
for d in build generator runtime; do ln -s "$PWD/$d" "$src/$d"; done
before=$(git status --porcelain --ignored python)

if /usr/bin/python3 -m venv --system-site-packages "$top/venv" >"$top/venv.log" 2>&1; then ok; else
    bad "venv: $(tail -3 "$top/venv.log")"; fi
py="$top/venv/bin/python3"
if (cd "$src/python" && env -u PIP_INDEX_URL "$py" -m pip install --no-index --no-build-isolation . ) >"$top/pip.log" 2>&1; then ok; else
    bad "pip install failed: $(tail -5 "$top/pip.log")"; fi

want=$(python_reference "$top")
out=$(cd "$top/elsewhere" && env -u SWIM_LIB -u SWIM_SHARE -u PYTHONPATH "$py" -c "$PYTHON_RUN" "$OLDPWD/models/example3.toml" 2>"$top/py.err")
site=$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
[ "$(sed -n 1p <<<"$out")" = "$site/swim/__init__.py" ] && ok || bad "swim imported from '$(sed -n 1p <<<"$out")', want $site ($(cat "$top/py.err"))"
[ "$(sed -n 2p <<<"$out")" = "$src/build/lib/libswim.so.$(cat VERSION)" ] && ok || bad "libswim loaded from '$(sed -n 2p <<<"$out")'"
[ "$(sed -n 3p <<<"$out")" = "$(cat VERSION)" ] && ok || bad "swim.__version__ '$(sed -n 3p <<<"$out")' vs VERSION $(cat VERSION)"
[ -n "$want" ] && [ "$(sed -n 4p <<<"$out")" = "$want" ] && ok || bad "final state '$(sed -n 4p <<<"$out")' vs swim run '$want'"

err=$(cd "$top/elsewhere" && SWIM_LIB="$top/absent.so" "$py" -c 'import swim; swim.run("x.toml")' 2>&1)
grep -q "make lib" <<<"$err" && grep -q "make install" <<<"$err" && ok || bad "a missing library does not say how to get it: $err"

"$py" -m pip uninstall -y swim >"$top/uninstall.log" 2>&1 && ok || bad "pip uninstall: $(tail -3 "$top/uninstall.log")"
[ ! -e "$site/swim" ] && ok || bad "left after pip uninstall: $site/swim"
[ "$(git status --porcelain --ignored python)" = "$before" ] && ok || bad "python/ changed: $(git status --porcelain --ignored python | tr '\n' ' ')"
echo "test_python_pip: $pass passed, $fail failed"
[ $fail -eq 0 ]
