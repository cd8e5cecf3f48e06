#!/usr/bin/env python3
"""The docs point at things that exist: every relative link in README.md and docs/*.md resolves
(to a file or folder of the repository), every path written as `docs/NAME.md` in them names a
file, and every `make TARGET` they name is a target of the Makefile. The README is a front door:
under 250 lines, linking every docs/*.md, its command list naming only commands of `swim --help`.
The Fig. 4.8 recipe (docs/integrators-and-events.md) runs as written. Measured numbers stay
true: every generated block (<!-- numbers: NAME -->, rewritten by `make docs-numbers`) is one
tools/docs_numbers.py knows and names an existing make target with its date and load (or says
it is not generated yet and which command makes it), and the measurements listed in LISTED are
quoted nowhere outside such blocks; more generally no timing figure (a number with a unit of
time, memory or speed, or a speed-up N×) stands in the prose outside a block: what counts and
what does not (code, bounds such as targets and limits, sizes A × B, a short list of settings
written in words) is tools/docs_numbers.py's TIMING and NOT_MEASURED, whose docstring states the
rule; `python3 tools/docs_numbers.py --inventory` lists the offenders. The README's package
list is the Makefile's DEB_PKGS.
Prints "test_docs: P passed, F failed"."""

import glob
import os
import re
import subprocess
import sys

from swimtest import ROOT, check, main

DOCS = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
# Pages being written at the same time as the README that links them: a link to one of these is
# accepted while the file does not exist yet (once it exists it is checked like any other).
PENDING = {"docs/python.md", "docs/export.md"}
RECIPE_DOC = os.path.join(ROOT, "docs", "integrators-and-events.md")


def pending(path):
    rel = os.path.relpath(path, ROOT)
    if rel in PENDING and not os.path.exists(path):
        print("note: %s is linked but not written yet (allowed: pending)" % rel)
        return True
    return False


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
            if pending(full):
                continue
            check(os.path.exists(full), "%s: the link %s does not resolve" % (os.path.relpath(doc, ROOT), target))


def test_named_doc_files_exist():
    for doc in DOCS:
        text = open(doc, encoding="utf-8").read()
        for path in set(re.findall(r"\bdocs/[A-Za-z0-9_/.-]+\.md\b", text)):
            if pending(os.path.join(ROOT, path)):
                continue
            check(os.path.exists(os.path.join(ROOT, path)), "%s names %s, which does not exist" % (os.path.relpath(doc, ROOT), path))


def test_make_targets_exist():
    """Every `make TARGET` in README.md and docs/*.md, and every target the README's list of
    targets names (`bench-soft`, ...), is a target of the Makefile."""
    targets = make_targets()
    check(len(targets) > 10, "could not read the Makefile's targets")
    for doc in DOCS:
        text = open(doc, encoding="utf-8").read()
        # (a placeholder such as `make fig-4-N` is no target name)
        for m in set(re.findall(r"`make ([a-z][a-z0-9-]*)(?![A-Za-z0-9_-])", text)):
            check(m in targets, "%s names `make %s`, which is not a target" % (os.path.relpath(doc, ROOT), m))
    text = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    block = re.search(r"The targets \(`make help` describes them\).*?\n\n(.*?)\n\n", text, re.S)
    check(block is not None, "README.md has no list of make targets")
    if block:
        listed = set(re.findall(r"`([a-z][a-z0-9-]*)`", block.group(1)))
        for m in listed:
            check(m in targets, "README.md lists the target %s, which is not a target" % m)
        # every target `make help` describes is in the README's list
        p = subprocess.run(["make", "-s", "help"], capture_output=True, text=True, cwd=ROOT)
        helped = set(re.findall(r"^make ([a-z][a-z0-9-]*)", p.stdout, re.M))
        check(len(helped) > 10, "could not read make help")
        for m in sorted(helped - {"run", "test"}):
            check(m in listed, "make help describes `make %s`, which the README's list of targets leaves out" % m)


