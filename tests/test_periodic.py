"""swim periodic: Newton shooting converges on Example 1 and Example 3 to a residual <= 1e-11 of the
state's scale; its period and displacement per period agree with a long plain run (the time
between two events of the section at rtol 1e-12, and y at those times: both examples swim along
y with theta = 0, so the body frame at the phase point is the fixed frame); the Newton history is
kept and the residual falls; the Floquet part is based at the phase point and its flow direction
is an eigenvector with multiplier 1. A conservative scene holds the guess's energy as a target
(the libration from rest at E = 0.3: its orbit, or a refusal naming the energy; the section's
second crossing reaches it). A damped scene (Example 7) has no periodic orbit: exit 1,
its last line saying Newton did not converge and why (after the scene's own
notice of its projected initial velocity), the history in periodic.json. Bad input: one
line, exit 2."""

import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import TMP, check, swim  # noqa: E402


def periodic(scene, name, *args):
    out = os.path.join(TMP, name)
    p = swim("periodic", scene, "--out", out, "--quiet", *args)
    path = os.path.join(out, "periodic.json")
    data = json.load(open(path)) if os.path.exists(path) else None
    return p, data


def final_y(scene, t_end, name):
    p, _, s = swimtest.run(scene, name, "--t-end", repr(t_end), "--rtol", "1e-12", "--atol", "1e-14")
    return s["final_state"]["y"] if s else None


def events(scene, name, t_end):
    p, _, s = swimtest.run(scene, name, "--t-end", repr(t_end), "--rtol", "1e-12", "--atol", "1e-14",
                           "--event", "am1:max", "--summary-only")
    path = os.path.join(TMP, name, "events.csv")
    rows = [ln.split(",") for ln in open(path).read().split("\n")[1:] if ln] if os.path.exists(path) else []
    return [float(r[0]) for r in rows]


def agree_with_long_run(scene, tag, t_end, period_hint):
    p, d = periodic(scene, tag)
    check(p.returncode == 0 and d and d["converged"], "%s: converged (%r)" % (tag, p.stderr[-300:]))
    if not d:
        return
    check(d["residual"] <= 1e-11, "%s: residual %.2g <= 1e-11" % (tag, d["residual"]))
    res = [h["residual"] for h in d["newton"]]
    check(len(res) >= 2 and res[-1] < res[0], "%s: the residual falls along the history %s" % (tag, res))
    check(abs(d["period"] - period_hint) < 1e-2, "%s: period %.10g near the paper's %.4g" % (tag, d["period"], period_hint))
    t = events(scene, tag + "-events", t_end)
    check(len(t) >= 3, "%s: events of a long run: %s" % (tag, t))
    if len(t) < 3:
        return
    gaps = [b - a for a, b in zip(t, t[1:])]
    check(all(abs(g - d["period"]) <= 1e-7 * d["period"] for g in gaps),
          "%s: every gap between events of a long run is the period to 1e-7: %.12g vs %s" % (tag, d["period"], gaps))
    dy_run = final_y(scene, t[2], tag + "-t2") - final_y(scene, t[1], tag + "-t1")
    dy = d["displacement_per_period"]["dy"]
    check(abs(dy - dy_run) <= 1e-7 * max(1.0, abs(dy)), "%s: dy per period %.12g vs the run's %.12g" % (tag, dy, dy_run))
    fl = d["floquet"]
    check(fl and fl["base"] == "the phase point" and fl["checks"]["flow_residual"] < 1e-5 and fl["checks"]["multipliers_at_1"] >= 2,
          "%s: Floquet at the phase point, f an eigenvector for 1 (%r)" % (tag, fl and fl["checks"]))


def multipliers_at_1(tag, exact_ones, reasons):
    """Each named multiplier at 1 checked against the monodromy periodic.json writes: the flow and
    a symmetry's generator are eigenvectors (M v = v), grad E a left eigenvector on the tangent
    space, to rounding; the complement's multipliers are M_t's others (computed here by numpy),
    on the unit circle; nothing at 1 is left unnamed."""
    import numpy as np
    d = json.load(open(os.path.join(TMP, tag, "periodic.json")))
    fl = d["floquet"]
    M, B = np.array(fl["monodromy"]), np.array(fl["tangent_basis"])
    named = []
    for a in fl["at_1"]:
        if "vector" in a and (a.get("symmetry", True)):
            v = np.array(a["vector"])
            r = np.linalg.norm(M @ v - v) / np.linalg.norm(v)
            check(r <= 1e-9, "%s: %s: M v = v to %.2g" % (tag, a["reason"][:40], r))
            named.append(a["reason"])
        elif "left_vector" in a:
            g = np.array(a["left_vector"])
            r = np.linalg.norm((g @ M - g) @ B) / np.linalg.norm(g @ B)
            check(r <= 1e-9, "%s: grad E M = grad E on the tangent space to %.2g" % (tag, r))
            named.append(a["reason"])
        elif "multiplier" in a:
            check(a["residual"] <= 1e-9, "%s: %s: the multiplier is 1 to %.2g" % (tag, a["reason"][:40], a["residual"]))
            named.append(a["reason"])
    check(all(any(r in n for n in named) for r in reasons), "%s: the multipliers at 1 are named %s" % (tag, named))
    ch = fl["checks"]
    check(ch["exact_ones"] == exact_ones and ch["complement_dimension"] == fl["tangent_dimension"] - exact_ones,
          "%s: %d multipliers taken out as exact, the rest on the complement (%s)" % (tag, exact_ones, ch))
    comp = [complex(m["re"], m["im"]) for m in ch["multipliers_complement"]]
    check(all(abs(abs(z) - 1) <= 1e-9 for z in comp), "%s: the complement's multipliers on the unit circle to 1e-9 %s"
          % (tag, [abs(z) for z in comp]))
    full = np.linalg.eigvals(B.T @ M @ B)
    check(all(min(abs(full - z)) <= 1e-6 for z in comp), "%s: the complement's multipliers are M_t's (%s vs %s)"
          % (tag, comp, full))
    check(fl["unidentified_at_1"] == 0, "%s: no multiplier at 1 left unnamed" % tag)


