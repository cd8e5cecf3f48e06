#!/usr/bin/env python3
"""members.csv says what each member's summary.json says, field for field: the numbers are the
summary's doubles (integers exactly), read at their place in the JSON tree -- `steps` is
stats.steps, never projection.steps or step_checks.steps, `energy_balance_abs` is energy_drift_abs
(max |E - E0 - W|) -- for abm, rk8pd, --no-projection and a prescribed stroke; a null or absent
value is an empty field. A resume rebuilds the rows in id order from the summaries and reruns the
members whose summary is not a whole one (truncated, trailing text, stopped by a signal), keeps a
crashed one, and reads integers beyond 2^53 exactly.
Prints "test_sweep_members_csv: P passed, F failed"."""

import csv
import json
import os
import subprocess
import sys

from swimtest import ROOT, SWIM, TMP, check, main

EX3 = os.path.join(ROOT, "models", "example3.toml")
LOOP = os.path.join(ROOT, "models", "stroke_loop.toml")

# members.csv column -> (path in summary.json, kind)
COLUMNS = [
    ("t_reached", ("t_reached",), float),
    ("x", ("final_state", "x"), float),
    ("y", ("final_state", "y"), float),
    ("theta", ("final_state", "theta"), float),
    ("energy_drift_rel", ("energy_drift_rel",), float),
    ("energy_balance_abs", ("energy_drift_abs",), float),
    ("jmin", ("jmin",), float),
    ("steps", ("stats", "steps"), int),
    ("rhs_evaluations", ("stats", "rhs_evaluations"), int),
    ("integrate_seconds", ("stats", "integrate_seconds"), float),
    ("wall_seconds", ("stats", "wall_seconds"), float),
]


def get(summary, path):
    v = summary
    for k in path:
        if not isinstance(v, dict) or k not in v:
            return None
        v = v[k]
    return v


def csv_reason(reason):
    """The reason as members.csv holds it (without its quotes): " as ', a newline as a space, other
    control characters and U+FFFD as ?, at most 399 bytes."""
    out = []
    for ch in reason:
        if ch == '"':
            ch = "'"
        elif ch == "\n":
            ch = " "
        elif ord(ch) < 0x20 or ord(ch) == 0x7F or ch == "\ufffd":
            ch = "?"
        out.append(ch)
    b = "".join(out).encode()
    return b[:399].decode("utf-8", "ignore")


def summary_of(out, m):
    """Member m's summary.json as Python reads it ({} when it is not JSON: the row cannot agree)."""
    try:
        with open(os.path.join(out, "members", "%05d" % m, "summary.json"), encoding="utf-8") as fh:
            return json.load(fh)
    except (OSError, ValueError) as exc:
        check(False, "%s: member %d: summary.json: %s" % (out, m, exc))
        return {}


def write_summary(out, m, text):
    with open(os.path.join(out, "members", "%05d" % m, "summary.json"), "w", encoding="utf-8") as fh:
        fh.write(text)


