#!/usr/bin/env python3
"""The layers of runtime/ only call down (docs/run-driver.md):
  - no file below cli/ includes a cli/ header or calls a command (swim_cmd_*); mpi/ is a program's
    front end and may read its command line with cli/sweep_args.h and take the program's signal policy from
    cli/run_signals.h, nothing else of cli/;
  - the run driver (driver/) prints nothing and exits nowhere: lines leave through its sink; the
    analyses (control/) and the sweep (sweep/) print nothing either: statuses and callbacks;
  - no integrator is tested by name outside the integrator registry (ode/): capabilities decide;
  - the driver's include graph has no cycle (a module: x.c with x.h and x_internal.h);
  - the command layer stays a command layer: runtime/cli/ at most 3 000 lines;
  - a problem is built in one place (docs/run-driver.md): problem/ sits below the driver and above
    scene/, codegen/ and model/ (it includes none of the layers above it, and none below includes
    it), and nothing else asks codegen for a scene's kernels (swim_codegen_for_scene).
  - every integration of a scene is a driver run: no file in control/ or output/ creates or
    advances an integrator (the orbit analyses and optimize's gradient use driver/flow.h).
Prints "test_layering: P passed, F failed"."""
import glob
import os
import re
import sys

import swimtest
from swimtest import ROOT, check

INTEGRATORS = ("abm", "rk8pd", "msadams", "rkf45", "msbdf", "cvode-adams", "cvode-bdf")


def sources(folder=""):
    for p in sorted(glob.glob(os.path.join(ROOT, "runtime", folder, "**", "*.[ch]"), recursive=True)):
        yield os.path.relpath(p, ROOT), open(p, encoding="utf-8").read()


def code(text):
    """The text without comments and string literals (what the compiler sees as calls)."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    return re.sub(r'"(\\.|[^"\\])*"', '""', text)


def test_nothing_below_cli_reaches_up():
    below = [(p, t) for p, t in sources() if not p.startswith("runtime/cli/")]
    check(len(below) > 50, "the runtime's files are found (%d)" % len(below))
    for path, text in below:
        includes = re.findall(r'#include\s+"(cli/[^"]+)"', text)
        allowed = {"cli/sweep_args.h", "cli/run_signals.h", "cli/report.h"} if path.startswith("runtime/mpi/") else set()
        if path == "runtime/export/simulate.c":   # a program (main), reading swim run's options with its code
            allowed = {"cli/args.h", "cli/run_settings.h", "cli/report.h"}
        bad = [h for h in includes if h not in allowed]
        check(not bad, "%s includes %s" % (path, ", ".join(bad)))
        calls = re.findall(r"\bswim_cmd_\w+", code(text))
        check(not calls, "%s calls a command: %s" % (path, ", ".join(sorted(set(calls)))))


def test_driver_prints_nothing():
    for path, text in sources("driver"):
        c = code(text)
        for pat in (r"\bswim_message\s*\(", r"\bprintf\s*\(", r"\bputs\s*\(", r"\bexit\s*\(", r"\bstderr\b",
                    r"\bstdout\b", r"\babort\s*\("):
            check(not re.search(pat, c), "%s: %s" % (path, pat))


def test_analyses_and_sweep_print_nothing():
    # control/ (the analyses: orbits, sensitivities, optimize) and sweep/ fill statuses and hand
    # notices and progress to their caller; the commands print. sweep/ checks the command's report
    # on stdout (flush and close) and writes a member's refusal into that member's log file.
    for folder in ("control", "sweep"):
        for path, text in sources(folder):
            c = code(text)
            pats = [r"\bstderr\b", r"\bprintf\s*\(", r"\bputs\s*\(", r"\bexit\s*\(", r"\babort\s*\(",
                    r"\bswim_message\s*\(\s*std(err|out)\b", r"\bfprintf\s*\(\s*std(err|out)\b"]
            if folder == "control":
                pats += [r"\bstdout\b", r"\bswim_message\s*\("]
            for pat in pats:
                check(not re.search(pat, c), "%s: %s" % (path, pat))


def test_no_integrator_named():
    names = "|".join(re.escape(n) for n in INTEGRATORS)
    for path, text in sources():
        if path.startswith("runtime/ode/"):
            continue
        hits = re.findall(r'strn?cmp\s*\([^;]*"(%s)"' % names, text)
        check(not hits, "%s tests an integrator by name: %s" % (path, ", ".join(hits)))
        creates = re.findall(r'swim_ode_create\s*\(\s*"(%s)"' % names, text)
        check(not creates, "%s hard-codes integrator %s" % (path, ", ".join(creates)))


def module_of(path):
    """driver/run.c, driver/run.h and driver/run_internal.h are one module, driver/run."""
    stem = os.path.splitext(path)[0]
    return stem[:-len("_internal")] if stem.endswith("_internal") else stem


def cycle(edges):
    """A cycle of the directed graph {node: set(nodes)} as a list of nodes, or None."""
    state, stack = {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(edges.get(n, ())):
            if state.get(m) == 1:
                return stack[stack.index(m):] + [m]
            if m not in state:
                found = visit(m)
                if found:
                    return found
        stack.pop()
        state[n] = 2
        return None

    for n in sorted(edges):
        if n not in state:
            found = visit(n)
            if found:
                return found
    return None


def test_driver_include_graph_has_no_cycle():
    # the check itself: a cycle through a header and a source of another module is found
    check(cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"] and cycle({"a": {"b"}, "b": set()}) is None,
          "the cycle finder finds a cycle and only a cycle")
    edges = {}
    for path, text in sources("driver"):
        here = module_of(os.path.relpath(path, "runtime"))
        for inc in re.findall(r'#include\s+"(driver/[^"]+)"', code_keep_strings(text)):
            there = module_of(inc)
            if there != here:
                edges.setdefault(here, set()).add(there)
    check(len(edges) >= 4, "the driver's modules and their includes are found (%d)" % len(edges))
    found = cycle(edges)
    check(found is None, "the driver's include graph has a cycle: %s" % " -> ".join(found or []))


def code_keep_strings(text):
    """The text without comments (include directives keep their quoted names)."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", " ", text)


