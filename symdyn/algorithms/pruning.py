"""Significance pruning of the configuration-space form (Armstrong, Khatib and Burdick's
"1 % model"): drop the terms of M, B, Csq and G that never matter over the joint ranges.

Every entry is a sum of terms c g^e trig(k . q + r) (symdyn.symbolic.trig_polynomial).
Over the box of joint ranges q_i in [lo_i, hi_i] a term is at most

    |c| * prod_j max(|lo_j|, |hi_j|)^e_j * max |cos or sin| of k . q + r over the box,

the last found exactly from the interval k . q + r covers (1 when it holds a multiple of pi,
resp. of pi/2 off one, else the larger end). A term is dropped when that bound is below
`rel` times the entry's largest value over the box (estimated on random states and the
box's corners, so a lower estimate: pruning is conservative about what it keeps). The error
of the entry is then at most the sum of the dropped terms' bounds, which `Pruned.bounds`
states for every entry; V = B [qd qd] + Csq [qd^2] errs by at most
sum bound(B[k,(i,j)]) |qd_i qd_j| + sum bound(Csq[k,i]) qd_i^2.

The box (`joint_box`) is the robot's own joint ranges: each coordinate's `limits` (the robot
file's `limits`, the URDF's <limit>; Robot.joint_ranges), else +-pi, a revolute joint's full
turn. A prismatic joint without limits gets +-pi too, read as metres, as pruning always did:
give it `limits` when it travels farther. The bounds hold for states inside the box only.

Reference: B. Armstrong, O. Khatib, J. Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986 (the simplified models).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp

from ..errors import SymdynError
from ..symbolic.trig_polynomial import TrigPoly, TrigRing
from .configuration_space import ConfigurationSpace, pair_columns

if TYPE_CHECKING:
    from ..model.robot import Robot

__all__ = ["Pruned", "prune", "prune_robot", "trig_bound", "joint_box"]

SAMPLES = 2000


def trig_bound(lo: float, hi: float, kind: int) -> float:
    """max |cos x| (kind 0) or |sin x| (kind 1) for x in [lo, hi]."""
    if hi - lo >= math.pi:
        return 1.0
    shift = 0.0 if kind == 0 else math.pi / 2  # |cos| peaks at m pi, |sin| at pi/2 + m pi
    if math.floor((hi - shift) / math.pi) >= math.ceil((lo - shift) / math.pi):
        return 1.0
    f = math.cos if kind == 0 else math.sin
    return max(abs(f(lo)), abs(f(hi)))


def _term_bound(ring: TrigRing, key, c, limits, values) -> float:
    mono, k, kind = key
    value = abs(float(c))
    for g, e in mono:
        if g < ring.n:
            lo, hi = limits[g]
            value *= max(abs(lo), abs(hi)) ** e
        else:
            value *= abs(float(sp.sympify(ring.gens[g]).xreplace(values))) ** e
    if any(k):
        lo = hi = float(k[ring.n])
        for j in range(ring.n):
            a, b = k[j] * limits[j][0], k[j] * limits[j][1]
            lo, hi = lo + min(a, b), hi + max(a, b)
        value *= trig_bound(lo, hi, kind)
    return value


@dataclass
class Pruned:
    """The pruned form, and for each entry (name, row, column) its largest value over the
    box and the bound on its error."""

    configuration: ConfigurationSpace
    rel: float
    largest: dict[tuple[str, int, int], float]
    bounds: dict[tuple[str, int, int], float]
    terms_before: int
    terms_after: int
    #: the box the bounds hold over: (lower, upper) per joint, and where it came from
    limits: list[tuple[float, float]] = field(default_factory=list)
    ranges: str = ""

    def worst(self) -> float:
        """The largest error bound relative to its entry's largest value (0 if none dropped)."""
        return max((b / self.largest[key] for key, b in self.bounds.items() if b > 0), default=0.0)


