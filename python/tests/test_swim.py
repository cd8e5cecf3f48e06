"""The Python package swim against bin/swim: the same numbers, bit for bit, and errors as exceptions.

Run by tests/test_python.py (pytest on this file, with the package of the source tree and
libswim of the build tree, or $SWIM_LIB). bin/swim is $SWIM_BIN (default ROOT/bin/swim).
"""
import csv
import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import swim  # noqa: E402

SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
EX3 = os.path.join(ROOT, "models", "example3.toml")
BARRIER = os.path.join(ROOT, "models", "hard", "near_boundary_a05.toml")


def swim_run(tmp_path, scene, *args):
    """`swim run SCENE --out DIR --quiet ARGS`: (summary.json as a dict, DIR)."""
    out = tmp_path / "cli"
    p = subprocess.run([SWIM, "run", scene, "--out", str(out), "--quiet", *args], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    with open(out / "summary.json") as f:
        return json.load(f), out


def reprs(d, keys=("t", "x", "y", "theta")):
    """The doubles as repr, so that an equality is one to the last bit."""
    return {k: repr(float(d[k])) for k in keys}


@pytest.mark.parametrize("scene,t_end", [(EX3, 5), (BARRIER, 1)], ids=["example3", "near_boundary_a05"])
def test_final_state_is_swim_runs(tmp_path, scene, t_end):
    r = swim.run(scene, t_end=t_end)
    want, _ = swim_run(tmp_path, scene, "--t-end", str(t_end))
    assert r.completed and r.status == "completed"
    assert reprs(r.final_state) == reprs(want["final_state"])
    assert r.summary["final_state"] == want["final_state"]
    assert r.summary["stats"]["steps"] == want["stats"]["steps"]


def test_rows_are_trajectory_csv(tmp_path):
    r = swim.run(EX3, t_end=5)
    _, out = swim_run(tmp_path, EX3, "--t-end", "5")
    with open(out / "trajectory.csv") as f:
        header = f.readline().strip().split(",")
    table = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1, ndmin=2)
    assert list(r.columns) == header
    assert r["y"].shape == (table.shape[0],)
    assert np.array_equal(r["y"], table[:, header.index("y")])
    assert np.array_equal(r.rows, table, equal_nan=True)   # every column, to the last bit
    assert r["t"][-1] == 5.0 and len(r.rows) == r.summary["rows"]


def test_state_is_the_summarys():
    r = swim.run(EX3, t_end=1)
    n = r.summary["modes"] * 2 + 2
    f = r.summary["final_state"]
    assert r.state.shape == (3 + 2 * n,)
    assert r.state.tolist() == [f["x"], f["y"], f["theta"]] + f["c"] + f["dc"]


def test_bad_override_is_a_scene_error_and_the_next_run_works():
    with pytest.raises(swim.SceneError) as e:
        swim.run(EX3, set={"model.rho0": -1})
    assert e.value.key == "model.rho0" and e.value.status == swim.EINPUT
    assert e.value.file and e.value.file.endswith("example3.toml") and "rho0" in e.value.message
    assert isinstance(e.value, swim.Error)
    assert swim.run(EX3, t_end=0.5).completed


def test_bad_text_scene_names_its_line():
    with open(EX3) as f:
        text = f.read().replace("rho0 = 1.0", "rho0 = -1.0")
    with pytest.raises(swim.SceneError) as e:
        swim.run(text)
    assert (e.value.file, e.value.key) == ("(text)", "model.rho0")
    assert e.value.line == text.splitlines().index("rho0 = -1.0") + 1
    with pytest.raises(swim.SceneError) as e:
        swim.run(text, name="mine.toml")
    assert e.value.file == "mine.toml"


def test_text_scene_runs_as_its_file():
    with open(EX3) as f:
        text = f.read()
    assert reprs(swim.run(text, t_end=1).final_state) == reprs(swim.run(EX3, t_end=1).final_state)


def test_bad_values_in_arguments():
    with pytest.raises(swim.SceneError):
        swim.run(EX3, set={"run.t_end": 2}, t_end=1)   # given twice
    with pytest.raises(swim.SceneError) as e:
        swim.run(EX3, t_end=1, events=["nosuchcolumn:max"])
    assert "nosuchcolumn" in e.value.message
    with pytest.raises(swim.SceneError):
        swim.run("/nonexistent/scene.toml")
    with pytest.raises(TypeError):
        swim.run(EX3, set={"model.rho0": [1, 2]})


def test_failed_run_is_a_result():
    """A member that fails is not an exception: completed False and the reason."""
    r = swim.run(BARRIER, t_end=4, set={"run.origin_shift": False})
    assert not r.completed and r.status == "failed" and r.reason and r.final_state["t"] < 4
    assert len(r.rows) == r.summary["rows"]


def test_an_exception_in_python_stops_the_run_and_is_raised(monkeypatch):
    calls = []

    def failing(self, values, ncol):
        calls.append(ncol)
        raise KeyboardInterrupt   # what Ctrl-C during a run raises in the row callback

    monkeypatch.setattr(swim._Rows, "_store", failing)
    with pytest.raises(KeyboardInterrupt):
        swim.run(EX3, t_end=5)
    assert len(calls) == 1   # the run stopped at the first row
    monkeypatch.undo()
    assert swim.run(EX3, t_end=0.5).completed


