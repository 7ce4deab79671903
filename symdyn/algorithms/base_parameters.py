"""Base parameters: the identifiable linear combinations of the standard parameters.

tau = Y pi (symdyn.algorithms.regressor) determines pi only up to the null space of Y: some
columns are zero at every state (a parameter that moves nothing, such as the inertia of the first
body about axes other than its joint axis) and others are fixed linear combinations of earlier
columns (the mass of link 2 seen at the end of link 1 acts like m2 a1 in mx1 and m2 a1^2 in Izz1).
With the columns split into r independent ones Y_1 and the rest Y_2 = Y_1 beta,

    tau = Y pi = Y_1 (pi_1 + beta pi_2) = Y_b pi_b,    pi_b = pi_1 + beta pi_2,

so the base regressor Y_b is the independent columns of Y and each base parameter is the kept
standard parameter plus the ones regrouped into it (Gautier, "Numerical calculation of the base
inertial parameters of robots", 1991; Khalil and Dombre, Modeling, Identification and Control of
Robots (2002), sec. 12.3).

Numerically: Y is evaluated at STATES_PER_COLUMN * 13 nb / n + 10 random states (revolute angles
uniform over a full turn, prismatic positions in +-0.5 m, on a floating base (n = NV rows) the
base in +-1 m with a random unit quaternion, rates and accelerations in +-2, free
parameters uniform in [0.5, 2]) and stacked into W. Columns with a norm below ZERO_TOL times the
largest are zero. The others are scaled to unit norm; a QR factorisation with column pivoting
(largest remaining norm first) gives the rank r, the number of diagonal entries |R_kk| above
RANK_TOL |R_00|. The kept columns are then chosen in the order of the standard parameters (body
1 first, m before the inertias): a column is kept when its distance to the span of the columns
kept before it exceeds RANK_TOL, so parameters of later bodies regroup into earlier ones (on a
floating base the base body, body 0, comes first). Both counts must agree. beta solves
W_1 beta = W_2 in the least-squares sense.

Coefficients: when beta depends on the robot's free parameters (symbolic lengths: beta differs at
two random values of them) it is found exactly.
The closed forms of the columns involved (where every angle must enter as sin(q) and cos(q):
else a SymdynError asks for the parameters' values) are evaluated at states whose sines and cosines are
rational points of the unit circle ((1 - t^2) / (1 + t^2), 2 t / (1 + t^2)) with the numbers of
the model made rational, and r independent rows solve W_1 beta = W_2 over the rational functions
of the parameters; the result is checked against the numeric beta. Otherwise each coefficient is
the numeric beta: an integer or a fraction with a denominator
up to 12 when it is one to 1e-10, else the number to 12 significant digits, and 0 when its
contribution is below 1e-9 of the column's.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..errors import SymdynError
from ..model.robot import Robot
from ..symbolic.program import Program

__all__ = ["BaseParameters", "find_base_parameters", "evaluate", "RANK_TOL", "ZERO_TOL", "STATES_PER_COLUMN"]

#: |R_kk| / |R_00| below this (unit-norm columns) counts as rank-deficient
RANK_TOL = 1e-8
#: a column whose norm is below this times the largest column norm is zero
ZERO_TOL = 1e-10
#: random states per column and joint row: STATES_PER_COLUMN * 13 nb / n + 10 states
STATES_PER_COLUMN = 3
_SEED = 20260


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters pi_b = K pi of a robot, and which columns of Y form Y_b.

    names: one per base parameter (the kept standard parameter's name, with "R" appended when
    others are regrouped into it); columns: the indices of the kept standard parameters (Y_b =
    Y[:, columns]); K: the r x 13 nb coefficient matrix (SymPy numbers, or expressions of the
    robot's free parameters); standard: the standard parameters' symbols (m1, mx1, ...).
    """

    names: tuple[str, ...]
    columns: tuple[int, ...]
    K: sp.ImmutableMatrix
    standard: tuple[sp.Symbol, ...]

    @property
    def expressions(self) -> tuple[sp.Expr, ...]:
        """Each base parameter as a linear combination of the standard parameters' symbols."""
        return tuple(
            sum((c * s for c, s in zip(self.K.row(k), self.standard, strict=True)), sp.S.Zero)
            for k in range(self.K.rows)
        )

    def matrix(self, params: dict | None = None) -> np.ndarray:
        """K as floats (r x 13 nb), with the free parameters' values (a symbol -> number map)."""
        K = self.K.xreplace({s: sp.Float(v) for s, v in (params or {}).items()}) if params else self.K
        return np.array(K.tolist(), dtype=float)


