"""swim sweep and swim run --set: spec expansion (grid, zip, linear, log, lists), key parsing and the
validation of every member before any work, a failing and a crashing member, resume after kill -9
(nothing lost or duplicated), --jobs 1 against --jobs 2 (identical numbers), and the physics a
family must obey: Example 1 has no potential energy, so its solutions scale in time with the
initial velocity (c(t; s v) = c(s t; v))."""

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import ROOT, SWIM, TMP, check  # noqa: E402

EX1 = "models/example1.toml"
TIMING = {"integrate_seconds", "wall_seconds"}


def sweep(name, *args, jobs=1):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "sweep", EX1, "--out", out, "--quiet", "--jobs", str(jobs), *args],
                       capture_output=True, text=True, cwd=ROOT)
    return p, out


def rows(out):
    with open(os.path.join(out, "members.csv")) as fh:
        return list(csv.DictReader(fh))


def by_id(out):
    return {int(r["id"]): r for r in rows(out)}


def same_numbers(a, b):
    """Every column but the timings equal, as text (the exact digits of the summaries)."""
    if sorted(a) != sorted(b):
        return False
    return all({k: v for k, v in a[i].items() if k not in TIMING} ==
               {k: v for k, v in b[i].items() if k not in TIMING} for i in a)


def test_grid_expansion():
    p, out = sweep("grid", "--t-end", "0.5", "--vary", "shape.dc0.bm2=-0.4:0.4:3",
                   "--vary", "run.rtol=log:1e-9:1e-11:3")
    check(p.returncode == 0, "grid sweep exits 0: %s" % p.stderr)
    r = by_id(out)
    check(sorted(r) == list(range(9)), "grid: 3 x 3 = 9 members, ids 0..8")
    bm2 = [-0.4, 0.0, 0.4]
    rtol = [1e-9, 1e-10, 1e-11]
    ok = all(math.isclose(float(r[3 * i + j]["shape.dc0.bm2"]), bm2[i], abs_tol=1e-15) and
             math.isclose(float(r[3 * i + j]["run.rtol"]), rtol[j], rel_tol=1e-12)
             for i in range(3) for j in range(3))
    check(ok, "grid: the last --vary varies fastest, linear and log values with exact endpoints")
    check(float(r[8]["run.rtol"]) == 1e-11 and float(r[0]["shape.dc0.bm2"]) == -0.4,
          "endpoints exact to the bit")
    check(all(x["status"] == "completed" for x in r.values()), "grid: every member completed")
    with open(os.path.join(out, "sweep.json")) as fh:
        d = json.load(fh)
    check(d["members"] == 9 and [v["key"] for v in d["vary"]] == ["shape.dc0.bm2", "run.rtol"],
          "sweep.json records the definition")
    s = json.load(open(os.path.join(out, "members", "00004", "summary.json")))
    check(s["rtol"] == 1e-10 and s["t_end"] == 0.5 and s["final_state"]["dc"] == [0.0] * 16,
          "member 4's summary has its overrides (bm2' = 0, rtol 1e-10, t_end 0.5)")
    check(not os.path.exists(os.path.join(out, "members", "00004", "trajectory.csv")),
          "default --keep summaries: no trajectory.csv")


def test_one_kernel_per_structure():
    """Two structures (R on a_-1 zero or not) in a fresh kernel cache: the sweep generates both before
    the members start, so every member loads its kernel from the cache, and members of one structure
    share it."""
    cache = os.path.join(TMP, "cache")
    out = os.path.join(TMP, "structures")
    p = subprocess.run([SWIM, "sweep", "models/example2a.toml", "--out", out, "--quiet", "--jobs", "2",
                        "--vary", "elastic.stiffness[2]=0,0.5", "--vary", "run.t_end=0.5,1"], cwd=ROOT,
                       capture_output=True, text=True, env=dict(os.environ, SWIM_CACHE=cache))
    ks = [json.load(open(os.path.join(out, "members", "%05d" % i, "summary.json")))["kernel"] for i in range(4)]
    check(p.returncode == 0 and all(k["kind"] == "specialized" and k["from_cache"] for k in ks),
          "every member loaded a pre-generated kernel: %s" % [(k["kind"], k["from_cache"]) for k in ks])
    check(ks[0]["cache"] == ks[1]["cache"] != ks[2]["cache"] == ks[3]["cache"],
          "one kernel per structure, shared by its members")
    check(sum(1 for e in os.listdir(cache) if os.path.isdir(os.path.join(cache, e))) == 2,
          "two structures, two kernels in the cache")


