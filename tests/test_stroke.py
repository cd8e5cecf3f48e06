#!/usr/bin/env python3
"""Prescribed strokes ([stroke] scenes, runtime/stroke/): `swim run` integrates (3.21) alone.

Checks:
- a stroke equal to a dynamic run's shape history reproduces that run's rigid motion (the shape
  of Example 1, fitted by a Fourier series over one period of the dynamic run, becomes the laws);
- (3.21) is homogeneous of degree one in c': one stroke traced at omega = 1 and omega = 3 moves
  the body by the same amount (a geometric phase), with and without c1 completed;
- small closed loops: the net displacement scales as the amplitude squared;
- c1 completed: the volume (2.5) and (2.14) hold to round-off on every row, and the summary says so;
- the power is dE/dt: E - E0 - work stays at the integration error; a closed stroke with c1
  prescribed costs no net work, and its positive work agrees with a quadrature of the rows;
- bad input: tables of effects, dc0, free, a kinked law, a stroke that is not allowable (the time
  and the constraint named), all exit status 2 with one line and nothing written;
- outputs: same summary keys as a dynamic run plus "stroke", --summary-only, --set, events,
  swim plot / flow / animate on the run directory, swim sweep of a stroke scene.
"""
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import ROOT, SWIM, TMP, check, run  # noqa: E402

LOOP = os.path.join(ROOT, "models", "stroke_loop.toml")
COMPLETED = os.path.join(ROOT, "models", "stroke_completed.toml")
TWO_PI = 2 * math.pi


def write(name, text):
    path = os.path.join(TMP, name)
    with open(path, "w") as fh:
        fh.write(text)
    return path


def stroke_scene(laws, modes=2, c0=None, t_end=TWO_PI, output_step=0.05, extra="", rtol="1e-11"):
    c0 = c0 or [1, 0] + [0] * (2 * modes)
    body = "".join('%s = "%s"\n' % kv for kv in laws.items())
    return ("[model]\nmodes = %d\nrho0 = 1.0\nrhof = 1.0\n\n[shape]\nc0 = %s\n\n[stroke]\n%s\n%s"
            "[run]\nt_end = %r\noutput_step = %r\nrtol = %s\natol = 1e-13\n"
            % (modes, json.dumps(c0), body, extra, t_end, output_step, rtol))


def first_stroke(summary):
    strokes = summary["stroke"]["strokes"]
    return strokes[0] if strokes else None


def loop_laws(eps, omega=1):
    """Example 1's loop (4.17) with beta = omega t, c1 = 1 prescribed."""
    w = "" if omega == 1 else "%d*" % omega
    return {"a1": "1", "am1": "%r*cos(%st)" % (eps, w), "bm2": "%r*sin(%st)/sqrt(2)" % (eps, w)}


