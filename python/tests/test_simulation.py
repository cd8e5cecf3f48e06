"""swim.Simulation against swim.run and bin/swim: pieces, set, events, dense output, sensitivities
and the Lyapunov pass give the same numbers, bit for bit where the issue asks for it.

Run by tests/test_python.py (pytest on python/tests/)."""
import csv
import math
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import swim  # noqa: E402

SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
EX3 = os.path.join(ROOT, "models", "example3.toml")


def test_advance_in_pieces_is_one_run():
    ref = swim.run(EX3, t_end=5)
    with swim.Simulation(EX3, t_end=5) as sim:
        a = sim.advance(2)
        assert sim.t == 2.0 and a[-1, 0] == 2.0
        assert np.array_equal(sim.state, ref.rows[a.shape[0] - 1, 1:1 + len(sim.state)])
        b = sim.advance(5)
        assert np.array_equal(np.vstack([a, b]), ref.rows)
        assert np.array_equal(sim.state, ref.state)
        r = sim.run()   # already at t_end: the same Result
        assert r.completed and r.final_state == ref.final_state and np.array_equal(r.rows, ref.rows)
        assert sim["y"].tolist() == ref["y"].tolist()


def test_set_is_an_override():
    ref = swim.run(EX3, t_end=3, set={"model.rho0": 2.0})
    with swim.Simulation(EX3, t_end=3) as sim:
        sim.advance(1)
        sim.set("model.rho0", 2.0)   # starts again from t = 0
        assert sim.t == 0.0
        r = sim.run()
        assert np.array_equal(r.rows, ref.rows) and r.summary["final_state"] == ref.summary["final_state"]
        with pytest.raises(swim.SceneError) as e:
            sim.set("model.modes", 3)
        assert e.value.key == "model.modes"


def test_a_result_is_the_run_when_it_was_made_and_rows_may_be_left():
    # the summary is read when asked for, but it is the one of the run when result() was called
    with swim.Simulation(EX3, t_end=5) as sim:
        sim.advance(2.0)
        early = sim.result()
        last = sim.run()
        assert early.summary["t_reached"] == early.final_state["t"] < last.final_state["t"] == 5.0
        assert early.status != "completed" and last.status == "completed"
        sim.set("model.rho0", 2.0)
        assert last.summary["t_reached"] == 5.0   # kept past set(), which starts a new run
    # without rows: the same run, no rows kept
    want = swim.run(EX3, t_end=5, rows=False)
    with swim.Simulation(EX3, t_end=5, rows=False) as sim:
        r = sim.run()
        assert r.final_state == want.final_state and len(r.rows) == 0 and len(sim.rows) == 0
        assert sim.t == 5.0 and sim.state.tolist() == want.state.tolist()
        timed = ("ns_per_rhs",)   # a timing too
        assert untimed({k: v for k, v in r.summary["stats"].items() if k not in timed}) == \
            untimed({k: v for k, v in want.summary["stats"].items() if k not in timed})
        assert untimed(dict(r.summary, stats=None)) == untimed(dict(want.summary, stats=None))


def test_on_event_stops_at_the_first_maximum():
    first = [e for e in swim.run(EX3, t_end=10, events=["am1:max"]).events if e["kind"] == "max"][0]
    seen = []

    def on_event(e):
        seen.append(e)
        return e.column == "am1" and e.kind == "max"

    with swim.Simulation(EX3, t_end=10, events=["am1:max"], on_event=on_event) as sim:
        r = sim.run()
        assert len(seen) == 1 and seen[0].time == first["t"] and seen[0].value == first["value"]
        assert sim.t == first["t"] and r.final_state["t"] == first["t"]
        assert not r.completed and "stopped by the caller at event am1:max" in r.reason
        # the event's state is the interpolant's there; the last row is that state projected onto
        # the constraints (G1, G2), as every row is: equal to rounding
        assert np.allclose(seen[0].state, sim.state, rtol=0, atol=1e-13)


def test_an_exception_in_on_event_is_raised():
    def on_event(e):
        raise RuntimeError("from the callback")

    with swim.Simulation(EX3, t_end=5, events=["am1:max"], on_event=on_event) as sim:
        with pytest.raises(RuntimeError, match="from the callback"):
            sim.run()


