#!/usr/bin/env python3
"""tests/run_tests.sh, the runner of `make test`, on small stand-in programs: it names its log
folder first, prints each program's line (name, counts, seconds, its FAIL lines) as the program
ends -- a quick program's line comes while a slow one still runs --, counts a crash without a
summary line as one failure, closes with "tests: P passed, F failed" and the exit status, and
with TEST_FILTER (make test T=PATTERN) runs only the matching programs."""
import os
import subprocess
import sys
import time

import swimtest
from swimtest import check

RUNNER = os.path.join(swimtest.ROOT, "tests", "run_tests.sh")


def programs(d):
    """Three stand-ins in D/tests/: test_quick (3 passed), test_slow (2 passed, 1 FAIL, after
    a pause the test ends itself), test_crash (no summary line, exit 3)."""
    t = os.path.join(d, "tests")
    os.makedirs(t, exist_ok=True)
    release = os.path.join(d, "release")
    progs = {
        "test_quick.sh": "echo 'test_quick: 3 passed, 0 failed'\n",
        # ends only when the test has seen test_quick's line (or after 60 s)
        "test_slow.sh": "for i in $(seq 600); do [ -e '%s' ] && break; sleep 0.1; done\n"
                        "echo 'FAIL something planted'\necho 'test_slow: 2 passed, 1 failed'\n"
                        "exit 1\n" % release,
        "test_crash.sh": "echo 'half a line'\nexit 3\n",
    }
    paths = []
    for name, body in progs.items():
        p = os.path.join(t, name)
        with open(p, "w") as fh:
            fh.write("#!/bin/sh\n" + body)
        os.chmod(p, 0o755)
        paths.append(os.path.join("tests", name))
    return paths, release


def test_streams_and_counts():
    d = os.path.join(swimtest.TMP, "runner")
    paths, release = programs(d)
    logs = os.path.join(d, "logs")
    env = dict(os.environ, TEST_JOBS="3", TEST_LOGS=logs, TEST_FILTER="")   # as make test runs it
    proc = subprocess.Popen(["bash", RUNNER] + paths, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env, cwd=d)
    lines = []
    end = time.time() + 60
    # the quick program's line arrives while the slow one is still waiting for `release`
    while time.time() < end:
        ln = proc.stdout.readline()
        if not ln:
            break
        lines.append(ln.rstrip("\n"))
        if ln.startswith("test_quick:"):
            break
    slow_running = not os.path.exists(release) and proc.poll() is None
    open(release, "w").close()
    rest, _ = proc.communicate(timeout=60)
    lines += rest.splitlines()
    text = "\n".join(lines)
    check(lines and lines[0].startswith("tests: 3 programs") and logs in lines[0],
          "first line does not name the log folder: %r" % lines[:1])
    check(any(ln.startswith("test_quick: 3 passed, 0 failed (") and ln.endswith(" s)")
              for ln in lines), "no line for test_quick with its seconds:\n" + text)
    check(slow_running, "test_quick's line came only after test_slow ended:\n" + text)
    i = next((k for k, ln in enumerate(lines) if ln.startswith("test_slow: 2 passed, 1 failed")), None)
    check(i is not None and i + 1 < len(lines) and "FAIL something planted" in lines[i + 1],
          "test_slow's line or its FAIL line missing:\n" + text)
    check(any(ln.startswith("test_crash: no summary line, exit status 3") for ln in lines),
          "the crash is not reported:\n" + text)
    check(lines[-1] == "tests: 5 passed, 2 failed", "closing line %r" % lines[-1:])
    check(proc.returncode == 1, "exit status %s with failures" % proc.returncode)
    check("failed: test_crash" in text and "half a line" in text,
          "the crash's output is not shown at the end:\n" + text)
    with open(os.path.join(logs, "durations")) as fh:
        names = sorted(ln.split()[0] for ln in fh if ln.strip())
    check(names == ["test_crash", "test_quick", "test_slow"], "durations: %s" % names)
    # the record make docs-numbers reads: passed, failed, programs, seconds, jobs, filter, date,
    # load at start and end, cores
    with open(os.path.join(logs, "last-run")) as fh:
        f = fh.read().rstrip("\n").split("\t")
    check(len(f) == 10 and f[:3] == ["5", "2", "3"] and f[4] == "3" and f[5] == "" and f[6].endswith("UTC"),
          "last-run record: %r" % f)


