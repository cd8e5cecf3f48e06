"""bin/swim-mpi sweep under mpirun with 3 ranks on loopback: the same members.csv numbers as
swim sweep --jobs 1 (every column but the timings), with members forked or exec'd (SWIM_MPI_EXEC=1), a failing member recorded, and a resume after
every process of the sweep was killed with SIGKILL (no member lost or duplicated).

Skipped (0 checks) when bin/swim-mpi is absent, unless SWIM_MPI=1 (make test-mpi) demands it."""

import csv
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import ROOT, SWIM, TMP, check  # noqa: E402

MPI_BIN = os.path.join(os.path.dirname(SWIM), "swim-mpi")
EX1 = "models/example1.toml"
ARGS = ["--t-end", "3", "--vary", "shape.c0.am1=0.5,0.8", "--vary", "shape.dc0.bm2=-0.7:0.7:7"]
TIMING = {"integrate_seconds", "wall_seconds"}
ENV = dict(os.environ, OMPI_MCA_btl="self,vader", OMPI_MCA_plm_rsh_agent="", OMPI_MCA_rmaps_base_oversubscribe="1")


def mpirun(out, ranks=3, popen=False, env=ENV):
    cmd = ["mpirun", "--oversubscribe", "--allow-run-as-root", "-np", str(ranks), MPI_BIN, "sweep", EX1,
           "--out", out, "--quiet", *ARGS]
    if popen:
        return subprocess.Popen(cmd, cwd=ROOT, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)
    return subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)


def by_id(out):
    with open(os.path.join(out, "members.csv")) as fh:
        return {int(r["id"]): {k: v for k, v in r.items() if k not in TIMING} for r in csv.DictReader(fh)}


def ids(out):
    with open(os.path.join(out, "members.csv")) as fh:
        return [int(r["id"]) for r in csv.DictReader(fh)]


def test_mpi_matches_jobs1_and_resumes():
    ref = os.path.join(TMP, "jobs1")
    p = subprocess.run([SWIM, "sweep", EX1, "--out", ref, "--quiet", "--jobs", "1", *ARGS], cwd=ROOT,
                       capture_output=True, text=True)
    check(p.returncode == 1, "reference sweep: exit 1 (7 members fail: gamma = 0.8 leaves D)")
    r1 = by_id(ref)
    check(len(r1) == 14 and sum(r["status"] == "failed" for r in r1.values()) == 6,
          "reference: 14 rows, 6 failed (bm2' = 0 stays in D)")

    out = os.path.join(TMP, "mpi3")
    p = mpirun(out)
    check(p.returncode == 1 and "14 members, 8 completed, 6 failed" in p.stdout,
          "mpirun -np 3: 14 members, 8 completed, 6 failed (%r %r)" % (p.stdout, p.stderr[-300:]))
    check(by_id(out) == r1, "MPI with 3 ranks: the same numbers as --jobs 1 in every column but timings")

    out = os.path.join(TMP, "mpi3-exec")
    p = mpirun(out, env=dict(ENV, SWIM_MPI_EXEC="1"))
    check(p.returncode == 1 and by_id(out) == r1, "SWIM_MPI_EXEC=1 (members exec bin/swim): the same numbers")

    # kill every process of the sweep (mpirun, ranks, members) mid-sweep, then resume
    out = os.path.join(TMP, "mpi-resume")
    proc = mpirun(out, popen=True)
    path = os.path.join(out, "members.csv")
    for _ in range(600):
        time.sleep(0.02)
        if os.path.exists(path) and sum(1 for _ in open(path)) >= 4:
            break
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    before = len(ids(out)) if os.path.exists(path) else 0
    time.sleep(0.3)
    p = mpirun(out)
    got = ids(out)
    check(sorted(got) == list(range(14)), "MPI resume after SIGKILL (%d rows then): 14 rows, none lost or "
          "duplicated (%s)" % (before, sorted(got)))
    check(0 < before < 14, "the kill came mid-sweep (%d of 14 rows)" % before)
    check(by_id(out) == r1, "the resumed MPI sweep has the numbers of --jobs 1")


if not os.path.exists(MPI_BIN) and os.environ.get("SWIM_MPI") != "1":
    print("test_sweep_mpi: skipped, %s not built (make mpi)" % MPI_BIN)
    print("test_sweep_mpi: 0 passed, 0 failed")
    sys.exit(0)
sys.exit(swimtest.main(globals(), "test_sweep_mpi"))
