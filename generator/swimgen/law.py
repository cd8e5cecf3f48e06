"""Forcing laws f(t) of scenes (5.1), from their text to a SymPy expression.

The grammar is the runtime's (runtime/scene/expr.c), parsed the same way so that the compiled
law and the interpreted one are the same function: numbers (C strtod syntax, decimal or hex),
t, pi, e; + - * / and ^ (right-associative, binding tighter than unary minus: -2^2 = -4, and
2^-1 allowed); parentheses; sin cos tan asin acos atan exp log sqrt abs sinh cosh tanh and step
(Heaviside, 1 for x >= 0); and the names of the scene's [parameters], given as a dict of
symbols (their values are run-time numbers the kernel reads, so the law's structure does not
depend on them). Nothing else is accepted: the law reaches C only through the one printer
(cprint.py).
"""

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
MAX_DEPTH = 64
_NUMBER = re.compile(r"0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?\d+)?"
                     r"|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


class LawError(ValueError):
    pass


class _Parser:
    def __init__(self, text, t, params=None):
        self.s, self.p, self.t, self.depth = text, 0, t, 0
        self.params = params or {}

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
        if text[:2].lower() == "0x":
            value = float.fromhex(text)
        else:
            value = float(text)
            if re.fullmatch(r"\d+", text):
                return sp.Integer(int(text))
        if value != value or value in (float("inf"), float("-inf")):
            self.fail("number out of range")
        # exactly the double strtod reads, printed back with 17 significant digits
        return sp.Float(repr(value), 17)

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
        elif c.isalpha():
            m = re.compile(r"[A-Za-z][A-Za-z0-9_]*").match(self.s, self.p)
            name = m.group(0)
            start, self.p = self.p, m.end()
            if name == "t":
                e = self.t
            elif name == "pi":
                e = sp.pi
            elif name == "e":
                e = sp.E
            elif name in FUNCTIONS and name not in self.params:
                if self.peek() != "(":
                    self.fail("expected '(' after function name")
                self.p += 1
                arg = self.sum()
                if self.peek() != ")":
                    self.fail("expected ')'")
                self.p += 1
                e = FUNCTIONS[name](arg)
            elif name in self.params:
                e = self.params[name]
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
            return sp.Pow(base, self.unary())
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
            return -e if c == "-" else e
        return self.power()

    def product(self):
        e = self.unary()
        while self.peek() in ("*", "/") and self.peek():
            op = self.s[self.p]
            self.p += 1
            rhs = self.unary()
            e = e * rhs if op == "*" else e / rhs
        return e

    def sum(self):
        e = self.product()
        while self.peek() in ("+", "-") and self.peek():
            op = self.s[self.p]
            self.p += 1
            rhs = self.product()
            e = e + rhs if op == "+" else e - rhs
        return e


RESERVED = {"t", "pi", "e"} | set(FUNCTIONS)


def parameter_symbols(names):
    """{name: Symbol} for the scene's [parameters]; a reserved name is a LawError."""
    for name in names:
        if name in RESERVED or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", name):
            raise LawError("'%s' cannot name a parameter" % name)
    return {name: sp.Symbol("law_param_%s" % name, real=True) for name in names}


def parse_law(text, t, params=None):
    """The law `text` as a SymPy expression in the symbol t and the parameter symbols of
    `params` ({name: Symbol}, see parameter_symbols); LawError names the column."""
    ps = _Parser(text, t, params)
    e = ps.sum()
    if ps.peek():
        ps.fail("unexpected text after the expression")
    return e
