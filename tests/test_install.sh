#!/usr/bin/env bash
# `make install PREFIX=<temporary folder>`, then the installed swim run from another directory
# with its own cache: it finds its generator and headers from its own location (no build-time
# path), generates the scene kernel and writes a correct run.
set -u
cd "$(dirname "$0")/.."
pass=0; fail=0
ok() { pass=$((pass+1)); }
bad() { echo "FAIL: $*"; fail=$((fail+1)); }
# A prefix with spaces and a quote: one folder, wherever the recipe passes it to the shell.
top=$(mktemp -d "/tmp/swim install-XXXXXX")
prefix="$top/pre fix 'q'"
work=$(mktemp -d /tmp/swim-work-XXXXXX)
trap 'rm -rf "$top" "$work"' EXIT
# every path of the checkout (empty folders too) but the build's own
checkout() { find . -path ./build -prune -o -path ./bin -prune -o -path ./.git -prune -o -print | LC_ALL=C sort; }
before=$(checkout)
if make --no-print-directory -s install PREFIX="$prefix" >"$work/install.log" 2>&1; then ok; else
    bad "make install failed: $(tail -3 "$work/install.log")"; fi
stray=$(LC_ALL=C comm -13 <(echo "$before") <(checkout) | tr '\n' ' ')
[ -z "$stray" ] && ok || bad "make install created files in the checkout: $stray"
[ "$(ls -A "$top")" = "pre fix 'q'" ] && ok || bad "make install: $top holds $(ls -A "$top"), not one prefix folder"
# a relative PREFIX would install into the checkout: refused before anything is made
make --no-print-directory -s install PREFIX="rel prefix" >"$work/rel.log" 2>&1
rc=$?
[ $rc -ne 0 ] && [ ! -e "rel prefix" ] && [ ! -e rel ] && grep -q "PREFIX='rel prefix'" "$work/rel.log" && ok \
    || bad "make install PREFIX='rel prefix': exit $rc, $(cat "$work/rel.log")"
rm -rf "rel prefix" rel
[ -x "$prefix/bin/swim" ] && [ -f "$prefix/share/swim/generator/generate.py" ] \
    && [ -f "$prefix/share/swim/runtime/kernel/assembly.h" ] && ok || bad "installed tree incomplete"
# the example scenes and the documentation, and the man page naming where they are
n_models=$(find models -type f | wc -l); n_docs=$(( $(find docs -type f | wc -l) + 1 ))
[ "$(find "$prefix/share/swim/models" -type f 2>/dev/null | wc -l)" -eq "$n_models" ] \
    && cmp -s models/README.md "$prefix/share/swim/models/README.md" && ok \
    || bad "make install: PREFIX/share/swim/models does not hold the $n_models files of models/"
[ "$(find "$prefix/share/doc/swim" -type f 2>/dev/null | wc -l)" -eq "$n_docs" ] && [ -f "$prefix/share/doc/swim/README.md" ] \
    && cmp -s docs/run-driver.md "$prefix/share/doc/swim/docs/run-driver.md" && ok \
    || bad "make install: PREFIX/share/doc/swim does not hold README.md and the $((n_docs - 1)) files of docs/"
grep -q 'PREFIX/share/swim/models' "$prefix/share/man/man1/swim.1" && grep -q 'PREFIX/share/doc/swim' "$prefix/share/man/man1/swim.1" \
    && ok || bad "the man page does not name PREFIX/share/swim/models and PREFIX/share/doc/swim"
cp models/example3.toml "$work/scene.toml"
# from another directory, the source tree out of sight (moved copy of the install as well)
mv "$prefix" "$prefix-moved" && prefix="$prefix-moved"
( cd "$work" && env -u SWIM_SHARE SWIM_CACHE="$work/cache" "$prefix/bin/swim" run scene.toml --out run --t-end 2 --quiet ) \
    >"$work/run.log" 2>&1 && ok || bad "installed swim run failed: $(tail -3 "$work/run.log")"
grep -q '"status": "completed"' "$work/run/summary.json" 2>/dev/null && ok || bad "installed run: no completed summary"
ls "$work"/cache/*/kernel.so >/dev/null 2>&1 && ok || bad "installed run: no kernel in \$SWIM_CACHE"
# the same scene with the build tree's swim gives the same trajectory
SWIM_CACHE="$work/cache2" "${SWIM_BIN:-bin/swim}" run "$work/scene.toml" --out "$work/run2" --t-end 2 --quiet >/dev/null 2>&1
cmp -s "$work/run/trajectory.csv" "$work/run2/trajectory.csv" && ok || bad "installed and build-tree runs differ"
# make uninstall removes the scenes and the documentation with the rest
make --no-print-directory -s uninstall PREFIX="$prefix" >"$work/uninstall.log" 2>&1 \
    && [ ! -e "$prefix/share/swim/models" ] && [ ! -e "$prefix/share/doc/swim" ] && ok \
    || bad "make uninstall left $(ls -d "$prefix/share/swim/models" "$prefix/share/doc/swim" 2>/dev/null) ($(tail -2 "$work/uninstall.log"))"
echo "test_install: $pass passed, $fail failed"
[ $fail -eq 0 ]
