#!/usr/bin/env python3
"""Can a user believe "completed, exit 0"? End-to-end checks of `swim run` and `swim inspect`
under the ways a careless or unlucky user breaks things: full disks, output folders removed
mid-run, outputs named twice, signals from a batch scheduler, absurd tolerances and values,
hostile text in scenes, huge files. One test per situation; each reproduces it and asserts the
behaviour: an output that could not be written is exit status 1 and named; bad input is exit
status 2 and one line naming the key or option.

Full disks are made two ways: a small tmpfs (`mount -t tmpfs`, needs root; the tests say
"skipped" when mount is not allowed and count nothing) and RLIMIT_FSIZE with SIGXFSZ ignored
(works everywhere: writes past the limit fail with EFBIG).
Prints "test_trust: P passed, F failed".
"""

import contextlib
import json
import os
import resource
import signal
import subprocess
import sys
import time

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main, one_line, scene, swim

BASE = open(os.path.join(ROOT, "models", "example3.toml")).read()
FORCING = '\n[forcing]\nlaw = "%s"\ndirection = [0,0,1,0,0,1,0,0,0,0,0,0,0,0,0,0]\n'





def read_summary(out):
    path = os.path.join(out, "summary.json")
    if not os.path.exists(path):
        return None
    with open(path) as fh:
        return json.load(fh)


@contextlib.contextmanager
def tmpfs(kb):
    """A tmpfs of `kb` kilobytes, or None when this machine does not allow mount."""
    mnt = os.path.join(TMP, "tmpfs%d" % kb)
    os.makedirs(mnt, exist_ok=True)
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=%dk" % kb, "tmpfs", mnt], capture_output=True)
    if p.returncode != 0:
        print("skipped: mount -t tmpfs not allowed here (%s)" % p.stderr.decode().strip())
        yield None
        return
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", mnt])


def file_size_limit(nbytes):
    """preexec_fn: files may not grow past nbytes (EFBIG instead of SIGXFSZ)."""
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return limit


def whole_rows(path, summary):
    """The CSV ends with a whole row and holds exactly the rows the summary counts."""
    with open(path, "rb") as fh:
        data = fh.read()
    lines = data.split(b"\n")
    ncol = len(lines[0].split(b","))
    return data.endswith(b"\n") and all(len(l.split(b",")) == ncol for l in lines[1:-1]) and \
        len(lines) - 2 == summary["rows"]


# ---- 2. write errors -------------------------------------------------------------------------

def test_disk_full_at_the_end():
    """Room for trajectory.csv but not for snapshots.json (~1 MB): failed, exit 1, names it."""
    with tmpfs(256) as mnt:
        if mnt is None:
            return
        out = os.path.join(mnt, "end")
        p = swim("run", "models/example3.toml", "--out", out, "--t-end", "2", "--quiet", "--snapshots")
        s = read_summary(out)
        check(p.returncode == 1, "disk full at the end (tmpfs): exit %d, want 1" % p.returncode)
        check(s is not None and s["status"] == "failed" and "snapshots.json" in s["reason"]
              and "No space left" in s["reason"], "disk full at the end: summary says %r" % (s and s["reason"]))
        check("completed" not in p.stdout, "disk full at the end: stdout says completed: " + p.stdout)
        check(not os.path.exists(os.path.join(out, "snapshots.json")), "a partial snapshots.json was left")


def test_disk_full_mid_run_tmpfs():
    """The disk fills during the run: no room for the summary either. stderr names summary.json
    and the CSV error; no empty or partial summary.json; the CSV ends with a whole row."""
    with tmpfs(64) as mnt:
        if mnt is None:
            return
        out = os.path.join(mnt, "mid")
        p = swim("run", "models/example3.toml", "--out", out, "--quiet")
        check(p.returncode == 1, "disk full mid-run (tmpfs): exit %d, want 1" % p.returncode)
        check("summary.json" in p.stderr and "No space left" in p.stderr and "trajectory.csv" in p.stderr,
              "disk full mid-run: stderr should name summary.json and trajectory.csv: " + p.stderr)
        check(not os.path.exists(os.path.join(out, "summary.json")), "an empty or partial summary.json was left")
        with open(os.path.join(out, "trajectory.csv"), "rb") as fh:
            data = fh.read()
        check(data.endswith(b"\n") and len(set(len(l.split(b",")) for l in data.split(b"\n")[:-1])) == 1,
              "disk full mid-run: trajectory.csv does not end with a whole row")


