"""SymPy's `Float.is_zero` answered by SymPy's own test, without the assumptions system's deduction.

Every product SymPy builds asks its number coefficient whether it is zero (`Mul.flatten`:
`coeff.is_zero`; `Add.flatten` asks each term's coefficient too). A Float made by arithmetic is a
new object, and the first assumption query on an object runs SymPy's whole deduction: the handler
(`Float._eval_is_zero`, a comparison of the mpf with mpmath's zero), then the implications of the
answer over every other fact (`sympy.core.facts.FactKB.deduce_all_facts`), which costs about a
hundred times the comparison. A derivation with float data (a robot file's `0.316`, `1.5707963267948966`)
creates tens of thousands of such Floats: twelve random chains of up to five joints asked 21,500
of them, and the deduction took a third of `derive`'s time (3.97 s without this, 2.66 s with it,
the same expressions; docs/python-api.md).

`install()` gives `sympy.Float` an `is_zero` property that returns a fact already known to the
object, else SymPy's handler's answer: the value SymPy's own property returns, for every Float
(tests/test_float_zero.py compares them), without deducing the other facts, which later queries
still deduce as before. It changes no expression, no printed text and no generated file. It
applies to the process's SymPy once symdyn's symbolic floor, the robot model
(symdyn.model.robot) or the robot-file number parser (symdyn.model.expressions) is imported, not
the model package alone, which a warm `simulate` imports without SymPy; and only to `Float`
(`original_is_zero` is SymPy's property, kept for the comparison).
"""

from __future__ import annotations

from sympy import Float

#: SymPy's own `is_zero` property of Float (inherited from Basic), as it was before `install()`.
original_is_zero: property | None = None


def _is_zero(self: Float) -> bool | None:
    """Float.is_zero: the fact if known, else SymPy's handler (Float._eval_is_zero)."""
    known = self._assumptions.get("zero")
    if known is not None:
        return known
    return self._eval_is_zero()


def install() -> None:
    """Give sympy.Float the `is_zero` property above (idempotent)."""
    global original_is_zero
    current = Float.__dict__.get("is_zero")
    if isinstance(current, property) and current.fget is _is_zero:
        return
    original_is_zero = next(
        cls.__dict__["is_zero"] for cls in Float.__mro__ if isinstance(cls.__dict__.get("is_zero"), property)
    )
    Float.is_zero = property(_is_zero, doc="Whether the Float is zero (symdyn.symbolic.float_zero).")


install()
