#!/usr/bin/env python3
"""A family of runs must be the family that was asked for: one value per key however it is
spelled, every member from the one validated scene text, one sweep per folder, every member
checked before any starts, write errors named, a bad command line said once under MPI.
Prints "test_trust_sweep: P passed, F failed"."""

import csv
import os
import resource
import shutil
import signal
import subprocess
import sys
import time

from swimtest import ROOT, SWIM, TMP, check, main

EX1 = os.path.join(ROOT, "models", "example1.toml")
EX3 = os.path.join(ROOT, "models", "example3.toml")
MPI_BIN = os.path.join(os.path.dirname(SWIM), "swim-mpi")


def swim(*args, **kw):
    return subprocess.run([SWIM, *args], capture_output=True, text=True, cwd=ROOT, **kw)


def one_line(p):
    return len(p.stderr.strip().splitlines()) == 1


def rows(out):
    with open(os.path.join(out, "members.csv")) as fh:
        return {int(r["id"]): r for r in csv.DictReader(fh)}


def test_two_spellings_of_one_key():
    out = os.path.join(TMP, "spell")
    p = swim("sweep", EX3, "--out", out, "--t-end", "1", "--vary", "shape.c0.am1=0.1,0.2", "--vary", "shape.c0[2]=0.3,0.4")
    check(p.returncode == 2 and one_line(p) and not os.path.exists(out),
          "sweep varying shape.c0.am1 and shape.c0[2]: exit %d %r" % (p.returncode, p.stderr))
    p = swim("sweep", EX3, "--out", out, "--t-end", "1", "--vary", "shape.c0.am1=0.1,0.2", "--set", "shape.c0[2]=0.3")
    check(p.returncode == 2 and one_line(p), "sweep varying and setting one value: exit %d %r" % (p.returncode, p.stderr))
    p = swim("optimize", EX3, "--out", os.path.join(TMP, "spell-opt"), "--set", "run.t_end=1", "--max-iter", "2",
             "--vary", "elastic.reference.am1=0.1:0.3", "--vary", "elastic.reference[2]=0.1:0.3", "--maximize", "y")
    check(p.returncode == 2 and one_line(p), "optimize over two spellings of one value: exit %d %r" % (p.returncode, p.stderr))


def test_members_are_checked_before_any_starts():
    out = os.path.join(TMP, "huge")
    p = swim("sweep", EX3, "--out", out, "--t-end", "1", "--vary", "model.rho0=1,1e308")
    check(p.returncode == 2 and one_line(p) and "model.rho0" in p.stderr and "1e+308" in p.stderr,
          "--vary model.rho0=1,1e308: exit %d %r" % (p.returncode, p.stderr))
    check(not os.path.exists(out), "--vary model.rho0=1,1e308: the sweep folder was made before the check")