def test_readme_is_a_front_door():
    """README.md stays short, links every page of docs/ (and the pages being written), and its
    command list names only commands `swim --help` knows."""
    text = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    check(len(text.splitlines()) < 250, "README.md has %d lines (limit 250)" % len(text.splitlines()))
    linked = set(LINK.findall(text))
    for doc in sorted(glob.glob(os.path.join(ROOT, "docs", "*.md"))) + [os.path.join(ROOT, p) for p in sorted(PENDING)]:
        rel = os.path.relpath(doc, ROOT)
        check(rel in linked, "README.md does not link %s" % rel)
    check("docs/figures/" in text and re.search(r"!\[[^\]]*\]\(docs/figures/[^)]+\.png\)", text) is not None,
          "README.md shows no figure of docs/figures/")
    block = re.search(r"## The contract: `bin/swim`.*?```\n(.*?)```", text, re.S)
    check(block is not None, "README.md has no command list")
    if block is None:
        return
    from swimtest import SWIM
    helptext = subprocess.run([SWIM, "--help"], capture_output=True, text=True, cwd=ROOT)
    known = set(re.findall(r"^  ([a-z]+)\s", helptext.stdout + helptext.stderr, re.M))
    check(len(known) >= 8, "could not read the commands of swim --help: %s" % sorted(known))
    listed = set()
    for line in block.group(1).splitlines():
        words = line.split()
        if not words:
            continue
        cmd = words[words.index("bin/swim-mpi") + 1] if "bin/swim-mpi" in words else words[1]
        listed.add(cmd)
        check(words[0] in ("swim", "mpirun") and cmd in known, "README command line names no command of swim --help: " + line)
        doc = re.search(r"\((docs/[a-z-]+\.md)\)\s*$", line)
        check(doc is not None and (os.path.exists(os.path.join(ROOT, doc.group(1))) or doc.group(1) in PENDING),
              "README command line points to no existing doc: " + line)
    for cmd in sorted(known - listed):
        check(False, "swim --help has the command %s, which the README's command list leaves out" % cmd)


def test_fig48_recipe_as_written():
    """The Fig. 4.8 recipe of docs/integrators-and-events.md (it was the README's), run as written
    (swim -> this build, out/ -> a temporary folder): it marks the paper's four instants, each an
    event of the run."""
    import csv
    import tempfile
    text = open(RECIPE_DOC, encoding="utf-8").read()
    block = re.search(r"Fig\. 4\.8 recipe.*?```sh\n(.*?)```", text, re.S)
    check(block is not None, "docs/integrators-and-events.md has no Fig. 4.8 recipe block")
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