def test_zip_and_keep():
    p, out = sweep("zip", "--zip", "--keep", "trajectories", "--vary", "shape.dc0.bm2=-0.2,0.1",
                   "--vary", "run.t_end=0.3,0.6")
    check(p.returncode == 0, "zip sweep exits 0: %s" % p.stderr)
    r = by_id(out)
    check(len(r) == 2 and float(r[1]["run.t_end"]) == 0.6 and float(r[1]["shape.dc0.bm2"]) == 0.1,
          "zip pairs the values (2 members, not 4)")
    check(float(r[1]["t_reached"]) == 0.6, "zip: member 1 ran to its own t_end")
    tr = os.path.join(out, "members", "00001", "trajectory.csv")
    check(os.path.exists(tr) and sum(1 for _ in open(tr)) == 14,
          "--keep trajectories writes each member's rows (13 rows + header)")
    check(not os.path.exists(os.path.join(out, "sweep.lock")), "no sweep.lock left in a finished sweep")


def test_bad_input():
    cases = [
        (["--vary", "shape.dc0.bm9=1,2"], "member 0 (shape.dc0.bm9=1): models/example1.toml: --set shape.dc0.bm9=1: index 19 is out of range"),
        (["--vary", "shape.dc0.zz=1,2"], "unknown coordinate 'zz'"),
        (["--vary", "nodot=1,2"], "expected TABLE.KEY"),
        (["--vary", "shape.dc0[16]=1"], "index 16 is out of range"),
        (["--vary", "elastic.stiffness[3]=1"], "no table [elastic]"),
        (["--vary", "shape.free=1"], "not a number"),
        (["--vary", "run.t_end=1:2"], "START:STOP:COUNT"),
        (["--vary", "run.t_end=1:2:0"], "COUNT must be"),
        (["--vary", "run.t_end=log:0:2:3"], "START > 0"),
        (["--vary", "run.t_end=1,x"], "item 2 ('x')"),
        (["--vary", "run.t_end=1,2", "--vary", "run.rtol=1e-8", "--zip"], "counts must agree"),
        (["--vary", "run.t_end=1,-2"], "member 1 (run.t_end=-2): models/example1.toml: --set run.t_end=-2: run.t_end: must be > 0"),
        (["--vary", "shape.c0.am1=0.5,2"], "member 1 (shape.c0.am1=2): models/example1.toml: --set shape.c0.am1=2: shape.c0: shape outside"),
        (["--vary", "shape.dc0.am1=0,1"], "member 1 (shape.dc0.am1=1): models/example1.toml: --set shape.dc0.am1=1: shape.dc0: violates"),
        (["--vary", "run.t_end=1", "--set", "run.nokey=3"], "run.nokey: unknown key"),
        (["--vary", "run.t_end=1", "--keep", "all"], "--keep: expected"),
        (["--vary", "run.t_end=1", "--jobs", "0"], "--jobs: 0 is out of range"),
        ([], "at least one --vary"),
    ]
    for i, (args, msg) in enumerate(cases):
        jobs = args[args.index("--jobs") + 1] if "--jobs" in args else 1   # an option is given once
        args = [a for j, a in enumerate(args) if "--jobs" not in args[max(j - 1, 0):j + 1]]
        p, out = sweep("bad%d" % i, *args, jobs=jobs)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2 and len(lines) == 1 and msg in lines[0],
              "bad sweep %s: exit 2 and one line with %r (got %d, %r)" % (args, msg, p.returncode, p.stderr))
        check(not os.path.exists(os.path.join(out, "members")), "bad sweep %s: no member ran" % args)
    # the same overrides on swim run
    p, rw, s = swimtest.run(EX1, "set-run", "--set", "shape.dc0.bm2=-0.7", "--set", "run.t_end=0.5",
                            "--set", "run.output_step=0.25")
    check(p.returncode == 0 and rw is not None and len(rw) == 3 and s["t_end"] == 0.5 and
          s["final_state"]["dc"][5] != 0, "swim run --set applies the overrides")
    p, rw, s = swimtest.run(EX1, "set-bad", "--set", "shape.dc0=1")
    check(p.returncode == 2 and "is a array, not a number" in p.stderr or "not a number" in p.stderr,
          "swim run --set on a vector without an index: exit 2 (%s)" % p.stderr.strip())