def test_inspect():
    c = [1, 0, 0.2, -0.05, 0.1, 0.04]
    v = [0, 0, 0.1, 0.3, -0.2, 0.1]
    m = swim.inspect(2, c, velocity=v, rho0=1.3, rhof=0.7)
    Mr, N, Md, K = m["mass_rigid"], m["mass_coupling"], m["mass_shape"], m["mass_reduced"]
    assert Mr.shape == (3, 3) and N.shape == (3, 6) and Md.shape == K.shape == (6, 6)
    scale = np.abs(Md).max()
    assert np.abs(K - K.T).max() <= 1e-13 * scale
    assert np.abs(K - (Md - N.T @ np.linalg.solve(Mr, N))).max() <= 1e-13 * scale
    G = m["christoffel"]
    assert G.shape == (6, 6, 6)
    assert np.abs(np.einsum("ijk,j,k->i", G, v, v) - m["christoffel_vv"]).max() <= 1e-12 * (1 + scale)
    assert m["jmin"] > 0
    small = swim.inspect(2, c, full=False)
    assert "christoffel" not in small and "christoffel_vv" not in small


def test_inspect_refuses_bad_shapes():
    with pytest.raises(swim.SceneError) as e:
        swim.inspect(2, [1, 0, 0, 0, 0.6, 0])   # outside D
    assert e.value.key == "shape" and "admissible" in e.value.message
    with pytest.raises(swim.SceneError) as e:
        swim.inspect(2, [1, 0, 0.2, 0])   # 4 values for n = 6
    assert e.value.key == "shape"
    with pytest.raises(swim.SceneError) as e:
        swim.inspect(2, [1, 0, 0.2, -0.05, 0.1, 0.04], rhof=0)
    assert e.value.key == "rhof"


