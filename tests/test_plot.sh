#!/usr/bin/env bash
# runtime/plot/plot_run.py on a tiny fake run directory (N = 1, 20 rows, 2 snapshots): all five
# PNGs are written and are PNGs; a truncated CSV, a missing snapshots.json and --only still work;
# a directory with nothing to plot exits 1. The fake data are made up here, not simulated.
set -u
cd "$(dirname "$0")/.."
PY=${PYTHON:-/usr/bin/python3}
PLOT=runtime/plot/plot_run.py
pass=0; fail=0
ok()   { pass=$((pass+1)); }
bad()  { echo "FAIL: $*"; fail=$((fail+1)); }
check() { if eval "$2"; then ok; else bad "$1"; fi; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/test_plot.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
run="$tmp/run"; mkdir -p "$run"

"$PY" - "$run" <<'EOF'
import json, math, sys
out = sys.argv[1]
cols = ("t,x,y,theta,a1,b1,am1,bm1,da1,db1,dam1,dbm1,"
        "kinetic_fluid,kinetic_shape,kinetic_rigid,potential,energy,"
        "impulse_body_x,impulse_body_y,impulse_body_ang,"
        "impulse_fluid_rigid_x,impulse_fluid_rigid_y,impulse_fluid_rigid_ang,"
        "impulse_fluid_shape_x,impulse_fluid_shape_y,impulse_fluid_shape_ang,"
        "res_volume,res_volume_rate,res_angular,res_locks,jmin,work,w1,w2").split(",")
rows = []
for i in range(20):
    t = 0.25 * i
    am1, dam1 = 0.3 * math.sin(t), 0.3 * math.cos(t)
    bm1, dbm1 = 0.1 * math.sin(2 * t), 0.2 * math.cos(2 * t)
    # starts at rest (total energy 0 in the first row: the percent panel must cope)
    s = math.sin(t) ** 2
    kf, ks, kr, w1, w2 = 0.5 * s, 0.3 * s, 0.1 * s, 0.2 * s, 0.0
    pb = 0.4 * math.sin(t)
    pr = -0.3 * math.sin(t)
    r = {"t": t, "x": 0.0, "y": 0.1 * t + 0.05 * math.sin(t), "theta": 0.0,
         "a1": 1.0, "b1": 0.0, "am1": am1, "bm1": bm1, "da1": 0.0, "db1": 0.0,
         "dam1": dam1, "dbm1": dbm1, "kinetic_fluid": kf, "kinetic_shape": ks,
         "kinetic_rigid": kr, "potential": w1 + w2, "energy": kf + ks + kr + w1 + w2,
         "impulse_body_y": pb, "impulse_fluid_rigid_y": pr, "impulse_fluid_shape_y": -pb - pr,
         "jmin": 0.8, "work": kf + ks + kr + w1, "w1": w1, "w2": w2}
    rows.append(",".join(repr(float(r.get(c, 0.0))) for c in cols))
with open(out + "/trajectory.csv", "w") as fh:
    fh.write(",".join(cols) + "\n" + "\n".join(rows) + "\n")
json.dump({"scene": "models/fake.toml", "title": "fake N=1 run", "modes": 1,
           "status": "completed", "reason": "", "t_end": 4.75, "t_reached": 4.75,
           "free": ["am1", "bm1"], "energy_drift_abs": 0.0, "stats": {}},
          open(out + "/summary.json", "w"))
snaps = []
for t in (0.0, 4.75):
    y = 0.1 * t + 0.05 * math.sin(t)
    c = 0.3 * math.sin(t)
    n = 64
    bx = [math.cos(2 * math.pi * k / n) * (1 + c) for k in range(n)]
    by = [y + math.sin(2 * math.pi * k / n) * (1 - c) for k in range(n)]
    X = [[r * (1 + c) * math.cos(2 * math.pi * k / 16) for k in range(16)] for r in (0, .5, 1)]
    Y = [[y + r * (1 - c) * math.sin(2 * math.pi * k / 16) for k in range(16)] for r in (0, .5, 1)]
    rho = [[1.0 / (1 - c * c) for _ in range(16)] for _ in range(3)]
    snaps.append({"t": t, "x": 0.0, "y": y, "theta": 0.0,
                  "boundary": {"X": bx, "Y": by},
                  "density": {"X": X, "Y": Y, "rho": rho},
                  "arrows": {"X": [-2, 2, 0, 0], "Y": [y, y, y - 2, y + 2],
                             "U": [0.1, -0.1, 0, 0], "V": [0, 0, -0.2, 0.2]}})
json.dump(snaps, open(out + "/snapshots.json", "w"))
EOF
[ -s "$run/trajectory.csv" ] || { echo "FAIL: fake data generator"; echo "test_plot: 0 passed, 1 failed"; exit 1; }

FIGS="trajectory energy impulse phase snapshots"
is_png() { [ -s "$1" ] && [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]; }

# 1. complete run directory: five PNGs, each path printed
"$PY" "$PLOT" "$run" >"$tmp/out1" 2>"$tmp/err1"; rc=$?
check "plot_run exit status $rc on a complete run (stderr: $(head -c 300 "$tmp/err1"))" '[ $rc -eq 0 ]'
check "traceback on a complete run" '! grep -q Traceback "$tmp/err1"'
for f in $FIGS; do
    check "$f.png missing, empty or not a PNG" 'is_png "$run/$f.png"'
    check "$f.png path not printed" 'grep -qx "$run/$f.png" "$tmp/out1"'
done

# 2. truncated CSV (half a line at the end): still exit 0 and plots
rm -f "$run"/*.png
last=$(tail -n 1 "$run/trajectory.csv")
printf '%s' "${last:0:$(( ${#last} / 2 ))}" >>"$run/trajectory.csv"
"$PY" "$PLOT" "$run" >"$tmp/out2" 2>"$tmp/err2"; rc=$?
check "plot_run exit status $rc on a truncated CSV (stderr: $(head -c 300 "$tmp/err2"))" '[ $rc -eq 0 ]'
check "traceback on a truncated CSV" '! grep -q Traceback "$tmp/err2"'
check "trajectory.png not written for a truncated CSV" 'is_png "$run/trajectory.png"'
check "energy.png not written for a truncated CSV" 'is_png "$run/energy.png"'

# 3. no snapshots.json: snapshots.png skipped with a message, the others written
rm -f "$run"/*.png "$run/snapshots.json"
"$PY" "$PLOT" "$run" >"$tmp/out3" 2>"$tmp/err3"; rc=$?
check "exit status $rc without snapshots.json" '[ $rc -eq 0 ]'
check "snapshots.png written without snapshots.json" '[ ! -e "$run/snapshots.png" ]'
check "no stderr message about the skipped snapshots" 'grep -q snapshots "$tmp/err3"'
check "phase.png not written without snapshots.json" 'is_png "$run/phase.png"'

# 4. --only draws just the named figures
rm -f "$run"/*.png
"$PY" "$PLOT" "$run" --only phase impulse >"$tmp/out4" 2>"$tmp/err4"; rc=$?
check "exit status $rc with --only" '[ $rc -eq 0 ]'
check "--only phase impulse wrote other figures" \
      '[ "$(ls "$run"/*.png 2>/dev/null | wc -l)" -eq 2 ] && is_png "$run/phase.png" && is_png "$run/impulse.png"'

# 5. nothing to plot: exit 1, no traceback
mkdir -p "$tmp/empty"
"$PY" "$PLOT" "$tmp/empty" >"$tmp/out5" 2>"$tmp/err5"; rc=$?
check "exit status $rc on an empty directory (want 1)" '[ $rc -eq 1 ]'
check "traceback on an empty directory" '! grep -q Traceback "$tmp/err5"'

echo "test_plot: $pass passed, $fail failed"
[ $fail -eq 0 ]