def fourier_law(values, period):
    """A trigonometric series through `values` (equally spaced over one period) as a law in t."""
    m = len(values)
    F = np.fft.rfft(values) / m
    terms = ["%.17g" % F[0].real]
    w = 2 * math.pi / period
    for h in range(1, m // 2):
        a, b = 2 * F[h].real, -2 * F[h].imag
        if abs(a) > 1e-16:
            terms.append("%.17g*cos(%.17g*t)" % (a, h * w))
        if abs(b) > 1e-16:
            terms.append("%.17g*sin(%.17g*t)" % (b, h * w))
    return " + ".join(terms).replace("+ -", "- ")


def test_reproduces_dynamic_run():
    # The dynamic run (Example 1: c_-1 and c_-2 move, c1 locked) at tight tolerance; its period
    # from the maxima of a_-1; then one period sampled at 256 points and fitted exactly.
    p, _, s = run("models/example1.toml", "dyn_period", "--t-end", "18", "--event", "am1:max",
                  "--rtol", "1e-12", "--atol", "1e-14")
    check(p.returncode == 0 and s["periodic"], "dynamic run with events: %s" % p.stderr)
    period = s["periodic"][0]["period"]
    m = 256
    p, dyn, _ = run("models/example1.toml", "dyn_fine", "--t-end", repr(2 * period), "--output-step",
                    repr(period / m), "--rtol", "1e-12", "--atol", "1e-14")
    check(p.returncode == 0 and len(dyn) == 2 * m + 1, "dynamic run on the period grid")
    # neither a1 nor b1 prescribed: c1 is completed (it stays 1 up to the fit's error)
    c0 = [1, 0] + [0] * 14
    laws = {"am1": fourier_law(dyn["am1"][:m], period), "bm2": fourier_law(dyn["bm2"][:m], period)}
    scene = write("from_dynamic.toml", stroke_scene(laws, modes=7, c0=c0, t_end=2 * period,
                                                    output_step=period / m))
    p, rows, s = run(scene, "from_dynamic")
    check(p.returncode == 0 and rows is not None and len(rows) == len(dyn), "stroke from the dynamic run: %s" % p.stderr)
    shape_err = max(np.abs(rows[c] - dyn[c]).max() for c in ("a1", "b1", "am1", "bm1", "am2", "bm2"))
    motion_err = max(np.abs(rows[c] - dyn[c]).max() for c in ("x", "y", "theta"))
    travel = np.abs(dyn["y"]).max()
    print("  stroke from Example 1's shape history: shape %.2g, rigid motion %.2g (y travels %.3f)"
          % (shape_err, motion_err, travel))
    check(shape_err < 1e-9, "the fitted laws reproduce the dynamic shape (%.3g)" % shape_err)
    check(travel > 0.5 and motion_err < 1e-9 * max(1.0, travel),
          "the rigid motion of the dynamic run is reproduced (%.3g over %.3g)" % (motion_err, travel))
    check(abs(s["stroke"]["period"] - period) < 1e-9 * period and s["stroke"]["period_source"] == "detected",
          "the period of the fitted laws is detected (%r vs %r)" % (s["stroke"]["period"], period))


def test_speed_does_not_matter():
    # the same closed loop at omega = 1 and 3: one stroke each, same displacement and rotation
    for name, laws in (("prescribed", lambda w: loop_laws(0.3, w)),
                       ("completed", lambda w: {"am1": "0.3*cos(%d*t)" % w, "bm1": "0.15*sin(%d*t)" % w,
                                                "am2": "0.12*sin(%d*t)" % (2 * w)})):
        got = []
        for w in (1, 3):
            scene = write("speed_%s_%d.toml" % (name, w), stroke_scene(laws(w), t_end=TWO_PI / w,
                                                                       output_step=TWO_PI / w / 100))
            p, _, s = run(scene, "speed_%s_%d" % (name, w))
            check(p.returncode == 0, "speed %s omega %d: %s" % (name, w, p.stderr))
            st = first_stroke(s)
            check(st is not None and abs(st["t_end"] - TWO_PI / w) < 1e-12,
                  "one stroke of period 2 pi/%d detected (%s)" % (w, s["stroke"]["period"]))
            got.append((st["dx"], st["dy"], st["dtheta"], s["final_state"]["c"][0], s["final_state"]["c"][1]))
        diff = max(abs(a - b) for a, b in zip(*got))
        size = max(abs(v) for v in got[0][:3])
        print("  %s stroke at omega = 1 and 3: displacement %s, largest difference %.2g"
              % (name, ["%.6f" % v for v in got[0][:3]], diff))
        check(size > 1e-3, "the %s stroke moves the body (%.3g)" % (name, size))
        check(diff < 1e-8, "%s stroke: displacement independent of the speed (difference %.3g)" % (name, diff))


def test_small_loops_move_as_amplitude_squared():
    d = {}
    for eps in (0.01, 0.02, 0.04):
        scene = write("small_%g.toml" % eps, stroke_scene(loop_laws(eps), output_step=TWO_PI / 64))
        p, _, s = run(scene, "small_%g" % eps)
        check(p.returncode == 0, "small loop %g: %s" % (eps, p.stderr))
        d[eps] = first_stroke(s)["dy"]
    r1, r2 = d[0.02] / d[0.01], d[0.04] / d[0.02]
    print("  loop amplitude 0.01, 0.02, 0.04: dy = %.6g, %.6g, %.6g (ratios %.5f, %.5f)"
          % (d[0.01], d[0.02], d[0.04], r1, r2))
    check(abs(r1 - 4) < 4e-3 and abs(r2 - 4) < 1.6e-2, "net displacement ~ amplitude^2 (ratios %.6f, %.6f)" % (r1, r2))
    check(abs(r1 - 4) < abs(r2 - 4), "the quadratic law improves as the loop shrinks")


def test_completion_keeps_volume_and_angular_momentum():
    p, rows, s = run(COMPLETED, "completed", "--rtol", "1e-10")
    check(p.returncode == 0 and rows is not None, "stroke_completed runs: %s" % p.stderr)
    check(s["stroke"]["completed_c1"] and "(2.5)" in s["stroke"]["completion"] and "(2.14)" in s["stroke"]["completion"],
          "the summary says that c1 was completed")
    report = subprocess.run([SWIM, "run", COMPLETED, "--out", os.path.join(TMP, "completed-report"), "--rtol", "1e-10"],
                            capture_output=True, text=True, cwd=ROOT).stdout   # without --quiet: the report
    check("c1 completed" in report, "the report says that c1 was completed")
    vol = rows["a1"] ** 2 + rows["b1"] ** 2 - (rows["am1"] ** 2 + rows["bm1"] ** 2) - 2 * (rows["am2"] ** 2 + rows["bm2"] ** 2)
    ang = ((rows["db1"] * rows["a1"] - rows["da1"] * rows["b1"]) / 2
           + (rows["dbm1"] * rows["am1"] - rows["dam1"] * rows["bm1"]) / 2
           + (rows["dbm2"] * rows["am2"] - rows["dam2"] * rows["bm2"]) / 3)
    rate = (rows["a1"] * rows["da1"] + rows["b1"] * rows["db1"] - rows["am1"] * rows["dam1"] - rows["bm1"] * rows["dbm1"]
            - 2 * (rows["am2"] * rows["dam2"] + rows["bm2"] * rows["dbm2"]))
    print("  c1 completed: volume varies by %.2g, (2.8) %.2g, (2.14) %.2g; c1 turns by %.4f"
          % (np.ptp(vol), np.abs(rate).max(), np.abs(ang).max(), rows["phase_c1"][-1] - rows["phase_c1"][0]))
    check(np.ptp(vol) < 1e-14 and abs(vol[0] - s["stroke"]["mu2"]) < 1e-14, "volume (2.5) to round-off (%.3g)" % np.ptp(vol))
    check(np.abs(rate).max() < 1e-14, "(2.8) to round-off (%.3g)" % np.abs(rate).max())
    check(np.abs(ang).max() < 1e-14, "(2.14) to round-off (%.3g)" % np.abs(ang).max())
    check(s["max_residuals"]["volume"] < 1e-14 and s["max_residuals"]["angular"] < 1e-14,
          "the summary's residuals are at round-off")
    check(np.ptp(rows["phase_c1"]) > 0.1, "c1 turns (the phase of (2.14) is not trivial)")
    check(rows["a1"][0] == 1.0 and rows["b1"][0] == 0.0, "c1(0) is c0's c1")
    # c1' (used by (3.21)) is the derivative of the completed c1 (phase integrated), and c1''
    # (used by the power) is right when E - E0 - int P dt stays at the integration error
    q, fine, _ = run(COMPLETED, "completed_fine", "--output-step", "0.005", "--set", "run.t_end=3")
    for c in ("a1", "b1"):   # central differences: error h^2 c(3)/6 ~ 1e-6 at h = 0.005
        fd = np.gradient(fine[c], fine["t"], edge_order=2)
        err = np.abs(fd - fine["d" + c]).max()
        check(q.returncode == 0 and err < 1e-4 * np.abs(fine["d" + c]).max(),
              "d%s is the derivative of %s (differences: %.3g)" % (c, c, err))
    check(s["energy_drift_abs"] < 1e-9, "with c1 completed, E - E0 - work = %.3g" % s["energy_drift_abs"])


def test_power_is_the_rate_of_energy():
    p, rows, s = run(LOOP, "loop")
    check(p.returncode == 0 and s["status"] == "completed", "stroke_loop runs: %s" % p.stderr)
    check(s["energy_drift_abs"] < 1e-10, "E - E0 - int P dt at the integration error (%.3g)" % s["energy_drift_abs"])
    strokes = s["stroke"]["strokes"]
    check(len(strokes) == 2, "two strokes in t_end = 4 pi")
    for st in strokes:   # a closed stroke in a perfect fluid: E returns, no net work
        check(abs(st["work"]) < 1e-10 and st["work_positive"] > 1e-3,
              "stroke %d: net work %.3g, positive work %.4g" % (st["stroke"], st["work"], st["work_positive"]))
    check(abs(strokes[0]["work_positive"] - strokes[1]["work_positive"]) < 1e-9 * strokes[0]["work_positive"],
          "every stroke costs the same positive work")
    check(abs(strokes[0]["dy"] - strokes[1]["dy"]) < 1e-9 and abs(strokes[0]["dy"]) > 0.1,
          "every stroke moves the body by the same amount")
    # an independent quadrature of max(P, 0) over the rows (P has simple zeros: trapezoid O(h^2))
    t, pw = rows["t"], np.maximum(rows["power"], 0.0)
    quad = float(np.sum(0.5 * (pw[1:] + pw[:-1]) * np.diff(t)))
    check(abs(quad - s["stroke"]["work_positive"]) < 1e-3 * quad,
          "positive work %.6g vs trapezoid of the rows %.6g" % (s["stroke"]["work_positive"], quad))
    p, fine, _ = run(LOOP, "loop_fine", "--output-step", "0.005")
    dE = np.gradient(fine["energy"], fine["t"], edge_order=2)   # error ~ h^2 E'(3)/6 ~ 3e-6
    err = np.abs(dE - fine["power"])[2:-2].max()
    check(err < 1e-4 * np.abs(fine["power"]).max(),
          "the power column is dE/dt (central differences of the energy column: %.3g)" % err)


def one_line_refusal(p, what):
    lines = p.stderr.strip().splitlines()
    check(p.returncode == 2 and len(lines) == 1, "%s: exit 2 with one line (rc %d: %r)" % (what, p.returncode, p.stderr))
    return lines[0] if lines else ""


def test_refused_keys():
    tables = {"elastic": "stiffness = [0, 0, 1, 1, 0, 0]\nreference = [1, 0, 0, 0, 0, 0]",
              "barrier": "epsilon = 0.01\nalpha = 0.5",
              "damping": "diagonal = [0, 0, 1, 1, 1, 1]",
              "forcing": 'law = "sin(t)"\ndirection = [0, 0, 1, 0, 0, 0]'}
    for table, body in tables.items():
        key = body.split()[0]
        scene = write("refused_%s.toml" % table, stroke_scene(loop_laws(0.3), extra="[%s]\n%s\n\n" % (table, body)))
        out = os.path.join(TMP, "refused_%s" % table)
        p, _, _ = run(scene, "refused_%s" % table)
        line = one_line_refusal(p, "[%s] in a stroke scene" % table)
        check(scene in line and "%s.%s" % (table, key) in line and "stroke" in line,
              "the line names the file and %s.%s: %s" % (table, key, line))
        check(not os.path.exists(out), "nothing written for [%s]" % table)
    base = stroke_scene(loop_laws(0.3))
    for key, value in (("dc0", "[0, 0, 0, 0, 0, 0]"), ("free", '["am1"]')):
        scene = write("refused_%s.toml" % key, base.replace("[stroke]", "%s = %s\n\n[stroke]" % (key, value)))
        p, _, _ = run(scene, "refused_%s" % key)
        line = one_line_refusal(p, "shape.%s in a stroke scene" % key)
        check("shape.%s" % key in line, "the line names shape.%s: %s" % (key, line))
    scene = write("kinked.toml", stroke_scene({"am1": "0.1*step(t-1)*(t-1)^3"}))
    line = one_line_refusal(run(scene, "kinked")[0], "a law with step()")
    check("stroke.am1" in line and "step" in line, "the kinked law is named: %s" % line)
    for opt in ("--generic", "--no-projection"):
        p = subprocess.run([SWIM, "run", LOOP, "--out", os.path.join(TMP, "opt"), opt], capture_output=True, text=True)
        line = one_line_refusal(p, opt)
        check(opt in line, "the option is named: %s" % line)


def violation_at(laws, t):
    """(2.8) and (2.14) residuals and the sizes of their terms for laws of c1, c_-1 (N = 1)."""
    env = {"t": t, "sin": math.sin, "cos": math.cos, "sqrt": math.sqrt}
    h = 1e-6

    def val(name, tt):
        env["t"] = tt
        return eval(laws.get(name, "0").replace("^", "**"), {}, env)

    c = {k: val(k, t) for k in ("a1", "b1", "am1", "bm1")}
    d = {k: (val(k, t + h) - val(k, t - h)) / (2 * h) for k in c}
    rate = c["a1"] * d["a1"] + c["b1"] * d["b1"] - c["am1"] * d["am1"] - c["bm1"] * d["bm1"]
    size = abs(c["a1"] * d["a1"]) + abs(c["b1"] * d["b1"]) + abs(c["am1"] * d["am1"]) + abs(c["bm1"] * d["bm1"])
    return rate, size


def test_not_allowable_refused_with_the_time():
    # c1 prescribed with c_-1 turning: (2.14) fails from t = 0
    laws = {"a1": "1", "am1": "0.3*cos(t)", "bm1": "0.3*sin(t)"}
    scene = write("turning.toml", stroke_scene(laws, modes=1))
    p, _, _ = run(scene, "turning")
    line = one_line_refusal(p, "a turning c_-1 with c1 prescribed")
    check("(2.14)" in line and "t = 0:" in line and "stroke.a1" in line and scene in line,
          "(2.14) named at t = 0: %s" % line)
    check(not os.path.exists(os.path.join(TMP, "turning")), "nothing written for a refused stroke")
    # |c1| grows while c_-1 beats: (2.8) holds at t = 0 (every velocity is 0 there) and fails after
    laws = {"a1": "1 + 0.05*(1 - cos(t))", "am1": "0.3*sin(t)^2"}
    t_end, step = 2.0, 0.25
    scene = write("growing.toml", stroke_scene(laws, modes=1, t_end=t_end, output_step=step))
    p, _, _ = run(scene, "growing")
    line = one_line_refusal(p, "a volume that changes")
    check("(2.8)" in line, "(2.8) named: %s" % line)
    try:
        t_bad = float(line.split("at t = ")[1].split(":")[0])
    except (IndexError, ValueError):
        t_bad = -1.0
    rate, size = violation_at(laws, t_bad)
    grid = sorted(set([k * t_end / 16384 for k in range(16385)] + [k * step for k in range(int(t_end / step) + 1)]))
    before = [t for t in grid if t < t_bad]
    prev_rate, prev_size = violation_at(laws, before[-1]) if before else (0.0, 1.0)
    check(0 < t_bad < t_end and abs(rate) > 1e-8 * size,
          "the named time t = %g fails (2.8): %.3g of terms %.3g" % (t_bad, rate, size))
    check(abs(prev_rate) <= 1e-8 * prev_size + 1e-12,
          "the sample before t = %g does not (%.3g of %.3g)" % (t_bad, prev_rate, prev_size))


def test_outputs_like_swim_run():
    p, _, dyn = run("models/example1.toml", "keys_dynamic", "--t-end", "0.5")
    q, _, s = run(LOOP, "keys_stroke", "--set", "run.t_end=3", "--event", "y:min")
    check(p.returncode == 0 and q.returncode == 0, "both runs complete")
    missing = sorted(set(dyn) - set(s))
    check(not missing and "stroke" in s, "the stroke summary has every key of a run summary (missing %s)" % missing)
    check(set(dyn["stats"]) <= set(s["stats"]), "and every statistic")
    check(s["t_end"] == 3 and s["kernel"]["kind"] == "stroke", "--set run.t_end applies")
    check(os.path.exists(os.path.join(TMP, "keys_stroke", "events.csv")) and "events" in s, "events are located")
    r, rows, t = run(LOOP, "summary_only", "--summary-only", "--set", "stroke.period=3.141592653589793")
    check(r.returncode == 0 and rows is None and not os.path.exists(os.path.join(TMP, "summary_only", "trajectory.csv")),
          "--summary-only writes no trajectory")
    check(t["stroke"]["period_source"] == "scene" and len(t["stroke"]["strokes"]) == 4,
          "[stroke] period (set on the command line) is used: 4 half-loops in 4 pi")
    full = json.load(open(os.path.join(TMP, "loop", "summary.json"))) if os.path.exists(
        os.path.join(TMP, "loop", "summary.json")) else None
    if full:
        check(abs(full["final_state"]["y"] - t["final_state"]["y"]) < 1e-12, "the summary-only run ends where the full one does")


def test_plot_and_flow_on_a_stroke_run():
    out = os.path.join(TMP, "plotted")
    p, _, _ = run(COMPLETED, "plotted", "--snapshots")
    check(p.returncode == 0 and os.path.exists(os.path.join(out, "snapshots.json")), "--snapshots on a stroke run")
    env = dict(os.environ, MPLBACKEND="Agg")
    q = subprocess.run([SWIM, "plot", out], capture_output=True, text=True, env=env)
    check(q.returncode == 0, "swim plot on a stroke run: %s" % q.stderr[-300:])
    for name in ("trajectory.png", "energy.png", "snapshots.png", "stroke.png"):
        check(os.path.getsize(os.path.join(out, name)) > 1000 if os.path.exists(os.path.join(out, name)) else False,
              "swim plot drew %s" % name)
    f = subprocess.run([SWIM, "flow", out, "--times", "1.5,4", "--out", "-"], capture_output=True, text=True)
    frames = json.loads(f.stdout) if f.returncode == 0 else []
    check(len(frames) == 2 and frames[0]["boundary"], "swim flow on a stroke run directory: %s" % f.stderr)
    if shutil.which("ffmpeg") is None:
        print("  swim animate not checked: no ffmpeg (make deps-media)")
        return
    a = subprocess.run([SWIM, "animate", out, "--duration", "1", "--fps", "4"], capture_output=True, text=True, env=env)
    movie = os.path.join(out, "animation.mp4")
    check(a.returncode == 0 and os.path.exists(movie) and os.path.getsize(movie) > 1000,
          "swim animate on a stroke run directory: %s" % a.stderr[-300:])


def test_modes_beyond_the_stroke_change_nothing():
    # the same stroke in a scene of N = 7 (c_-3 ... c_-7 at 0): the mass matrices on the moving
    # coordinates are those of N = 2, so the motion is the same to round-off
    text = open(COMPLETED).read().replace("modes = 2", "modes = 7")
    text = "\n".join(l if not l.startswith("c0") else "c0 = %s" % json.dumps([1, 0] + [0] * 14) for l in text.splitlines())
    scene = write("completed_n7.toml", text + "\n")
    p, rows7, s7 = run(scene, "completed_n7")
    q, rows2, s2 = run(COMPLETED, "completed_n2")
    check(p.returncode == 0 and q.returncode == 0, "N = 2 and N = 7: %s %s" % (p.stderr, q.stderr))
    diff = max(np.abs(rows7[c] - rows2[c]).max() for c in ("x", "y", "theta", "energy", "work_positive"))
    check(diff < 1e-12, "the same stroke at N = 2 and N = 7 (largest difference %.3g)" % diff)


def test_sweep_of_strokes():
    out = os.path.join(TMP, "sweep")
    p = subprocess.run([SWIM, "sweep", LOOP, "--out", out, "--vary", "run.t_end=3.141592653589793,6.283185307179586",
                        "--jobs", "1", "--quiet"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "swim sweep of a stroke scene: %s" % p.stderr)
    members = np.atleast_1d(np.genfromtxt(os.path.join(out, "members.csv"), delimiter=",", names=True, dtype=None,
                                          encoding="utf-8"))
    check(len(members) == 2 and all(m["status"] == "completed" for m in members), "both members complete")
    single = json.load(open(os.path.join(out, "members", "00001", "summary.json")))
    check(single["kernel"]["kind"] == "stroke" and len(single["stroke"]["strokes"]) == 1,
          "a member is a stroke run with one stroke")
    check(abs(members[1]["y"] - single["stroke"]["strokes"][0]["dy"]) < 1e-12, "members.csv has the member's final y")


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_stroke"))
