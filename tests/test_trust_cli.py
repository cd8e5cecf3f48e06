#!/usr/bin/env python3
"""The command-line surfaces under bad input and faults (docs/trust.md, "Command-line bounds").

1. Bounds: every numeric option has a row in one table (scene/keys.c); --lyapunov-interval 1e-9
   and 1e-300 (10^10 and more renormalizations), swim periodic/floquet --t-max 1e300, and a value
   out of each row's bounds are refused in one line, exit 2, nothing written.
2. swim continue --param KEY=A:B and swim optimize --vary KEY=LO:HI: an end the scene refuses
   (rhof = 0, a negative stiffness) is refused before any work, naming the option given.
3. Messages name only options the user gave (continue/optimize keys, continue's remedy).
4. swim periodic/continue --out: a file, a folder where periodic.json goes: refused before the
   Newton work; nothing named as written that was not.
5. Stop signals: SIGTERM during a run carrying the Lyapunov vector and SIGINT during one carrying
   sensitivities fail the run naming the signal (the status of a stopped run), the rows computed
   kept; swim optimize
   keeps best.toml and optimize.json on SIGHUP; swim sweep stops on SIGHUP keeping its rows. Each
   signal is sent after a progress marker (a file's content), never after a sleep.
6. swim sweep --format hdf5 when family.h5 cannot be written (a file-size limit: the disk is
   full for it): one line with the reason, exit 1, no crash at exit, no family.h5. Stopped with
   --format hdf5 and resumed without it: family.h5 lists every member of members.csv.
7. swim export with no usable kernel cache writes nothing of the tree; a tree left partial (a
   file-size limit) does not block the retry. swim cache list > /dev/full: one line with the true
   reason.
Prints "test_trust_cli: P passed, F failed".
"""

import csv
import json
import os
import resource
import signal
import subprocess
import sys
import time

import h5py

from swimtest import ROOT, SWIM, TMP, check, main, wait_rows

EX1 = "models/example1.toml"
EX3 = "models/example3.toml"
SELF = "models/selfpropelled.toml"


def swim(*args, **kw):
    return subprocess.run([SWIM, *args], capture_output=True, text=True, cwd=ROOT, **kw)


def refused(args, want, out=None):
    """exit 2, one line on stderr containing want, nothing at out."""
    p = swim(*args)
    lines = [l for l in p.stderr.splitlines() if l.strip()]
    check(p.returncode == 2 and len(lines) == 1 and want in lines[0],
          "%s: exit 2, one line with %r (%d %r)" % (" ".join(args), want, p.returncode, p.stderr))
    if out:
        check(not os.path.exists(out), "%s: nothing written" % " ".join(args))
    return p


def wait_for(pred, proc, limit=600):
    """Polls pred() until it holds or proc ends (a progress marker, however loaded the machine)."""
    t0 = time.time()
    while time.time() - t0 < limit:
        if pred():
            return True
        if proc.poll() is not None:
            return pred()
        time.sleep(0.02)
    return False


def test_bounds():
    out = os.path.join(TMP, "bounds")
    refused(["run", EX3, "--out", out, "--lyapunov", "--lyapunov-interval", "1e-9"], "more than 1000000", out)
    refused(["run", EX3, "--out", out, "--lyapunov", "--lyapunov-interval", "1e-300"], "--lyapunov-interval", out)
    refused(["run", EX3, "--out", out, "--lyapunov", "--lyapunov-interval", "0"], "must be a number > 0", out)
    refused(["periodic", EX3, "--out", out, "--t-max", "1e300"], "--t-max: must be > 0 and below 1e6", out)
    refused(["floquet", EX3, "--out", out, "--t-max", "1e300"], "--t-max: must be > 0 and below 1e6", out)
    refused(["floquet", EX3, "--out", out, "--t-max", "9e5"], "more than 1e+07", out)
    refused(["periodic", EX3, "--out", out, "--tol", "1"], "--tol: must be in (0, 1)", out)
    refused(["periodic", EX3, "--out", out, "--max-iter", "41"], "out of range 1..40", out)
    refused(["continue", EX1, "--out", out, "--param", "energy=0.1:0.3", "--max-points", "1001"],
            "out of range 2..1000", out)
    refused(["continue", EX1, "--out", out, "--param", "energy=0.1:0.3", "--tol", "-1"], "--tol", out)
    refused(["optimize", SELF, "--out", out, "--vary", "parameters.A=1:2", "--maximize", "x", "--starts", "65"],
            "out of range 1..64", out)
    refused(["optimize", SELF, "--out", out, "--vary", "parameters.A=1:2", "--maximize", "x", "--tol", "0"],
            "--tol: must be in (0, 1)", out)
    refused(["sweep", EX3, "--out", out, "--vary", "model.rho0=1,2", "--jobs", "0"], "out of range 1..4096", out)
    refused(["sweep", EX3, "--out", out, "--vary", "model.rho0=1,2", "--progress", "1e300"], "--progress", out)
    refused(["inspect", "--modes", "1", "--shape", "0,0,0,0", "--rhof", "0"], "--rhof: the fluid's density must be > 0")
    refused(["cache", "clean", "--older-than", "1e300"], "--older-than: must be")


