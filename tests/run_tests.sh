#!/usr/bin/env bash
# Runs the test programs given on the command line, TEST_JOBS at a time (default: the machine's
# cores), each with its output kept in $TEST_LOGS/NAME.log (default build/test-logs). With
# TEST_FILTER (make test T=PATTERN) only the programs whose name matches that extended regular
# expression run. It names the log folder first, then prints one line per program AS IT ENDS
# ("NAME: p passed, f failed (S s)", with the program's FAIL lines under it), and closes with
# the programs that failed and one line "tests: P passed, F failed" summing the programs'
# "NAME: p passed, f failed" lines (CI reads that last line). A program that crashes or exits
# non-zero without a summary line counts as one failure. The programs that took longest last
# time start first (build/test-logs/durations), so the slowest one does not start last; a
# sanitized build (asan-NAME, tsan-NAME) starts after NAME has ended.
set -u
jobs="${TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}"
logs="${TEST_LOGS:-build/test-logs}"
filter="${TEST_FILTER:-}"
mkdir -p "$logs"
durations="$logs/durations"
touch "$durations"

# A program's name: its path without the build and tests folders, "/" as "-" (build/tests/test_io
# is test_io, the sanitized build/asan/tests/test_io is asan-test_io, tests/test_flow.py test_flow).
name_of() { sed -E -e 's#^(\./)?(build/)?##' -e 's#(^|/)tests/#\1#' -e 's#/#-#g' -e 's/\.(py|sh)$//' <<<"$1"; }

progs=()
for prog in "$@"; do
    if [ -z "$filter" ] || grep -qE -- "$filter" <<<"$(name_of "$prog")"; then progs+=("$prog"); fi
done
if [ "${#progs[@]}" -eq 0 ]; then
    echo "tests: no test program matches T=$filter (names as in $logs: test_io, asan-test_io, test_flow, ...)" >&2
    exit 2
fi

# summary LOG RC: "p f" from the program's summary line; "" when it has none
summary() {
    local line
    line=$(grep -E '^[A-Za-z0-9_.-]+: [0-9]+ passed, [0-9]+ failed' "$1" | tail -n 1)
    [ -n "$line" ] && sed -E 's/.*: ([0-9]+) passed, ([0-9]+) failed.*/\1 \2/' <<<"$line"
}

run_one() {   # run_one PROG: output to its log, exit status and milliseconds to its .rc file, one line out
    local prog="$1" name start rc ms counts report fails
    name=$(name_of "$prog")
    start=$(date +%s%N)
    case "$prog" in
        *.py) "${PYTHON:-/usr/bin/python3}" "$prog" >"$logs/$name.log" 2>&1; rc=$? ;;
        *) "$prog" >"$logs/$name.log" 2>&1; rc=$? ;;
    esac
    ms=$((($(date +%s%N) - start) / 1000000))
    echo "$rc $ms" >"$logs/$name.rc"
    counts=$(summary "$logs/$name.log")
    if [ -n "$counts" ]; then
        report=$(printf '%s: %s passed, %s failed (%d.%d s)' "$name" ${counts% *} ${counts#* } \
                 $((ms / 1000)) $((ms % 1000 / 100)))
        [ "$rc" -ne 0 ] && [ "${counts#* }" -eq 0 ] && report="$report, exit status $rc"
    else
        report=$(printf '%s: no summary line, exit status %d (%d.%d s)' "$name" "$rc" \
                 $((ms / 1000)) $((ms % 1000 / 100)))
    fi
    # one write per program, so that lines of programs ending together do not interleave
    fails=$(grep -E 'FAIL' "$logs/$name.log" | head -n 20 | sed 's/^/    /')
    if [ -n "$fails" ]; then printf '%s\n%s\n' "$report" "$fails"; else printf '%s\n' "$report"; fi
}

load_start=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo 0)
clock_start=$(date +%s)
[ "${#progs[@]}" -eq 1 ] && word=program || word=programs
echo "tests: ${#progs[@]} $word, $jobs at a time; each one's output in $logs/NAME.log"

