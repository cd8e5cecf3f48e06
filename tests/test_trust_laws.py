#!/usr/bin/env python3
"""Is the law that runs the law that was validated? The runtime checks a forcing or stroke law
with its interpreter (runtime/scene/expr.c); the kernel computes it from the generator's C
(generator/swimgen/law.py). Checks:
- the two compute the same function, bit for bit: random laws over the whole grammar (big
  integers, powers, rationals, hex, every function, parameters), each printed by the generator's
  law printer, compiled with the kernels' flags beside the interpreter's own object and evaluated
  by both at several t, huge arguments of trigonometric functions included; and a stroke kernel
  generated for some of them gives the same c(t);
- end to end: 10^20 in a law is 1e20 (not an integer cut by the compiler), sin(1e23) and
  sin(pi*1e17) are the C library's values, in forcing and stroke laws alike;
- a law with a part that is not a finite real number (sqrt(-1), log(0), step(sqrt(-1))) is bad
  input: exit status 2, one line naming the file, the key and the law, no kernel generated.
Prints "test_trust_laws: P passed, F failed".
"""

import math
import os
import random
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import ROOT, SWIM, TMP, check, main  # noqa: E402

sys.path.insert(0, os.path.join(ROOT, "generator"))
from swimgen.law import LawError, parse  # noqa: E402
from swimgen.stroke import stroke_kernel_source  # noqa: E402

BASE = open(os.path.join(ROOT, "models", "example3.toml")).read()
FORCING = '\n[forcing]\nlaw = "%s"\ndirection = [0,0,1,0,0,1,0,0,0,0,0,0,0,0,0,0]\n'
KERNEL_CFLAGS = ["-O3", "-march=native", "-std=c11"]   # SWIM_KERNEL_CFLAGS and codegen's -std
PARAMS = {"A": 0.75, "B": -2.5}
TIMES = [0.0, 0.5, 1.3, 2.75, 10.0, -1.5, 1e3, 1e6, 3.5e15]
LAW_NAMES = {"t": "t", "A": "par[0]", "B": "par[1]"}   # the C of t and of the parameters


