"""Prescribed strokes (section 3.3, (3.21)): the laws c_i(t) of a scene's [stroke] table and their
exact first and second time derivatives, emitted as one C function.

With the shape prescribed, the rigid motion follows from (3.21) alone: q* = -Mr^-1 N c'. The
runtime (runtime/stroke/) takes Mr^-1 N and K from the kernel of N modes; this file supplies
c(t), c'(t) -- which (3.21) needs exactly, so they are differentiated here by SymPy and never by
differences -- and c''(t), which the power the body spends, c'.(K c'' + <Gamma, c', c'>), needs.
c(t) itself is printed from the law's tree (law.py, Law.c): the function the runtime's
interpreter validated, bit for bit; SymPy's expression (Law.sympy, the same doubles as numbers)
serves only the derivatives.

structure (JSON written by runtime/codegen):
    {"format": 1, "key": str, "modes": N, "laws": [[index, "law in t"], ...],
     "parameters": ["name", ...]}
`parameters` are named numbers a law may use; their values come at run time (par[i] in the
order of the list), so that changing them never regenerates the kernel.
"""

import sympy as sp

from .cprint import KernelPrinter, emit_assignments
from .emit import banner, c_string
from .law import LawError, parse

STROKE_FORMAT = 1

# A derivative that SymPy can only leave unevaluated (or as a distribution) has no C form: the
# law is then not twice differentiable, which a stroke must be (c'' enters the power).
_NOT_SMOOTH = (sp.Derivative, sp.Subs, sp.DiracDelta, sp.Heaviside)


def _smooth(expr):
    from .law import Step
    return not any(expr.has(kind) for kind in _NOT_SMOOTH + (Step,))


def stroke_laws(structure, t, params):
    """[(index, law, c, c', c'')] of the prescribed coordinates: the Law (its value is printed
    from it, operation for operation, as the runtime's interpreter computes it) and c, c', c''
    as SymPy expressions."""
    out = []
    for index, text in structure["laws"]:
        law = parse(text, list(params))
        c = law.sympy(t, params)
        dc = sp.diff(c, t)
        ddc = sp.diff(dc, t)
        if not _smooth(ddc):
            err = LawError("\"%s\" is not twice differentiable in t (step, or abs at a kink, "
                           "perhaps hidden as sqrt(u^2)): a stroke needs c'' for its power" % text)
            err.index = int(index)
            raise err
        out.append((int(index), law, c, dc, ddc))
    return out


def stroke_kernel_source(structure, command):
    if structure.get("format") != STROKE_FORMAT:
        raise ValueError("stroke structure format %r, expected %d" % (structure.get("format"),
                                                                      STROKE_FORMAT))
    modes = int(structure["modes"])
    t = sp.Symbol("t", real=True)
    names = [str(p) for p in structure.get("parameters", [])]
    params = {name: sp.Symbol("par_%s" % name, real=True) for name in names}
    laws = stroke_laws(structure, t, params)
    if not laws:
        raise ValueError("a stroke needs at least one prescribed coordinate")
    printed = {t: "t"}
    law_names = {"t": "t"}
    for i, name in enumerate(names):
        printed[params[name]] = "par[%d]" % i
        law_names[name] = "par[%d]" % i
    pr = KernelPrinter(printed)
    rows = []
    for k, (_, _, _, dc, ddc) in enumerate(laws):
        rows += [("dc[%d]" % k, dc), ("ddc[%d]" % k, ddc)]
    # c itself as the interpreter that validated it computes it; its derivatives from SymPy
    lines = ["    c[%d] = %s;" % (k, law.c(law_names)) for k, (_, law, _, _, _) in enumerate(laws)]
    lines += emit_assignments(rows, pr)
    body = "\n".join(lines)
    unused = "".join("    (void)%s;\n" % a for a in ("t", "par")
                     if not any(_uses(l, a) for l in lines))
    return STROKE_TEMPLATE.format(
        banner=banner(command), modes=modes, count=len(laws), nparams=len(names),
        index=", ".join(str(i) for i, _, _, _, _ in laws),
        laws="\n".join(" *   x[%d] = %s" % (i, _comment(text))
                       for (i, text) in structure["laws"]),
        key=c_string(structure["key"]), body=unused + body)


def _uses(line, name):
    import re
    return re.search(r"(?<![A-Za-z0-9_])%s(?![A-Za-z0-9_])" % name, line.split("=", 1)[-1]) is not None


def _comment(text):
    return "".join(ch if " " <= ch <= "~" else "?" for ch in text).replace("*/", "* /")


STROKE_TEMPLATE = """\
/* stroke kernel -- the prescribed shape coordinates of one stroke, with exact derivatives.
 *
 * {banner}
 *
 * Laws (index into the shape vector (a1, b1, a-1, b-1, ...)):
{laws}
 */
#include <math.h>

#include "kernel/law_functions.h"
#include "kernel/stroke_kernel.h"

static const int stroke_index[{count}] = {{{index}}};

/* c, c' and c'' of each prescribed coordinate at time t (par: the parameters' values). */
static void stroke_eval(double t, const double *par, double *c, double *dc, double *ddc)
{{
{body}
}}

const swim_stroke_kernel swim_stroke_kernel_entry = {{
    .abi = SWIM_STROKE_ABI,
    .modes = {modes},
    .count = {count},
    .index = stroke_index,
    .nparams = {nparams},
    .structure = "{key}",
    .eval = stroke_eval,
}};
"""
