"""The stance schedule of a simulation with contacts (docs/contacts.md, "Simulating contacts"):
which contacts hold over which samples.

A schedule is a list of (T, names): from time T on, exactly the contacts named hold (the others are
free). Times increase strictly and lie in [0, duration]; before the first T every contact holds
(as without a schedule), so an entry at T = 0 sets the starting stance. Each change happens at the
first sample t_k >= T (two changes may not fall on one sample). A touchdown `impulse_at` T is
the schedule [(0, ()), (T, every contact)]: free, then all held.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...errors import SymdynError, shown

__all__ = ["stance_schedule"]


def _entry(robot, entry, i: int, duration: float) -> tuple[float, np.ndarray]:
    """(T, the NCONTACT mask) of one (T, names) entry, checked."""
    names = [c.name for c in robot.contacts]
    if isinstance(entry, (str, bytes)) or not isinstance(entry, Sequence) or len(entry) != 2:
        raise SymdynError(f"stance entry {i} must be a pair (time, contact names), got {shown(entry)}")
    t, held = entry
    if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)):
        raise SymdynError(f"stance entry {i}: the time must be a number, got {shown(t)}")
    if not (math.isfinite(t) and 0.0 <= t <= duration):
        raise SymdynError(
            f"stance entry {i}: the time {t!r} s must lie in [0, {duration:g}] s, the run's time"
        )
    if isinstance(held, (str, bytes)) or not isinstance(held, Sequence | set | frozenset):
        raise SymdynError(f"stance entry {i}: the contacts must be a list of names, got {shown(held)}")
    mask = np.zeros(len(names))
    for name in held:
        if name not in names:
            raise SymdynError(
                f"stance at t = {t:g} s: no contact is named {shown(name)} (contacts: {', '.join(names)})"
            )
        mask[names.index(name)] = 1.0
    return float(t), mask


def stance_schedule(
    robot, t: np.ndarray, duration: float, stance=None, impulse_at: float | None = None
) -> list[tuple[int, np.ndarray]]:
    """[(k, mask)]: from sample k on (k strictly increasing, the first 0) the contacts with mask 1
    hold (module docstring). Raises SymdynError for a bad schedule, one line."""
    ncontact = len(robot.contacts)
    if impulse_at is not None:
        if stance is not None:
            raise SymdynError("give the touchdown either as impulse_at or in the stance, not both")
        entries = [(0.0, np.zeros(ncontact)), (float(impulse_at), np.ones(ncontact))]
    elif stance is None:
        entries = []
    else:
        if isinstance(stance, (str, bytes)) or not isinstance(stance, Sequence) or not stance:
            raise SymdynError(
                f"the stance must be a non-empty list of (time, contact names), got {shown(stance)}"
            )
        entries = [_entry(robot, e, i, duration) for i, e in enumerate(stance)]
        for (t0, _), (t1, _) in zip(entries, entries[1:], strict=False):
            if not t1 > t0:
                raise SymdynError(f"the stance's times must increase: {t1:g} s after {t0:g} s")
    slack = 1e-12 * max(1.0, duration)
    out, placed = [(0, np.ones(ncontact))], set()
    for time, mask in entries:
        k = int(np.searchsorted(t, time - slack))
        if k in placed:
            raise SymdynError(
                f"the stance changes twice at the sample t = {t[k]:g} s: give the times a dt apart"
            )
        placed.add(k)
        if k == 0:
            out[0] = (0, mask)
        else:
            out.append((k, mask))
    return out
