#!/usr/bin/env bash
# Runs each test program given on the command line, keeps its output, and prints one
# closing line "tests: P passed, F failed" summing the "NAME: p passed, f failed" lines.
# A program that crashes or exits non-zero without a summary line counts as one failure.
set -u
total_pass=0; total_fail=0
for prog in "$@"; do
    case "$prog" in
        *.py) out=$("${PYTHON:-/usr/bin/python3}" "$prog" 2>&1); rc=$? ;;
        *) out=$("$prog" 2>&1); rc=$? ;;
    esac
    printf '%s\n' "$out" | grep -E 'FAIL|passed, [0-9]+ failed' || true
    line=$(printf '%s\n' "$out" | grep -E '^[A-Za-z0-9_.-]+: [0-9]+ passed, [0-9]+ failed' | tail -n 1)
    if [ -n "$line" ]; then
        p=$(sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\1/' <<<"$line")
        f=$(sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\2/' <<<"$line")
        total_pass=$((total_pass + p)); total_fail=$((total_fail + f))
        if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
            echo "$prog: exit status $rc"; total_fail=$((total_fail + 1))
        fi
    else
        echo "$prog: no summary line (exit status $rc)"; printf '%s\n' "$out" | tail -n 20
        total_fail=$((total_fail + 1))
    fi
done
echo "tests: $total_pass passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