def test_summary_only():
    """swim run --summary-only: the same summary (every row still computed) without the rows."""
    p1, rw, full = swimtest.run(EX1, "full", "--t-end", "3")
    p2, none, short = swimtest.run(EX1, "short", "--t-end", "3", "--summary-only")
    out = os.path.join(TMP, "short")
    check(p1.returncode == 0 and p2.returncode == 0 and rw is not None and none is None and
          not os.path.exists(os.path.join(out, "snapshots.json")), "--summary-only writes no rows and no snapshots")
    same = all(full[k] == short[k] for k in ("final_state", "jmin", "energy_drift_abs", "max_residuals", "rows"))
    check(same and full["stats"]["steps"] == short["stats"]["steps"], "--summary-only: the same summary numbers")
    # the split itself (how the parts compare is a benchmark, bench_sweep.py: timings are not
    # asserted in tests, a loaded machine reorders them)
    for name, summary in (("full", full), ("--summary-only", short)):
        st = summary["stats"]
        parts = [st[k] for k in ("integrate_seconds", "diagnostics_seconds", "output_seconds")]
        check(all(x >= 0 for x in parts) and sum(parts) <= st["wall_seconds"] * 1.05 + 1e-3,
              "%s: the summary splits integrate/diagnostics/output seconds within the wall time (%s of %.2g s)"
              % (name, parts, st["wall_seconds"]))


def test_different_definition_refused():
    p, out = sweep("redef", "--t-end", "0.2", "--vary", "shape.dc0.bm2=0.1,0.2")
    check(p.returncode == 0, "first sweep ok")
    p2, _ = sweep("redef", "--t-end", "0.2", "--vary", "shape.dc0.bm2=0.1,0.3")
    check(p2.returncode == 2 and "different sweep" in p2.stderr, "a different definition in DIR is refused")
    p3, _ = sweep("redef", "--t-end", "0.2", "--vary", "shape.dc0.bm2=0.1,0.2", jobs=2)
    check(p3.returncode == 0 and len(rows(out)) == 2, "the same definition with other --jobs resumes (nothing to do)")
    p4 = subprocess.run([SWIM, "run", EX1, "--out", os.path.join(TMP, "plain"), "--quiet", "--t-end", "0.1"],
                        capture_output=True, cwd=ROOT)
    p5 = subprocess.run([SWIM, "sweep", EX1, "--out", os.path.join(TMP, "plain"), "--vary", "run.t_end=1"],
                        capture_output=True, text=True, cwd=ROOT)
    check(p5.returncode == 2 and "not a sweep directory" in p5.stderr, "a run directory is not taken over")


def test_failing_and_crashing_member():
    # gamma = 0.8: the curve (4.17) leaves D at beta = pi/4 or so (1 - gamma|cos b| - sqrt2 gamma|sin b| < 0)
    p, out = sweep("fail", "--t-end", "5", "--vary", "shape.c0.am1=0.5,0.8,0.4")
    r = by_id(out)
    check(p.returncode == 1 and len(r) == 3, "a failing member: the sweep goes on, exit 1, 3 rows")
    check(r[1]["status"] == "failed" and "left the admissible set D" in r[1]["reason"],
          "the failing member's row says why: %r" % r[1]["reason"])
    check(r[0]["status"] == "completed" and r[2]["status"] == "completed", "the others completed")
    # a member that crashes (SIGSEGV: its own fault) gets a "crashed" row and is not rerun
    out = os.path.join(TMP, "crash")
    proc, child = start_and_signal(out, "3000", signal.SIGSEGV)
    wait_for_row(out, 0)              # the crash recorded, however long a loaded machine takes
    proc.send_signal(signal.SIGINT)   # stop the second (long) member: it is unfinished
    proc.communicate(timeout=60)
    r = by_id(out)
    check(child is not None and 0 in r and r[0]["status"] == "crashed" and "signal 11" in r[0]["reason"],
          "a crashing member gets a row 'crashed ... signal 11': %r" % (r.get(0),))
    check(1 not in r and proc.returncode == 1, "SIGINT: the running member is not recorded, exit 1")


