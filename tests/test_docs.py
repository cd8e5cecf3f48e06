#!/usr/bin/env python3
"""The docs point at things that exist: every relative link in README.md and docs/*.md resolves
(to a file or folder of the repository), every path written as `docs/NAME.md` in them names a
file, and every `make TARGET` the README names is a target of the Makefile.
Prints "test_docs: P passed, F failed"."""

import glob
import os
import re
import subprocess
import sys

from swimtest import ROOT, check, main

DOCS = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def make_targets():
    p = subprocess.run(["make", "-pRrq", "-f", "Makefile", ":"], capture_output=True, text=True, cwd=ROOT)
    targets = set()
    for line in p.stdout.splitlines():
        m = re.match(r"^([A-Za-z0-9][A-Za-z0-9_.-]*):(?!=)", line)
        if m:
            targets.add(m.group(1))
    return targets


def test_relative_links_resolve():
    for doc in DOCS:
        text = open(doc, encoding="utf-8").read()
        for target in LINK.findall(text):
            if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                continue
            path = target.split("#", 1)[0]
            full = os.path.normpath(os.path.join(os.path.dirname(doc), path))
            check(os.path.exists(full), "%s: the link %s does not resolve" % (os.path.relpath(doc, ROOT), target))


def test_named_doc_files_exist():
    for doc in DOCS:
        text = open(doc, encoding="utf-8").read()
        for path in set(re.findall(r"\bdocs/[A-Za-z0-9_/.-]+\.md\b", text)):
            check(os.path.exists(os.path.join(ROOT, path)), "%s names %s, which does not exist" % (os.path.relpath(doc, ROOT), path))


def test_readme_make_targets_exist():
    targets = make_targets()
    check(len(targets) > 10, "could not read the Makefile's targets")
    text = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    for m in set(re.findall(r"`make ([a-z][a-z0-9-]*)", text)):
        check(m in targets, "README.md names `make %s`, which is not a target" % m)


def test_fig48_recipe_as_written():
    """The README's Fig. 4.8 recipe, run as written (swim -> this build, out/ -> a temporary
    folder): it marks the paper's four instants, each an event of the run."""
    import csv
    import tempfile
    text = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    block = re.search(r"Fig\. 4\.8 recipe.*?```sh\n(.*?)```", text, re.S)
    check(block is not None, "README.md has no Fig. 4.8 recipe block")
    if block is None:
        return
    from swimtest import SWIM
    tmp = tempfile.mkdtemp(prefix="swim-fig48-")
    marks = None
    for line in block.group(1).strip().splitlines():
        words = line.split()
        check(words[0] == "swim", "recipe line does not start with swim: " + line)
        words = [SWIM] + [w.replace("out/", tmp + "/") for w in words[1:]]
        if "--mark" in words:
            marks = [float(x) for x in words[words.index("--mark") + 1].split(",")]
        p = subprocess.run(words, capture_output=True, text=True, cwd=ROOT)
        check(p.returncode == 0, "recipe: %s: exit %d %s" % (line, p.returncode, p.stderr[-300:]))
    check(os.path.exists(os.path.join(tmp, "fig48", "instants.png")), "recipe: no instants.png")
    with open(os.path.join(tmp, "fig48", "events.csv")) as fh:
        events = [float(r["t"]) for r in csv.DictReader(fh)]
    paper = [3.17, 3.95, 6.07, 9.50]
    check(marks is not None and len(marks) == 4 and all(abs(m - q) < 0.01 for m, q in zip(marks, paper)),
          "recipe marks %s, the paper's instants are %s" % (marks, paper))
    check(marks is not None and all(min(abs(m - e) for e in events) < 1e-6 for m in marks),
          "recipe marks %s are not events of the run" % marks)
    # without --mark: the first 12 event times, and stderr says how many were left out
    run = os.path.join(tmp, "fig48")
    p = subprocess.run([SWIM, "plot", run, "--only", "energy"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0 and "left out" in p.stderr and "--events all" in p.stderr,
          "plot without marks should say how many events it left out: " + p.stderr)
    p = subprocess.run([SWIM, "plot", run, "--only", "energy", "--events", "all"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0 and "left out" not in p.stderr, "plot --events all: " + p.stderr)
    p = subprocess.run([SWIM, "plot", run, "--events", "nonsense"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, "plot --events nonsense: %d %s" % (p.returncode, p.stderr))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_docs"))
