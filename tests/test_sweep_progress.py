"""swim sweep as a long family is watched: a progress line on stderr (members done / total, failed,
members/s, time left), one every --progress seconds when stderr is not a terminal, none with
--quiet, and at every tenth of the family in a log; members.csv in member-id order when the sweep ends although members finish out of order
(a long member 0 beside short ones on two jobs), and again after a resume."""

import csv
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import TMP, check, swim  # noqa: E402

EX3 = "models/example3.toml"
# member 0 runs 30 times longer than the others: with two jobs it finishes last
LENGTHS = "run.t_end=3,0.1,0.1,0.1,0.1"
LINE = re.compile(r"^swim sweep: (\d+) / (\d+) members \((\d+) failed\)(, [0-9.e+]+ members/s, about .+ left)?$")


def ids(folder):
    with open(os.path.join(folder, "members.csv")) as fh:
        return [int(r["id"]) for r in csv.DictReader(fh)]


def test_progress_lines_and_order():
    out = os.path.join(TMP, "progress")
    p = swim("sweep", EX3, "--out", out, "--vary", LENGTHS, "--jobs", "2", "--progress", "0")
    check(p.returncode == 0, "sweep ran: %s" % p.stderr[-300:])
    lines = [ln for ln in p.stderr.splitlines() if ln.startswith("swim sweep:")]
    parsed = [LINE.match(ln) for ln in lines]
    check(len(lines) == 5 and all(parsed), "one progress line per finished member, each whole: %r" % lines)
    if all(parsed) and parsed:
        done = [int(m.group(1)) for m in parsed]
        check(done == sorted(done) and done[-1] == 5 and all(int(m.group(2)) == 5 for m in parsed),
              "the count of done members rises to the total: %s" % done)
        check(all(m.group(4) for m in parsed), "a rate and a time left once members have finished")
    check(ids(out) == [0, 1, 2, 3, 4], "members.csv in id order at the end: %s" % ids(out))


def test_quiet_and_period():
    out = os.path.join(TMP, "quiet")
    p = swim("sweep", EX3, "--out", out, "--vary", LENGTHS, "--jobs", "2", "--quiet")
    check(p.returncode == 0 and p.stderr == "", "--quiet: nothing on stderr: %r" % p.stderr)
    # a log (stderr not a terminal), the default period of 10 s: a line at every tenth of the
    # members, so a family of a few seconds still shows its progress, and not one per member
    out = os.path.join(TMP, "default")
    p = swim("sweep", EX3, "--out", out, "--vary", "model.rho0=1:3:40", "--t-end", "0.2", "--jobs", "2")
    lines = [ln for ln in p.stderr.splitlines() if ln.startswith("swim sweep:")]
    check(p.returncode == 0 and 9 <= len(lines) <= 11 and lines and lines[-1].startswith("swim sweep: 40 / 40 members"),
          "40 members, default period: a line per tenth, the last at 40 / 40: %r" % lines)


def test_resume_keeps_order():
    out = os.path.join(TMP, "resume")
    swim("sweep", EX3, "--out", out, "--vary", LENGTHS, "--jobs", "2", "--quiet")
    member2 = [d for d in os.listdir(os.path.join(out, "members")) if int(d) == 2][0]
    os.remove(os.path.join(out, "members", member2, "summary.json"))   # member 2 to be rerun
    p = swim("sweep", EX3, "--out", out, "--vary", LENGTHS, "--jobs", "2", "--progress", "0")
    check(p.returncode == 0 and "resuming" in p.stderr, "resumed: %r" % p.stderr[-300:])
    check("swim sweep: 5 / 5 members (0 failed)" in p.stderr, "the progress counts members finished before")
    check(ids(out) == [0, 1, 2, 3, 4], "members.csv in id order after a resume: %s" % ids(out))


def test_family_of_200_listed_values():
    # 200 values as one list (a SPEC of ~1 kB, kept whole) on the default period: a line at every
    # tenth, 200 rows in id order
    values = ",".join(repr(1 + i / 100) for i in range(200))
    out = os.path.join(TMP, "two-hundred")
    p = swim("sweep", EX3, "--out", out, "--vary", "model.rho0=" + values, "--t-end", "0.05", "--jobs", "2")
    lines = [ln for ln in p.stderr.splitlines() if ln.startswith("swim sweep:")]
    check(p.returncode == 0 and "200 members" in p.stdout, "200 members run: %r" % p.stdout[-200:])
    check(ids(out) == list(range(200)), "200 rows in id order")
    check(10 <= len(lines) <= 12 and lines[-1].startswith("swim sweep: 200 / 200 members"),
          "progress lines at every tenth: %r" % lines[-3:])


def test_bad_progress():
    p = swim("sweep", EX3, "--out", os.path.join(TMP, "bad"), "--vary", LENGTHS, "--progress", "-1")
    check(p.returncode == 2 and swimtest.one_line(p) and "--progress" in p.stderr,
          "--progress -1 refused in one line: %r" % p.stderr)


sys.exit(swimtest.main(globals(), "test_sweep_progress"))
