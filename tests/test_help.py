"""Help that is complete: `swim CMD --help` of every command lists every option its parser
accepts -- the rows of its option table, the repeatable options a command takes out of argv
itself (swim_args_take_all / take_sets in its source), and for plot and animate the options their
scripts parse -- each with a line of help; every listed option is accepted (no "unknown option");
--integrator names every integrator of the registry; `swim run --quiet` prints nothing but
errors; `swim --version` is VERSION's; the man page and the bash completion made from the help
name every command and option."""

import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import ROOT, SWIM, TMP, check, swim  # noqa: E402

CLI = os.path.join(ROOT, "runtime", "cli")
# the source file that parses each command's options
SOURCES = {"inspect": ["inspect.c"], "run": ["run.c", "run_settings.c"], "flow": ["flow.c"],
           "sweep": ["sweep_args.c"], "floquet": ["floquet.c"], "optimize": ["optimize.c"],
           "cache": ["cache.c"], "export": ["export.c"], "periodic": ["periodic.c"], "continue": ["continue.c"],
           "plot": ["../plot/plot_run.py"], "animate": ["../plot/animate_run.py"]}
OPTION = re.compile(r"^  --([a-z0-9-]+)(?: (.+?))?( \(repeatable\))?$")


def commands():
    p = swim("--help")
    return [m.group(1) for m in (re.match(r"^  ([a-z]+) +\S", ln) for ln in p.stdout.splitlines()) if m]


def listed(cmd):
    """{option: help text} of `swim CMD --help`, and the process."""
    p = swim(cmd, "--help")
    opts, cur = {}, None
    for line in p.stdout.partition("\noptions:\n")[2].splitlines():
        m = OPTION.match(line)
        if m:
            cur = m.group(1)
            opts[cur] = ""
        elif cur and line.startswith("      "):
            opts[cur] += " " + line.strip()
        else:
            cur = None
    return opts, p


def accepted(cmd):
    """The options the command's parser takes, read from its source."""
    names = set()
    for f in SOURCES.get(cmd, []):
        text = open(os.path.join(CLI, f)).read()
        if f.endswith(".py"):
            names |= set(re.findall(r'take_values\(argv, "([a-z-]+)"', text))
            names |= set(re.findall(r'a == "--([a-z-]+)"', text))
            m = re.search(r"opts = \{([^}]*)\}", text)
            if m:
                names |= set(re.findall(r'"([a-z-]+)":', m.group(1)))
            continue
        names |= set(re.findall(r'\{"([a-z][a-z0-9-]*)", [012], NULL', text))
        names |= set(re.findall(r'swim_args_take_all\([^;]*?,\s*(?:\d+|first),\s*"([a-z-]+)"', text, re.S))
        if "swim_args_take_sets(" in text:
            names.add("set")
        if "swim_run_settings_key_options(" in text:
            names.add("step-lookahead")   # the plain scene keys with an option (scene/keys.c)
    names.discard("help")
    return names


def test_every_command_lists_every_option():
    cmds = commands()
    check(set(SOURCES) <= set(cmds), "swim --help lists every command: %s" % cmds)
    for cmd in cmds:
        opts, p = listed(cmd)
        check(p.returncode == 0 and p.stdout.startswith("swim %s:" % cmd), "swim %s --help: exit 0 (%d)" % (cmd, p.returncode))
        want = accepted(cmd)
        check(want and want <= set(opts), "swim %s --help lists every option the parser takes; missing %s"
              % (cmd, sorted(want - set(opts))))
        check(all(len(t.strip()) > 10 and "undocumented" not in t for t in opts.values()),
              "swim %s --help: every option has its meaning: %s" % (cmd, [o for o, t in opts.items() if len(t.strip()) <= 10]))


def test_top_level_help_names_every_option():
    """`swim --help`'s synopsis of each command names every option of `swim CMD --help`."""
    p = subprocess.run([SWIM, "--help"], capture_output=True, text=True, cwd=ROOT, timeout=60)
    blocks = re.split(r"\n  (?=[a-z]+ )", "\n" + p.stdout.split("\ncommands:\n", 1)[-1])
    block = {b.split(" ", 1)[0]: b for b in blocks if b.strip()}
    for cmd in commands():
        text = block.get(cmd, "")
        named = set(re.findall(r"--([a-z][a-z0-9-]*)", text))
        if "[run options]" in text:       # sweep: the options of swim run, named there
            named |= set(re.findall(r"--([a-z][a-z0-9-]*)", block.get("run", "")))
        opts, _ = listed(cmd)
        missing = sorted(set(opts) - named - {"help"})
        check(text and not missing, "swim --help on %s does not name %s" % (cmd, ["--" + m for m in missing]))