def _states(robot: Robot, rng: np.random.Generator, count: int):
    revolute = np.array([lk.joint == "revolute" for lk in robot.links if lk.mimic is None])
    q = np.where(
        revolute, rng.uniform(-np.pi, np.pi, (count, robot.n)), rng.uniform(-0.5, 0.5, (count, robot.n))
    )
    nv = robot.nv
    qd = rng.uniform(-2, 2, (count, nv))
    qd[np.abs(qd) < 1e-3] = 0.5
    if robot.floating:  # base position in +-1 m, a random unit quaternion, then the joints
        quat = rng.normal(size=(count, 4))
        quat /= np.linalg.norm(quat, axis=1, keepdims=True)
        q = np.concatenate([rng.uniform(-1, 1, (count, 3)), quat, q], 1)
    return q, qd, rng.uniform(-2, 2, (count, nv))


def _value(e: sp.Expr, values: dict, memo: dict, count: int):
    """e at `count` states: a NumPy array, or a float when it is a constant."""
    if e.is_Symbol:
        return values[e]
    if e.is_Number:
        return float(e)
    hit = memo.get(e)
    if hit is not None:
        return hit
    args = [_value(a, values, memo, count) for a in e.args]
    if e.is_Add:
        out = sum(args[1:], args[0])
    elif e.is_Mul:
        out = args[0]
        for a in args[1:]:
            out = out * a
    elif e.is_Pow:
        out = args[0] ** args[1]
    elif isinstance(e, sp.sin):
        out = np.sin(args[0])
    elif isinstance(e, sp.cos):
        out = np.cos(args[0])
    elif isinstance(e, sp.sign):
        out = np.sign(args[0])
    elif isinstance(e, sp.Heaviside):
        out = np.heaviside(args[0], args[1])
    else:
        out = (
            float(e)
            if not e.free_symbols
            else np.asarray(
                sp.lambdify(list(e.free_symbols), e)(*(values[s] for s in e.free_symbols)), dtype=float
            )
        )
    memo[e] = out
    return out


def evaluate(program: Program, outputs: list[sp.Expr], values: dict, count: int) -> np.ndarray:
    """The outputs (over the program's intermediates) at `count` states, (len(outputs), count):
    a direct NumPy walk of the needed assignments (the inputs' arrays in `values`)."""
    values = dict(values)
    memo: dict = {}
    for sym, expr in program.needed(outputs):
        values[sym] = _value(expr, values, memo, count)
    return np.array([np.broadcast_to(_value(sp.sympify(e), values, memo, count), (count,)) for e in outputs])


def _pivoted_rank(A: np.ndarray) -> int:
    """Rank of A (unit-norm columns) by Householder QR with column pivoting: |R_kk| > RANK_TOL |R_00|."""
    A = A.copy()
    m, ncols = A.shape
    norms = np.sum(A * A, axis=0)
    first = None
    for k in range(min(m, ncols)):
        p = k + int(np.argmax(norms[k:]))
        A[:, [k, p]], norms[[k, p]] = A[:, [p, k]], norms[[p, k]]
        x = A[k:, k]
        alpha = np.linalg.norm(x)
        first = alpha if first is None else first
        if alpha <= RANK_TOL * first:
            return k
        v = x.copy()
        v[0] += np.copysign(alpha, x[0])
        v /= np.linalg.norm(v)
        A[k:, k:] -= 2.0 * np.outer(v, v @ A[k:, k:])
        norms[k + 1 :] = np.sum(A[k + 1 :, k + 1 :] ** 2, axis=0)
    return min(m, ncols)


def _kept_in_order(A: np.ndarray, candidates: list[int]) -> list[int]:
    """The columns of A (unit norm) kept in order: each farther than RANK_TOL from the earlier ones."""
    basis = np.zeros((A.shape[0], 0))
    kept = []
    for c in candidates:
        x = A[:, c]
        for _ in range(2):  # Gram-Schmidt, twice for orthogonality
            x = x - basis @ (basis.T @ x)
        d = np.linalg.norm(x)
        if d > RANK_TOL:
            kept.append(c)
            basis = np.column_stack([basis, x / d])
    return kept


