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


if __name__ == "__main__":
    sys.exit(main(globals(), "test_docs"))
