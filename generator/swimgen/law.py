"""Forcing laws f(t) of scenes (5.1) and stroke laws c(t) (3.3): from their text to C and SymPy.

The grammar is the runtime's (runtime/scene/expr.c), parsed the same way: numbers (C strtod
syntax, decimal or hex), t, pi, e; + - * / and ^ (right-associative, binding tighter than unary
minus: -2^2 = -4, and 2^-1 allowed); parentheses; sin cos tan asin acos atan exp log sqrt abs
sinh cosh tanh and step (Heaviside, 1 for x >= 0); and the names of the scene's [parameters]
(run-time numbers the kernel reads, so the law's structure does not depend on their values).

The runtime validates a law with its interpreter, and the kernel must compute the same function,
to the last bit. So a law is kept as its tree of operations (Law) and printed to C operation for
operation (Law.c): every number is the double the interpreter reads, printed back exactly
(repr), every operation is the interpreter's, in its order, in double precision; nothing is
simplified or evaluated in exact or higher-precision arithmetic (SymPy would print 10^20 as an
integer C cannot hold, reduce sin(k*pi + x) with an exact pi, or round 1e23 to 17 digits).
A part without t or parameters is folded here, by Python's floats and math module, which are the
C library's own operations: the literal is the interpreter's value. The functions the C library
may round differently from the compiler are called through kernel/law_functions.h.

Law.sympy is the same function for SymPy, with those doubles as its numbers, for what only
SymPy can give: the exact derivatives of a stroke law (stroke.py). A part whose value is not
finite (sqrt(-1), log(0), 1/0, 10^400) is a LawError: the runtime refuses such a law before it
asks for a kernel, so reaching it here means the two parsers disagree.
"""

import math
import re

import sympy as sp


class Step(sp.Function):
    """Heaviside step with step(0) = 1, as in the runtime; printed by cprint.KernelPrinter."""
    nargs = 1

    @classmethod
    def eval(cls, x):
        if x.is_extended_real and x.is_number:
            return sp.Integer(1) if x >= 0 else sp.Integer(0)
        return None


FUNCTIONS = {
    "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "asin": sp.asin, "acos": sp.acos,
    "atan": sp.atan, "exp": sp.exp, "log": sp.log, "sqrt": sp.sqrt, "abs": sp.Abs,
    "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh, "step": Step,
}
# The interpreter's functions on doubles: Python's math module calls the C library's (it raises
# where C returns inf or NaN; _fold maps that to "not finite").
_FLOAT_FUNCTIONS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "exp": math.exp, "log": math.log, "sqrt": math.sqrt, "abs": math.fabs,
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh,
    "step": lambda x: 1.0 if x >= 0.0 else 0.0,
}
# How each function is written in C: exact ones directly, the others through law_functions.h.
_C_FUNCTIONS = dict({name: "swim_law_" + name for name in _FLOAT_FUNCTIONS},
                    sqrt="sqrt", abs="fabs")
_FLOAT_OPS = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
              "/": lambda a, b: a / b, "^": math.pow}
