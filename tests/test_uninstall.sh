#!/usr/bin/env bash
# `make uninstall PREFIX=P` removes exactly what `make install PREFIX=P` created, by the manifest
# install writes (tools/install_manifest.sh):
# 1. P with folders that were there before, empty (include, lib/pkgconfig, share/man/man1, the
#    Python folder, bin with another program in it): after install and uninstall, P is as it was,
#    folder for folder and file for file. Installed twice (a reinstall), the same.
# 2. A P that did not exist: after install and uninstall, P is gone.
# 3. A file put into an installed folder afterwards stays, and so does its folder.
set -u
cd "$(dirname "$0")/.."
pass=0; fail=0
ok() { pass=$((pass+1)); }
bad() { echo "FAIL: $*"; fail=$((fail+1)); }
top=$(mktemp -d "/tmp/swim uninstall-XXXXXX")
trap 'rm -rf "$top"' EXIT
tree() { ( cd "$1" && find . | LC_ALL=C sort ); }
inst() { make --no-print-directory -s install PREFIX="$1" >>"$top/log" 2>&1; }
uninst() { make --no-print-directory -s uninstall PREFIX="$1" >>"$top/log" 2>&1; }

p="$top/pre 'q'"
mkdir -p "$p/include" "$p/lib/pkgconfig" "$p/share/man/man1" "$p/lib/python3/dist-packages" "$p/bin"
echo "#!/bin/sh" >"$p/bin/other"
before=$(tree "$p")
inst "$p" && ok || bad "make install failed: $(tail -3 "$top/log")"
[ -x "$p/bin/swim" ] && [ -f "$p/include/swim.h" ] && [ -f "$p/share/swim/install-manifest" ] && ok \
    || bad "installed tree incomplete or no manifest"
grep -qx "include" "$p/share/swim/install-manifest" && bad "the manifest claims include/, which was there before" || ok
grep -qx "share/swim" "$p/share/swim/install-manifest" && ok || bad "the manifest lacks share/swim, which install made"
inst "$p" && ok || bad "make install (again) failed: $(tail -3 "$top/log")"
grep -qx "share/swim/generator/generate.py" "$p/share/swim/install-manifest" && ok \
    || bad "a reinstall lost the files of the first install from the manifest"
uninst "$p" && ok || bad "make uninstall failed: $(tail -3 "$top/log")"
after=$(tree "$p")
[ "$before" = "$after" ] && ok || bad "P differs after install + uninstall: $(diff <(echo "$before") <(echo "$after") | tr '\n' ' ')"

q="$top/fresh/prefix"
inst "$q" && ok || bad "make install into a new folder failed: $(tail -3 "$top/log")"
uninst "$q" && ok || bad "make uninstall failed: $(tail -3 "$top/log")"
[ ! -e "$q" ] && [ -d "$top/fresh" ] && ok || bad "a new P is not removed, or its parent is: $(ls -R "$top/fresh" | head -5 | tr '\n' ' ')"

inst "$q" && echo "mine" >"$q/share/swim/notes.txt" && uninst "$q"
[ -f "$q/share/swim/notes.txt" ] && [ ! -e "$q/bin/swim" ] && ok || bad "a file added after install was removed, or swim stayed"
echo "test_uninstall: $pass passed, $fail failed"
[ $fail -eq 0 ]