def start_sweep(out, scene, members=6, t_end="3000", extra=()):
    values = ",".join("%.2f" % (-0.5 + 0.2 * i) for i in range(members))
    return subprocess.Popen([SWIM, "sweep", scene, "--out", out, "--quiet", "--jobs", "1", "--t-end", t_end,
                             "--vary", "shape.dc0.bm2=" + values, *extra], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_rows(out, n, timeout=60):
    path = os.path.join(out, "members.csv")
    deadline = time.time() + timeout
    while time.time() < deadline:
        if os.path.exists(path) and sum(1 for _ in open(path)) >= n + 1:
            return True
        time.sleep(0.02)
    return False


def test_scene_edited_during_the_sweep():
    scene = os.path.join(TMP, "edited.toml")
    shutil.copy(EX1, scene)
    ref = os.path.join(TMP, "edited-ref")
    p = start_sweep(ref, scene, t_end="400")
    p.communicate(timeout=300)
    out = os.path.join(TMP, "edited")
    p = start_sweep(out, scene, t_end="400")
    wait_rows(out, 1)
    text = open(EX1).read().replace("rho0 = 1.0", "rho0 = 3.0")
    check("rho0 = 3.0" in text, "the edit does not apply (example1.toml has no 'rho0 = 1.0')")
    with open(scene, "w") as fh:
        fh.write(text)
    p.communicate(timeout=300)
    a, b = rows(ref), rows(out)
    check(len(a) == 6 and len(b) == 6 and all(a[i]["y"] == b[i]["y"] for i in a),
          "members after the edit ran another scene: %r vs %r" % ([a[i]["y"] for i in a], [b[i]["y"] for i in b]))
    # a resume with the edited file is refused: it would mix two scenes in one family
    p = swim("sweep", scene, "--out", out, "--quiet", "--jobs", "1", "--t-end", "400",
             "--vary", "shape.dc0.bm2=" + ",".join("%.2f" % (-0.5 + 0.2 * i) for i in range(6)))
    check(p.returncode == 2 and one_line(p), "resume with an edited scene: exit %d %r" % (p.returncode, p.stderr))


def test_two_sweeps_into_one_folder():
    out = os.path.join(TMP, "twice")
    first = start_sweep(out, EX1)
    wait_rows(out, 0)
    time.sleep(0.3)
    p = swim("sweep", EX1, "--out", out, "--quiet", "--jobs", "1", "--t-end", "3000",
             "--vary", "shape.dc0.bm2=" + ",".join("%.2f" % (-0.5 + 0.2 * i) for i in range(6)))
    check(p.returncode == 2 and one_line(p) and str(first.pid) in p.stderr,
          "a second sweep into a busy folder: exit %d %r (first sweep pid %d)" % (p.returncode, p.stderr, first.pid))
    first.send_signal(signal.SIGINT)
    first.communicate(timeout=60)
    r = rows(out)
    check(all(v["status"] != "crashed" for v in r.values()), "members marked crashed: %r" % r)


def test_full_stdout():
    with open("/dev/full", "w") as full:
        p = subprocess.run([SWIM, "sweep", EX1, "--out", os.path.join(TMP, "devfull"), "--t-end", "1",
                            "--vary", "shape.dc0.bm2=-0.1,0.1"], stdout=full, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    check(p.returncode == 1 and "stdout" in p.stderr, "sweep > /dev/full: exit %d %r" % (p.returncode, p.stderr))


def test_write_error_named():
    """members.csv cannot grow (RLIMIT_FSIZE, EFBIG): the reason reaches stderr, exit 1."""
    out = os.path.join(TMP, "efbig")

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (3000, 3000))   # members.csv outgrows it
    p = subprocess.run([SWIM, "sweep", EX1, "--out", out, "--quiet", "--t-end", "1",
                        "--vary", "shape.dc0.bm2=-0.7:0.7:40"], capture_output=True, text=True, cwd=ROOT,
                       preexec_fn=limit)
    check(p.returncode == 1 and "too large" in p.stderr.lower(),
          "sweep whose files cannot grow: exit %d, stderr should name the error: %r" % (p.returncode, p.stderr[-400:]))
    check("completed" not in p.stdout, "sweep whose files cannot grow says completed: " + p.stdout)


def test_mpi_bad_option_said_once():
    if not (os.path.exists(MPI_BIN) and shutil.which("mpirun")):
        print("skipped: no bin/swim-mpi or mpirun")
        return
    env = dict(os.environ, OMPI_MCA_btl="self,vader", OMPI_MCA_plm_rsh_agent="", OMPI_MCA_rmaps_base_oversubscribe="1")
    p = subprocess.run(["mpirun", "--oversubscribe", "--allow-run-as-root", "-np", "3", MPI_BIN, "sweep", EX1,
                        "--out", os.path.join(TMP, "mpibad"), "--no-such-option"], capture_output=True, text=True,
                       cwd=ROOT, env=env, timeout=120)
    lines = [l for l in p.stderr.splitlines() if "no-such-option" in l]
    check(p.returncode != 0 and len(lines) == 1, "swim-mpi bad option: exit %d, said %d times: %r"
          % (p.returncode, len(lines), p.stderr[-400:]))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_sweep"))
