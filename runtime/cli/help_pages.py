#!/usr/bin/env python3
"""The man page swim(1) and the bash completion of swim, made from the program's own help.

    help_pages.py SWIM --man FILE --completion FILE

`swim --help` gives the commands; `swim CMD --help` gives each command's synopsis and its
options, printed from the table its parser uses (runtime/cli/args.h), so neither file can list an
option the program does not take or miss one it does. Run by the Makefile after bin/swim is
built; installed by `make install` (share/man/man1, share/bash-completion/completions)."""

import re
import subprocess
import sys

OPTION = re.compile(r"^  --([a-z0-9-]+)(?: (.+?))?( \(repeatable\))?$")


def helptext(swim, *args):
    p = subprocess.run([swim, *args], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("help_pages: %s %s exited with %d: %s" % (swim, " ".join(args), p.returncode, p.stderr.strip()))
    return p.stdout


def commands(swim):
    """(name, one-line summary) of every command, in `swim --help`'s order."""
    out = []
    for line in helptext(swim, "--help").splitlines():
        m = re.match(r"^  ([a-z]+) +(.+)$", line)
        if m:
            out.append((m.group(1), m.group(2)))
    return out


def parse_command(text):
    """The synopsis lines (before "options:") and the options [(name, arg, repeatable, help)]."""
    head, _, body = text.partition("\noptions:\n")
    options, current = [], None
    for line in body.splitlines():
        m = OPTION.match(line)
        if m:
            current = [m.group(1), m.group(2) or "", bool(m.group(3)), []]
            options.append(current)
        elif current is not None and line.startswith("      "):
            current[3].append(line.strip())
        elif line.strip():
            current = None   # a note after the list
    return head.strip(), [(n, a, r, " ".join(h)) for n, a, r, h in options]


def roff(text):
    return text.replace("\\", "\\e").replace("-", "\\-").replace("\n.", "\n\\&.")


def man_page(swim, version, cmds):
    out = ['.TH SWIM 1 "" "swim %s" "User Commands"' % version,
           ".SH NAME", "swim \\- a deformable swimmer in a 2D perfect fluid, from symbols to C",
           ".SH SYNOPSIS", ".B swim", "\\fICOMMAND\\fR [\\fIoptions\\fR]", ".br", ".B swim --version",
           ".SH DESCRIPTION",
           roff("swim simulates the hyperelastic swimmer of Munnier's paper: a SymPy generator derives the "
                "mass matrices and the Christoffel symbol of N modes and emits C kernels; a C runtime "
                "integrates the equations of motion. A scene is a TOML file (models/README.md lists its keys; "
                "installed: PREFIX/share/swim/models/README.md)."),
           ".SH COMMANDS"]
    for name, summary in cmds:
        head, options = parse_command(helptext(swim, name, "--help"))
        out += [".SS %s" % roff(name), roff(summary), ".PP", ".nf", roff(head), ".fi"]
        for opt, arg, repeat, text in options:
            out += [".TP", "\\fB\\-\\-%s\\fR%s%s" % (roff(opt), " \\fI%s\\fR" % roff(arg) if arg else "",
                                                    " (repeatable)" if repeat else ""), roff(text)]
    out += [".SH ENVIRONMENT",
            ".TP", ".B SWIM_CACHE", roff("the kernel cache (default ~/.cache/swim; `swim cache path` prints it)"),
            ".TP", ".B SWIM_SHARE", roff("the generator and kernel headers (default: ../share/swim beside the program)"),
            ".TP", ".B SWIM_PYTHON", roff("the Python with SymPy that generates kernels (default python3)"),
            ".SH FILES",
            ".TP", ".I PREFIX/share/swim/models/", roff("the example scenes (models/README.md lists a scene's keys); "
                                                      "PREFIX is the folder above the installed bin/swim"),
            ".TP", ".I PREFIX/share/doc/swim/", roff("the documentation: README.md and docs/ (run-driver.md, "
                                                   "library.md, families.md, ...)"),
            ".SH EXIT STATUS", roff("0 success; 1 a run or an output that failed (said on stderr); "
                                    "2 bad input (one line naming the file, key or option)."),
            ".SH SEE ALSO", roff("The docs/ folder (installed: PREFIX/share/doc/swim/docs/): run-driver.md (the commands and their "
                                 "outputs), library.md (libswim), families.md, integrators-and-events.md.")]
    return "\n".join(out) + "\n"


def completion(swim, cmds, integrators):
    cases = []
    for name, _ in cmds:
        _, options = parse_command(helptext(swim, name, "--help"))
        words = " ".join("--" + o[0] for o in options) + " --help"
        cases.append("        %s) opts=\"%s\" ;;" % (name, words))
    return """# bash completion of swim (made by runtime/cli/help_pages.py from swim's own help)
_swim()
{
    local cur prev opts
    cur="${COMP_WORDS[COMP_CWORD]}"
    prev="${COMP_WORDS[COMP_CWORD-1]}"
    if [ "$COMP_CWORD" -eq 1 ]; then
        COMPREPLY=($(compgen -W "%s --help --version" -- "$cur"))
        return
    fi
    case "$prev" in
        --integrator) COMPREPLY=($(compgen -W "%s" -- "$cur")); return ;;
        --format) COMPREPLY=($(compgen -W "csv hdf5" -- "$cur")); return ;;
        --keep) COMPREPLY=($(compgen -W "summaries trajectories" -- "$cur")); return ;;
    esac
    case "${COMP_WORDS[1]}" in
%s
        *) opts="" ;;
    esac
    if [[ "$cur" == --* ]]; then
        COMPREPLY=($(compgen -W "$opts" -- "$cur"))
    else
        COMPREPLY=($(compgen -f -- "$cur"))
    fi
}
complete -o filenames -F _swim swim
""" % (" ".join(n for n, _ in cmds), " ".join(integrators), "\n".join(cases))


def integrator_names(swim):
    """The registry's names, from the help of --integrator ("one of abm, rk8pd, ... (default")."""
    _, options = parse_command(helptext(swim, "run", "--help"))
    text = dict((o[0], o[3]) for o in options)["integrator"]
    m = re.search(r"one of (.+?) \(", text)
    return [w.strip() for w in m.group(1).split(",")] if m else []


def main(argv):
    if len(argv) != 5 or argv[1] != "--man" or argv[3] != "--completion":
        sys.exit(__doc__.strip())
    swim = argv[0]
    version = helptext(swim, "--version").split()[-1]
    cmds = commands(swim)
    with open(argv[2], "w") as fh:
        fh.write(man_page(swim, version, cmds))
    with open(argv[4], "w") as fh:
        fh.write(completion(swim, cmds, integrator_names(swim)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
