"""A safe evaluator for user expressions of one variable, with exact symbolic derivatives.

Text such as ``"40*cos(p) + 10*sin(3*p)"`` is parsed with :mod:`ast` into a small expression
tree; only numbers, the variable, the constants ``pi`` and ``e``, the operators
``+ - * / **`` and a whitelist of functions are accepted (never :func:`eval`). Derivatives are
taken symbolically on the tree, so a path given as text gets exact ``r', r'', r'''``.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np

from .._arrays import Array
from ..errors import ParameterError

# A node is a tuple: ("num", value) | ("var",) | (op, a, b) for op in + - * / ** |
# ("neg", a) | ("fn", name, a)
Node: TypeAlias = tuple[Any, ...]

FUNCTIONS: dict[str, Callable[[Array], Array]] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
    "sqrt": np.sqrt, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh,
    "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
}
CONSTANTS = {"pi": math.pi, "e": math.e}
MAX_NODES = 20000

ZERO: Node = ("num", 0.0)
ONE: Node = ("num", 1.0)


def _num(v: float) -> Node:
    return ("num", float(v))


def _is(n: Node, v: float) -> bool:
    return bool(n[0] == "num" and n[1] == v)


def _add(a: Node, b: Node) -> Node:
    if _is(a, 0.0):
        return b
    if _is(b, 0.0):
        return a
    if a[0] == "num" and b[0] == "num":
        return _num(a[1] + b[1])
    return ("+", a, b)


def _sub(a: Node, b: Node) -> Node:
    if _is(b, 0.0):
        return a
    if _is(a, 0.0):
        return _neg(b)
    if a[0] == "num" and b[0] == "num":
        return _num(a[1] - b[1])
    return ("-", a, b)


def _mul(a: Node, b: Node) -> Node:
    if _is(a, 0.0) or _is(b, 0.0):
        return ZERO
    if _is(a, 1.0):
        return b
    if _is(b, 1.0):
        return a
    if a[0] == "num" and b[0] == "num":
        return _num(a[1] * b[1])
    return ("*", a, b)


def _div(a: Node, b: Node) -> Node:
    if _is(a, 0.0):
        return ZERO
    if _is(b, 1.0):
        return a
    if a[0] == "num" and b[0] == "num" and b[1] != 0.0:
        return _num(a[1] / b[1])
    return ("/", a, b)


def _power(a: Node, b: Node) -> Node:
    if _is(b, 0.0):
        return ONE
    if _is(b, 1.0):
        return a
    if a[0] == "num" and b[0] == "num":
        try:
            return _num(a[1] ** b[1])
        except (OverflowError, ZeroDivisionError):
            pass
    return ("**", a, b)


def _neg(a: Node) -> Node:
    if a[0] == "num":
        return _num(-a[1])
    if a[0] == "neg":
        return tuple(a[1])
    return ("neg", a)


def _fn(name: str, a: Node) -> Node:
    if a[0] == "num":
        return _num(float(FUNCTIONS[name](np.asarray(a[1], dtype=float))))
    return ("fn", name, a)


def parse(text: str, variable: str = "p") -> Node:
    """Parse ``text`` into an expression tree in ``variable``; raise on anything not allowed."""
    if not isinstance(text, str) or not text.strip():
        raise ParameterError(f"expression {text!r} is empty")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ParameterError(f"expression {text!r} is not valid: {exc.msg}") from None

    def build(n: ast.AST) -> Node:
        if isinstance(n, ast.Constant) and isinstance(n.value, (int, float)) \
                and not isinstance(n.value, bool):
            return _num(n.value)
        if isinstance(n, ast.Name):
            if n.id == variable:
                return ("var",)
            if n.id in CONSTANTS:
                return _num(CONSTANTS[n.id])
            raise ParameterError(f"expression {text!r}: unknown name {n.id!r} (the variable is "
                                 f"{variable!r}; constants pi, e)")
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.USub, ast.UAdd)):
            a = build(n.operand)
            return _neg(a) if isinstance(n.op, ast.USub) else a
        if isinstance(n, ast.BinOp):
            ops = {ast.Add: _add, ast.Sub: _sub, ast.Mult: _mul, ast.Div: _div, ast.Pow: _power}
            for kind, make in ops.items():
                if isinstance(n.op, kind):
                    return make(build(n.left), build(n.right))
            raise ParameterError(f"expression {text!r}: operator "
                                 f"{type(n.op).__name__} is not allowed")
        if isinstance(n, ast.Call):
            name = n.func.id if isinstance(n.func, ast.Name) else None
            if name not in FUNCTIONS:
                raise ParameterError(f"expression {text!r}: function {name!r} is not allowed; "
                                     f"allowed: {', '.join(FUNCTIONS)}")
            if len(n.args) != 1 or n.keywords:
                raise ParameterError(f"expression {text!r}: {name}() takes one argument")
            return _fn(name, build(n.args[0]))
        raise ParameterError(f"expression {text!r}: {type(n).__name__} is not allowed")

    return build(tree.body)


_DERIVATIVES: dict[str, Callable[[Node], Node]] = {
    "sin": lambda a: _fn("cos", a),
    "cos": lambda a: _neg(_fn("sin", a)),
    "tan": lambda a: _add(ONE, _power(_fn("tan", a), _num(2))),
    "exp": lambda a: _fn("exp", a),
    "log": lambda a: _div(ONE, a),
    "sqrt": lambda a: _div(_num(0.5), _fn("sqrt", a)),
    "sinh": lambda a: _fn("cosh", a),
    "cosh": lambda a: _fn("sinh", a),
    "tanh": lambda a: _sub(ONE, _power(_fn("tanh", a), _num(2))),
    "asin": lambda a: _div(ONE, _fn("sqrt", _sub(ONE, _power(a, _num(2))))),
    "acos": lambda a: _neg(_div(ONE, _fn("sqrt", _sub(ONE, _power(a, _num(2)))))),
    "atan": lambda a: _div(ONE, _add(ONE, _power(a, _num(2)))),
}


def _derivative(n: Node) -> Node:
    """The exact derivative of an expression tree with respect to its variable."""
    kind = n[0]
    if kind == "num":
        return ZERO
    if kind == "var":
        return ONE
    if kind == "neg":
        return _neg(_derivative(n[1]))
    if kind == "fn":
        return _mul(_DERIVATIVES[n[1]](n[2]), _derivative(n[2]))
    a, b = n[1], n[2]
    da, db = _derivative(a), _derivative(b)
    if kind == "+":
        return _add(da, db)
    if kind == "-":
        return _sub(da, db)
    if kind == "*":
        return _add(_mul(da, b), _mul(a, db))
    if kind == "/":
        return _div(_sub(_mul(da, b), _mul(a, db)), _power(b, _num(2)))
    # a ** b
    if b[0] == "num":
        return _mul(_mul(b, _power(a, _num(b[1] - 1.0))), da)
    return _mul(n, _add(_mul(db, _fn("log", a)), _div(_mul(b, da), a)))


def _size(n: Node) -> int:
    if n[0] in ("num", "var"):
        return 1
    return 1 + sum(_size(c) for c in n[1:] if isinstance(c, tuple))


def _evaluate(n: Node, x: Array) -> Array:
    kind = n[0]
    if kind == "num":
        return np.full(np.shape(x), n[1])
    if kind == "var":
        return np.asarray(x, dtype=float)
    if kind == "neg":
        return -_evaluate(n[1], x)
    if kind == "fn":
        return FUNCTIONS[n[1]](_evaluate(n[2], x))
    a, b = _evaluate(n[1], x), _evaluate(n[2], x)
    if kind == "+":
        return a + b
    if kind == "-":
        return a - b
    if kind == "*":
        return a * b
    if kind == "/":
        return a / b
    return np.power(a, b)


@dataclass(frozen=True)
class Expression:
    """A parsed expression of one variable and its first ``order`` derivatives.

    >>> e = Expression.parse("3*p**2 + sin(p)", order=2)
    >>> [float(v) for v in e(0.0)]
    [0.0, 1.0, 6.0]
    """

    text: str
    trees: tuple[Node, ...]

    @classmethod
    def parse(cls, text: str, *, variable: str = "p", order: int = 3) -> Expression:
        """Parse ``text`` in ``variable`` and differentiate it ``order`` times."""
        trees = [parse(text, variable)]
        for _ in range(order):
            trees.append(_derivative(trees[-1]))
            if _size(trees[-1]) > MAX_NODES:
                raise ParameterError(f"expression {text!r}: derivatives grow too large")
        return cls(text, tuple(trees))

    def __call__(self, x: object) -> list[Array]:
        """Values of the expression and its derivatives at ``x`` (same shape as ``x``)."""
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            vals = [_evaluate(t, x) for t in self.trees]
        for k, v in enumerate(vals):
            if not np.isfinite(v).all():
                bad = np.flatnonzero(~np.isfinite(np.broadcast_to(v, x.shape)))[0]
                where = "" if k == 0 else f" (derivative {k})"
                raise ParameterError(f"expression {self.text!r}{where} is not finite at "
                                     f"p = {x.reshape(-1)[bad]:.6g}")
        return vals