def test_listed_options_are_accepted():
    for cmd in commands():
        opts, _ = listed(cmd)
        for opt in opts:
            p = subprocess.run([SWIM, cmd, "--" + opt, "x", "/nonexistent/scene.toml"], capture_output=True,
                               text=True, cwd=ROOT, timeout=60)
            check("unknown option" not in p.stderr, "swim %s --%s is accepted by the parser: %r" % (cmd, opt, p.stderr[-200:]))


def test_integrators_and_defaults():
    opts, _ = listed("run")
    p = swim("run", "--integrator", "bogus", "models/example3.toml")
    names = re.search(r"\(([a-z0-9, -]+)\)", p.stderr).group(1).split(", ")
    check(len(names) >= 5 and all(n in opts["integrator"] for n in names),
          "--integrator's help names the registry's integrators %s: %r" % (names, opts["integrator"]))
    check("default" in opts["rtol"] and "1e-8" in opts["rtol"], "defaults are given: %r" % opts["rtol"])
    check("zero, min or max" in opts["event"], "event kinds are given: %r" % opts["event"])


def test_quiet_prints_nothing():
    out = os.path.join(TMP, "quiet")
    p = swim("run", "models/example3.toml", "--out", out, "--t-end", "0.2", "--quiet")
    check(p.returncode == 0 and p.stdout == "" and p.stderr == "", "--quiet: nothing printed: %r %r" % (p.stdout, p.stderr))
    # a run that fails (the shape leaves D, as in test_sweep): one line on stderr, exit 1
    p = swim("run", "models/example1.toml", "--out", out, "--t-end", "5", "--set", "shape.c0.am1=0.8", "--quiet")
    check(p.returncode == 1 and p.stdout == "" and swimtest.one_line(p) and "FAILED" in p.stderr,
          "--quiet: a failed run is one line on stderr: %r %r" % (p.stdout, p.stderr))


def test_version():
    p = swim("--version")
    with open(os.path.join(ROOT, "VERSION")) as fh:
        check(p.returncode == 0 and p.stdout.strip() == "swim " + fh.read().strip(), "swim --version: %r" % p.stdout)


def test_man_page_and_completion():
    d = tempfile.mkdtemp(dir=TMP)
    man, comp = os.path.join(d, "swim.1"), os.path.join(d, "swim.bash")
    p = subprocess.run(["/usr/bin/python3", os.path.join(CLI, "help_pages.py"), SWIM, "--man", man, "--completion", comp],
                       capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "help_pages.py: %s" % p.stderr[-300:])
    if p.returncode:
        return
    page, words = open(man).read(), open(comp).read()
    for cmd in commands():
        opts, _ = listed(cmd)
        check(".SS %s" % cmd in page, "the man page has a section for %s" % cmd)
        missing = [o for o in opts if "\\-\\-%s" % o.replace("-", "\\-") not in page or "--" + o not in words]
        check(not missing, "man page and completion list every option of %s: missing %s" % (cmd, missing))
    b = subprocess.run(["bash", "-c", "source %s; COMP_WORDS=(swim ru); COMP_CWORD=1; _swim; echo ${COMPREPLY[@]}; "
                        "COMP_WORDS=(swim run --rt); COMP_CWORD=2; _swim; echo ${COMPREPLY[@]}" % comp],
                       capture_output=True, text=True)
    check(b.stdout.split("\n")[:2] == ["run", "--rtol"], "bash completes a command and an option: %r" % b.stdout)
    m = subprocess.run(["man", "-l", "-P", "cat", man], capture_output=True, text=True,
                       env=dict(os.environ, MANWIDTH="100"))
    check(m.returncode != 0 or "--sensitivity-steps" in m.stdout, "man renders the page: %r" % m.stderr[-200:])


sys.exit(swimtest.main(globals(), "test_help"))
