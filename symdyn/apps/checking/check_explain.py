"""What `symdyn check` prints about an answer entry that differs: symdyn's entry in the form
`symdyn derive` prints it, the difference answer - symdyn simplified, and a note when an answer
M is not symmetric (M = M^T for every robot, R. Grupen, "Dynamics" (2015), slide 14).

The form `derive` prints: on a fixed base, M and G (and the C, V and tau built from them) as
canonical trigonometric polynomials over the joint angles, expanded, terms in a fixed order
(symdyn.algorithms.configuration_space); a floating base's entries and F as the derivation gives
them. The difference is expanded, its floating-point rounding noise dropped (below 1e-12 of the
largest number of the two entries), and replaced by `sympy.simplify` of it when that has at most
half its operations (a sum of terms that cancel in part), for differences of at most
SIMPLIFY_MAX_OPS operations; otherwise it is printed expanded, term by term like the entries.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import sympy as sp

from ...dynamics import Dynamics

__all__ = ["derive_form", "difference_text", "asymmetry_notes", "SIMPLIFY_MAX_OPS", "CHOP"]

#: differences with more operations are printed expanded, not simplified
SIMPLIFY_MAX_OPS = 400
#: floats at most this fraction of the largest number of the two entries are rounding noise
CHOP = 1e-12


def chop(diff: sp.Expr, *exprs: sp.Expr) -> sp.Expr:
    """diff without the floating-point rounding noise of numeric parameter values."""
    floats = [abs(f) for x in exprs for f in x.atoms(sp.Float)]
    if not floats:
        return diff
    tiny = CHOP * max(1.0, float(max(floats)))
    return diff.xreplace({f: sp.S.Zero for f in diff.atoms(sp.Float) if abs(f) <= tiny})


def derive_form(dyn: Dynamics) -> Callable[[str, tuple[int, ...], sp.Expr], str]:
    """A function (quantity, 1-based index, symdyn's entry) -> that entry as `symdyn derive`
    prints it (module docstring); the closed forms are built once per quantity."""
    cs = None if dyn.robot.floating else dyn.configuration_space
    canonical = cs is not None and cs.readable
    built: dict[str, list[sp.Expr]] = {}
    n = dyn.n

    def show(name: str, index: tuple[int, ...], entry: sp.Expr) -> str:
        if not canonical or name not in ("M", "C", "V", "G", "tau"):
            return sp.sstr(entry)
        k = index[0] - 1
        if name in ("M", "G"):
            return cs.text(name, k, index[1] - 1 if name == "M" else 0)
        if name not in built:
            built[name] = cs.closed(name, dyn.qd, dyn.qdd, dyn.closed_form("F"))
        return sp.sstr(built[name][k * n + index[1] - 1 if name == "C" else k])

    return show


def difference_text(expected: sp.Expr, got: sp.Expr) -> str:
    """answer - symdyn, expanded without rounding noise, simplified when that halves it."""
    diff = chop(sp.expand(got - expected), expected, got)
    if diff == 0 or sp.count_ops(diff) > SIMPLIFY_MAX_OPS:
        return sp.sstr(diff)
    try:
        simpler = sp.simplify(diff)
    except Exception:  # simplification failing only leaves the expanded difference
        return sp.sstr(diff)
    return sp.sstr(simpler if 2 * sp.count_ops(simpler) <= sp.count_ops(diff) else diff)


def asymmetry_notes(
    answers: Mapping[tuple[int, ...], sp.Expr], differs: Callable[[sp.Expr, sp.Expr], bool]
) -> list[str]:
    """A note for each pair M[i,j], M[j,i] of an answer M that differ (`differs` compares two
    entries as the check compares an entry with symdyn's)."""
    notes = []
    for (i, j), upper in sorted(answers.items()):
        lower = answers.get((j, i))
        if i < j and lower is not None and differs(upper, lower):
            notes.append(
                f"the answer's M is not symmetric: M[{i},{j}] - M[{j},{i}] = {difference_text(lower, upper)} "
                "(every M is symmetric: M = M^T)"
            )
    return notes
