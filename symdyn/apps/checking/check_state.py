"""Answers given as numbers at one state (`at:` in an answers file), e.g. a textbook's printed
values or a library's output:

    at: {q: [0, 0.5236, ...], qd: [0.2, ...], qdd: [0.1, ...]}   # and NAME: value for free parameters
    tolerance: 1e-4        # absolute, per entry (default 1e-9 times max(1, |value|))
    M: [[...numbers...], ...]
    tau: [...]

Each answer entry (a number, or an expression that the state makes a number) is compared
with symdyn's derivation evaluated at that state (Dynamics.evaluate): it matches when
|answer - symdyn| <= tolerance.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import sympy as sp

from ...dynamics import Dynamics
from ...errors import SymdynError
from ...model.symbols import joint_symbols

__all__ = ["AT_KEY", "TOLERANCE_KEY", "read_state", "compare_at_state"]

AT_KEY = "at"
TOLERANCE_KEY = "tolerance"
RELATIVE = 1e-9


def read_state(raw: object, dyn: Dynamics, file: str | None) -> tuple[list[np.ndarray], dict[str, float]]:
    """(q, qd, qdd) and the free parameters' values of an `at:` mapping."""
    if not isinstance(raw, Mapping):
        raise SymdynError("expected a mapping with q, qd, qdd (and free parameters)", file=file, field=AT_KEY)
    robot = dyn.robot
    vectors = []
    for name in ("q", "qd", "qdd"):
        value = raw.get(name, [0] * dyn.n)
        if not isinstance(value, list) or not all(_is_number(x) for x in value):
            raise SymdynError(f"expected a list of {dyn.n} numbers", file=file, field=f"{AT_KEY}.{name}")
        vectors.append(robot.joint_values(value, name, f"{file or 'answers'}: {AT_KEY}"))
    params = {str(k): v for k, v in raw.items() if k not in ("q", "qd", "qdd")}
    names = [str(p) for p in dyn.params]
    unknown = sorted(set(params) - set(names))
    if unknown:
        listed = ", ".join(names) or "none"
        raise SymdynError(
            f"unknown name(s) {', '.join(unknown)} (free parameters: {listed})", file=file, field=AT_KEY
        )
    missing = [k for k in names if k not in params]
    if missing or not all(_is_number(v) for v in params.values()):
        raise SymdynError(
            f"give a number for each free parameter ({', '.join(names)})", file=file, field=AT_KEY
        )
    return vectors, {k: float(v) for k, v in params.items()}


def _is_number(x: object) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def compare_at_state(
    dyn: Dynamics,
    parsed: dict[str, dict[tuple[int, ...], sp.Expr]],
    raw: object,
    tolerance: object,
    file: str | None,
) -> list[tuple[str, tuple[int, ...], sp.Expr, sp.Expr, str]]:
    """(quantity, index, symdyn's number, the answer, status) per entry given (`parsed`: quantity ->
    {1-based index: answer}, symdyn.apps.checking.check.parse_answers), at the state of `raw`."""
    (q, qd, qdd), params = read_state(raw, dyn, file)
    if tolerance is not None and not (_is_number(tolerance) and tolerance > 0):
        raise SymdynError("expected a positive number", file=file, field=TOLERANCE_KEY)
    qs, qds, qdds = joint_symbols(dyn.n)
    state = {
        **dict(zip(qs, q, strict=True)),
        **dict(zip(qds, qd, strict=True)),
        **dict(zip(qdds, qdd, strict=True)),
    }
    state.update({p: params[str(p)] for p in dyn.params})
    out = []
    for name, got in parsed.items():
        expected = np.atleast_1d(dyn.evaluate(name, q, qd, qdd, [params[str(p)] for p in dyn.params]))
        for index, answer in got.items():
            e = float(expected[tuple(i - 1 for i in index)])
            g = sp.sympify(answer).xreplace(state)
            allowed = tolerance if tolerance is not None else RELATIVE * max(1.0, abs(e))
            ok = g.is_number and abs(float(g) - e) <= allowed
            out.append((name, index, sp.Float(e, 12), g, "at the state" if ok else "differs"))
    return out
