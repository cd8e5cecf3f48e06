#!/usr/bin/env bash
# swim export (docs/export.md): Example 3, Example 7 (barrier) and a prescribed stroke exported,
# each tree built with `make -C DIR` under a PATH without python3, DIR/simulate run to a short
# t_end and compared with `swim run SCENE` to the same t_end: trajectory.csv and the scene as run
# byte for byte, events.csv when there is one, summary.json key for key but provenance.command,
# provenance.scene_original and the timings. Also: the tree reads its scene.toml at run time
# (events added), --set as swim run's, a --set that changes the kernel's structure refused,
# --event and --output-step as swim run's, an option given twice and a full stdout refused,
# bad options (exit 2, one line), a non-empty folder refused. Last line "test_export: P passed, F failed".
set -u
cd "$(dirname "$0")/.."
ROOT=$PWD
SWIM="${SWIM_BIN:-$ROOT/bin/swim}"
export SWIM_CACHE="${SWIM_CACHE:-$ROOT/build/cache}"
PY=/usr/bin/python3
T_END=2
pass=0; fail=0
ok() { pass=$((pass+1)); }
bad() { echo "FAIL: $*"; fail=$((fail+1)); }
check() { local what="$1"; shift; if "$@"; then ok; else bad "$what"; fi; }
W=$(mktemp -d /tmp/swim-export-XXXXXX)
trap 'rm -rf "$W"' EXIT

# a PATH of the build tools only: a call to python3 (or the generator) fails
mkdir -p "$W/tools"
for t in cc gcc make sh bash mkdir rm ar as ld ld.bfd cat sed; do
    p=$(command -v "$t") && ln -s "$(readlink -f "$p")" "$W/tools/$t"
done
[ -e "$W/tools/cc" ] || ln -s "$(readlink -f "$(command -v gcc)")" "$W/tools/cc"
check "the build PATH has no python3" env PATH="$W/tools" sh -c '! command -v python3 >/dev/null && ! command -v python >/dev/null'

# swim run and swim export from $W/run (models/ the checkout's), simulate from $W/sim: the same
# relative names for the scene and the output folder
mkdir -p "$W/run" "$W/sim" "$W/trees"
ln -s "$ROOT/models" "$W/run/models"

# same_summary A B: summary.json equal but for the fields that name the command or time it
same_summary() {
    "$PY" - "$1" "$2" <<'EOF'
import json, sys
TIMES = ("integrate_seconds", "diagnostics_seconds", "output_seconds", "rhs_seconds", "wall_seconds",
         "ns_per_rhs", "max_rss_kb", "jacobian_seconds")
def load(p):
    d = json.load(open(p))
    d["provenance"].pop("command"); d["provenance"].pop("scene_original")
    d.get("step_checks", {}).pop("seconds", None)
    for k in TIMES: d["stats"].pop(k, None)
    return d
a, b = load(sys.argv[1]), load(sys.argv[2])
if a != b:
    for k in sorted(set(a) | set(b)):
        if a.get(k) != b.get(k): print("  %s: %r vs %r" % (k, a.get(k), b.get(k)))
    sys.exit(1)
EOF
}

# compare NAME A B: the output folder A of simulate against B of swim run
compare() {
    local name="$1" a="$2" b="$3"
    check "$name: trajectory.csv differs" cmp -s "$a/trajectory.csv" "$b/trajectory.csv"
    check "$name: scene.toml (the scene as run) differs" cmp -s "$a/scene.toml" "$b/scene.toml"
    if [ -e "$a/events.csv" ] || [ -e "$b/events.csv" ]; then
        check "$name: events.csv differs" cmp -s "$a/events.csv" "$b/events.csv"
    fi
    local diffs
    diffs=$(same_summary "$a/summary.json" "$b/summary.json" 2>&1) && ok || bad "$name: summary.json differs:
$diffs"
}

for scene in example3 example7 stroke_loop; do
    tree="$W/trees/$scene"
    start=$(date +%s%N)
    ( cd "$W/run" && "$SWIM" export "models/$scene.toml" --out "$tree" --quiet ) >"$W/$scene.export.log" 2>&1 \
        && ok || bad "$scene: swim export failed: $(tail -3 "$W/$scene.export.log")"
    t1=$(date +%s%N)
    env -i PATH="$W/tools" HOME="$W" make -C "$tree" -j2 >"$W/$scene.make.log" 2>&1 && [ -x "$tree/simulate" ] \
        && ok || bad "$scene: make -C DIR without python3 failed: $(tail -5 "$W/$scene.make.log")"
    t2=$(date +%s%N)
    echo "$scene: export $(( (t1 - start) / 1000000 )) ms, build $(( (t2 - t1) / 1000000 )) ms, $(du -sk "$tree" --exclude=build --exclude=simulate | cut -f1) kB of sources"
    # summary.json is built as a jansson object (driver/summary.h): the tree links jansson, and the
    # summary's reader (driver/summary_read.h, sweeps only) stays out
    grep -q -- "-ljansson" "$tree/Makefile" && [ ! -e "$tree/runtime/driver/summary_read.h" ] && ok \
        || bad "$scene: the tree does not link jansson, or holds the summary reader"
    ( cd "$W/sim" && "$tree/simulate" --out "$scene" --t-end "$T_END" --quiet ) >"$W/$scene.sim.log" 2>&1 \
        && ok || bad "$scene: simulate failed: $(tail -3 "$W/$scene.sim.log")"
    ( cd "$W/run" && "$SWIM" run "models/$scene.toml" --out "$scene" --t-end "$T_END" --quiet ) >"$W/$scene.run.log" 2>&1 \
        && ok || bad "$scene: swim run failed: $(tail -3 "$W/$scene.run.log")"
    compare "$scene" "$W/sim/$scene" "$W/run/$scene"