def test_example1():
    agree_with_long_run("models/example1.toml", "ex1", 30.0, 8.335)
    multipliers_at_1("ex1", 3, ["time shift", "energy", "turned against the body"])


def test_example3():
    agree_with_long_run("models/example3.toml", "ex3", 12.0, 3.699)
    multipliers_at_1("ex3", 2, ["time shift", "energy", "reversibility"])


def test_damped_scene_does_not_converge():
    p, d = periodic("models/example7.toml", "ex7", "--max-iter", "1")
    last = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else ""
    check(p.returncode == 1 and "did not converge" in last and "periodic.json" in last,
          "damped: exit 1, one line saying why: %d %r" % (p.returncode, p.stderr))
    check(d is not None and d["converged"] is False and "dissipates" in d["reason"] and len(d["newton"]) >= 1,
          "damped: periodic.json keeps the history and the reason")


LIB = "tests/scenes/example3_libration.toml"
# at rest at E = 0.3 on the ellipse a_-1^2 + 2 b_-2^2 = 0.4899^2 (the invariant plane), beyond 90
# degrees from c_ref: a libration whose b_-2 passes its maximum twice per period
AT_REST_03 = ["--set", "shape.c0.am1=-0.12246987140232701", "--set", "shape.c0.bm2=0.33541253748085914"]


def test_energy_held_as_target():
    """A conservative scene keeps the guess's energy as a target: from the libration at rest at
    E = 0.3, the section bm2:max (crossed twice per period) gives a half-period guess, from which
    Newton used to converge to the rotation at E = 0.544 while saying the energy was kept; now it
    refuses, saying the orbit left the energy. bm2:max:2 spans the whole period: the libration of
    energy 0.3 (to 1e-9), with no displacement per period, in the invariant plane."""
    p, d = periodic(LIB, "lib03-half", "--guess-event", "bm2:max", *AT_REST_03)
    check(d is not None and abs(d["energy_target"] - 0.3) < 1e-12 and d["section"] == "bm2:max"
          and d["section_events_per_period"] == 1, "half guess: target 0.3 and the section in periodic.json")
    converged = p.returncode == 0 and d and d["converged"]
    check((converged and abs(d["energy"] - 0.3) <= 1e-9) or
          (p.returncode == 1 and d and not d["converged"] and "left the energy" in d["reason"]
           and "left the energy" in p.stderr),
          "half guess: an orbit of energy 0.3 or a refusal naming the energy: exit %d, %r" % (p.returncode, p.stderr))
    p, d = periodic(LIB, "lib03", "--guess-event", "bm2:max:2", *AT_REST_03)
    check(p.returncode == 0 and d and d["converged"], "bm2:max:2: converged (%r)" % p.stderr[-300:])
    if not (d and d["converged"]):
        return
    check(abs(d["energy"] - 0.3) <= 1e-9 and d["section"] == "bm2:max:2" and d["section_events_per_period"] == 2,
          "bm2:max:2: energy %.15g, section %r" % (d["energy"], d["section"]))
    z = d["phase_point"]
    check(abs(d["displacement_per_period"]["dy"]) < 1e-9 and max(abs(z[k]) for k in ("bm1", "am2", "dbm1", "dam2")) < 1e-9,
          "bm2:max:2: a libration in the plane b_-1 = a_-2 = 0 (dy %.3g, %r)" % (d["displacement_per_period"]["dy"], z))
    check("energy 0.3" in p.stdout and "target" in p.stdout, "the report names the target: %r" % p.stdout)


def test_bad_input():
    for args, what in ((["--guess-event", "nosuch:max"], "nosuch"), (["--guess-event", "am1:sideways"], "COLUMN:KIND"),
                       (["--guess-event", "am1:max:0"], "integer 1..16"), (["--guess-event", "am1:max:x"], "am1:max:x"),
                       (["--tol", "2"], "--tol"), (["--max-iter", "0"], "max-iter")):
        p = swim("periodic", "models/example3.toml", "--out", os.path.join(TMP, "bad"), *args)
        check(p.returncode == 2 and swimtest.one_line(p) and what in p.stderr, "%s: one line, exit 2: %r" % (args, p.stderr))
    p = swim("periodic", "models/stroke_loop.toml", "--out", os.path.join(TMP, "bad"))
    check(p.returncode == 2 and swimtest.one_line(p) and "stroke" in p.stderr, "a stroke is refused: %r" % p.stderr)


sys.exit(swimtest.main(globals(), "test_periodic"))