# Longest first (by the last run's milliseconds; unknown programs first of all, in the given order).
order=$(for prog in "${progs[@]}"; do
    s=$(awk -v n="$(name_of "$prog")" '$1 == n { print $2 }' "$durations")
    printf '%s %s\n' "${s:-1e9}" "$prog"
done | sort -s -g -r -k1,1 | cut -d' ' -f2-)

for prog in "${progs[@]}"; do rm -f "$logs/$(name_of "$prog").rc"; done
# A sanitized build of a program (asan-NAME, tsan-NAME) starts once NAME has ended, when both run:
# on an empty kernel cache the two ask for the same kernels and take turns making them, each
# holding a slot while it waits for the other's (asan-test_rhs took 57 s of a cold run, 1 s warm).
declare -A listed name_by
for prog in "${progs[@]}"; do
    name_by[$prog]=$(name_of "$prog")   # once: ready() runs at every start
    listed[${name_by[$prog]}]=1
done
ready() {   # ready PROG: 0 when nothing it waits for is still to run
    local name=${name_by[$1]} twin
    twin=${name#asan-}; twin=${twin#tsan-}
    [ "$twin" = "$name" ] || [ -z "${listed[$twin]+set}" ] || [ -e "$logs/$twin.rc" ]
}
queue=($order)
running=0
while [ "${#queue[@]}" -gt 0 ]; do
    next=-1
    if [ "$running" -lt "$jobs" ]; then
        for i in "${!queue[@]}"; do
            if ready "${queue[$i]}"; then next=$i; break; fi
        done
    fi
    if [ "$next" -lt 0 ]; then wait -n; running=$((running - 1)); continue; fi
    run_one "${queue[$next]}" &
    running=$((running + 1))
    unset "queue[$next]"
    queue=("${queue[@]+"${queue[@]}"}")
done
wait

total_pass=0; total_fail=0; failed=()
cp "$durations" "$durations.new"
for prog in "${progs[@]}"; do
    name=$(name_of "$prog")
    read -r rc ms <"$logs/$name.rc" 2>/dev/null || { rc=255; ms=0; }
    # this run's time replaces the last one; programs not run this time (T=...) keep theirs
    awk -v n="$name" '$1 != n' "$durations.new" >"$durations.tmp" && mv "$durations.tmp" "$durations.new"
    echo "$name $ms" >>"$durations.new"
    counts=$(summary "$logs/$name.log")
    if [ -n "$counts" ]; then
        p=${counts% *}; f=${counts#* }
        total_pass=$((total_pass + p)); total_fail=$((total_fail + f))
        if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then total_fail=$((total_fail + 1)); f=1; fi
    else
        total_fail=$((total_fail + 1)); f=1
    fi
    [ "$f" -gt 0 ] && failed+=("$name")
done
mv "$durations.new" "$durations"
for name in "${failed[@]+"${failed[@]}"}"; do
    echo "failed: $name (see $logs/$name.log)"
    grep -q -E '^[A-Za-z0-9_.-]+: [0-9]+ passed, [0-9]+ failed' "$logs/$name.log" || tail -n 20 "$logs/$name.log"
done
# this run's record for make docs-numbers (tools/docs_numbers.py): passed, failed, programs,
# seconds, jobs, filter, date, load average at the start and at the end, cores. Only a run of
# make test writes it (make sets TEST_FILTER, empty for the whole suite): a run of a few programs
# named on the command line is not the suite's count.
[ -n "${TEST_FILTER+set}" ] && printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$total_pass" "$total_fail" "${#progs[@]}" \
    "$(($(date +%s) - clock_start))" "$jobs" "$filter" "$(date -u '+%Y-%m-%d %H:%M UTC')" "$load_start" \
    "$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo 0)" "$(nproc 2>/dev/null || echo 1)" >"$logs/last-run"
echo "tests: $total_pass passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
