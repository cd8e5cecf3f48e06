"""Shared helpers of the Python end-to-end tests: run `swim run`, read what it wrote, count checks.

Each test module defines functions named test_* and ends with `sys.exit(swimtest.main(globals(),
"test_name"))`, which runs them and prints "test_name: P passed, F failed"."""

import json
import os
import subprocess
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
TMP = tempfile.mkdtemp(prefix="swim-test-")
counts = {"passed": 0, "failed": 0}


def check(cond, what):
    if cond:
        counts["passed"] += 1
    else:
        counts["failed"] += 1
        print("FAIL:", what)


def run(scene, name, *args, env=None):
    """Run `swim run SCENE --out TMP/name --quiet ARGS`; returns (process, rows, summary), the
    last two None when the file is missing or empty."""
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "run", scene, "--out", out, "--quiet", *args], capture_output=True,
                       text=True, cwd=ROOT, env=env)
    rows = None
    path = os.path.join(out, "trajectory.csv")
    if os.path.exists(path) and os.path.getsize(path) > 0:
        rows = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
    summary = None
    if os.path.exists(os.path.join(out, "summary.json")):
        with open(os.path.join(out, "summary.json")) as fh:
            summary = json.load(fh)
    return p, rows, summary


def scene(name, text, folder=None):
    """Writes `text` to FOLDER/name.toml (TMP by default); its path."""
    path = os.path.join(folder or TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


def swim(*args, **kw):
    """`swim ARGS` from the repository's root, output captured as text."""
    return subprocess.run([SWIM, *args], capture_output=True, text=True, cwd=ROOT, **kw)


def signal_at_marker(args, marker, sig):
    """Runs swim ARGS, sends sig once a line of stderr holds marker; (proc, stdout, stderr, seen)."""
    proc = subprocess.Popen([SWIM, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    seen, err = False, []
    for line in iter(proc.stderr.readline, ""):
        err.append(line)
        if marker in line:
            seen = True
            proc.send_signal(sig)
            break
    so, se = proc.communicate(timeout=600)
    return proc, so, "".join(err) + se, seen


def one_line(p):
    """Exactly one line on stderr (the form of every refusal)."""
    return len(p.stderr.strip().splitlines()) == 1


def check_refusals(command, cases):
    """Each (scene, args, want) of `swim COMMAND scene --out DIR --quiet args` is refused: exit 2,
    one line on stderr containing `want` (kernel notices "swim: ..." aside), nothing written."""
    for i, (scene_path, args, want) in enumerate(cases):
        out = os.path.join(TMP, "refused_%s_%d" % (command, i))
        p = subprocess.run([SWIM, command, scene_path, "--out", out, "--quiet", *args], capture_output=True,
                           text=True, cwd=ROOT)
        lines = [l for l in p.stderr.splitlines() if l.strip() and not l.startswith("swim: ")]
        check(p.returncode == 2 and len(lines) == 1 and want in lines[0], "%s: exit 2, one line with '%s' (%d %r)"
              % (" ".join(args), want, p.returncode, p.stderr))
        check(not os.path.exists(out), "%s: nothing written" % " ".join(args))


def wait_rows(proc, out, rows=2, seconds=60):
    """Until DIR/trajectory.csv holds ROWS data rows (or the process ends, or SECONDS pass); True
    when it does. Rows are written only once `swim run` integrates, after it has installed its
    signal handlers: a signal sent then is the run's to handle, however slowly a loaded machine
    got there (a fixed sleep may hit the program before, where the default action kills it)."""
    import time
    path = os.path.join(out, "trajectory.csv")
    end = time.time() + seconds
    while time.time() < end and proc.poll() is None:
        try:
            with open(path) as fh:
                if sum(1 for _ in fh) > rows:
                    return True
        except OSError:
            pass
        time.sleep(0.05)
    return False


def main(namespace, name):
    for fname, fn in sorted(namespace.items()):
        if fname.startswith("test_") and callable(fn):
            try:
                fn()
            except Exception as exc:   # a crash in one test is a failure, not the end of the run
                check(False, "%s raised %r" % (fname, exc))
    print("%s: %d passed, %d failed" % (name, counts["passed"], counts["failed"]))
    return 1 if counts["failed"] else 0