def scene(name, text):
    path = os.path.join(TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


def swim(*args, env=None):
    return subprocess.run([SWIM, *args], capture_output=True, text=True, cwd=ROOT, env=env)


def stroke_scene(laws, t_end=2.0):
    body = "".join('%s = "%s"\n' % kv for kv in laws.items())
    return ("[model]\nmodes = 2\nrho0 = 1.0\nrhof = 1.0\n\n[shape]\nc0 = [1, 0, 0, 0, 0, 0]\n\n"
            "[stroke]\n%s\n[run]\nt_end = %r\noutput_step = 0.05\nrtol = 1e-10\natol = 1e-12\n"
            % (body, t_end))


# ---- random laws ---------------------------------------------------------------------------------

NUMBERS = ["0", "1", "2", "3", "10", "0.1", "1.5", ".5", "2.5e-3", "1e23", "1e300", "7e-310",
           "100000000000000000000", "18446744073709551617", "123456789012345678901234567890",
           "0x1.8p3", "0x10", "3.14159", "1e20", "4e15", "0.3333333333333333333"]
FUNCS = ["sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "sqrt", "abs", "sinh", "cosh",
         "tanh", "step"]


def random_law(rng, depth):
    """A law over the interpreter's grammar, written with random spacing and redundant signs."""
    r = rng.random()
    if depth == 0 or r < 0.2:
        leaf = rng.choice(NUMBERS + ["t", "t", "t", "pi", "e", "A", "B"])
        return leaf
    if r < 0.45:
        return "%s(%s)" % (rng.choice(FUNCS), random_law(rng, depth - 1))
    if r < 0.55:
        return "%s%s" % (rng.choice("-+"), random_law(rng, depth - 1))
    if r < 0.65:
        return "(%s)" % random_law(rng, depth - 1)
    op = rng.choice(["+", "-", "*", "/", "^", "*", "^"])
    gap = rng.choice(["", " "])
    return "%s%s%s%s%s" % (random_law(rng, depth - 1), gap, op, gap, random_law(rng, depth - 1))


def random_laws(count, seed):
    rng = random.Random(seed)
    laws = ["sin(t)*10^20/(1e20+t)", "sin(1e23)+t", "sin(pi*1e17)*t", "cos(10^22)*t", "t^2",
            "t^-1", "2^-t", "(t+1e20)-1e20", "0.1*3*t", "t*0.1*3", "sin(1e22*t)",
            "1/3*t", "10^20*t/10^20", "exp(log(t))", "tan(pi/2)*t", "(-8)^(1/3)+t", "step(t-1)*abs(t)"]
    while len(laws) < count:
        laws.append(random_law(rng, rng.randint(1, 5)))
    return laws


def c_string(text):
    return '"%s"' % text.replace("\\", "\\\\").replace('"', '\\"')


def interpreter_object():
    """The interpreter as bin/swim has it (the build's object), else its source."""
    obj = os.path.join(ROOT, "build", "runtime", "scene", "expr.o")
    return obj if os.path.exists(obj) else os.path.join(ROOT, "runtime", "scene", "expr.c")


def harness(laws, printed):
    """C program: for each law, the interpreter's value and the compiled law's at each t, as
    hex bit patterns (NaN as "nan": its payload is not part of the function)."""
    fns = "\n".join("static double law%d(double t, const double *par) { (void)t; (void)par; return %s; }"
                    % (k, c.replace("\n", " ")) for k, c in enumerate(printed))
    return """#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include "kernel/law_functions.h"
#include "scene/expr.h"
%s
typedef double (*law_fn)(double, const double *);
static const law_fn fn[] = {%s};
static const char *const text[] = {%s};
static void bits(double v) { uint64_t u; memcpy(&u, &v, 8); if (isnan(v)) printf(" nan"); else printf(" %%016llx", (unsigned long long)u); }
int main(void)
{
    static const char *const names[] = {"A", "B"};
    const double par[] = {%r, %r}, ts[] = {%s};
    for (size_t k = 0; k < sizeof fn / sizeof fn[0]; k++) {
        char err[200];
        swim_expr *e = swim_expr_compile_params(text[k], names, 2, par, err, sizeof err);
        if (!e) { printf("%%zu refused %%s\\n", k, err); continue; }
        for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
            printf("%%zu", k); bits(swim_expr_eval(e, ts[i])); bits(fn[k](ts[i], par));
            printf(" %%d\\n", swim_expr_defined(e, ts[i], NULL, 0));
        }
        swim_expr_free(e);
    }
    return 0;
}
""" % (fns, ", ".join("law%d" % k for k in range(len(printed))), ", ".join(c_string(x) for x in laws),
       PARAMS["A"], PARAMS["B"], ", ".join(repr(t) for t in TIMES))


def build_and_run(source, name, extra=()):
    d = os.path.join(TMP, name)
    os.makedirs(d, exist_ok=True)
    src, exe = os.path.join(d, "h.c"), os.path.join(d, "h")
    with open(src, "w") as fh:
        fh.write(source)
    p = subprocess.run(["cc", *KERNEL_CFLAGS, "-I" + os.path.join(ROOT, "runtime"), "-o", exe, src,
                        *extra, interpreter_object(), "-lm"], capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr[-2000:]
    return subprocess.run([exe], capture_output=True, text=True).stdout, ""


def test_random_laws_interpreter_equals_compiled():
    """400 random laws: the generator's C and the interpreter agree bit for bit wherever the law is
    defined (NaN where it is not), and the generator refuses exactly the laws that are defined
    nowhere because a constant part is not finite."""
    laws = random_laws(400, 20261202)
    kept, printed, refused = [], [], []
    for text in laws:
        try:
            printed.append(parse(text, list(PARAMS)).c(LAW_NAMES))
            kept.append(text)
        except LawError:
            refused.append(text)
    check(len(kept) > 250, "random laws: only %d of %d printed" % (len(kept), len(laws)))
    source = harness(kept + refused, printed + ["0.0"] * len(refused))
    out, err = build_and_run(source, "random_laws")
    check(out is not None, "random laws: harness does not compile: %s" % err)
    if out is None:
        return
    mismatches, compared = [], 0
    for line in out.splitlines():
        parts = line.split()
        k = int(parts[0])
        if parts[1] == "refused":
            mismatches.append("interpreter refuses %r, the generator printed it" % (kept + refused)[k])
            continue
        interp, comp, defined = parts[1], parts[2], parts[3] == "1"
        if k >= len(kept):   # refused by the generator: the interpreter must find it undefined
            if defined:
                mismatches.append("generator refused %r, the interpreter finds it defined" % refused[k - len(kept)])
            continue
        compared += 1
        if interp != comp:
            mismatches.append("%r: interpreter %s, compiled %s" % (kept[k], interp, comp))
    check(not mismatches, "random laws: %d mismatches, e.g. %s" % (len(mismatches), mismatches[:3]))
    check(compared >= 250 * len(TIMES), "random laws: only %d comparisons" % compared)


def test_stroke_kernel_law_equals_interpreter():
    """The generated stroke kernel (stroke_kernel_source, the code path of swim run) gives c(t) as
    the interpreter computes it, for laws with big integers, huge trig arguments and rationals."""
    laws = ["0.4*cos(t)*10^20/(1e20+t)", "sin(1e23)*t^2/3", "sin(pi*1e17)*sin(t)", "cos(10^22)*exp(-t)",
            "0.1*3*t", "(t+1e20)-1e20+A*sin(B*t)", "1/3*t^(5/2)", "atan(t)^2*18446744073709551617/1e19"]
    structure = {"format": 1, "key": "test", "modes": 3, "laws": [[i + 2, x] for i, x in enumerate(laws)],
                 "parameters": ["A", "B"]}
    src = stroke_kernel_source(structure, "test_trust_laws")
    body = src + """
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include "scene/expr.h"
int main(void)
{
    static const char *const names[] = {"A", "B"};
    static const char *const text[] = {%s};
    const double par[] = {%r, %r}, ts[] = {%s};
    double c[16], dc[16], ddc[16];
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        stroke_eval(ts[i], par, c, dc, ddc);
        for (int k = 0; k < %d; k++) {
            char err[200];
            swim_expr *e = swim_expr_compile_params(text[k], names, 2, par, err, sizeof err);
            double v = swim_expr_eval(e, ts[i]);
            uint64_t a, b;
            memcpy(&a, &v, 8);
            memcpy(&b, &c[k], 8);
            printf("%%d %%g %%s\\n", k, ts[i], a == b || (v != v && c[k] != c[k]) ? "same" : "differ");
            swim_expr_free(e);
        }
    }
    return 0;
}
""" % (", ".join(c_string(x) for x in laws), PARAMS["A"], PARAMS["B"],
       ", ".join(repr(t) for t in TIMES[:6]), len(laws))
    out, err = build_and_run(body, "stroke_kernel", ["-Wno-unused-function"])
    check(out is not None, "stroke kernel harness does not compile: %s" % err)
    if out is None:
        return
    bad = [line for line in out.splitlines() if line.endswith("differ")]
    check(not bad and len(out.splitlines()) == 6 * len(laws),
          "stroke kernel c(t) differs from the interpreter: %s" % [(laws[int(b.split()[0])], b) for b in bad[:3]])


# ---- end to end --------------------------------------------------------------------------------

def final(summary):
    return summary["final_state"] if summary else None


def test_forcing_law_big_integer_and_huge_trig():
    """sin(t)*10^20/(1e20+t) is sin(t) to 1e-20: the run is sin(t)'s (the integer used to be cut to
    7.77e18 by the compiler). sin(1e23)*sin(t) is the run of the C library's sin(1e23) written out,
    bit for bit (SymPy used to evaluate it at 17 digits of 10^23); likewise sin(pi*1e17)."""
    runs = {}
    for name, law in (("big", "sin(t)*10^20/(1e20+t)"), ("plain", "sin(t)"),
                      ("trig", "sin(1e23)*sin(t)"), ("trig_value", "%r*sin(t)" % math.sin(1e23)),
                      ("pik", "sin(pi*1e17) + sin(t)"), ("pik_value", "%r + sin(t)" % math.sin(math.pi * 1e17))):
        p, _, s = swimtest.run(scene("law_" + name, BASE + FORCING % law), "law_" + name, "--t-end", "1")
        check(p.returncode == 0, "forcing law %s: exit %d %s" % (law, p.returncode, p.stderr))
        runs[name] = final(s)
    a, b = runs["big"], runs["plain"]
    check(a and b and max(abs(x - y) for x, y in zip(a["c"], b["c"])) < 1e-12,
          "sin(t)*10^20/(1e20+t) is not the law sin(t): %s vs %s" % (a and a["c"][:4], b and b["c"][:4]))
    check(runs["trig"] == runs["trig_value"], "sin(1e23) in a law is not the C library's value")
    check(runs["pik"] == runs["pik_value"], "sin(pi*1e17) in a law is not the C library's value")


def test_stroke_law_big_integer():
    """The same in a stroke: 0.4*cos(t)*10^20/(1e20+t) moves the body as 0.4*cos(t) (c1 completed:
    the law is 0.4*cos(t) only to 1e-20, so c1 = 1 prescribed would not keep the volume exactly)."""
    finals = {}
    for name, am1 in (("big", "0.4*cos(t)*10^20/(1e20+t)"), ("plain", "0.4*cos(t)")):
        laws = {"am1": am1, "bm2": "0.4*sin(t)/sqrt(2)"}
        p, _, s = swimtest.run(scene("stroke_" + name, stroke_scene(laws)), "stroke_" + name)
        check(p.returncode == 0, "stroke %s: exit %d %s" % (am1, p.returncode, p.stderr))
        finals[name] = final(s)
    a, b = finals["big"], finals["plain"]
    check(a and b and abs(a["y"] - b["y"]) < 1e-12 and abs(a["x"] - b["x"]) < 1e-12,
          "stroke with 10^20 is not the stroke 0.4*cos(t): %s vs %s" % (a, b))


def refused(path, key, law, env):
    p = swim("run", path, "--out", os.path.join(TMP, "refused"), "--quiet", env=env)
    ok = (p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and (path + ":") in p.stderr
          and key in p.stderr and law in p.stderr)
    check(ok, "law %s: want exit 2, one line naming %s and %s: got %d %r" % (law, path, key, p.returncode, p.stderr))


def test_non_real_laws_refused_before_any_kernel():
    """A part that is not a finite real number, in a forcing or a stroke law, is refused when the
    scene is checked: exit 2, one line naming the file, the key and the law; nothing is generated
    (the kernel cache stays empty)."""
    cache = os.path.join(TMP, "empty_cache")
    env = dict(os.environ, SWIM_CACHE=cache)
    for law in ("step(sqrt(-1))*t", "t + 0*log(0)", "abs(asin(2))*t", "step(1/0)*sin(t)", "t*(-8)^(1/3)",
                "sin(t) + 0*10^400"):
        refused(scene("nonreal_forcing", BASE + FORCING % law), "forcing.law", law, env)
    for law in ("sqrt(-1)", "0.1*cos(t) + 0*log(-1)", "0.1*sqrt(1-t)", "0.1*cos(t)/(t-1)"):
        laws = {"am1": law, "bm2": "0.4*sin(t)/sqrt(2)"}
        refused(scene("nonreal_stroke", stroke_scene(laws)), "stroke.am1", law, env)
    entries = os.listdir(cache) if os.path.isdir(cache) else []
    check(not entries, "a kernel was generated for a refused law: %s" % entries)
    shutil.rmtree(cache, ignore_errors=True)


def test_hidden_kinks_in_stroke_laws_refused():
    """A stroke law that parses and is finite but is not twice differentiable (an abs hidden as
    sqrt(u^2), which the generator reduces to |u|) is bad input as well, found when its kernel is
    generated: exit 2, one line naming the file, the key and the law, nothing written; in a sweep,
    no DIR either."""
    env = dict(os.environ, SWIM_CACHE=os.path.join(TMP, "kink_cache"))
    for key, law in (("am1", "0.4*cos(t) + 0.01*sqrt((t-0.5)^2)"), ("bm2", "0.4*sqrt(sin(t)^2)/sqrt(2)")):
        laws = {"am1": "0.4*cos(t)", "bm2": "0.4*sin(t)/sqrt(2)"}
        laws[key] = law
        path = scene("kink_" + key, stroke_scene(laws))
        out = os.path.join(TMP, "kink_out_" + key)
        p = swim("run", path, "--out", out, "--quiet", env=env)
        one = p.stderr.strip().splitlines()
        check(p.returncode == 2 and len(one) == 1 and (path + ":") in p.stderr and ("stroke." + key) in p.stderr
              and law in p.stderr and "twice differentiable" in p.stderr,
              "hidden kink %s: want exit 2 and one line naming the key: got %d %r" % (law, p.returncode, p.stderr))
        check(not os.path.exists(out), "hidden kink %s: %s was written" % (law, out))
        sweep_dir = os.path.join(TMP, "kink_sweep_" + key)
        p = swim("sweep", path, "--vary", "model.rho0=1,2", "--out", sweep_dir, "--quiet", env=env)
        check(p.returncode == 2 and ("stroke." + key) in p.stderr and not os.path.exists(sweep_dir),
              "sweep with hidden kink %s: exit %d, DIR exists %s, %r" % (law, p.returncode, os.path.exists(sweep_dir),
                                                                        p.stderr[-300:]))


def test_law_with_undefined_part_later_stops_run():
    """step(sqrt(1-t)) is defined (0 or 1) only up to t = 1, where sqrt goes NaN: the forcing run
    stops there and says so, as for 1/(t-1), instead of going on with a law that has no meaning."""
    p, d, s = swimtest.run(scene("law_hidden", BASE + FORCING % "step(sqrt(1-t))*sin(t)"), "law_hidden",
                           "--t-end", "3")
    check(p.returncode == 1 and s and s["status"] == "failed" and "forcing law" in s["reason"]
          and "t = 1" in s["reason"], "step(sqrt(1-t)): exit %d, reason %r" % (p.returncode, s and s["reason"]))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_laws"))