def test_library_md_c_blocks_compile_and_run():
    """Every ```c block of docs/library.md is a program: compiled against runtime/lib/swim.h with
    -Wall -Wextra -Werror, linked with make lib's libswim and run from the source tree (exit 0)."""
    import shutil
    import tempfile
    text = open(os.path.join(ROOT, "docs", "library.md"), encoding="utf-8").read()
    blocks = re.findall(r"```c\n(.*?)```", text, re.S)
    check(len(blocks) >= 2, "docs/library.md has %d C blocks, expected the programs" % len(blocks))
    with open(os.path.join(ROOT, "VERSION")) as f:
        so = os.path.join(ROOT, "build", "lib", "libswim.so." + f.read().strip())
    abi = re.search(r"^#define SWIM_ABI (\d+)$", open(os.path.join(ROOT, "runtime", "lib", "swim.h")).read(), re.M)
    check(os.path.exists(so) and abi is not None, "no %s (make lib) or no SWIM_ABI in swim.h" % so)
    if not os.path.exists(so) or abi is None:
        return
    # in build/: the library finds the generator next to the program, as for the test programs
    tmp = tempfile.mkdtemp(prefix="libdocs-", dir=os.path.join(ROOT, "build"))
    try:
        os.symlink(so, os.path.join(tmp, "libswim.so." + abi.group(1)))   # the SONAME the program asks for
        env = dict(os.environ, LD_LIBRARY_PATH=tmp)
        env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
        for i, block in enumerate(blocks):
            src, exe = os.path.join(tmp, "block%d.c" % i), os.path.join(tmp, "block%d" % i)
            with open(src, "w") as f:
                f.write(block)
            p = subprocess.run(["cc", "-std=c11", "-Wall", "-Wextra", "-Werror", "-I", os.path.join(ROOT, "runtime", "lib"),
                                src, so, "-o", exe], capture_output=True, text=True)
            first = block.strip().splitlines()[0] if block.strip() else ""
            check(p.returncode == 0, "docs/library.md C block %d (%s) does not compile: %s" % (i + 1, first, p.stderr[-600:]))
            if p.returncode != 0:
                continue
            p = subprocess.run([exe], capture_output=True, text=True, cwd=ROOT, env=env, timeout=120)
            check(p.returncode == 0, "docs/library.md C block %d exits %d: %s%s" % (i + 1, p.returncode, p.stdout[-300:],
                                                                                  p.stderr[-300:]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


# Measurements that only a generated block may quote (a number next to them in the prose goes
# stale): (what, pattern over the text outside the blocks and code).
LISTED = [
    ("a run's split into integration and diagnostics time",
     re.compile(r"integrates in \d+(\.\d+)? ?ms|diagnostics[^.|\n]{0,30}?\b\d+(\.\d+)? ?ms"
                r"|\d+(\.\d+)? ?ms (integration|diagnostics)\b")),
    ("a Lyapunov exponent", re.compile(r"Lyapunov exponent[^.]{0,40}?\b\d+\.\d+")),
    ("λ of a soft scene", re.compile(r"soft_n10_a(1|05)[^.\n]{0,60}?λ\s*=?\s*\d+\.\d")),
    ("the cost of the four energy events", re.compile(r"energy events[^.|\n]{0,20}?\d+(\.\d+)? ?s\b")),
    ("the number of checks of make test", re.compile(r"\b\d{1,3} \d{3} (checks|in \d+ test programs)")),
]


def outside_blocks(text):
    """The page without its generated blocks and code blocks."""
    text = re.sub(r"<!-- numbers: [a-z0-9_.]+ -->.*?<!-- /numbers -->", "", text, flags=re.S)
    return re.sub(r"```.*?```", "", text, flags=re.S)


def test_number_blocks():
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    import docs_numbers
    targets = make_targets()
    seen = 0
    for doc in DOCS:
        text = open(doc, encoding="utf-8").read()
        rel = os.path.relpath(doc, ROOT)
        check(text.count("<!-- numbers: ") == text.count("<!-- /numbers -->"),
              "%s: a generated block is not closed" % rel)
        for name, body in docs_numbers.blocks_in(text):
            seen += 1
            check(name in docs_numbers.BLOCKS, "%s: unknown generated block %s" % (rel, name))
            if name not in docs_numbers.BLOCKS:
                continue
            cmd = docs_numbers.command_of(name)
            check(cmd.startswith("make ") and cmd[5:] in targets,
                  "%s: block %s is made by `%s`, not a make target" % (rel, name, cmd))
            made = re.search(r"\*Generated by `make docs-numbers` from `([^`]+)` \(([^)]+)\), "
                             r"(\d{4}-\d\d-\d\d \d\d:\d\d UTC), load average [0-9.]+ → [0-9.]+ on \d+ cores", body)
            waiting = "not generated yet: run `%s`, then `make docs-numbers`" % cmd in body
            check(made is not None or waiting,
                  "%s: block %s says neither its command, date and load nor that it waits for `%s`"
                  % (rel, name, cmd))
            if made:
                check(made.group(1) == cmd and made.group(2) == docs_numbers.source_of(name),
                      "%s: block %s names %s (%s), want %s (%s)" % (rel, name, made.group(1), made.group(2),
                                                                    cmd, docs_numbers.source_of(name)))
    check(seen >= 15, "only %d generated blocks in README.md and docs/" % seen)
    check("docs-numbers" in targets and "bench-docs" in targets, "make docs-numbers or bench-docs missing")


def test_docs_numbers_rewrites_blocks():
    """tools/docs_numbers.py on a small tree: a block whose source exists is rewritten from it
    with its stamp (command, source, date, load), the text around it untouched; a block whose
    source is missing is left as it is and named with the command that makes it."""
    import json
    import shutil
    import tempfile
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    import docs_numbers
    tmp = tempfile.mkdtemp(prefix="docs-numbers-")
    old_root = docs_numbers.ROOT
    try:
        os.makedirs(os.path.join(tmp, "docs"))
        os.makedirs(os.path.join(tmp, "build", "bench", "docs"))
        page = ("before\n<!-- numbers: member_cost.sentence -->\nold 2.4 ms\n<!-- /numbers -->\nafter\n"
                "<!-- numbers: event_cost -->\nkept\n<!-- /numbers -->\n")
        with open(os.path.join(tmp, "docs", "a.md"), "w") as fh:
            fh.write(page)
        with open(os.path.join(tmp, "README.md"), "w") as fh:
            fh.write("no blocks\n")
        stats = {"integrate_seconds": 0.0046, "diagnostics_seconds": 0.0016, "output_seconds": 1e-5,
                 "wall_seconds": 0.0063}
        rec = {"name": "member_cost", "command": "make bench-docs", "date": "2026-12-05 18:00 UTC",
               "load_before": 1.5, "load_after": 2.5, "cores": 2,
               "values": {"runs": 5, "scene": "models/example3.toml", "full": stats, "summary_only": stats}}
        with open(os.path.join(tmp, "build", "bench", "docs", "member_cost.json"), "w") as fh:
            json.dump(rec, fh)
        docs_numbers.ROOT = tmp
        rc = docs_numbers.main([])
        with open(os.path.join(tmp, "docs", "a.md")) as fh:
            new = fh.read()
        body = dict(docs_numbers.blocks_in(new))
        check(rc == 0 and new.startswith("before\n") and "\nafter\n" in new and "old 2.4 ms" not in new,
              "the block was not rewritten in place: %r" % new)
        check("integration 4.6 ms" in body.get("member_cost.sentence", "") and "diagnostics of the rows" in body.get(
            "member_cost.sentence", "") and "load average 1.5 → 2.5 on 2 cores" in body.get("member_cost.sentence", ""),
            "the rewritten block: %r" % body.get("member_cost.sentence"))
        check(body.get("event_cost") == "kept\n", "a block without its source was changed: %r" % body.get("event_cost"))
        check(docs_numbers.main(["--check"]) == 1, "--check does not fail on a missing source")
    finally:
        docs_numbers.ROOT = old_root
        shutil.rmtree(tmp, ignore_errors=True)


def test_listed_measurements_only_in_blocks():
    for doc in DOCS:
        prose = outside_blocks(open(doc, encoding="utf-8").read())
        for what, pat in LISTED:
            for m in pat.finditer(prose):
                check(False, "%s quotes %s outside a generated block: %r"
                      % (os.path.relpath(doc, ROOT), what, m.group(0)[:80]))
    # the checker sees them
    planted = "It integrates in 2.4 ms. The largest Lyapunov exponent 2.6 of it."
    check(sum(bool(p.search(outside_blocks(planted))) for _, p in LISTED) == 2,
          "LISTED misses planted quotes")
    check(not any(p.search(outside_blocks("<!-- numbers: x -->\n" + planted + "\n<!-- /numbers -->"))
                  for _, p in LISTED), "a quote inside a block was flagged")


def test_no_timing_figure_outside_blocks():
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    import docs_numbers
    for doc in DOCS:
        rel = os.path.relpath(doc, ROOT)
        for n, fig, line in docs_numbers.timings_outside_blocks(open(doc, encoding="utf-8").read(), rel):
            check(False, "%s:%d quotes the timing %r outside a generated block (make it a block of `make "
                  "docs-numbers` or say which command measures it): %s" % (rel, n, fig, line.strip()[:100]))
    # every phrase of the list of settings still exists (a stale entry would hide nothing, or the wrong thing)
    for page, phrase, _ in docs_numbers.NOT_MEASURED:
        check(phrase in open(os.path.join(ROOT, page), encoding="utf-8").read(),
              "NOT_MEASURED: %s no longer says %r" % (page, phrase))
    # the rule on planted text: measurements are seen, settings, bounds, sizes and code are not
    seen = [f for _, f, _ in docs_numbers.timings_outside_blocks(
        "A member costs 17.6 ms, the sweep took 76 s (1.44× faster), 35–45 µs a row, ~55 000 members/s, "
        "4.5 MB of memory, 2 min 3 s left.\n")]
    check(sorted(seen) == sorted(["17.6 ms", "76 s", "1.44×", "35–45 µs", "~55 000 members/s", "4.5 MB", "2 min",
                                  "3 s"]),
          "the timing pattern found %s in the planted measurements" % seen)
    # tables: a column headed by a unit of time, a row labelled with one; not a column of counts or ratios
    seen = [f for _, f, _ in docs_numbers.timings_outside_blocks(
        "| N | C lines | compile (s) | ratio |\n|---|---|---|---|\n| 7 | 1 640 | 2.2 | 0.9 |\n\n"
        "| measure | after/before |\n|---|---|\n| start-up, process ms | 5.1 |\n| start-up, process time | 0.17 |\n")]
    check(seen == ["2.2", "5.1"], "the table rule found %s in the planted tables" % seen)
    quiet = docs_numbers.timings_outside_blocks(
        "Targets: N = 20 ≤ 30 s; the 3×3 block and 121 × 68 matrix; min J at 2 min J; 20 s of video; "
        "`--older-than 12h` and `--t-max 2`; exact 1s; drift cut 7–19× at equal tolerance; T = 30.\n"
        "```\nreal 0.3 s\n```\n<!-- numbers: x -->\nintegration 4.7 ms\n<!-- /numbers -->\n")
    check(quiet == [], "the timing pattern flags what is no measurement: %s" % [f for _, f, _ in quiet])


def test_readme_packages_are_make_deps():
    with open(os.path.join(ROOT, "Makefile")) as fh:
        m = re.search(r"^DEB_PKGS\s*:=\s*(.*)$", fh.read(), re.M)
    readme = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    listed = re.search(r"installs the Debian packages it needs\s*\(`([^`]*)`", readme)
    check(m is not None and listed is not None and listed.group(1).split() == m.group(1).split(),
          "README's package list %s is not make deps' DEB_PKGS %s" % (
              listed and listed.group(1).split(), m and m.group(1).split()))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_docs"))