def test_ranges_validated_as_a_scene():
    out = os.path.join(TMP, "ranges")
    refused(["continue", EX1, "--out", out, "--param", "model.rhof=0:2"], "--param model.rhof=0:2", out)
    p = refused(["continue", EX3, "--out", out, "--param", "elastic.stiffness.am1=1:-1"], "R must be >= 0", out)
    check("--set" not in p.stderr, "the message names --param, not --set: %r" % p.stderr)
    refused(["continue", EX1, "--out", out, "--param", "energy=0.1:inf"], "finite numbers", out)
    refused(["optimize", SELF, "--out", out, "--vary", "model.rho0=-1:2", "--maximize", "x"],
            "--vary model.rho0=-1:2", out)


def test_messages_name_the_options_given():
    out = os.path.join(TMP, "messages")
    p = swim("continue", EX1, "--out", out, "--param", "model.foo=1:2")
    check(p.returncode == 2 and "--param" in p.stderr and "--sensitivity" not in p.stderr,
          "continue --param model.foo: names --param only (%r)" % p.stderr)
    p = swim("optimize", SELF, "--out", out, "--vary", "parameters.foo=1:2", "--maximize", "x", "--method", "bfgs")
    check(p.returncode == 2 and "--vary" in p.stderr and "--sensitivity" not in p.stderr and "--set" not in p.stderr,
          "optimize --method bfgs --vary parameters.foo: names --vary only (%r)" % p.stderr)
    p = swim("continue", EX3, "--out", out, "--param", "energy=0.9:1", "--max-points", "2", "--set", "run.t_end=1",
             "--quiet")
    check(p.returncode != 0 and "--t-max" not in p.stderr and "swim periodic" not in p.stderr
          and "run.t_end" in p.stderr, "continue without a period: names run.t_end, not periodic's --t-max (%r)"
          % p.stderr)


def test_out_checked_first():
    f = os.path.join(TMP, "a_file")
    open(f, "w").close()
    t0 = time.time()
    refused(["periodic", EX3, "--out", f], "is not a folder")
    refused(["periodic", EX3, "--out", os.path.join(f, "sub")], "Not a directory")
    refused(["continue", EX1, "--out", f, "--param", "energy=0.1:0.3"], "is not a folder")
    d = os.path.join(TMP, "json_is_a_folder")
    os.makedirs(os.path.join(d, "periodic.json"))
    refused(["periodic", EX3, "--out", d], "periodic.json is a folder")
    os.makedirs(os.path.join(TMP, "branch_folder", "branch.json"))
    refused(["continue", EX1, "--out", os.path.join(TMP, "branch_folder"), "--param", "energy=0.1:0.3"],
            "branch.json is a folder")
    # a folder made for the command that is not there yet: fine, and made only when written
    p = swim("periodic", EX3, "--out", os.path.join(TMP, "new", "deeper"), "--quiet")
    check(p.returncode == 0 and os.path.isfile(os.path.join(TMP, "new", "deeper", "periodic.json")),
          "periodic into a new folder: written (%s)" % p.stderr)