def test_sweep_is_its_members_runs_and_swim_sweeps(tmp_path):
    rows = swim.sweep(EX3, vary={"model.rho0": "0.5:2:3"}, t_end=1)
    assert [r["id"] for r in rows] == [0, 1, 2]
    assert [r["model.rho0"] for r in rows] == [0.5, 1.25, 2.0]
    for r in rows:
        one = swim.run(EX3, set={"model.rho0": r["model.rho0"]}, t_end=1)
        assert r["completed"] and r["status"] == "completed"
        assert reprs(r, ("x", "y", "theta")) == reprs(one.final_state, ("x", "y", "theta"))
        assert r["steps"] == one.summary["stats"]["steps"]
    out = tmp_path / "sweep"
    p = subprocess.run([SWIM, "sweep", EX3, "--out", str(out), "--vary", "model.rho0=0.5:2:3", "--t-end", "1",
                        "--jobs", "1", "--quiet"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    with open(out / "members.csv") as f:
        table = list(csv.DictReader(f))
    same = ["id", "model.rho0", "status", "reason", "t_reached", "x", "y", "theta", "energy_drift_rel",
            "energy_balance_abs", "jmin", "steps", "rhs_evaluations"]
    assert set(table[0]) <= set(rows[0])   # members.csv's names, all there
    words = ("status", "reason")
    for mine, theirs in zip(rows, table):
        for k in same:   # the same doubles (repr) and words
            assert (mine[k] if k in words else repr(float(mine[k]))) == \
                (theirs[k] if k in words else repr(float(theirs[k]))), k


def test_sweep_product_zip_and_bad_member():
    rows = swim.sweep(EX3, vary={"model.rho0": [1.0, 2.0], "model.rhof": [0.5, 2.0]}, t_end=0.2)
    assert [(r["model.rho0"], r["model.rhof"]) for r in rows] == [(1.0, 0.5), (1.0, 2.0), (2.0, 0.5), (2.0, 2.0)]
    rows = swim.sweep(EX3, vary={"model.rho0": [1.0, 2.0], "model.rhof": [0.5, 2.0]}, zip=True, t_end=0.2)
    assert [(r["model.rho0"], r["model.rhof"]) for r in rows] == [(1.0, 0.5), (2.0, 2.0)]
    with pytest.raises(swim.SceneError) as e:
        swim.sweep(EX3, vary={"model.rho0": [1.0, -1.0]}, t_end=0.2)
    assert e.value.key == "model.rho0" and e.value.message.startswith("member 1 (model.rho0=-1.0)")
    with pytest.raises(swim.SceneError):
        swim.sweep(EX3, vary={"run.t_end": [1, 2]}, t_end=1)   # varied and set


def test_spec_values():
    assert swim.spec_values("1,2.5,3") == [1.0, 2.5, 3.0]
    v = swim.spec_values("0.1:0.7:7")
    assert v[0] == 0.1 and v[-1] == 0.7 and len(v) == 7
    w = swim.spec_values("log:1e-3:1:4")
    assert w[0] == 1e-3 and w[-1] == 1.0 and abs(w[1] - 1e-2) < 1e-15


def test_version_is_VERSION():
    with open(os.path.join(ROOT, "VERSION")) as f:
        assert swim.__version__ == f.read().strip()


def test_events_are_swim_runs(tmp_path):
    ev = ["am1:max", "kinetic_rigid:min"]
    r = swim.run(EX3, t_end=10, events=ev)
    _, out = swim_run(tmp_path, EX3, "--t-end", "10", "--event", ev[0], "--event", ev[1])
    with open(out / "events.csv") as f:
        want = list(csv.DictReader(f))
    assert len(r.events) == len(want) >= 4
    for mine, theirs in zip(r.events, want):
        assert (repr(mine["t"]), mine["column"], mine["kind"], repr(mine["value"])) == \
            (repr(float(theirs["t"])), theirs["column"], theirs["kind"], repr(float(theirs["value"])))


def test_stop_event_ends_the_run():
    r = swim.run(EX3, t_end=10, events=["am1:max:stop"])
    assert r.completed and r.final_state["t"] == r.events[0]["t"] < 1


def test_two_threads_give_the_sequential_results():
    jobs = [(EX3, 3), (BARRIER, 0.5)]
    seq = [swim.run(s, t_end=t) for s, t in jobs]
    par = [None, None]

    def one(i):
        par[i] = swim.run(jobs[i][0], t_end=jobs[i][1])

    threads = [threading.Thread(target=one, args=(i,)) for i in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for a, b in zip(seq, par):
        assert np.array_equal(a.rows, b.rows) and reprs(a.final_state) == reprs(b.final_state)


def test_library_not_found_says_make_lib():
    env = dict(os.environ, SWIM_LIB="/nonexistent/libswim.so.0", PYTHONDONTWRITEBYTECODE="1")
    p = subprocess.run([sys.executable, "-c", "import swim"], capture_output=True, text=True, env=env,
                       cwd=os.path.join(ROOT, "python"))
    assert p.returncode != 0 and "LibraryNotFound" in p.stderr and "make lib" in p.stderr


def test_model_set_is_a_model_opened_with_the_override():
    with swim.Model(EX3, t_end=2) as m:
        first = m.run()
        m.set("model.rho0", 2.0)
        after = m.run()
        assert "rho0 = 2" in m.scene_text()
        with pytest.raises(swim.SceneError) as e:
            m.set("model.modes", 3)   # a structure key
        assert e.value.key == "model.modes" and "structure" in e.value.message
        with pytest.raises(swim.SceneError) as e:
            m.set("model.rho0", -1)
        assert e.value.key == "model.rho0"
        assert np.array_equal(m.run().rows, after.rows)   # the refusals left it as it was
    want = swim.run(EX3, overrides={"model.rho0": 2.0}, t_end=2)
    assert np.array_equal(after.rows, want.rows) and reprs(after.final_state) == reprs(want.final_state)
    assert not np.array_equal(after.rows, first.rows)
    with pytest.raises(ValueError):
        m.run()   # closed


def test_keyword_aliases():
    a = swim.run(EX3, overrides={"model.rho0": 2.0}, t_end=0.3)
    b = swim.run(EX3, set={"model.rho0": 2.0}, t_end=0.3)
    assert np.array_equal(a.rows, b.rows)
    with pytest.raises(TypeError):
        swim.run(EX3, overrides={"model.rho0": 2.0}, set={"model.rho0": 2.0})
    vary = {"model.rho0": [1.0, 2.0], "model.rhof": [0.5, 2.0]}
    z = swim.sweep(EX3, vary=vary, zipped=True, t_end=0.2)
    assert [(r["model.rho0"], r["model.rhof"]) for r in z] == [(1.0, 0.5), (2.0, 2.0)]
    assert [r["y"] for r in swim.sweep(EX3, vary=vary, zip=True, t_end=0.2)] == [r["y"] for r in z]


def test_struct_sizes_are_checked_at_load(monkeypatch):
    assert swim._lib.size_mismatches(swim._L) == []
    for m in swim._lib.MIRRORS:   # each mirror starts with its size, set on creation
        assert m._fields_[0][0] == "size" and m().size == swim._L.swim_struct_size(m.__name__.encode()) > 0

    class swim_result(swim._lib._Sized):   # a mirror one field longer than the library's
        _fields_ = swim._lib.swim_result._fields_ + [("later", swim._lib.ctypes.c_double)]

    monkeypatch.setattr(swim._lib, "MIRRORS", (swim._lib.swim_error, swim_result))
    lib, why = swim._lib.load()
    assert lib is None and "swim_result" in why and "bytes" in why


def test_strerror_names_the_statuses():
    for name in ("OK", "EFAILED", "EINPUT", "ENOMEM", "EKERNEL"):
        assert swim.strerror(getattr(swim, name)).startswith("SWIM_%s: " % name)


def test_every_public_name_has_a_docstring():
    import inspect
    missing = []
    for name in swim.__all__:
        obj = getattr(swim, name)
        if not (inspect.isclass(obj) or inspect.isfunction(obj)):
            continue
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and obj.__module__ == "swim":
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and inspect.isfunction(member) and not (member.__doc__ or "").strip():
                    missing.append(name + "." + attr)
    assert missing == []
