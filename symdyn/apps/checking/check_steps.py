"""Answers for the derivation's intermediate steps (`steps:` in an answers file), checked in order.

    steps:
      2:                       # a link, by number (from 1) or by name
        omega: [0, 0, "qd1 + qd2"]
        f: ["...", "...", 0]
      link1:
        tau: "..."

The quantities are those of symdyn.apps.checking.steps: for Newton-Euler omega, omegadot, vdot,
vdotC, F, N, f, n (3 entries each, in link i's body frame {i}) and tau; for Lagrange T, U
(per link), dL_dqd, ddt_dL_dqd, dL_dq and tau (per joint), one entry each; `null` (an entry, a
quantity or a whole link) is not checked. Every entry is
compared with symdyn's step like a final answer (symdyn.apps.checking.check passes its parser and
comparison in, so this module needs nothing from it); the first
step that differs, in the order the recursion computes them, is reported.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import sympy as sp

from ...dynamics import simplify_entry
from ...errors import SymdynError
from ...model.robot import Robot
from .steps import LAGRANGE_STEPS, NEWTON_EULER_STEPS, derivation_steps

__all__ = ["check_steps"]

_PHASES = {
    "outward": "outward iteration",
    "inward": "inward iteration",
    "energy": "energies",
    "joint": "joint",
}


def _link_number(key: object, robot: Robot, file: str | None) -> int:
    names = {link.name: i + 1 for i, link in enumerate(robot.links)}
    if isinstance(key, int) and not isinstance(key, bool) and 1 <= key <= robot.nb:
        return key
    if isinstance(key, str) and key in names:
        return names[key]
    raise SymdynError(
        f"unknown link {key!r} (a number 1..{robot.nb} or a link name: {', '.join(names)})",
        file=file,
        field=f"steps.{key}",
    )


#: entry(value, label) -> the parsed answer entry
Entry = Callable[[object, str], sp.Expr]


def _parse(raw: object, robot: Robot, method: str, file: str | None, entry: Entry) -> dict:
    """(quantity, link) -> the answer's entries (3 for a vector, 1 for a scalar; None: not checked)."""
    allowed = NEWTON_EULER_STEPS if method == "newton-euler" else LAGRANGE_STEPS
    if not isinstance(raw, Mapping) or not raw:
        raise SymdynError("steps: expected a mapping of links to their quantities", file=file, field="steps")
    out = {}
    for key, quantities in raw.items():
        i = _link_number(key, robot, file)
        if quantities is None:  # a link left out: nothing of it is checked
            continue
        if not isinstance(quantities, Mapping):
            raise SymdynError("expected a mapping of quantities", file=file, field=f"steps.{key}")
        for name, value in quantities.items():
            where = f"steps.{key}.{name}"
            if name not in allowed:
                raise SymdynError(
                    f"unknown quantity {name!r} for method {method} (use {', '.join(allowed)})",
                    file=file,
                    field=where,
                )
            size = 3 if method == "newton-euler" and name != "tau" else 1
            values = [None] * size if value is None else value if isinstance(value, list) else [value]
            if len(values) != size:
                raise SymdynError(f"expected {size} entries, got {len(values)}", file=file, field=where)
            out[(name, i)] = [
                None if v is None else entry(v, f"{where}[{k + 1}]") for k, v in enumerate(values)
            ]
    return out


def check_steps(
    robot: Robot,
    raw: object,
    method: str,
    file: str | None,
    entry: Entry,
    compare: Callable[[sp.Expr, sp.Expr], str],
) -> tuple[list[tuple[str, tuple[int, ...], sp.Expr, sp.Expr, str]], str | None, list[int]]:
    """Compare the step answers `raw` with symdyn's steps, in the order they are computed.

    Args:
        entry: parses one answer entry (value, label for messages).
        compare: judges one entry, compare(expected, got) -> "symbolic", "numeric" or "differs".

    Returns:
        (quantity, index, expected, got, status) per entry given (null entries are not checked),
        the first differing step in words (None when all match), and the number of entries of
        each step given, checked or not.
    """
    answers = _parse(raw, robot, method, file, entry)
    results = []
    first = None
    for step in derivation_steps(robot, method, simplify=False).steps:
        got = answers.get((step.name, step.link))
        if got is None:
            continue
        for k in range(len(got)):
            if got[k] is None:
                continue
            status = compare(step.value[k], got[k])
            index = (k + 1,) if len(got) > 1 else ()
            expected = simplify_entry(step.value[k]) if status == "differs" else step.value[k]  # to print
            results.append((f"{step.name}_{step.link}", index, expected, got[k], status))
            if status == "differs" and first is None:
                where = f"link {step.link}" if step.phase != "joint" else f"joint {step.link}"
                frame = f", frame {step.frame}" if step.frame else ""
                first = f"{step.name}_{step.link} ({_PHASES[step.phase]}, {where}{frame})"
    return results, first, [len(got) for got in answers.values()]