def test_filter():
    d = os.path.join(swimtest.TMP, "runner-filter")
    paths, release = programs(d)
    open(release, "w").close()
    logs = os.path.join(d, "logs")
    os.makedirs(logs)
    with open(os.path.join(logs, "durations"), "w") as fh:
        fh.write("test_crash 5\ntest_quick 7\ntest_slow 9\n")
    env = dict(os.environ, TEST_JOBS="2", TEST_LOGS=logs, TEST_FILTER="quick|nothing")
    p = subprocess.run(["bash", RUNNER] + paths, capture_output=True, text=True, env=env,
                       timeout=60, cwd=d)
    out = p.stdout.splitlines()
    check(p.returncode == 0 and out[:1] and out[0].startswith("tests: 1 program,")
          and out[-1] == "tests: 3 passed, 0 failed",
          "T=quick: status %d, output %s" % (p.returncode, out))
    with open(os.path.join(logs, "durations")) as fh:
        names = sorted(ln.split()[0] for ln in fh if ln.strip())
    check(names == ["test_crash", "test_quick", "test_slow"],
          "a subset run forgot the other programs' durations: %s" % names)
    with open(os.path.join(logs, "last-run")) as fh:
        f = fh.read().rstrip("\n").split("\t")
    check(len(f) == 10 and f[5] == "quick|nothing", "a subset's record names its filter: %r" % f)
    env["TEST_FILTER"] = "no_such_test"
    p = subprocess.run(["bash", RUNNER] + paths, capture_output=True, text=True, env=env,
                       timeout=60, cwd=d)
    check(p.returncode == 2 and "no test program matches T=no_such_test" in p.stderr
          and p.stdout == "", "an empty selection: status %d, %r %r" % (
              p.returncode, p.stdout, p.stderr))


def test_sanitized_twin_waits():
    """asan-NAME starts only once NAME has ended (they would wait for the same kernels), even when
    the durations put it first; a program without a twin does not wait."""
    d = os.path.join(swimtest.TMP, "runner-twins")
    marker = os.path.join(d, "plain-ended")
    bodies = {
        os.path.join("build", "tests", "test_pair.sh"): "sleep 1\ntouch '%s'\necho 'test_pair: 1 passed, 0 failed'\n"
                                                          % marker,
        os.path.join("build", "asan", "tests", "test_pair.sh"):
            "if [ -e '%s' ]; then echo 'asan-test_pair: 1 passed, 0 failed'; else "
            "echo 'FAIL started before test_pair ended'; echo 'asan-test_pair: 0 passed, 1 failed'; fi\n" % marker,
        os.path.join("build", "tests", "test_alone.sh"): "echo 'test_alone: 1 passed, 0 failed'\n",
    }
    for rel, body in bodies.items():
        p = os.path.join(d, rel)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "w") as fh:
            fh.write("#!/bin/sh\n" + body)
        os.chmod(p, 0o755)
    logs = os.path.join(d, "logs")
    os.makedirs(logs, exist_ok=True)
    with open(os.path.join(logs, "durations"), "w") as fh:   # longest first would start the twin first
        fh.write("asan-test_pair 90000\ntest_alone 50000\ntest_pair 10\n")
    env = dict(os.environ, TEST_JOBS="2", TEST_LOGS=logs, TEST_FILTER="")
    p = subprocess.run(["bash", RUNNER] + list(bodies), capture_output=True, text=True, env=env, timeout=60, cwd=d)
    out = p.stdout.splitlines()
    check(p.returncode == 0 and out[-1:] == ["tests: 3 passed, 0 failed"],
          "the twin did not wait for its program: status %d\n%s" % (p.returncode, p.stdout))
    ends = [ln.split(":")[0] for ln in out[1:-1]]
    check(ends.index("test_alone") < ends.index("test_pair") < ends.index("asan-test_pair"),
          "order of the ends %s (test_alone has no twin: it runs at once)" % ends)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_run_tests"))