done

# the tree reads DIR/scene.toml when it runs: events added to it (no rebuild: the structure is the
# same) give the events.csv of swim run on the same scene
ev="$W/trees/example3"
if [ -x "$ev/simulate" ]; then
    cp -a "$ev" "$W/trees/example3-events"
    ev="$W/trees/example3-events"
    printf '\n[events]\nlist = ["am1:max", "y:zero"]\n' >>"$ev/scene.toml"
    mkdir -p "$W/run-ev/models" && cp "$ev/scene.toml" "$W/run-ev/models/example3.toml"
    ( cd "$W/sim" && "$ev/simulate" --out ev --t-end 4 --quiet ) >"$W/ev.sim.log" 2>&1 && ok || bad "events: simulate failed: $(cat "$W/ev.sim.log")"
    ( cd "$W/run-ev" && "$SWIM" run models/example3.toml --out ev --t-end 4 --quiet ) >"$W/ev.run.log" 2>&1 \
        && ok || bad "events: swim run failed: $(cat "$W/ev.run.log")"
    check "events: no events.csv" test -s "$W/sim/ev/events.csv"
    compare "events" "$W/sim/ev" "$W/run-ev/ev"

    # --set as swim run's (a run-time value: the compiled-in kernel serves it)
    ( cd "$W/sim" && "$W/trees/example3/simulate" --out rho --t-end "$T_END" --set model.rho0=2 --rtol 1e-9 --quiet ) \
        >"$W/rho.sim.log" 2>&1 && ok || bad "--set: simulate failed: $(cat "$W/rho.sim.log")"
    ( cd "$W/run" && "$SWIM" run models/example3.toml --out rho --t-end "$T_END" --set model.rho0=2 --rtol 1e-9 --quiet ) \
        >"$W/rho.run.log" 2>&1 && ok || bad "--set: swim run failed: $(cat "$W/rho.run.log")"
    compare "--set model.rho0=2 --rtol 1e-9" "$W/sim/rho" "$W/run/rho"

    # --event and --output-step as swim run's (its parsing and semantics: events.csv, the rows, a stop)
    evo="--t-end 4 --output-step 0.25 --event am1:max --event y:zero:stop"
    # shellcheck disable=SC2086
    ( cd "$W/sim" && "$W/trees/example3/simulate" --out evo $evo --quiet ) >"$W/evo.sim.log" 2>&1 \
        && ok || bad "--event/--output-step: simulate failed: $(cat "$W/evo.sim.log")"
    # shellcheck disable=SC2086
    ( cd "$W/run" && "$SWIM" run models/example3.toml --out evo $evo --quiet ) >"$W/evo.run.log" 2>&1 \
        && ok || bad "--event/--output-step: swim run failed: $(cat "$W/evo.run.log")"
    check "--event: no events.csv" test -s "$W/sim/evo/events.csv"
    compare "--event am1:max --event y:zero:stop --output-step 0.25" "$W/sim/evo" "$W/run/evo"

    # a report lost to a full stdout is a failure: non-zero exit, one line on stderr
    "$W/trees/example3/simulate" --out "$W/sim/full" --t-end 0.5 >/dev/full 2>"$W/devfull.err"
    rc=$?
    [ $rc -ne 0 ] && [ "$(wc -l <"$W/devfull.err")" -eq 1 ] && grep -q stdout "$W/devfull.err" && ok \
        || bad "simulate >/dev/full: exit $rc, stderr: $(cat "$W/devfull.err")"

    # bad input: one line, exit 2, naming the option (an option given twice included)
    for args in "--t-end abc" "--bogus 1" "--set model.rho0" "--rtol 1e-30" "--t-end 1 --t-end 2" \
                "--output-step -1" "--event nosuch:max" "--quiet --quiet"; do
        # shellcheck disable=SC2086
        "$W/trees/example3/simulate" --out "$W/sim/bad" $args >"$W/bad.out" 2>"$W/bad.err"
        rc=$?
        opt=${args%% *}
        [ $rc -eq 2 ] && [ "$(wc -l <"$W/bad.err")" -eq 1 ] && grep -q -- "${opt#--}" "$W/bad.err" && [ ! -e "$W/sim/bad" ] \
            && ok || bad "simulate $args: exit $rc, stderr: $(cat "$W/bad.err")"
    done
fi
# a --set that changes the kernel's structure (no barrier) is refused: this tree has no kernel for it
if [ -x "$W/trees/example7/simulate" ]; then
    "$W/trees/example7/simulate" --out "$W/sim/eps0" --set barrier.epsilon=0 >"$W/eps.out" 2>"$W/eps.err"
    rc=$?
    # (the scene reader's notice of the projected dc0 comes first, as with swim run)
    [ $rc -eq 2 ] && [ "$(grep -v "projected onto the constraints" "$W/eps.err" | wc -l)" -eq 1 ] \
        && tail -1 "$W/eps.err" | grep -q "export the scene again" && [ ! -e "$W/sim/eps0" ] && ok \
        || bad "simulate --set barrier.epsilon=0: exit $rc, stderr: $(cat "$W/eps.err")"
fi
# swim export into a folder that holds other files: refused before anything is written
mkdir -p "$W/full" && echo x >"$W/full/keep"
"$SWIM" export models/example3.toml --out "$W/full" >"$W/full.out" 2>"$W/full.err"
rc=$?
[ $rc -eq 2 ] && [ "$(ls "$W/full")" = keep ] && [ "$(wc -l <"$W/full.err")" -eq 1 ] && ok \
    || bad "swim export into a non-empty folder: exit $rc, $(cat "$W/full.err")"

echo "test_export: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
