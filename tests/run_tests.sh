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
# Into the variable $name, in bash alone: it is found for every program given, before any starts.
name_of() {
    name=${1#./}
    name=${name#build/}
    if [[ $name == tests/* ]]; then name=${name#tests/}; else name=${name/\/tests\//\/}; fi
    name=${name//\//-}
    name=${name%.py}
    name=${name%.sh}
}

progs=()
declare -A name_by
for prog in "$@"; do
    name_of "$prog"
    if [ -z "$filter" ] || [[ $name =~ $filter ]]; then
        progs+=("$prog")
        name_by[$prog]=$name
    fi
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
    local prog="$1" name=${name_by[$1]} start rc ms counts report fails
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
declare -A last_ms
while read -r n ms _; do [ -n "$n" ] && last_ms[$n]=$ms; done <"$durations"
order=$(for prog in "${progs[@]}"; do
    printf '%s %s\n' "${last_ms[${name_by[$prog]}]:-1e9}" "$prog"
done | sort -s -g -r -k1,1 | cut -d' ' -f2-)

for prog in "${progs[@]}"; do rm -f "$logs/${name_by[$prog]}.rc"; done
# A sanitized build of a program (asan-NAME, tsan-NAME) starts once NAME has ended, when both run:
# on an empty kernel cache the two ask for the same kernels and take turns making them, each
# holding a slot while it waits for the other's (asan-test_rhs took 57 s of a cold run, 1 s warm).
declare -A listed
for prog in "${progs[@]}"; do listed[${name_by[$prog]}]=1; done
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
for prog in "${progs[@]}"; do
    name=${name_by[$prog]}
    read -r rc ms <"$logs/$name.rc" 2>/dev/null || { rc=255; ms=0; }
    last_ms[$name]=$ms   # this run's time replaces the last one; programs not run (T=...) keep theirs
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
for n in "${!last_ms[@]}"; do echo "$n ${last_ms[$n]}"; done >"$durations.new" && mv "$durations.new" "$durations"
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