def test_file_size_limit_mid_run():
    """RLIMIT_FSIZE (EFBIG) cuts trajectory.csv at 64 kB: the summary (small) is written and says
    which file failed and why; exit 1; the rows it counts are all in the CSV."""
    out = os.path.join(TMP, "fsize")
    p = swim("run", "models/example3.toml", "--out", out, "--quiet", preexec_fn=file_size_limit(65536))
    s = read_summary(out)
    check(p.returncode == 1, "file size limit: exit %d, want 1" % p.returncode)
    check(s is not None and s["status"] == "failed" and "trajectory.csv" in s["reason"] and "too large" in s["reason"],
          "file size limit: summary reason %r" % (s and s["reason"]))
    check(s is not None and whole_rows(os.path.join(out, "trajectory.csv"), s), "file size limit: rows lost or cut")


def test_trace_steps_on_full_disk():
    """A --trace-steps file that cannot grow: the run fails naming the trace, not silently cut."""
    trace = os.path.join(TMP, "trace_full.csv")
    out = os.path.join(TMP, "trace_full")
    # the limit is per file: the trace (one row per step) outgrows it long before the CSV does
    p = swim("run", "models/example3.toml", "--out", out, "--t-end", "3", "--quiet", "--trace-steps", trace,
             preexec_fn=file_size_limit(20000))
    s = read_summary(out)
    check(p.returncode == 1 and s is not None and trace in s["reason"],
          "trace on a full disk: exit %d, reason %r" % (p.returncode, s and s["reason"]))
    with tmpfs(16) as mnt:
        if mnt is None:
            return
        trace = os.path.join(mnt, "trace.csv")
        p = swim("run", "models/example3.toml", "--out", out, "--t-end", "3", "--quiet", "--trace-steps", trace)
        s = read_summary(out)
        check(p.returncode == 1 and s is not None and trace in s["reason"] and "No space left" in s["reason"],
              "trace on a full tmpfs: exit %d, reason %r" % (p.returncode, s and s["reason"]))