def read_rows(out):
    with open(os.path.join(out, "members.csv"), newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def agree(name, out, members):
    """One check per column: every row of members.csv against its member's summary.json."""
    rows = read_rows(out)
    check(sorted(int(r["id"]) for r in rows) == list(range(members)),
          "%s: members.csv has the rows %r, expected ids 0..%d" % (name, [r["id"] for r in rows], members - 1))
    summaries = {int(r["id"]): summary_of(out, int(r["id"])) for r in rows}
    bad = [(r["id"], r["status"], summaries[int(r["id"])].get("status")) for r in rows
           if r["status"] != summaries[int(r["id"])].get("status")]
    check(not bad, "%s: status differs from summary.json: %r" % (name, bad))
    bad = [(r["id"], r["reason"], summaries[int(r["id"])].get("reason")) for r in rows
           if r["reason"] != csv_reason(summaries[int(r["id"])].get("reason") or "")]
    check(not bad, "%s: reason differs from summary.json: %r" % (name, bad))
    for col, path, kind in COLUMNS:
        bad = []
        for r in rows:
            v, f = get(summaries[int(r["id"])], path), r[col]
            if v is None:
                ok = f == ""
            elif kind is int:
                ok = f.lstrip("-").isdigit() and int(f) == v   # exactly, digit for digit
            else:
                try:
                    ok = float(f) == float(v)   # the same double
                except ValueError:
                    ok = False
            if not ok:
                bad.append("member %s: members.csv %r, summary %s = %r" % (r["id"], f, ".".join(path), v))
        check(not bad, "%s: %s: %s" % (name, col, "; ".join(bad)))
    return rows, summaries


def sweep(out, scene, *args):
    return subprocess.run([SWIM, "sweep", scene, "--out", out, "--quiet", "--jobs", "2", *args],
                          capture_output=True, text=True, cwd=ROOT)


# Example 3 (abm with projection, rk8pd, abm without projection) and a stroke: short, cheap members.
CASES = [
    ("abm", EX3, ["--t-end", "1", "--vary", "elastic.stiffness[2]=1,2,3,4"]),
    ("rk8pd", EX3, ["--t-end", "1", "--integrator", "rk8pd", "--vary", "elastic.stiffness[2]=1,3"]),
    ("no-projection", EX3, ["--t-end", "1", "--no-projection", "--vary", "elastic.stiffness[2]=1,3"]),
    ("stroke", LOOP, ["--t-end", "1", "--vary", "model.rho0=1,2,4"]),
]


def test_rows_agree_with_summaries():
    for name, scene, args in CASES:
        out = os.path.join(TMP, "csv-" + name)
        members = 1
        for a in args:
            if "=" in a and "," in a:
                members *= len(a.split("=", 1)[1].split(","))
        p = sweep(out, scene, *args)
        check(p.returncode == 0, "%s: sweep exit %d %r" % (name, p.returncode, p.stderr))
        rows, summaries = agree(name, out, members)
        # the total of accepted steps, which projection.steps is not (0 for rk8pd, without
        # projection and for a stroke; more than stats.steps with it)
        steps = [get(s, ("stats", "steps")) for s in summaries.values()]
        check(all(isinstance(n, int) and n > 0 for n in steps), "%s: stats.steps of the members: %r" % (name, steps))
        proj = [get(s, ("projection", "steps")) for s in summaries.values()]
        check(proj != steps, "%s: projection.steps %r equal stats.steps %r: the sweep cannot tell them apart"
              % (name, proj, steps))
        # the same sweep again: nothing to run, members.csv rebuilt from the summaries in id order
        p = sweep(out, scene, *args)
        rows2, _ = agree(name + " (rebuilt)", out, members)
        check(p.returncode == 0 and [int(r["id"]) for r in rows2] == list(range(members)),
              "%s: the rebuilt members.csv is in id order: %r (exit %d)" % (name, [r["id"] for r in rows2], p.returncode))


def test_resume_reads_whole_summaries():
    name, scene, args = CASES[0]
    out = os.path.join(TMP, "csv-resume")
    p = sweep(out, scene, *args)
    check(p.returncode == 0, "resume: first sweep exit %d %r" % (p.returncode, p.stderr))
    texts = [open(os.path.join(out, "members", "%05d" % m, "summary.json"), encoding="utf-8").read() for m in range(4)]
    # member 0: a truncated summary (a JSON text cut short) is not whole: it reruns
    write_summary(out, 0, texts[0][: len(texts[0]) // 2])
    # member 1: a whole summary with text after it is not one JSON text: it reruns
    write_summary(out, 1, texts[1] + "{}\n")
    # member 2: stopped by a signal: it reruns
    s2 = json.loads(texts[2])
    s2["status"], s2["reason"] = "failed", "interrupted by SIGINT at t = 0.5"
    write_summary(out, 2, json.dumps(s2, indent=2))
    # member 3: whole, with values null or absent, and an integer beyond 2^53: kept as written
    s3 = json.loads(texts[3])
    s3["jmin"] = None
    del s3["t_reached"]
    s3["stats"]["steps"] = 2 ** 53 + 1
    write_summary(out, 3, json.dumps(s3, indent=2))
    p = sweep(out, scene, *args)
    check(p.returncode == 0 and "3 ran now" in p.stdout,
          "resume: the three members without a whole summary rerun: exit %d %r %r" % (p.returncode, p.stdout, p.stderr))
    rows, summaries = agree("resume", out, 4)
    r = {int(x["id"]): x for x in rows}
    check(all(summaries[m].get("status") == "completed" and "max_rss_kb" in summaries[m]["stats"] for m in range(3)),
          "resume: members 0-2 have fresh summaries: %r" % [summaries[m].get("reason") for m in range(3)])
    check(r[3]["jmin"] == "" and r[3]["t_reached"] == "" and r[3]["steps"] == "9007199254740993",
          "resume: member 3's null jmin, absent t_reached, steps 2^53+1: %r %r %r"
          % (r[3]["jmin"], r[3]["t_reached"], r[3]["steps"]))
    # a crashed summary (the sweep's own, for a member that died without one) is kept; its reason
    # is quoted as members.csv quotes reasons, its numbers are empty
    # (escaped as runtime/io/json.c escapes: \" \n, \u00XX for other control characters, \ufffd for
    # bytes that are not UTF-8, other characters as they are)
    text = ('{\n  "scene": %s,\n  "status": "crashed",\n  "reason": "member process exited with status 3: '
            'a \\"quoted\\"\\nline\\u0009tab \\ufffd \u00e9t\u00e9"\n}\n' % json.dumps(scene))
    write_summary(out, 1, text)
    p = sweep(out, scene, *args)
    rows, _ = agree("crashed", out, 4)
    r = {int(x["id"]): x for x in rows}
    check(p.returncode == 1 and "0 ran now" in p.stdout, "crashed: kept, not rerun: exit %d %r" % (p.returncode, p.stdout))
    check(r[1]["status"] == "crashed" and r[1]["reason"] == "member process exited with status 3: a 'quoted' line?tab ? \u00e9t\u00e9"
          and all(r[1][c] == "" for c, _, _ in COLUMNS),
          "crashed: the row %r" % (r[1],))
    raw = open(os.path.join(out, "members.csv"), encoding="utf-8").read().splitlines()
    check(raw[2].startswith('1,2,crashed,"member process exited with status 3: a \'quoted\' line?tab ? \u00e9t\u00e9",'),
          "crashed: the reason between double quotes as before: %r" % raw[2])


if __name__ == "__main__":
    sys.exit(main(globals(), "test_sweep_members_csv"))