MAX_DEPTH = 64
_NUMBER = re.compile(r"0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?\d+)?"
                     r"|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


class LawError(ValueError):
    pass


# Tree nodes: ("num", v) ("t",) ("par", name) ("neg", a) ("fun", name, a) ("op", "+-*/^", a, b)

def _c_number(v):
    """The double v as a C literal that reads back as exactly v."""
    text = repr(v)
    return "(%s)" % text if text.startswith("-") else text


class Law:
    """A parsed law: its text and its tree of operations, as the interpreter evaluates it."""

    def __init__(self, text, tree, params=()):
        self.text, self.tree, self.params = text, tree, list(params)
        self._folded = {}

    def _fold(self, node):
        """The value of a node without t or parameters (a double), else None."""
        key = id(node)
        if key in self._folded:
            return self._folded[key]
        kind = node[0]
        if kind == "num":
            v = node[1]
        elif kind in ("t", "par"):
            v = None
        elif kind == "neg":
            a = self._fold(node[1])
            v = None if a is None else -a
        elif kind == "fun":
            a = self._fold(node[2])
            v = None if a is None else _apply(_FLOAT_FUNCTIONS[node[1]], a)
        else:
            a, b = self._fold(node[2]), self._fold(node[3])
            v = None if a is None or b is None else _apply(_FLOAT_OPS[node[1]], a, b)
        if v is not None and not math.isfinite(v):
            raise LawError("\"%s\": %s is not a finite real number" % (self.text, _describe(node)))
        self._folded[key] = v
        return v

    def c(self, names):
        """C99 expression of the law, operation for operation; names maps "t" and each parameter
        name to its C text."""
        def emit(node):
            v = self._fold(node)
            if v is not None:
                return _c_number(v)
            kind = node[0]
            if kind == "t":
                return names["t"]
            if kind == "par":
                return names[node[1]]
            if kind == "neg":
                return "(-%s)" % emit(node[1])
            if kind == "fun":
                if node[1] == "step":
                    return "((%s) >= 0.0 ? 1.0 : 0.0)" % emit(node[2])
                return "%s(%s)" % (_C_FUNCTIONS[node[1]], emit(node[2]))
            a, b = emit(node[2]), emit(node[3])
            if node[1] == "^":
                return "swim_law_pow(%s, %s)" % (a, b)
            return "(%s %s %s)" % (a, node[1], b)
        return emit(self.tree)

    def sympy(self, t, params=None):
        """The law as a SymPy expression in the symbol t and the parameter symbols of `params`
        ({name: Symbol}), with the interpreter's doubles as its numbers (integers as Integer)."""
        params = params or {}

        def build(node):
            v = self._fold(node)
            if v is not None:
                if v == int(v) and abs(v) <= 2.0 ** 53:
                    return sp.Integer(int(v))
                return sp.Float(v, precision=53)
            kind = node[0]
            if kind == "t":
                return t
            if kind == "par":
                return params[node[1]]
            if kind == "neg":
                return -build(node[1])
            if kind == "fun":
                return FUNCTIONS[node[1]](build(node[2]))
            a, b = build(node[2]), build(node[3])
            return {"+": lambda: a + b, "-": lambda: a - b, "*": lambda: a * b,
                    "/": lambda: a / b, "^": lambda: sp.Pow(a, b)}[node[1]]()
        return build(self.tree)


def _apply(f, *args):
    try:
        return f(*args)
    except (ValueError, ZeroDivisionError):   # domain error, x/0: C's NaN or inf
        return math.nan
    except OverflowError:
        return math.inf


def _describe(node):
    """Short text of a node for messages."""
    kind = node[0]
    if kind == "num":
        return repr(node[1])
    if kind == "t":
        return "t"
    if kind == "par":
        return node[1]
    if kind == "neg":
        return "-" + _describe(node[1])
    if kind == "fun":
        return "%s(%s)" % (node[1], _describe(node[2]))
    return "(%s %s %s)" % (_describe(node[2]), node[1], _describe(node[3]))


class _Parser:
    def __init__(self, text, params=()):
        self.s, self.p, self.depth = text, 0, 0
        self.params = set(params)

    def fail(self, msg):
        raise LawError("at column %d: %s" % (self.p + 1, msg))

    def skip(self):
        while self.p < len(self.s) and self.s[self.p] in " \t":
            self.p += 1

    def peek(self):
        self.skip()
        return self.s[self.p] if self.p < len(self.s) else ""

    def number(self):
        m = _NUMBER.match(self.s, self.p)
        text = m.group(0)
        self.p = m.end()
        # exactly the double strtod reads (both round correctly)
        value = float.fromhex(text) if text[:2].lower() == "0x" else float(text)
        if not math.isfinite(value):
            self.fail("number out of range")
        return ("num", value)

    def atom(self):
        c = self.peek()
        self.depth += 1
        if self.depth > MAX_DEPTH:
            self.fail("expression nested too deeply")
        if c == "(":
            self.p += 1
            e = self.sum()
            if self.peek() != ")":
                self.fail("expected ')'")
            self.p += 1
        elif c.isdigit() or (c == "." and self.s[self.p + 1:self.p + 2].isdigit()):
            e = self.number()
        elif c.isascii() and c.isalpha():
            name = _NAME.match(self.s, self.p).group(0)
            start, self.p = self.p, self.p + len(name)
            if name == "t":
                e = ("t",)
            elif name == "pi":
                e = ("num", 3.14159265358979323846)
            elif name == "e":
                e = ("num", 2.71828182845904523536)
            elif name in FUNCTIONS:
                if self.peek() != "(":
                    self.fail("expected '(' after function name")
                self.p += 1
                arg = self.sum()
                if self.peek() != ")":
                    self.fail("expected ')'")
                self.p += 1
                e = ("fun", name, arg)
            elif name in self.params:
                e = ("par", name)
            else:
                self.p = start
                self.fail("unknown name '%s' (use t, pi, e, %sa function such as sin)"
                          % (name, "a name of [parameters], " if self.params else ""))
        else:
            self.fail("unexpected character" if c else "unexpected end of expression")
        self.depth -= 1
        return e

    def power(self):
        base = self.atom()
        if self.peek() == "^":
            self.p += 1
            return ("op", "^", base, self.unary())
        return base

    def unary(self):
        c = self.peek()
        if c in "+-" and c:
            self.p += 1
            self.depth += 1
            if self.depth > MAX_DEPTH:
                self.fail("expression nested too deeply")
            e = self.unary()
            self.depth -= 1
            return ("neg", e) if c == "-" else e
        return self.power()

    def product(self):
        e = self.unary()
        while self.peek() in ("*", "/") and self.peek():
            op = self.s[self.p]
            self.p += 1
            e = ("op", op, e, self.unary())
        return e

    def sum(self):
        e = self.product()
        while self.peek() in ("+", "-") and self.peek():
            op = self.s[self.p]
            self.p += 1
            e = ("op", op, e, self.product())
        return e


RESERVED = {"t", "pi", "e"} | set(FUNCTIONS)


def parameter_symbols(names):
    """{name: Symbol} for the scene's [parameters]; a reserved name is a LawError."""
    for name in names:
        if name in RESERVED or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", name):
            raise LawError("'%s' cannot name a parameter" % name)
    return {name: sp.Symbol("law_param_%s" % name, real=True) for name in names}


def parse(text, params=()):
    """The law `text` (parameters: the names it may use) as a Law; LawError names the column,
    or the part of it that is not finite."""
    ps = _Parser(text, params)
    tree = ps.sum()
    if ps.peek():
        ps.fail("unexpected text after the expression")
    law = Law(text, tree, params)
    law._fold(tree)   # every part: a part that is not finite is refused here
    return law


def parse_law(text, t, params=None):
    """The law `text` as a SymPy expression in the symbol t and the parameter symbols of
    `params` ({name: Symbol}, see parameter_symbols); LawError names the column."""
    return parse(text, params or {}).sympy(t, params)
