#!/usr/bin/env bash
# Runs the test programs given on the command line, TEST_JOBS at a time (default: the machine's
# cores), each with its output kept in $TEST_LOGS/NAME.log (default build/test-logs). The
# programs that took longest last time start first (build/test-logs/durations), so the slowest
# one does not start last. When all have ended it prints, in the order given, each program's
# FAIL lines and summary line, then one closing line "tests: P passed, F failed" summing the
# "NAME: p passed, f failed" lines. A program that crashes or exits non-zero without a summary
# line counts as one failure.
set -u
jobs="${TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}"
logs="${TEST_LOGS:-build/test-logs}"
mkdir -p "$logs"
durations="$logs/durations"
touch "$durations"

# A program's name: its path without the build and tests folders, "/" as "-" (build/tests/test_io
# is test_io, the sanitized build/asan/tests/test_io is asan-test_io, tests/test_flow.py test_flow).
name_of() { sed -E -e 's#^(\./)?(build/)?##' -e 's#(^|/)tests/#\1#' -e 's#/#-#g' -e 's/\.(py|sh)$//' <<<"$1"; }

run_one() {   # run_one PROG: output to its log, exit status and seconds to its .rc file
    local prog="$1" name start rc
    name=$(name_of "$prog")
    start=$(date +%s%N)
    case "$prog" in
        *.py) "${PYTHON:-/usr/bin/python3}" "$prog" >"$logs/$name.log" 2>&1; rc=$? ;;
        *) "$prog" >"$logs/$name.log" 2>&1; rc=$? ;;
    esac
    echo "$rc $((($(date +%s%N) - start) / 1000000))" >"$logs/$name.rc"   # milliseconds
}

# Longest first (by the last run's milliseconds; unknown programs first of all, in the given order).
order=$(for prog in "$@"; do
    s=$(awk -v n="$(name_of "$prog")" '$1 == n { print $2 }' "$durations")
    printf '%s %s\n' "${s:-1e9}" "$prog"
done | sort -s -g -r -k1,1 | cut -d' ' -f2-)

for prog in "$@"; do rm -f "$logs/$(name_of "$prog").rc"; done
running=0
for prog in $order; do
    if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
    run_one "$prog" &
    running=$((running + 1))
done
wait

total_pass=0; total_fail=0
: >"$durations.new"
for prog in "$@"; do
    name=$(name_of "$prog")
    read -r rc secs <"$logs/$name.rc" 2>/dev/null || { rc=255; secs=0; }
    echo "$name $secs" >>"$durations.new"
    out="$logs/$name.log"
    grep -E 'FAIL' "$out" || true
    line=$(grep -E '^[A-Za-z0-9_.-]+: [0-9]+ passed, [0-9]+ failed' "$out" | tail -n 1)
    [ -n "$line" ] && echo "$name:${line#*:}"
    if [ -n "$line" ]; then
        p=$(sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\1/' <<<"$line")
        f=$(sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\2/' <<<"$line")
        total_pass=$((total_pass + p)); total_fail=$((total_fail + f))
        if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
            echo "$prog: exit status $rc"; total_fail=$((total_fail + 1))
        fi
    else
        echo "$prog: no summary line (exit status $rc)"; tail -n 20 "$out"
        total_fail=$((total_fail + 1))
    fi
done
mv "$durations.new" "$durations"
echo "(outputs in $logs/NAME.log; $jobs programs at a time)"
echo "tests: $total_pass passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
