"""C99 printer used for every generated expression.

Differences from SymPy's default C printer: half-integer and small integer powers
are multiplications and square roots (delta^1.5 -> delta*sqrt(delta)), never
``pow``; floats carry 17 significant digits.
"""
from __future__ import annotations

import sympy as sp
from sympy.printing.c import C99CodePrinter


class PdwPrinter(C99CodePrinter):
    def __init__(self, names):
        super().__init__()
        self._names = names

    def _print_Symbol(self, expr):
        return self._names.get(expr, expr.name)

    def _print_Pow(self, expr):
        base, e = expr.base, expr.exp
        b = self.parenthesize(base, sp.printing.precedence.PRECEDENCE["Mul"] + 1)
        if e == sp.S.Half:
            return "sqrt(%s)" % self._print(base)
        if e == -sp.S.Half:
            return "(1.0/sqrt(%s))" % self._print(base)
        if e == sp.Rational(3, 2):
            return "(%s*sqrt(%s))" % (b, self._print(base))
        if e.is_Integer and 2 <= e <= 4:
            return "(" + "*".join([b] * int(e)) + ")"
        if e.is_Integer and -4 <= e <= -1:
            return "(1.0/(" + "*".join([b] * int(-e)) + "))"
        return super()._print_Pow(expr)

    def _print_Piecewise(self, expr):
        if expr.args[-1].cond != True:  # noqa: E712  (SymPy's true, not Python's)
            raise ValueError("Piecewise without a default branch: %s" % expr)
        out = self._print(expr.args[-1].expr)
        for e, c in reversed(expr.args[:-1]):
            out = "((%s) ? (%s) : %s)" % (self._print(c), self._print(e), out)
        return out

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return "%s.0/%s.0" % (expr.p, expr.q)


def c_block(exprs, targets, names, tmp_prefix="t", indent="    "):
    """C statements computing ``exprs`` into ``targets`` with common subexpressions eliminated.

    Parameters
    ----------
    exprs : sequence of sympy.Expr
    targets : sequence of str
        C lvalues, one per expression.
    names : dict
        Maps SymPy symbols to C expressions (array elements, locals).

    Returns
    -------
    (str, int)
        The code and its operation count (SymPy ``count_ops`` after CSE).
    """
    syms = sp.numbered_symbols(tmp_prefix)
    repl, reduced = sp.cse(list(exprs), symbols=syms, order="canonical")
    printer = PdwPrinter(names)
    lines, ops = [], 0
    for s, e in repl:
        ctype = "int" if isinstance(e, sp.logic.boolalg.Boolean) else "double"
        lines.append("%sconst %s %s = %s;" % (indent, ctype, s.name, printer.doprint(e)))
        ops += sp.count_ops(e)
    for t, e in zip(targets, reduced):
        lines.append("%s%s = %s;" % (indent, t, printer.doprint(e)))
        ops += sp.count_ops(e)
    return "\n".join(lines), int(ops)