def _number(c: float, scale: float) -> sp.Expr:
    """A numeric coefficient as an integer, a small fraction or a 12-digit number (see the module)."""
    if abs(c) * scale < 1e-9:
        return sp.S.Zero
    f = Fraction(c).limit_denominator(12)
    if abs(float(f) - c) <= 1e-10 * max(1.0, abs(c)):
        return sp.Rational(f.numerator, f.denominator)
    return sp.Float(float(f"{c:.12g}"), 15)


def _rational_trig(robot: Robot, q, qd, qdd, rng: np.random.Generator, program: Program, Y, cols, count):
    """Exact rows of Y[:, cols] at `count` states with rational sines and cosines (module docstring)."""
    exprs = program.expand([Y[r, c] for r in range(Y.rows) for c in cols])
    joints = set(q) | {-x for x in q}
    other = sorted({str(f) for e in exprs for f in e.atoms(sp.sin, sp.cos) if f.args[0] not in joints})
    if other:
        raise SymdynError(
            f"robot '{robot.name}': the base parameters depend on its free parameters, and are found "
            f"exactly only when the joint angles enter as sin(q) and cos(q), not as {other[0]} (a mimic "
            "joint's multiplier or a joint offset): give the free parameters values"
        )
    rows = []
    for _ in range(count):
        subs = {}
        for qi in q:
            t = sp.Rational(int(rng.integers(-40, 41)), int(rng.integers(1, 41)))
            subs[sp.cos(qi)], subs[sp.sin(qi)] = (1 - t**2) / (1 + t**2), 2 * t / (1 + t**2)
            subs[sp.cos(-qi)], subs[sp.sin(-qi)] = subs[sp.cos(qi)], -subs[sp.sin(qi)]
            subs[qi] = sp.Rational(int(rng.integers(1, 51)) * int(rng.choice([-1, 1])), 25)
        for x in (*qd, *qdd):
            subs[x] = sp.Rational(int(rng.integers(1, 51)) * int(rng.choice([-1, 1])), 25)
        vals = []
        for e in exprs:
            e = e.xreplace({f: sp.Rational(str(f)) for f in e.atoms(sp.Float)}).xreplace(subs)
            assert e.free_symbols <= set(robot.params), e.free_symbols
            vals.append(sp.expand(e))
        rows += [vals[r * len(cols) : (r + 1) * len(cols)] for r in range(Y.rows)]
    return sp.Matrix(rows)