def test_state_at_inside_the_last_step():
    with swim.Simulation(EX3, t_end=5) as sim:
        rows = sim.advance(2)
        assert np.array_equal(sim.state_at(2.0), rows[-1, 1:1 + len(sim.state)])
        mid = sim.state_at(np.nextafter(2.0, 0))
        assert np.all(np.isfinite(mid)) and np.max(np.abs(mid - sim.state)) < 1e-6
        with pytest.raises(swim.SceneError) as e:
            sim.state_at(1.0)
        assert e.value.key == "t" and "last step" in e.value.message


def test_sensitivities_are_sensitivity_csv(tmp_path):
    out = tmp_path / "cli"
    p = subprocess.run([SWIM, "run", EX3, "--out", str(out), "--quiet", "--t-end", "2",
                        "--sensitivity", "model.rho0,elastic.stiffness[2]"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    with open(out / "sensitivity.csv") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    with swim.Simulation(EX3, t_end=2, sensitivity=["model.rho0", "elastic.stiffness[2]"]) as sim:
        with pytest.raises(swim.Error):
            sim.sensitivities   # not before the run completed
        sim.run()
        got = sim.sensitivities
        assert list(got) == header
        for i, name in enumerate(header):
            assert got[name].tolist() == data[:, i].tolist(), name
        assert sim.sensitivity("y", "model.rho0").tolist() == data[:, header.index("dy/dmodel.rho0")].tolist()
    with pytest.raises(swim.SceneError) as e:
        swim.Simulation(EX3, sensitivity="model.nothing")
    assert e.value.key == "sensitivity"


def test_lyapunov_is_summary_json(tmp_path):
    out = tmp_path / "cli"
    p = subprocess.run([SWIM, "run", EX3, "--out", str(out), "--quiet", "--t-end", "4", "--lyapunov",
                        "--lyapunov-interval", "0.5"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    import json
    with open(out / "summary.json") as f:
        want = json.load(f)["lyapunov"]
    with swim.Simulation(EX3, t_end=4, lyapunov=0.5) as sim:
        sim.run()
        lyap = sim.lyapunov
        assert lyap.computed and lyap.exponent == want["exponent"] and lyap.verdict == want["verdict"]
        horizon = want["horizon"]
        assert lyap.horizon == (math.inf if horizon is None else horizon)
        assert sim.lyapunov_exponent == lyap.exponent and len(lyap.t) == 8


def test_sweep_on_threads_is_sweep():
    def strip(rows):   # everything but the timings
        return [{k: v for k, v in r.items() if "seconds" not in k} for r in rows]

    vary = {"model.rho0": "0.5:2:6", "elastic.stiffness[2]": [1.0, 3.0]}
    one = swim.sweep(EX3, vary=vary, t_end=1)
    two = swim.sweep(EX3, vary=vary, t_end=1, threads=2)
    assert strip(two) == strip(one) and [r["id"] for r in two] == list(range(12))
    assert all(r["completed"] for r in one)
    # each member equals its own run
    assert one[7]["y"] == swim.run(EX3, t_end=1, set={"model.rho0": 1.4, "elastic.stiffness[2]": 3.0}).final_state["y"]
    # a structure key varied: a model per member, the same rows as one after another
    modes = swim.sweep(EX3, vary={"elastic.stiffness[3]": [0.0, 1.0, 0.0]}, t_end=0.5, threads=2)
    assert strip(modes) == strip(swim.sweep(EX3, vary={"elastic.stiffness[3]": [0.0, 1.0, 0.0]}, t_end=0.5))
    assert modes[1]["y"] == swim.run(EX3, t_end=0.5, set={"elastic.stiffness[3]": 1.0}).final_state["y"]
    # a member that fails is a row; a bad member is refused before any runs, naming it
    barrier = os.path.join(ROOT, "models", "hard", "near_boundary_a05.toml")
    hard = swim.sweep(barrier, vary={"run.origin_shift": [True, False]}, t_end=4, threads=2)
    assert hard[0]["completed"] and not hard[1]["completed"] and hard[1]["status"] == "failed"
    with pytest.raises(swim.SceneError, match="member 1"):
        swim.sweep(EX3, vary={"model.rho0": [1.0, -1.0, 2.0]}, t_end=1, threads=2)
    with pytest.raises(swim.SceneError):
        swim.sweep(EX3, vary={"model.rho0": [1.0]}, threads=0)


def cli_json(tmp_path, cmd, scene, name, *args):
    out = tmp_path / cmd
    p = subprocess.run([SWIM, cmd, scene, "--out", str(out), "--quiet", *args], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    import json
    with open(out / name) as f:
        return json.load(f), out


def untimed(d):
    """A JSON value without its timings (seconds differ from run to run)."""
    if isinstance(d, dict):
        return {k: untimed(v) for k, v in d.items() if "seconds" not in k}
    if isinstance(d, list):
        return [untimed(v) for v in d]
    return d


def test_periodic_and_floquet_are_the_commands_files(tmp_path):
    ex1 = os.path.join(ROOT, "models", "example1.toml")
    want, _ = cli_json(tmp_path, "periodic", ex1, "periodic.json")
    p = swim.periodic(ex1)
    assert untimed(p.json) == untimed(want) and p.converged and p.period == want["period"]
    tangent = want["floquet"]["multipliers_tangent"]
    assert p.floquet["multipliers_tangent"].tolist() == [complex(m["re"], m["im"]) for m in tangent]
    assert p.phase_point == want["phase_point"]
    # the C result's arrays (libswim's swim_orbit_periodic) are the file's numbers
    assert p.monodromy.tolist() == want["floquet"]["monodromy"] and p.exit_status == 0
    assert p.multipliers.tolist() == [complex(m["re"], m["im"]) for m in tangent]
    want, _ = cli_json(tmp_path, "floquet", EX3, "floquet.json", "--event", "am1:max")
    f = swim.floquet(EX3, event="am1:max")
    assert untimed(f.json) == untimed(want) and f.monodromy.tolist() == want["monodromy"]
    assert f.multipliers.tolist() == [complex(m["re"], m["im"]) for m in want["multipliers_full"]]
    with pytest.raises(swim.SceneError):
        swim.periodic(EX3, overrides={"model.rho0": -1})


def test_continuation_is_branch_csv(tmp_path):
    ex1 = os.path.join(ROOT, "models", "example1.toml")
    _, out = cli_json(tmp_path, "continue", ex1, "branch.json", "--param", "energy=0.1:0.15", "--max-points", "2")
    c = swim.continuation(ex1, "energy", 0.1, 0.15, max_points=2)
    with open(out / "branch.csv") as f:
        rows = list(csv.reader(f))
    assert list(c.columns) == rows[0]
    for i, name in enumerate(rows[0]):
        try:
            want = np.array([float(r[i]) if r[i] != "" else math.nan for r in rows[1:]])
            assert np.array_equal(c.table[name], want, equal_nan=True), name
        except ValueError:   # a column of words
            assert c.table[name].tolist() == [r[i] for r in rows[1:]], name


def test_optimize_is_optimize_json(tmp_path):
    want, out = cli_json(tmp_path, "optimize", EX3, "optimize.json", "--vary", "elastic.reference.am1=0:1",
                         "--minimize", "energy", "--set", "run.t_end=1")
    o = swim.optimize(EX3, {"elastic.reference.am1": (0, 1)}, minimize="energy", overrides={"run.t_end": 1})
    # every number of the command's file but the timings; no best.toml is written by the library
    assert o.json.pop("best_scene") is None and want.pop("best_scene")
    assert untimed(o.json) == untimed(want) and o.exit_status == 0
    # the C result's best values are the file's
    assert o.best_values.tolist() == [want["best"]["elastic.reference.am1"]]
    with open(out / "optimize.csv") as f:
        rows = list(csv.reader(f))
    assert list(o.columns) == rows[0]
    for i, name in enumerate(rows[0]):
        assert o.table[name].tolist() == [float(r[i]) for r in rows[1:]], name
    with pytest.raises(swim.SceneError) as e:
        swim.optimize(EX3, {"elastic.reference.am1": (0, 1)}, maximize="displacement_per_work", method="bfgs")
    assert e.value.key == "method"
    with pytest.raises(swim.SceneError) as e:
        swim.optimize(EX3, {"model.modes": (1, 2)}, minimize="energy")
    assert e.value.key == "model.modes"