def test_output_folder_removed_mid_run():
    """The folder is removed while the run is stopped (SIGSTOP), so the run cannot finish first."""
    out = os.path.join(TMP, "removed")
    proc = subprocess.Popen([SWIM, "run", "models/example4.toml", "--out", out, "--t-end", "300", "--quiet"],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for _ in range(3000):   # wait for the first rows, then pull the folder away
        if os.path.exists(os.path.join(out, "trajectory.csv")) and os.path.getsize(os.path.join(out, "trajectory.csv")) > 1000:
            break
        time.sleep(0.01)
    proc.send_signal(signal.SIGSTOP)
    subprocess.run(["rm", "-rf", out])
    proc.send_signal(signal.SIGCONT)
    stdout, stderr = proc.communicate(timeout=120)
    check(proc.returncode == 1, "output folder removed: exit %d, want 1" % proc.returncode)
    check("summary.json" in stderr and "removed" in stderr and "trajectory.csv" in stderr,
          "output folder removed: stderr should say so: " + stderr)
    check("completed" not in stdout, "output folder removed: stdout says completed: " + stdout)


# ---- 3. outputs named twice --------------------------------------------------------------------

def test_trace_steps_is_an_output():
    out = os.path.join(TMP, "twice")
    p = swim("run", "models/example3.toml", "--out", out, "--t-end", "0.5", "--quiet")
    before = open(os.path.join(out, "trajectory.csv")).read()
    os.symlink(os.path.join(out, "summary.json"), os.path.join(TMP, "link_to_summary"))
    for trace in (os.path.join(out, "trajectory.csv"), os.path.join(out, "..", "twice", "./trajectory.csv"),
                  os.path.join(TMP, "link_to_summary"), os.path.join(out, "snapshots.json")):
        p = swim("run", "models/example3.toml", "--out", out, "--t-end", "0.5", "--quiet", "--trace-steps", trace)
        check(p.returncode == 2 and one_line(p) and "--trace-steps" in p.stderr and "own" in p.stderr,
              "--trace-steps %s: want exit 2 naming it, got %d %r" % (trace, p.returncode, p.stderr))
    check(open(os.path.join(out, "trajectory.csv")).read() == before, "a refused run touched trajectory.csv")
    copy = scene("trace_scene", BASE)
    p = swim("run", copy, "--out", out, "--quiet", "--trace-steps", copy)
    check(p.returncode == 2 and "scene file" in p.stderr and open(copy).read() == BASE,
          "--trace-steps SCENE: want exit 2 and the scene intact: %r" % p.stderr)


# ---- 4. long forcing laws ------------------------------------------------------------------------

def test_long_forcing_law():
    """A law of 620 characters is simulated whole (it used to be cut at 511)."""
    long_law = "sin(t)" + " " * 600 + "+ 100*t"
    finals = {}
    for name, law in (("long", long_law), ("same", "sin(t) + 100*t"), ("cut", "sin(t)")):
        path = scene("law_" + name, BASE + FORCING % law)
        p, d, s = swimtest.run(path, "law_" + name, "--t-end", "1")
        check(p.returncode == 0, "law %s: exit %d %s" % (name, p.returncode, p.stderr))
        finals[name] = s["final_state"]["c"] if s else None
    check(finals["long"] == finals["same"], "the 620-character law is not the law written")
    check(finals["long"] != finals["cut"], "the 620-character law was cut")


# ---- 5. signals ------------------------------------------------------------------------------------

def test_sigterm_sighup():
    for sig, name in ((signal.SIGTERM, "SIGTERM"), (signal.SIGHUP, "SIGHUP")):
        out = os.path.join(TMP, "sig_" + name)
        proc = subprocess.Popen([SWIM, "run", "models/example4.toml", "--out", out, "--t-end", "100000",
                                 "--quiet", "--snapshots"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        swimtest.wait_rows(proc, out)
        proc.send_signal(sig)
        proc.wait(timeout=30)
        s = read_summary(out)
        check(proc.returncode == 1, "%s: exit status %d, want 1" % (name, proc.returncode))
        check(s is not None and s["status"] == "failed" and ("terminated by %s at t = " % name) in s["reason"],
              "%s: summary %r" % (name, s and s["reason"]))
        try:
            with open(os.path.join(out, "snapshots.json")) as fh:
                snaps = json.load(fh)
            check(len(snaps) >= 1, "%s: no snapshot" % name)
        except (OSError, ValueError) as exc:
            check(False, "%s: snapshots.json invalid: %r" % (name, exc))
        d = np.genfromtxt(os.path.join(out, "trajectory.csv"), delimiter=",", names=True)
        check(s is not None and len(d) == s["rows"] and abs(d["t"][-1] - s["t_reached"]) < 1e-9,
              "%s: rows kept and counted" % name)


# ---- 6. row cap and tolerances, one check for scene and command line -------------------------------

def test_run_settings_bounds():
    for args, option in [(["--t-end", "1e308"], "--t-end"), (["--t-end", "1e9"], "--t-end"),
                         (["--rtol", "10"], "--rtol"), (["--rtol", "1e-16"], "--rtol"),
                         (["--atol", "1"], "--atol"), (["--output-step", "1e-9"], "--output-step"),
                         (["--t-end", "1e6", "--output-step", "1e-3"], "--output-step")]:
        p = swim("run", "models/example3.toml", "--out", os.path.join(TMP, "bounds"), *args)
        check(p.returncode == 2 and one_line(p) and p.stderr.startswith("swim run: " + option + ":"),
              "%s: want exit 2 naming %s, got %d %r" % (args, option, p.returncode, p.stderr))
    for old, new, key in [("rtol = 1e-10", "rtol = 10", "run.rtol"), ("rtol = 1e-10", "rtol = 1e-17", "run.rtol"),
                          ("atol = 1e-12", "atol = 5", "run.atol"), ("t_end = 30.0", "t_end = 1e308", "run.output_step")]:
        path = scene("bounds_" + key, BASE.replace(old, new))
        p = swim("run", path, "--out", os.path.join(TMP, "bounds"))
        check(p.returncode == 2 and one_line(p) and (path + ":") in p.stderr and key in p.stderr,
              "scene %s: want exit 2 naming %s, got %d %r" % (new, key, p.returncode, p.stderr))
    p = swim("run", "models/example3.toml", "--out", os.path.join(TMP, "bounds"), "--rtol", "0.1", "--t-end", "0.2",
             "--quiet")
    check(p.returncode == 0, "rtol 0.1 (the bound itself) should run: %r" % p.stderr)


# ---- 7. inspect ----------------------------------------------------------------------------------

def test_inspect_refuses_overflow():
    for args, option in [(["--shape", "1e200,0,0,0"], "--shape"), (["--shape", "1,0,0,0", "--rho0", "1e308"], "--rho0"),
                         (["--shape", "1,0,0,0", "--rhof", "1e300"], "--rhof"),
                         (["--shape", "1,0,0.1,0", "--velocity", "1e100,0,1e100,0"], "--velocity")]:
        p = swim("inspect", "--modes", "1", *args, "--full")
        check(p.returncode == 2 and one_line(p) and option in p.stderr and p.stdout == "",
              "inspect %s: want exit 2 naming %s, got %d %r" % (args, option, p.returncode, p.stderr))


# ---- 8. values that are not finite ------------------------------------------------------------------

def test_forcing_law_not_finite_at_t0():
    for law in ("1/t", "log(0*t)", "sqrt(-1)"):
        path = scene("law_t0", BASE + FORCING % law)
        p = swim("run", path, "--out", os.path.join(TMP, "law_t0"))
        check(p.returncode == 2 and one_line(p) and "forcing.law" in p.stderr and "t = 0" in p.stderr,
              "law %s: want exit 2 naming forcing.law, got %d %r" % (law, p.returncode, p.stderr))


def test_forcing_law_not_finite_later():
    """1/(t-1) is finite at t0 and infinite at t = 1: the run stops there, says so, keeps the rows."""
    path = scene("law_later", BASE + FORCING % "1/(t-1)")
    p, d, s = swimtest.run(path, "law_later", "--t-end", "3")
    check(p.returncode == 1 and s["status"] == "failed" and "forcing law" in s["reason"] and "t = 1" in s["reason"],
          "law 1/(t-1): exit %d, reason %r" % (p.returncode, s and s["reason"]))
    check(len(d) == s["rows"] and abs(d["t"][-1] - 0.95) < 1e-12, "law 1/(t-1): rows up to t = 0.95 kept")


def test_overflowing_values():
    for old, new, key in [("rho0 = 1.0", "rho0 = 1e308", "model.rho0"), ("rhof = 1.0", "rhof = 1e300", "model.rhof"),
                          ("c0  = [ 1, 0,", "c0  = [ 1e200, 0,", "shape.c0"),
                          ("dc0 = [ 0, 0, 0.6, 0,  0, -0.6,", "dc0 = [ 0, 0, 0.6e200, 0,  0, -0.6e200,", "shape.dc0")]:
        text = BASE.replace(old, new)
        check(text != BASE, "overflow %s: replacement did not apply" % key)
        path = scene("overflow", text)
        p = swim("run", path, "--out", os.path.join(TMP, "overflow"))
        check(p.returncode == 2 and one_line(p) and key in p.stderr,
              "%s: want exit 2 naming %s, got %d %r" % (new, key, p.returncode, p.stderr))


# ---- 9. long paths -----------------------------------------------------------------------------------

def test_long_paths():
    deep = os.path.join(TMP, *(["d" * 100] * 10))   # over 1000 characters
    out = os.path.join(deep, "out")
    p, d, s = swimtest.run("models/example3.toml", os.path.relpath(out, TMP), "--t-end", "0.1")
    check(p.returncode == 0 and os.path.exists(os.path.join(out, "summary.json")) and s["out"] == out,
          "--out of %d characters: exit %d, out %r" % (len(out), p.returncode, s and s["out"]))
    os.makedirs(deep, exist_ok=True)
    long_scene = os.path.join(deep, "s" * 200 + ".toml")
    with open(long_scene, "w") as fh:
        fh.write(BASE)
    p = subprocess.run([SWIM, "run", long_scene, "--t-end", "0.1", "--quiet"], capture_output=True, text=True, cwd=TMP)
    default = os.path.join(TMP, "out", "s" * 200)
    s = read_summary(default)
    check(p.returncode == 0 and s is not None and s["scene"] == long_scene,
          "scene path of %d characters: default output %s (exit %d %r)" % (len(long_scene), default, p.returncode, p.stderr))


# ---- 10. hostile text, BOM, folders, huge files ------------------------------------------------------

def test_messages_quote_user_text():
    text = BASE.replace("atol = 1e-12", 'atol = 1e-12\nintegrator = "eu\\u001b[2J\\nler\\u009b"')
    path = scene("escape", text)
    p = swim("run", path, "--out", os.path.join(TMP, "escape"))
    check(p.returncode == 2 and one_line(p) and "\x1b" not in p.stderr and "\x9b" not in p.stderr
          and "\\x1b[2J\\nler\\u009b" in p.stderr, "escape sequences in a value: %r" % p.stderr)
    weird = os.path.join(TMP, "we\nird\x1b[2J.toml")
    with open(weird, "w") as fh:
        fh.write(BASE.replace("modes = 7", "modes = 99"))
    p = swim("run", weird, "--out", os.path.join(TMP, "escape"))
    check(p.returncode == 2 and one_line(p) and "\x1b" not in p.stderr and "we\\nird\\x1b[2J.toml" in p.stderr,
          "escape sequences in a file name: %r" % p.stderr)
    p = swim("inspect", "--modes", "1", "--shape", "1,0,\x1b[2J,0")
    check(p.returncode == 2 and one_line(p) and "\x1b" not in p.stderr, "escape in an option value: %r" % p.stderr)
    path = scene("title_escape", 'title = "a\\u001b[2Jb"\n' + "\n".join(l for l in BASE.splitlines()
                                                                        if not l.startswith("title")))
    p, d, s = swimtest.run(path, "title_escape", "--t-end", "0.1")
    check(p.returncode == 0 and "\x1b" not in p.stdout + p.stderr and s["title"] == "a\x1b[2Jb",
          "title with an escape: terminal clean, summary keeps the title: %r" % (p.stdout + p.stderr))


def test_summary_of_a_non_utf8_file_name():
    """File names are bytes: summary.json must still be UTF-8 JSON (the byte becomes U+FFFD)."""
    path = os.path.join(TMP.encode(), b"latin\xe9.toml")
    with open(path, "w") as fh:
        fh.write(BASE)
    out = os.path.join(TMP, "latin")
    p = subprocess.run([SWIM.encode(), b"run", path, b"--out", out.encode(), b"--t-end", b"0.1"],
                       capture_output=True, cwd=ROOT)   # the report on stdout is checked below
    try:
        s = read_summary(out)
        check(p.returncode == 0 and s["scene"].endswith("latin\ufffd.toml"), "non-UTF-8 name: %r" % (s and s["scene"]))
    except ValueError as exc:
        check(False, "non-UTF-8 name: summary.json is not UTF-8 JSON: %r" % exc)
    check(b"latin\\xe9.toml" in p.stdout, "non-UTF-8 name: the report shows the byte escaped: %r" % p.stdout)


def test_bom_directory_huge_file():
    path = os.path.join(TMP, "bom.toml")
    with open(path, "wb") as fh:
        fh.write(b"\xef\xbb\xbf" + BASE.encode())
    p, d, s = swimtest.run(path, "bom", "--t-end", "0.1")
    check(p.returncode == 0 and s["status"] == "completed", "UTF-8 BOM: exit %d %r" % (p.returncode, p.stderr))
    p = swim("run", "models", "--out", os.path.join(TMP, "dir"))
    check(p.returncode == 2 and one_line(p) and "is a directory" in p.stderr, "a directory as scene: %r" % p.stderr)
    huge = os.path.join(TMP, "huge.toml")
    with open(huge, "w") as fh:
        fh.write(BASE + "\n[damping]\ndiagonal = [" + "0," * 8000000 + "0]\n")
    def max_rss_kb(scene_path):
        proc = subprocess.Popen([SWIM, "run", scene_path, "--out", os.path.join(TMP, "huge")],
                                stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
        err = proc.stderr.read()
        proc.stderr.close()
        _, status, usage = os.wait4(proc.pid, 0)
        return os.waitstatus_to_exitcode(status), err, usage.ru_maxrss

    # Linux counts the spawning process's own pages in a child's maxrss: compare with a run
    # spawned the same way that reads nothing.
    _, _, baseline = max_rss_kb(os.path.join(TMP, "no_such_scene.toml"))
    rc, err, rss = max_rss_kb(huge)
    check(rc == 2 and "too large" in err and len(err.strip().splitlines()) == 1, "16 MB scene: %r" % err)
    check(rss < baseline + 20000, "16 MB scene: %d kB of memory before the refusal (baseline %d kB)" % (rss, baseline))

def test_bad_output_paths_before_any_kernel():
    """An output that cannot be created is refused before a kernel is generated (which can take
    a minute): one line, exit 2, and nothing in an empty kernel cache."""
    for args, what in ((["--trace-steps", "/nonexistent/steps.csv"], "--trace-steps"),
                       (["--out", "models/example3.toml/run"], "--out")):
        cache = os.path.join(TMP, "empty-cache-" + what.strip("-"))
        os.makedirs(cache, exist_ok=True)
        env = dict(os.environ, SWIM_CACHE=cache)
        out = [] if what == "--out" else ["--out", os.path.join(TMP, "preflight")]
        p = subprocess.run([SWIM, "run", "models/example3.toml", *out, *args], capture_output=True,
                           text=True, cwd=ROOT, env=env)
        check(p.returncode == 2 and one_line(p) and what in p.stderr,
              "%s: exit %d, stderr %r" % (what, p.returncode, p.stderr))
        check(os.listdir(cache) == [], "%s: a kernel was built before the refusal: %s" % (what, os.listdir(cache)))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust"))