def _states(limits, samples: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = np.array(limits, dtype=float).T
    points = rng.uniform(lo, hi, (samples, len(limits)))
    if len(limits) <= 8:
        corners = np.array(list(itertools.product(*limits)), dtype=float)
        points = np.vstack([points, corners])
    return points


def prune(
    cs: ConfigurationSpace,
    rel: float,
    limits: Sequence[tuple[float, float]] | None = None,
    values: Mapping[sp.Symbol, float] | None = None,
    samples: int = SAMPLES,
    seed: int = 0,
) -> Pruned:
    """Drop the terms of M, Gamma (hence B and Csq) and G below `rel` of their entry's
    largest value over the joint ranges.

    Args:
        cs: the configuration-space form (joint space).
        rel: the relative threshold, e.g. 0.01 for AKB's 1 % model.
        limits: (lower, upper) per joint; default +-pi.
        values: numbers for the free parameters (all of them).
        samples: random states to estimate each entry's largest value.

    Raises:
        SymdynError: rel not in (0, 1), limits of the wrong length, or a free parameter without a value.
    """
    n = cs.n
    if not 0 < rel < 1:
        raise SymdynError(f"prune: the relative threshold must be between 0 and 1, got {rel}")
    ranges = "joint ranges: +-pi" if limits is None else "joint ranges: as given"
    limits = [(-math.pi, math.pi)] * n if limits is None else [(float(a), float(b)) for a, b in limits]
    if len(limits) != n:
        raise SymdynError(f"prune: {len(limits)} joint ranges for {n} joints")
    values = dict(values or {})
    free = [g for g in cs.ring.gens[n:] if sp.sympify(g).xreplace(values).free_symbols]
    if free:
        raise SymdynError(f"prune: needs numbers for the free parameters ({', '.join(map(str, free))})")
    states = _states(limits, samples, seed)
    largest: dict = {}
    bounds: dict = {}
    before = after = 0

    def cut(name: str, r: int, c: int, p: TrigPoly) -> TrigPoly:
        nonlocal before, after
        if not p:
            return p
        top = float(np.abs(cs.ring.numeric(p, values)(states)).max())
        tb = {key: _term_bound(cs.ring, key, coef, limits, values) for key, coef in p.items()}
        kept = {key: coef for key, coef in p.items() if tb[key] >= rel * top}
        largest[(name, r, c)] = top
        bounds[(name, r, c)] = sum(b for key, b in tb.items() if key not in kept)
        before, after = before + len(p), after + len(kept)
        return kept

    M = [[{} for _ in range(n)] for _ in range(n)]
    for i in range(n):
        for j in range(i, n):
            M[i][j] = M[j][i] = cut("M", i, j, cs.M[i][j])
    G = [cut("G", k, 0, p) for k, p in enumerate(cs.G)]
    gamma = {(k, i, j): cut("Gamma", k, i * n + j, p) for (k, i, j), p in cs.gamma.items()}
    gamma = {key: p for key, p in gamma.items() if p}
    pruned = replace(cs, M=M, G=G, gamma=gamma, _sympy={})
    # the entries of B and Csq: B = 2 Gamma (i < j), Csq = Gamma (i = j)
    pairs = {pair: c for c, pair in enumerate(pair_columns(n))}
    for key in list(bounds):
        if key[0] == "Gamma":
            _, k, flat = key
            i, j = divmod(flat, n)
            scale = 1.0 if i == j else 2.0
            target = ("Csq", k, i) if i == j else ("B", k, pairs[(i, j)])
            largest[target] = scale * largest.pop(key)
            bounds[target] = scale * bounds.pop(key)
    return Pruned(pruned, rel, largest, bounds, before, after, limits, ranges)


def _span(indices: list[int]) -> str:
    """q1..q3, q5, q6 for coordinates 0, 1, 2, 4, 5 (runs of three or more shortened)."""
    runs: list[list[int]] = []
    for k in indices:
        if runs and k == runs[-1][-1] + 1:
            runs[-1].append(k)
        else:
            runs.append([k])
    names = [[f"q{k + 1}" for k in r] for r in runs]
    return ", ".join(f"{r[0]}..{r[-1]}" if len(r) > 2 else ", ".join(r) for r in names)


def joint_box(robot: Robot) -> tuple[list[tuple[float, float]], str]:
    """The joint ranges to prune over, and a line saying where they come from.

    Returns:
        (lower, upper) per independent coordinate: its link's `limits` (Robot.joint_ranges),
        else +-pi (a prismatic joint's +-pi read as metres); and the text, e.g.
        "joint ranges: robot file limits for q1..q5; +-pi for q6 (no limits)".

    Raises:
        SymdynError: limits that are not numbers lower < upper (naming the link).
    """
    ranges = robot.joint_ranges()
    kinds = [lk.joint for lk in robot.links if lk.mimic is None]
    origin = "URDF" if robot.convention == "urdf" else "robot file" if robot.source else "link"
    groups: dict[str, list[int]] = {
        f"{origin} limits": [],
        "+-pi": [],
        f"+-{math.pi:.4g} m": [],
    }
    for k, (r, kind) in enumerate(zip(ranges, kinds, strict=True)):
        key = 0 if r is not None else 1 if kind == "revolute" else 2
        groups[list(groups)[key]].append(k)
    notes = {"+-pi": " (no limits)", f"+-{math.pi:.4g} m": " (prismatic, no limits)"}
    text = "; ".join(f"{name} for {_span(ks)}{notes.get(name, '')}" for name, ks in groups.items() if ks)
    return [(-math.pi, math.pi) if r is None else r for r in ranges], f"joint ranges: {text}"


def prune_robot(cs: ConfigurationSpace, robot: Robot, rel: float) -> Pruned:
    """`prune` over the robot's own joint ranges (joint_box), which `Pruned.ranges` names."""
    limits, ranges = joint_box(robot)
    return replace(prune(cs, rel, limits=limits), ranges=ranges)
