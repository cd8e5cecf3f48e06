#!/usr/bin/env bash
# Regenerating the committed kernels must reproduce them byte for byte.
set -u
cd "$(dirname "$0")/.."
pass=0; fail=0
# Into a folder of its own, not in place: other tests run at the same time, and rewriting
# generated/ would make `make` rebuild bin/swim under them.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
modes=$(sed -n 's/^MODES *?= *//p' Makefile)
# (run from $work with `--out generated`: the files record the command that made them)
root=$PWD
if (cd "$work" && "${PYTHON:-/usr/bin/python3}" "$root/generator/generate.py" --modes $modes --out generated --quiet) >"$work/log" 2>&1; then
    for f in generated/*.c; do
        if cmp -s "$f" "$work/$f"; then pass=$((pass+1)); else
            echo "FAIL: regenerating $f gives other bytes"; fail=$((fail+1)); fi
    done
else
    echo "FAIL: the generator failed: $(tail -3 "$work/log")"; fail=$((fail+1))
fi
echo "test_regenerate: $pass passed, $fail failed"
[ $fail -eq 0 ]
