#!/usr/bin/env bash
# Compares bin/swim with the build of an earlier commit on the same machine, scene by scene:
# trajectory.csv and events.csv byte for byte, summary.json key for key (timings and keys only
# one side has left out). The refactoring of the run driver (runtime/driver/) promised no change
# of behaviour; this is the check, run before and after (`make compare-reference`).
#
#   tests/compare_reference.sh [REF]     REF: a commit (default: the last one before the driver)
#
# Scenes: every paper scene (models/example*.toml, to t = 12 or its own end), the self-propelled
# and stroke scenes, the control scenes, every hard scene to t = 3, and a few option variants
# (rk8pd, --no-projection, events, --set). Both builds use the kernel cache of this tree.
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

failed=0
for c in "${cases[@]}"; do
    IFS='|' read -r name scene opts <<<"$c"
    for side in old new; do
        exe=$OLD; [ $side = new ] && exe=$NEW
        rm -rf "$WORK/$side/$name"
        # shellcheck disable=SC2086
        "$exe" run "$scene" --out "$WORK/$side/$name" --quiet $opts >"$WORK/$side.$name.log" 2>&1
        echo $? >"$WORK/$side.$name.rc"
    done
    why=""
    cmp -s "$WORK/old.$name.rc" "$WORK/new.$name.rc" || why="exit status $(cat "$WORK/old.$name.rc") vs $(cat "$WORK/new.$name.rc")"
    for f in trajectory.csv events.csv; do
        if [ -e "$WORK/old/$name/$f" ] || [ -e "$WORK/new/$name/$f" ]; then
            cmp -s "$WORK/old/$name/$f" "$WORK/new/$name/$f" || why="$why $f differs"
        fi
    done
    d=$("$PY" - "$WORK/old/$name/summary.json" "$WORK/new/$name/summary.json" <<'EOF'
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
    print("summary.json unreadable: %s" % e); sys.exit()
# the cache folder is named by the kernel key, which hashes the kernel sources: a change there
# renames it without changing a result; provenance.command names the two binaries' paths
skip = ("seconds", "max_rss_kb", "wall", "timing", "ns_per_rhs", "from_cache", "kernel.cache", "provenance.command")
bad = [k for k in a if k in b and a[k] != b[k] and k != ".out" and not any(s in k for s in skip)]
print(" ".join("summary%s: %r vs %r" % (k, a[k], b[k]) for k in bad[:4]))
EOF
)
    why="$why${d:+ $d}"
    if [ -n "$why" ]; then echo "DIFFER $name:$why"; failed=$((failed + 1)); else echo "same   $name"; fi
done
echo "${#cases[@]} cases, $failed differ (reference $REF)"
[ $failed -eq 0 ]
