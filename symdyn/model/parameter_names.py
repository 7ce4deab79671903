"""What is wrong with a name -> value map of a robot's free parameters: its names, and each
value as a number (no SymPy: the cached applications check parameters without it)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from ..errors import SymdynError

__all__ = ["MAX_MAGNITUDE", "parameter_names_problem", "parameter_number"]

#: the largest absolute value of any number symdyn takes, in a file or at run time (no robot
#: quantity comes near it; far larger ones overflow double precision once multiplied)
MAX_MAGNITUDE = 1e150


def parameter_number(name: str, value, prefix: str = "") -> float:
    """`value` of parameter `name` as a float: a number, finite, at most MAX_MAGNITUDE in size.

    Raises:
        SymdynError: starting with `prefix`, naming the parameter and the value.
    """
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SymdynError(f"{prefix}parameter {name} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise SymdynError(f"{prefix}parameter {name} must be finite, got {value!r}")
    if abs(x) > MAX_MAGNITUDE:
        raise SymdynError(
            f"{prefix}parameter {name} = {x:g} is too large (more than {MAX_MAGNITUDE:g} in absolute "
            "value, as for a number in a robot file)"
        )
    return x


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
