"""What is wrong with the names of a name -> value map of a robot's free parameters (no SymPy:
the cached applications check names without it)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

__all__ = ["parameter_names_problem"]


def parameter_names_problem(given: Iterable[str], names: Sequence[str], robot_name: str) -> str | None:
    """What is wrong with the names of a name -> value map of free parameters (`names`, in the
    robot's order), as a sentence naming the unknown ones and the missing ones; None when nothing."""
    given = list(given)
    unknown = [k for k in given if k not in names]
    missing = [k for k in names if k not in given]
    parts = []
    if unknown:
        listing = ", ".join(names) or "none"
        parts.append(
            f"unknown parameter(s) {', '.join(unknown)} (free parameters of robot '{robot_name}': {listing})"
        )
    if missing:
        parts.append(f"no value for parameter(s) {', '.join(missing)}")
    return "; ".join(parts) or None