def test_cli_is_small():
    lines = sum(t.count("\n") for _, t in sources("cli"))
    # 3300: inspect --energy, the commands' up-front --out and range checks, the printing of
    # statuses the layers below return instead of printing (io/status.h) and the programs' own
    # printing helpers (cli/report.c, moved up from io/); the option parsing of the run settings
    # (cli/run_settings.c) is what could move below next
    check(0 < lines <= 3300, "runtime/cli/ has %d lines (at most 3300)" % lines)


ABOVE_PROBLEM = ("cli", "mpi", "output", "sweep", "driver", "control", "lib", "export")
BELOW_PROBLEM = ("scene", "codegen", "model", "ode", "shape", "stroke", "io", "kernel")


def test_problem_in_its_layer():
    files = list(sources("problem"))
    check(len(files) >= 2, "runtime/problem/ is found (%d files)" % len(files))
    for path, text in files:
        ups = [h for h in re.findall(r'#include\s+"(\w+)/[^"]+"', text) if h in ABOVE_PROBLEM]
        check(not ups, "%s includes a layer above it: %s" % (path, ", ".join(ups)))
    for folder in BELOW_PROBLEM:
        for path, text in sources(folder):
            check('#include "problem/' not in text, "%s (below problem/) includes problem/" % path)


def test_kernels_of_a_scene_in_one_place():
    for path, text in sources():
        # codegen/ defines it; export/kernels.c is its stand-in in an exported tree
        if path.startswith(("runtime/codegen/", "runtime/problem/")) or path == "runtime/export/kernels.c":
            continue
        calls = re.findall(r"\bswim_codegen_for_scene\s*\(", code(text))
        check(not calls, "%s asks for a scene's kernels itself (use problem/problem.h)" % path)



def test_integrators_only_in_the_driver():
    found = 0
    for folder in ("control", "output"):
        for path, text in sources(folder):
            found += 1
            calls = re.findall(r"\bswim_ode_(create|advance)\s*\(", code(text))
            check(not calls, "%s integrates itself (swim_ode_%s): use a driver run (driver/flow.h)"
                  % (path, ", swim_ode_".join(sorted(set(calls)))))
    check(found > 5, "control/ and output/ are found (%d files)" % found)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_layering"))