def _exact_beta(robot, q, qd, qdd, program, Y, kept, dependent, rng, beta_num, p0) -> sp.Matrix:
    """beta over the rational functions of the free parameters, checked against the numeric beta."""
    cols = kept + dependent
    count = -(-2 * len(kept) // Y.rows) + 2
    W = _rational_trig(robot, q, qd, qdd, rng, program, Y, cols, count)
    at_p0 = np.array(W.xreplace({s: sp.Float(v) for s, v in p0.items()}).tolist(), dtype=float)
    # r rows independent at p0: pivoted selection on W_1^T
    A = at_p0[:, : len(kept)].T
    A = A / np.maximum(np.linalg.norm(A, axis=0), 1e-300)
    rows = _kept_in_order(A, list(range(A.shape[1])))
    assert len(rows) == len(kept), (len(rows), len(kept))
    W1 = DomainMatrix.from_Matrix(W.extract(rows, list(range(len(kept))))).to_field()
    W2 = DomainMatrix.from_Matrix(W.extract(rows, list(range(len(kept), len(cols)))))
    dom = W1.domain.unify(W2.domain)
    beta = W1.convert_to(dom).to_field().lu_solve(W2.convert_to(dom).to_field()).to_Matrix()
    beta = beta.applyfunc(lambda x: sp.factor(sp.cancel(x)))
    got = np.array(beta.xreplace({s: sp.Float(v) for s, v in p0.items()}).tolist(), dtype=float)
    assert np.allclose(got, beta_num, rtol=1e-7, atol=1e-9 * np.abs(beta_num).max(initial=1.0)), (
        got,
        beta_num,
    )
    return beta


def _stacked(program: Program, Y: sp.Matrix, joints, states, p: dict) -> np.ndarray:
    """Y at the states (q, qd, qdd arrays of shape (count, n)) stacked row block by row block,
    with the free parameters' values p."""
    count = len(states[0])
    values: dict = {s: np.full(count, v) for s, v in p.items()}
    for symbols, x in zip(joints, states, strict=True):
        values.update({s: x[:, i] for i, s in enumerate(symbols)})
    Ys = evaluate(program, list(Y), values, count)  # (entries, count)
    return np.concatenate([Ys[r * Y.cols : (r + 1) * Y.cols].T for r in range(Y.rows)], axis=0)


def find_base_parameters(
    robot: Robot, Y: sp.Matrix, program: Program, q, qd, qdd, names: tuple[str, ...]
) -> BaseParameters:
    """The base parameters of `robot` from its regressor Y (n x 13 nb over `program`); see the module.

    Args:
        robot: the model with values substituted (`Robot.resolved`); its free parameters stay symbols.
        Y: the regressor over the program's intermediates (symdyn.algorithms.regressor).
        program: the intermediates Y uses.
        q, qd, qdd: the joint symbols Y is written in.
        names: the standard parameters' names (symdyn.standard_parameters), one per column.
    """
    rng = np.random.default_rng(_SEED)
    params = list(robot.params)
    p0 = {s: float(v) for s, v in zip(params, rng.uniform(0.5, 2.0, len(params)), strict=True)}
    count = -(-STATES_PER_COLUMN * Y.cols // Y.rows) + 10
    states = _states(robot, rng, count)
    with np.errstate(all="ignore"):
        W = _stacked(program, Y, (q, qd, qdd), states, p0)
        norms = np.linalg.norm(W, axis=0)
    if not np.isfinite(norms).all():
        raise SymdynError(
            f"robot '{robot.name}': the regressor overflows double precision at ordinary joint states "
            "(a length, mass or inertia so large that its powers exceed 1e308), so its base parameters "
            "cannot be found; give the robot in units that keep its numbers moderate"
        )
    nonzero = [c for c in range(W.shape[1]) if norms[c] > ZERO_TOL * norms.max()]
    A = W[:, nonzero] / norms[nonzero]
    rank = _pivoted_rank(A)
    order = list(range(len(nonzero)))
    if robot.floating:  # the base body (its 10 columns last) first: the links regroup into it
        order = [k for k in order if nonzero[k] >= Y.cols - 10] + [
            k for k in order if nonzero[k] < Y.cols - 10
        ]
    kept = [nonzero[k] for k in _kept_in_order(A, order)]
    if len(kept) != rank:
        raise SymdynError(
            f"robot '{robot.name}': the numeric rank of the regressor is ambiguous "
            f"({rank} by pivoted QR, {len(kept)} in order); report this robot"
        )
    dependent = [c for c in nonzero if c not in kept]
    beta = np.linalg.lstsq(W[:, kept], W[:, dependent], rcond=None)[0] if dependent else np.zeros((rank, 0))
    assert np.allclose(W[:, kept] @ beta, W[:, dependent], atol=1e-8 * norms.max())
    exact = False
    if params and dependent:
        p1 = {s: float(v) for s, v in zip(params, rng.uniform(0.5, 2.0, len(params)), strict=True)}
        W1 = _stacked(program, Y, (q, qd, qdd), states, p1)
        beta1 = np.linalg.lstsq(W1[:, kept], W1[:, dependent], rcond=None)[0]
        exact = not np.allclose(beta, beta1, rtol=1e-9, atol=1e-12 * np.abs(beta).max())
    if exact:  # the coefficients depend on the free parameters
        coeffs = _exact_beta(robot, q, qd, qdd, program, Y, kept, dependent, rng, beta, p0)
    else:
        coeffs = sp.Matrix(
            rank, len(dependent), lambda k, d: _number(beta[k, d], norms[kept[k]] / norms[dependent[d]])
        )
    K = sp.zeros(rank, Y.cols)
    for k, c in enumerate(kept):
        K[k, c] = 1
        for d, dc in enumerate(dependent):
            K[k, dc] = coeffs[k, d]
    base_names = tuple(
        names[c] + ("R" if any(K[k, dc] != 0 for dc in dependent) else "") for k, c in enumerate(kept)
    )
    standard = tuple(sp.Symbol(x) for x in names)
    return BaseParameters(base_names, tuple(kept), sp.ImmutableMatrix(K), standard)
