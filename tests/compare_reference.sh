#!/usr/bin/env bash
# Compares bin/swim with the build of an earlier commit on the same machine, case by case: every
# CSV and TOML file of the output folder value for value (bit for bit as doubles), every JSON file
# key for key (timings and keys only one side has left out). The refactoring of the run driver (runtime/driver/) promised no change
# of behaviour; this is the check, run before and after (`make compare-reference`).
#
#   tests/compare_reference.sh [REF]     REF: a commit (default: the last one before the driver)
#
# Scenes: every paper scene (models/example*.toml, to t = 12 or its own end), the self-propelled
# and stroke scenes, the control scenes, every hard scene to t = 3, and a few option variants
# (rk8pd, --no-projection, events, --set), sensitivities and Lyapunov exponents, and the analysis
# commands (periodic, floquet, continue, optimize with both methods). Both builds use the kernel
# cache of this tree.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
REF=${1:-b08e746}
WORK=${COMPARE_DIR:-$ROOT/build/compare-reference}
PY=${PYTHON:-/usr/bin/python3}
export SWIM_CACHE=${SWIM_CACHE:-$ROOT/build/cache}
NEW=$ROOT/bin/swim
OLD=$WORK/src/bin/swim

mkdir -p "$WORK"
if [ ! -x "$OLD" ] || [ "$(cat "$WORK/ref" 2>/dev/null)" != "$(git -C "$ROOT" rev-parse "$REF")" ]; then
    rm -rf "$WORK/src" && mkdir -p "$WORK/src"
    git -C "$ROOT" archive "$REF" | tar -x -C "$WORK/src" || exit 2
    ln -s "$ROOT/../shared" "$WORK/shared" 2>/dev/null
    make -C "$WORK/src" -j"$(nproc)" bin/swim >"$WORK/build.log" 2>&1 || { echo "cannot build $REF (see $WORK/build.log)"; exit 2; }
    git -C "$ROOT" rev-parse "$REF" >"$WORK/ref"
fi
[ -x "$NEW" ] || { echo "bin/swim is not built"; exit 2; }