def start_and_signal(out, t_end, sig):
    """A two-member sweep; its first member gets `sig` once it runs. (process, member pid)."""
    proc = subprocess.Popen([SWIM, "sweep", EX1, "--out", out, "--quiet", "--jobs", "1", "--t-end", t_end,
                             "--vary", "shape.dc0.bm2=-0.7,0.7"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    child = None
    swim_exe = os.path.realpath(SWIM)
    deadline = time.time() + 60
    while child is None and time.time() < deadline and proc.poll() is None:
        time.sleep(0.02)
        ps = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True, text=True).stdout.split()
        # a member is a forked copy of swim (no exec); other children (the compiler's --version
        # for the kernel key, a generator) run other programs, and a signal meant for the member
        # must not hit them on a loaded machine, where they live long enough to be seen
        members = [int(p) for p in ps if exe_of(int(p)) == swim_exe]
        if not members:
            continue
        time.sleep(0.2)
        try:
            os.kill(members[0], sig)
            child = members[0]
        except ProcessLookupError:
            continue
    return proc, child


def exe_of(pid):
    try:
        return os.path.realpath(os.readlink("/proc/%d/exe" % pid))
    except OSError:
        return None


def wait_for_row(out, member, seconds=60):
    """Until members.csv has MEMBER's row (or SECONDS pass)."""
    end = time.time() + seconds
    while time.time() < end:
        try:
            if member in by_id(out):
                return True
        except (OSError, ValueError, KeyError):
            pass
        time.sleep(0.05)
    return False


def test_member_stopped_by_a_signal_reruns():
    """A member killed by someone (SIGTERM, SIGKILL: a scheduler, an operator) did not fail: it is
    not recorded, and a resume runs it again to completion."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        out = os.path.join(TMP, "stopped%d" % sig)
        proc, child = start_and_signal(out, "8000", sig)
        proc.communicate(timeout=120)
        r = by_id(out)
        check(child is not None and 0 not in r, "a member stopped by signal %d was recorded: %r" % (sig, r.get(0)))
        p = subprocess.run([SWIM, "sweep", EX1, "--out", out, "--quiet", "--t-end", "8000",
                            "--vary", "shape.dc0.bm2=-0.7,0.7"], cwd=ROOT, capture_output=True, text=True)
        r = by_id(out)
        check(p.returncode == 0 and 0 in r and r[0]["status"] == "completed",
              "resume after signal %d: member 0 should rerun and complete: %d %r" % (sig, p.returncode, r.get(0)))


def test_resume_after_kill9_and_jobs():
    args = ["--t-end", "4", "--vary", "shape.dc0.bm2=-0.7:0.7:24"]
    out = os.path.join(TMP, "resume")
    proc = subprocess.Popen([SWIM, "sweep", EX1, "--out", out, "--quiet", "--jobs", "2", *args], cwd=ROOT,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    path = os.path.join(out, "members.csv")
    for _ in range(400):
        time.sleep(0.02)
        if os.path.exists(path) and sum(1 for _ in open(path)) >= 5:
            break
    proc.kill()
    proc.wait()
    before = len(rows(out))
    time.sleep(0.2)
    # a member is a forked copy of the sweep (same command line) or an exec'd `swim run --out OUT/...`
    orphans = subprocess.run(["pgrep", "-f", "--out " + out], capture_output=True, text=True).stdout.split()
    check(not orphans, "kill -9 of the sweep leaves no member running (%s)" % orphans)
    p, _ = sweep("resume", *args, jobs=2)
    r = rows(out)
    ids = [int(x["id"]) for x in r]
    check(p.returncode == 0 and sorted(ids) == list(range(24)),
          "resume after kill -9 (%d rows then): 24 rows, none lost or duplicated" % before)
    check(0 < before < 24, "the kill came mid-sweep (%d of 24 rows)" % before)
    check(not os.path.exists(os.path.join(out, "sweep.lock")), "no sweep.lock left after the resumed sweep ended")
    p1, out1 = sweep("jobs1", *args, jobs=1)
    check(p1.returncode == 0 and same_numbers(by_id(out1), by_id(out)),
          "--jobs 1 and the interrupted --jobs 2 sweep give the same numbers in every column but timings")


def test_example1_time_scaling():
    """No potential energy: the solution with initial velocity s v at time T is the one with v at s T."""
    v0, T = -0.35355339059327373, 6.0
    s = [0.5, 1.5, 2.5]
    bm2 = [x * v0 for x in s] + [v0] * len(s)
    tend = [T] * len(s) + [x * T for x in s]
    p, out = sweep("scaling", "--zip", "--vary", "shape.dc0.bm2=" + ",".join("%.17g" % x for x in bm2),
                   "--vary", "run.t_end=" + ",".join("%.17g" % x for x in tend), jobs=2)
    r = by_id(out)
    check(p.returncode == 0 and len(r) == 6, "scaling sweep ran 6 members: %s" % p.stderr)
    for i, x in enumerate(s):
        a, b = r[i], r[i + len(s)]
        ya, yb = float(a["y"]), float(b["y"])
        check(abs(ya - yb) <= 1e-7 * max(1.0, abs(yb)) and abs(ya) > 0.05,
              "s = %g: y(T; s v) = %.12g equals y(s T; v) = %.12g" % (x, ya, yb))
        check(float(a["x"]) == 0.0 and float(b["x"]) == 0.0, "s = %g: Example 1 moves along y only" % x)
        ea = json.load(open(os.path.join(out, "members", "%05d" % i, "summary.json")))["energy_initial"]
        eb = json.load(open(os.path.join(out, "members", "%05d" % (i + len(s)), "summary.json")))["energy_initial"]
        check(math.isclose(ea, x * x * eb, rel_tol=1e-12), "s = %g: kinetic energy scales as s^2" % x)


def test_plot_family_and_phase():
    """swim plot on a sweep of Example 2a on the curve (4.17): the family and the phase portrait are
    drawn, trapped and passing solutions told apart, the reduced energy m beta'^2/2 + V (from swim
    inspect) equals swim's energy along every computed trajectory, flapping does not swim."""
    red = subprocess.run([sys.executable, "runtime/plot/reduction_members.py", "--gamma", "0.5", "--beta0", "0",
                          "--betadot", "0.6,-1.8,1.8"], capture_output=True, text=True, cwd=ROOT).stdout.split()
    out = os.path.join(TMP, "phase2a")
    p = subprocess.run([SWIM, "sweep", "models/example2a.toml", "--out", out, "--quiet", "--jobs", "2", "--t-end", "25",
                        "--keep", "trajectories", *red], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "Example 2a family on (4.17): %s" % p.stderr)
    p = subprocess.run([SWIM, "plot", out], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0 and "k = m'/2 to" in p.stdout, "swim plot DIR on a sweep: %s %s" % (p.stdout, p.stderr))
    for f in ("family.png", "phase.png"):
        path = os.path.join(out, f)
        check(os.path.exists(path) and open(path, "rb").read(8) == b"\x89PNG\r\n\x1a\n", "%s written" % f)
    mism = float(p.stdout.split("k = m'/2 to ")[1].split()[0])
    check(mism < 1e-10, "the kernels' <Gamma, v, v> projected on the curve is m'/2 (%.1e)" % mism)
    rows_ = {int(r["id"]): r for r in csv.DictReader(open(os.path.join(out, "periods.csv")))}
    check([rows_[i]["kind"] for i in range(3)] == ["trapped", "passing", "passing"],
          "beta'0 = 0.6 is trapped in the well at 0, +-1.8 pass (%s)" % [rows_[i]["kind"] for i in rows_])
    check(all(float(r["energy_mismatch"]) < 1e-10 for r in rows_.values()),
          "reduced energy = swim's energy along every trajectory (%s)" % [r["energy_mismatch"] for r in rows_.values()])
    dy = [float(rows_[i]["dy_per_period"] or "nan") for i in range(3)]
    check(abs(dy[0]) < 1e-4 and abs(dy[1]) > 0.4 and math.isclose(dy[1], -dy[2], rel_tol=1e-3),
          "flapping: no net displacement; passing: the same displacement per period, opposite signs (%s)" % dy)


sys.exit(swimtest.main(globals(), "test_sweep"))