def signal_once_integrating(args, out, sig):
    """swim ARGS, the signal sent once trajectory.csv has rows (the run integrates, its handlers are
    installed); (proc, stdout, stderr, sent)."""
    proc = subprocess.Popen([SWIM, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    sent = wait_rows(proc, out, rows=2) and proc.poll() is None
    if sent:
        proc.send_signal(sig)
    so, se = proc.communicate(timeout=600)
    return proc, so, se, sent


def test_signal_while_carrying_lyapunov():
    # the tangent vector rides on the run's integration: a signal stops both; 10^6 intervals keep
    # the run going long after its first rows
    out = os.path.join(TMP, "lyap_sig")
    proc, so, se, sent = signal_once_integrating(["run", EX3, "--out", out, "--t-end", "3", "--lyapunov",
                                                  "--lyapunov-interval", "3e-6"], out, signal.SIGTERM)
    check(sent, "the run was integrating when SIGTERM came (%r)" % se[-200:])
    s = json.load(open(os.path.join(out, "summary.json")))
    check(proc.returncode == 1, "exit 1 after SIGTERM with --lyapunov, not 0 (%d)" % proc.returncode)
    check(s["status"] == "failed" and s["reason"].startswith("terminated by SIGTERM"),
          "the summary names the signal as a stopped run's: %r" % s["reason"])
    check("FAILED (terminated by SIGTERM" in so and "completed" not in so.split("\n")[0],
          "the report says FAILED and names the signal: %r" % so[:300])
    lyap = os.path.join(out, "lyapunov.csv")
    rows = list(csv.reader(open(lyap)))[1:] if os.path.exists(lyap) else None
    check(s["lyapunov"]["status"] == "interrupted" and rows is not None and len(rows) >= 1
          and float(rows[-1][0]) == s["lyapunov"]["t_end"] and "%d intervals" % len(rows) in s["lyapunov"]["reason"],
          "lyapunov.csv keeps the intervals done, up to the last row, as the entry says (%r)" % s["lyapunov"])


def test_signal_while_carrying_sensitivities():
    out = os.path.join(TMP, "sens_sig")
    proc, so, se, sent = signal_once_integrating(["run", EX3, "--out", out, "--t-end", "400", "--sensitivity",
                                                  "model.rho0"], out, signal.SIGINT)
    check(sent, "the run was integrating when SIGINT came (%r)" % se[-200:])
    s = json.load(open(os.path.join(out, "summary.json")))
    check(proc.returncode == 1 and s["reason"].startswith("interrupted (SIGINT)"),
          "SIGINT with --sensitivity: exit 1, named (%d, %r)" % (proc.returncode, s["reason"]))
    path = os.path.join(out, "sensitivity.csv")
    rows = sum(1 for _ in open(path)) - 1 if os.path.exists(path) else -1
    check(rows >= 1 and s["sensitivity"]["status"] == "interrupted" and s["sensitivity"]["rows"] == rows,
          "the sensitivity rows computed are kept and counted (%d, %r)" % (rows, s["sensitivity"]))


def test_optimize_keeps_results_on_sighup():
    out = os.path.join(TMP, "opt_hup")
    log = os.path.join(out, "optimize.csv")
    proc = subprocess.Popen([SWIM, "optimize", "models/control/selfpropelled_params.toml", "--out", out, "--vary",
                             "parameters.A=0.5:4", "--vary", "parameters.w=0.1:1", "--maximize",
                             "displacement_per_work", "--max-iter", "100000", "--tol", "1e-12", "--quiet",
                             "--set", "run.t_end=10"],   # short runs: the search logs within a second
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    ok = wait_for(lambda: os.path.exists(log) and sum(1 for _ in open(log)) >= 3, proc)
    proc.send_signal(signal.SIGHUP)
    so, se = proc.communicate(timeout=600)
    check(ok, "the search logged runs before the signal (%r)" % se)
    check(proc.returncode == 1 and "INTERRUPTED (SIGHUP)" in so,
          "SIGHUP: named, the best so far reported, exit 1 (%d, %r, %r)" % (proc.returncode, so[-300:], se[-300:]))
    check(os.path.isfile(os.path.join(out, "best.toml")) and os.path.isfile(os.path.join(out, "optimize.json")),
          "best.toml and optimize.json kept on SIGHUP")


def test_sweep_stops_on_sighup():
    out = os.path.join(TMP, "sweep_hup")
    rows = os.path.join(out, "members.csv")
    proc = subprocess.Popen([SWIM, "sweep", EX3, "--out", out, "--vary", "run.t_end=0.5,400000", "--jobs", "1",
                             "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    ok = wait_for(lambda: os.path.exists(rows) and sum(1 for _ in open(rows)) >= 2, proc)
    proc.send_signal(signal.SIGHUP)
    so, se = proc.communicate(timeout=600)
    check(ok, "one member finished before the signal (%r)" % se)
    check(proc.returncode == 1 and "stopped by SIGHUP" in se and sum(1 for _ in open(rows)) == 2,
          "SIGHUP: the sweep stops, names it, keeps its row (%d, %r)" % (proc.returncode, se))


def limit_file_size():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)   # a write past the limit fails with EFBIG
    resource.setrlimit(resource.RLIMIT_FSIZE, (60 * 1024, 60 * 1024))


def test_family_h5_cannot_be_written():
    out = os.path.join(TMP, "h5_full")
    p = subprocess.run([SWIM, "sweep", EX3, "--out", out, "--vary", "model.rho0=1,2.5", "--vary", "run.t_end=3,6",
                        "--keep", "trajectories", "--format", "hdf5", "--jobs", "1", "--quiet"],
                       capture_output=True, text=True, cwd=ROOT, preexec_fn=limit_file_size)
    check(p.returncode == 1, "family.h5 over the limit: exit 1, no crash (%d: %r)" % (p.returncode, p.stderr))
    check("cannot write" in p.stderr and "family.h5" in p.stderr and "File too large" in p.stderr,
          "the failure and its reason said: %r" % p.stderr)
    check(not os.path.exists(os.path.join(out, "family.h5")) and
          not os.path.exists(os.path.join(out, "family.h5.tmp")), "no family.h5 left")


def test_family_h5_after_resume_without_format():
    out = os.path.join(TMP, "h5_resume")
    rows = os.path.join(out, "members.csv")
    args = ["sweep", EX3, "--out", out, "--vary", "run.t_end=0.5,0.6,5000", "--jobs", "1", "--quiet"]
    proc = subprocess.Popen([SWIM, *args, "--format", "hdf5"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=ROOT)
    ok = wait_for(lambda: os.path.exists(rows) and sum(1 for _ in open(rows)) >= 2, proc)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=600)
    check(ok and proc.returncode == 1, "the hdf5 sweep stopped early (%d)" % proc.returncode)
    with h5py.File(os.path.join(out, "family.h5"), "r") as f:
        before = len(f["members"]["id"])
    p = swim(*args)
    check(p.returncode == 0, "resumed without --format: completed (%r)" % p.stderr)
    with open(rows) as fh:
        n = len(list(csv.DictReader(fh)))
    with h5py.File(os.path.join(out, "family.h5"), "r") as f:
        got = len(f["members"]["id"])
    check(before < 3 and got == n == 3, "family.h5 rewritten with every member (%d before, %d now, %d rows)"
          % (before, got, n))


def test_export_checks_cache_first_and_retries():
    bad = os.path.join(TMP, "open_cache")
    os.makedirs(bad)
    os.chmod(bad, 0o777)   # writable by every user: not used as a cache (a private folder instead)
    out = os.path.join(TMP, "export_tree")
    p = swim("export", EX3, "--out", out, "--quiet", env=dict(os.environ, SWIM_CACHE=bad))
    check(p.returncode == 1 and "the cache is not usable" in p.stderr, "export with no usable cache: exit 1, said (%r)"
          % p.stderr[-300:])
    check(not os.path.exists(out) or os.listdir(out) == [], "nothing of the tree written: %r"
          % (os.listdir(out) if os.path.exists(out) else None))
    # a tree left partial (a file-size limit: the disk full for it) does not block the retry
    def small_files():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (16 * 1024, 16 * 1024))
    p = subprocess.run([SWIM, "export", EX3, "--out", out, "--quiet"], capture_output=True, text=True, cwd=ROOT,
                       preexec_fn=small_files)
    check(p.returncode != 0 and "File too large" in p.stderr, "export over the limit fails with the reason (%r)"
          % p.stderr[-300:])
    p = swim("export", EX3, "--out", out, "--quiet")
    check(p.returncode == 0 and os.path.isfile(os.path.join(out, "simulate.c")),
          "the retry replaces the partial tree (%r)" % p.stderr[-300:])
    with open(os.path.join(out, ".swim-export")) as fh:
        check(fh.read() == "swim export\n", "the finished tree's marker says complete")


def test_cache_to_full_stdout():
    with open("/dev/full", "w") as full:
        p = subprocess.run([SWIM, "cache", "list"], stdout=full, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    lines = [l for l in p.stderr.splitlines() if l.strip()]
    check(p.returncode == 1 and len(lines) == 1 and "No space left on device" in lines[0],
          "swim cache list > /dev/full: one line with the reason (%r)" % p.stderr)


if __name__ == "__main__":
    sys.exit(main(dict(globals()), "test_trust_cli"))