cases=()
for f in "$ROOT"/models/example*.toml; do cases+=("$(basename "$f" .toml)|$f|--set run.t_end=12"); done
for f in "$ROOT"/models/selfpropelled.toml "$ROOT"/models/stroke_*.toml "$ROOT"/models/control/*.toml; do
    cases+=("$(basename "$f" .toml)|$f|--set run.t_end=6")
done
for f in "$ROOT"/models/hard/*.toml; do cases+=("hard_$(basename "$f" .toml)|$f|--set run.t_end=3"); done
cases+=("example3_rk8pd|$ROOT/models/example3.toml|--integrator rk8pd --set run.t_end=6")
cases+=("example3_noproj|$ROOT/models/example3.toml|--no-projection --set run.t_end=6")
cases+=("example3_rho0|$ROOT/models/example3.toml|--set model.rho0=2 --set run.t_end=6")
cases+=("example1_events|$ROOT/models/example1.toml|--event a1:max --event y:zero --set run.t_end=12")
cases+=("example5_cvode|$ROOT/models/example5.toml|--integrator cvode-bdf --set run.t_end=6")
# The analyses: a case "NAME|SCENE|OPTIONS|COMMAND" runs `swim COMMAND` (default run); every CSV,
# TOML and JSON file of its folder is compared.
cases+=("example3_sens|$ROOT/models/example3.toml|--sensitivity model.rho0 --sensitivity shape.c0.am1 --set run.t_end=6")
cases+=("example3_lyap|$ROOT/models/example3.toml|--lyapunov --set run.t_end=20")
cases+=("example7_sens_lyap|$ROOT/models/example7.toml|--sensitivity model.rho0 --lyapunov --set run.t_end=4")
cases+=("periodic_example3|$ROOT/models/example3.toml||periodic")
cases+=("floquet_example3|$ROOT/models/example3.toml||floquet")
cases+=("continue_example1|$ROOT/models/example1.toml|--param energy=0.05:0.3 --max-points 4|continue")
cases+=("optimize_example3|$ROOT/models/example3.toml|--set run.t_end=1 --vary elastic.reference.am1=0.3:0.6 --minimize energy --max-iter 8|optimize")
cases+=("optimize_bfgs_example3|$ROOT/models/example3.toml|--set run.t_end=1 --vary model.rho0=0.5:2 --maximize x --method bfgs --max-iter 4|optimize")

# The same values in other text (the number format changed from %.17g to the shortest text that
# reads back to the same double): cell by cell, numbers compared as doubles (bit for bit), the
# rest as text.
same_values() {
    "$PY" - "$1" "$2" <<'EOF'
import math, sys
a, b = (open(f).read().splitlines() for f in sys.argv[1:3])
def same(x, y):
    if x == y: return True
    try:
        u, v = float(x), float(y)
    except ValueError:
        return False
    return u == v or (math.isnan(u) and math.isnan(v))
ok = len(a) == len(b) and all(len(r.split(",")) == len(q.split(",")) and all(map(same, r.split(","), q.split(",")))
                              for r, q in zip(a, b))
sys.exit(0 if ok else 1)
EOF
}

failed=0
for c in "${cases[@]}"; do
    IFS='|' read -r name scene opts cmd <<<"$c"
    for side in old new; do
        exe=$OLD; [ $side = new ] && exe=$NEW
        rm -rf "$WORK/$side/$name"
        # shellcheck disable=SC2086
        "$exe" "${cmd:-run}" "$scene" --out "$WORK/$side/$name" --quiet $opts >"$WORK/$side.$name.log" 2>&1
        echo $? >"$WORK/$side.$name.rc"
    done
    why=""
    cmp -s "$WORK/old.$name.rc" "$WORK/new.$name.rc" || why="exit status $(cat "$WORK/old.$name.rc") vs $(cat "$WORK/new.$name.rc")"
    files=$(cd "$WORK" && { ls "old/$name" "new/$name" 2>/dev/null; } | grep -E '\.(csv|toml|json)$' | sort -u)
    for f in $(grep -E '\.(csv|toml)$' <<<"$files"); do
        cmp -s "$WORK/old/$name/$f" "$WORK/new/$name/$f" || same_values "$WORK/old/$name/$f" "$WORK/new/$name/$f" \
            || why="$why $f differs"
    done
    for f in $(grep -E '\.json$' <<<"$files"); do
    d=$("$PY" - "$WORK/old/$name/$f" "$WORK/new/$name/$f" "$OLD" "$NEW" "$WORK/old/" "$WORK/new/" <<'EOF'
import json, sys
def flat(x, p=""):
    if isinstance(x, dict):
        for k, v in x.items(): yield from flat(v, p + "." + k)
    elif isinstance(x, list):
        for i, v in enumerate(x): yield from flat(v, "%s[%d]" % (p, i))
    else:
        yield p, x
try:
    a, b = (dict(flat(json.load(open(f)))) for f in sys.argv[1:3])
except Exception as e:
    print("%s unreadable: %s" % (sys.argv[1].rsplit("/", 1)[-1], e)); sys.exit()
# the cache folder is named by the kernel key, which hashes the kernel sources: a change there
# renames it without changing a result
skip = ("seconds", "max_rss_kb", "wall", "timing", "ns_per_rhs", "from_cache", "kernel.cache")
# texts name each build's own program and output folder (the command line, best.toml's path):
# compared with those swapped
old_bin, new_bin, old_out, new_out = sys.argv[3:7]
a = {k: v.replace(old_bin, new_bin).replace(old_out, new_out) if isinstance(v, str) else v for k, v in a.items()}
bad = [k for k in a if k in b and a[k] != b[k] and k != ".out" and not any(s in k for s in skip)]
print(" ".join("%s%s: %r vs %r" % (sys.argv[1].rsplit("/", 1)[-1], k, a[k], b[k]) for k in bad[:4]))
EOF
)
    why="$why${d:+ $d}"
    done
    if [ -n "$why" ]; then echo "DIFFER $name:$why"; failed=$((failed + 1)); else echo "same   $name"; fi
done
echo "${#cases[@]} cases, $failed differ (reference $REF)"
[ $failed -eq 0 ]
