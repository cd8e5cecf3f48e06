"""The one C printer of the generator: SymPy expressions -> C99 statements, with `cse`."""

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import precedence


class KernelPrinter(C99CodePrinter):
    """C99 printer that maps model symbols to array elements (or any C lvalue text: `names`),
    prints small powers as products (x*x rather than pow(x, 2): exact, and much cheaper) and
    constants as literals."""

    def __init__(self, names):
        # no math macros (M_SQRT2, M_1_PI, ...): strict C11's <math.h> does not define them, so
        # a law such as sqrt(2)*sin(t) would not compile; SymPy then prints sqrt(2) itself.
        super().__init__({"math_macros": {}})
        self._names = names

    def _print_Symbol(self, expr):
        name = self._names.get(expr)
        return name if name is not None else super()._print_Symbol(expr)

    def _print_Pi(self, expr):
        return "3.14159265358979323846"   # M_PI is not in strict C11

    def _print_Exp1(self, expr):
        return "2.71828182845904523536"

    def _print_Step(self, expr):
        """Heaviside with step(0) = 1 (swimgen.law.Step, the runtime's `step`)."""
        return "((%s) >= 0.0 ? 1.0 : 0.0)" % self._print(expr.args[0])

    # Numbers are printed as the doubles they stand for, exactly: an integer beyond 2^53 (C
    # would read 10^20 as an integer constant it cannot hold, and cut it), a rational with such
    # terms, and a Float of 53 bits (a law's double: 15 digits would round it) become the
    # nearest double, written so that it reads back as that double.
    def _print_Integer(self, expr):
        if abs(expr.p) <= 2 ** 53:
            return super()._print_Integer(expr)
        return self._double(expr.p, 1)

    def _print_Rational(self, expr):
        if abs(expr.p) <= 2 ** 53 and expr.q <= 2 ** 53:   # both exact: p/q rounds once
            return super()._print_Rational(expr)
        return self._double(expr.p, expr.q)

    def _print_Float(self, expr):
        if expr._prec <= 53:
            return self._double(float(expr), 1)
        return super()._print_Float(expr)

    @staticmethod
    def _double(p, q):
        """p/q (Python ints, or a float and 1) correctly rounded to a double, as C text."""
        try:
            v = p / q   # int / int is correctly rounded
        except OverflowError:
            v = float("inf")
        if v != v or v in (float("inf"), float("-inf")):
            raise ValueError("the number %s/%s has no C double" % (p, q))
        text = repr(v)
        return "(%s)" % text if text.startswith("-") else text

    def _print_Mul(self, expr):
        """SymPy prints a/J**2 as a / <J**2>; with _print_Pow's products that would read a/J*J,
        which C takes as (a/J)*J: such a denominator is printed in parentheses."""
        num, den = [], []
        for f in sp.Mul.make_args(expr):
            if f.is_Pow and f.exp.is_Integer and f.exp < 0:
                den.append(sp.Pow(f.base, -f.exp))
            else:
                num.append(f)
        if not any(d.is_Pow and 2 <= int(d.exp) <= 4 for d in den):
            return super()._print_Mul(expr)
        numerator = sp.Mul(*num)
        text = self.parenthesize(numerator, precedence(expr))
        return "%s/(%s)" % (text, self._print(sp.Mul(*den)))

    def _print_Pow(self, expr):
        if expr.exp.is_Integer and 2 <= int(expr.exp) <= 4:
            base = self.parenthesize(expr.base, precedence(expr))
            return "*".join([base] * int(expr.exp))
        return super()._print_Pow(expr)


def emit_assignments(assignments, printer, indent="    ", tmp="t"):
    """Print a list of (lhs, expr) as C statements, sharing common subexpressions.

    `cse` runs once over the whole list, so work shared between outputs is done once.
    """
    if not assignments:
        return []
    exprs = [e for _, e in assignments]
    temps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols(tmp), optimizations=None)
    lines = []
    for sym, e in temps:
        lines.append("%sconst double %s = %s;" % (indent, sym.name, printer.doprint(e)))
    for (lhs, _), e in zip(assignments, reduced):
        lines.append("%s%s = %s;" % (indent, lhs, printer.doprint(e)))
    return lines
