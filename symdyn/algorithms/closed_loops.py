"""Closed kinematic loops: closure equations, their Jacobian, and the projection onto the
actuated coordinates (Khalil and Dombre, "Modeling, Identification and Control of Robots"
(2002), ch. 7 (geometry of closed loops) and ch. 14 (dynamics of closed-loop robots)).

The robot's links form a spanning tree with coordinates q (n); each loop (symdyn.model.loops)
closes it at two frames A (on `link`) and B (on `to`), world axes:

    point:  phi = p_A(q) - p_B(q)                                   (3 rows: x y z)
    weld:   phi = [p_A - p_B;  1/2 vee(R_A R_B^T - R_B R_A^T)]       (6 rows: x y z, rx ry rz)

The rotation rows vanish when R_A = R_B and equal the rotation vector of R_A R_B^T to first
order. Every row is then expressed in B's axes (phi <- R_B^T phi per block of three), so that a
loop that stays in a plane of its `to` link (a parallelogram behind a waist joint) keeps the
same dependent rows at every configuration. The closure Jacobian is K = R_B^T (J_A - J_B)
(world-aligned frame Jacobians, rows v then w; symdyn.algorithms.frame_kinematics), so that
phi_dot = K qd on the closure, and the drift, with w_B the angular velocity of B (world),

    Kdot qd = R_B^T ((Jdot qd)_A - (Jdot qd)_B - w_B x (J_A - J_B) qd)       (at qdd = 0).

Rows that depend on the others (a planar loop's out-of-plane rows, a loop whose constraints
repeat another's) are dropped: `analyse` assembles the loops numerically (damped Gauss-Newton
on phi from several seeded random starts) and keeps, in order, the rows that raise the
numeric rank of K at the assembled configurations. The mobility is n - rank K; with q split
into the actuated q_a (Robot.actuated_links) and the passive q_p, K = [K_a K_p] and K_p
must be square and invertible:

    qd = W qd_a,  W = [I; -K_p^-1 K_a]         qdd = W qdd_a - [0; K_p^-1 Kdot qd]

(coordinates in their own order, the actuated ones taking the rows of I). The symbolic
inverse of K_p is never printed: `solve_columns` applies it through the normal equations
K_p^T K_p X = K_p^T B, factorised by the unrolled L D L^T of symdyn.algorithms.derivatives
(K_p^T K_p is symmetric positive definite wherever K_p is invertible, so no pivot vanishes
away from the singular configurations; every step is branch-free).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..errors import SymdynError, SymdynWarning
from ..model.robot import Robot
from ..symbolic.program import Program
from .derivatives import ldlt_factor
from .frame_kinematics import FrameKinematics

__all__ = [
    "ROW_NAMES",
    "LoopAnalysis",
    "closure",
    "analyse",
    "check_loops",
    "solve_columns",
    "spd_solve",
    "loop_rows_text",
]

#: The names of a closure's rows, in order (a point loop has the first three).
ROW_NAMES = ("x", "y", "z", "rx", "ry", "rz")
#: Starts of the assembly solve, iterations per start and its tolerance (m, rad).
STARTS, ITERATIONS, ASSEMBLED = 12, 200, 1e-10
#: Relative singular-value threshold of the numeric rank.
RANK_TOL = 1e-8


def _vee_skew(A: sp.Matrix) -> list[sp.Expr]:
    """1/2 vee(A - A^T) of a 3 x 3 matrix."""
    return [(A[2, 1] - A[1, 2]) / 2, (A[0, 2] - A[2, 0]) / 2, (A[1, 0] - A[0, 1]) / 2]


def _cross(a, b) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def closure(fk: FrameKinematics, robot: Robot, drift: bool = True):
    """Every row of every loop (module docstring): (phi, K, Kdot qd or None), lists of rows,
    K's rows as lists of n entries, in B's axes, over fk's program and its q, qd."""
    phi, K, kd = [], [], []
    n = robot.n
    qd = sp.Matrix(fk.qd)
    for loop in robot.loops:
        A, B = loop.frames()
        TA, TB = fk.pose(A), fk.pose(B)
        Kw = fk.jacobian(A) - fk.jacobian(B)
        RBt = TB[:3, :3].T
        d = RBt * (TA[:3, 3] - TB[:3, 3])
        phi += list(d)
        if loop.type == "weld":
            phi += _vee_skew(RBt * TA[:3, :3])
        blocks = range(loop.equations // 3)
        for b in blocks:
            rows = RBt * Kw[3 * b : 3 * b + 3, :]
            K += [[rows[i, j] for j in range(n)] for i in range(3)]
        if drift:
            wB = list(fk.jacobian(B)[3:, :] * qd)
            rel = Kw * qd
            dw = fk.jacobian_dot_qd(A) - fk.jacobian_dot_qd(B)
            for b in blocks:
                turn = _cross(wB, rel[3 * b : 3 * b + 3])
                kd += list(RBt * sp.Matrix([dw[3 * b + i] - turn[i] for i in range(3)]))
    return phi, K, (kd if drift else None)


@dataclass(frozen=True)
class LoopAnalysis:
    """What the numbers say about a robot's loops: the closure rows kept (indices into the rows
    of `closure`), the actuated and passive coordinates, notes on the rows dropped, and the
    assembled configurations found (one per successful start)."""

    rows: tuple[int, ...]
    actuated: tuple[int, ...]
    passive: tuple[int, ...]
    notes: tuple[str, ...]
    assembled: tuple[tuple[float, ...], ...]

    @property
    def mobility(self) -> int:
        return len(self.actuated)


def loop_rows_text(robot: Robot, rows: Sequence[int]) -> list[str]:
    """'B.x', 'B.y', ... naming closure rows (indices into `closure`'s rows)."""
    names = [f"{loop.name}.{ROW_NAMES[k]}" for loop in robot.loops for k in range(loop.equations)]
    return [names[r] for r in rows]


def geometry_parameters(robot: Robot) -> set[sp.Symbol]:
    """The free parameters of the geometry the closure depends on (joint placements and axes, the
    loops' points): the loops are analysed on numbers only when there are none."""
    geometry = set()
    for link in robot.links:
        geometry |= link.placement.matrix().free_symbols | link.axis.free_symbols
    for loop in robot.loops:
        geometry |= loop.point.free_symbols | loop.to_point.free_symbols
    return geometry


def _numeric(robot: Robot):
    """phi(q) and K(q) of every row as NumPy functions (lambdified over a fresh program)."""
    geometry = geometry_parameters(robot)
    if geometry:
        names = ", ".join(sorted(str(s) for s in geometry))
        raise SymdynError(
            f"robot '{robot.name}': the loops are analysed on numbers: give values to the "
            f"parameters of the geometry ({names})",
            file=robot.source,
        )
    q = sp.symbols(f"aq1:{robot.n + 1}")
    prog = Program()
    fk = FrameKinematics(robot, q, [0] * robot.n, prog.copy("A"))
    phi, K, _ = closure(fk, robot, drift=False)
    outs = list(phi) + [e for row in K for e in row]
    steps = fk.program.needed(outs)
    f = sp.lambdify([list(q)], outs, modules="numpy", cse=lambda exprs: (steps, exprs))
    m, n = len(phi), robot.n

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        v = np.array([float(e) for e in f(x)])
        return v[:m], v[m:].reshape(m, n)

    return evaluate


def _assemble(evaluate, rows: list[int], n: int, rng: np.random.Generator) -> list[np.ndarray]:
    """Configurations closing `rows` (damped Gauss-Newton on phi from random starts)."""
    found = []
    for _ in range(STARTS):
        x = rng.uniform(-np.pi, np.pi, n)
        for _ in range(ITERATIONS):
            phi, K = evaluate(x)
            phi, K = phi[rows], K[rows]
            if np.max(np.abs(phi)) < ASSEMBLED:
                found.append(x)
                break
            step = np.linalg.solve(K.T @ K + 1e-9 * np.eye(n), -K.T @ phi)
            x = x + step
        if len(found) >= 3:
            break
    return found


def analyse(robot: Robot) -> LoopAnalysis:
    """Assemble the loops, drop the dependent rows, and check the mobility against
    `Robot.actuated_links` (module docstring). `robot`: its valued parameters substituted.

    Raises:
        SymdynError: a loop that cannot close (its lengths never meet: no start assembles it,
            naming the loop), an actuated set that does not match the mobility, or passive
            joints that the closure does not determine (K_p singular).
    """
    assert robot.loops
    evaluate = _numeric(robot)
    n = robot.n
    where = f"robot '{robot.name}'"
    rng = np.random.default_rng(0)
    start, spans = 0, []
    for loop in robot.loops:
        spans.append(list(range(start, start + loop.equations)))
        start += loop.equations
    for loop, rows in zip(robot.loops, spans, strict=True):
        if not _assemble(evaluate, rows, n, rng):
            raise SymdynError(
                f"{where}: loop '{loop.name}': cannot close: no configuration brings its points "
                f"together from {STARTS} starts (check the lengths and points of field 'loops')",
                file=robot.source,
            )
    every = list(range(start))
    configs = _assemble(evaluate, every, n, rng)
    if not configs:
        raise SymdynError(
            f"{where}: the loops {', '.join(lp.name for lp in robot.loops)} cannot close together "
            f"from {STARTS} starts (check the lengths and points of field 'loops')",
            file=robot.source,
        )
    Ks = [evaluate(x)[1] for x in configs]
    kept: list[int] = []
    for r in every:
        trial = kept + [r]
        if all(
            np.linalg.matrix_rank(K[trial], tol=RANK_TOL * max(1.0, np.abs(K).max())) == len(trial)
            for K in Ks
        ):
            kept.append(r)
    dropped = [r for r in every if r not in kept]
    notes = []
    if dropped:
        names = ", ".join(loop_rows_text(robot, dropped))
        notes.append(f"{where}: closure rows {names} depend on the others and are dropped")
    coordinate = [c.index for c in robot.coordinates]
    actuated = tuple(sorted({coordinate[i] for i in robot.actuated_links}))
    passive = tuple(j for j in range(n) if j not in actuated)
    mobility = n - len(kept)
    if len(actuated) != mobility:
        listed = ", ".join(robot.links[i].name for i in robot.actuated_links) or "none"
        raise SymdynError(
            f"{where}: field 'actuated': {len(actuated)} actuated joints ({listed}) but the loops "
            f"leave {mobility} degrees of freedom ({n} joints, {len(kept)} independent closure "
            "equations): list that many",
            file=robot.source,
        )
    for K in Ks:
        Kp = K[np.ix_(kept, passive)]
        if np.linalg.matrix_rank(Kp, tol=RANK_TOL * max(1.0, np.abs(Kp).max())) < len(passive):
            raise SymdynError(
                f"{where}: field 'actuated': the closure does not determine the passive joints "
                f"({', '.join(_coordinate_names(robot, passive))}) from the actuated ones: choose "
                "other actuated joints",
                file=robot.source,
            )
    return LoopAnalysis(
        tuple(kept), actuated, passive, tuple(notes), tuple(tuple(map(float, x)) for x in configs)
    )


def check_loops(robot: Robot) -> LoopAnalysis:
    """`analyse`, with a SymdynWarning for each note (the closure rows dropped as dependent): the
    check of the loops that both `symdyn generate` and `symdyn derive` make before they print."""
    an = analyse(robot)
    for note in an.notes:
        warnings.warn(note, SymdynWarning, stacklevel=3)
    return an


def _coordinate_names(robot: Robot, coords: Sequence[int]) -> list[str]:
    own = [link.name for link in robot.links if link.mimic is None]
    return [own[j] for j in coords]


def spd_solve(M: sp.Matrix, B: sp.Matrix, program: Program, hint: str) -> tuple[sp.Matrix, list[sp.Expr]]:
    """(X, D): X = M^-1 B for a symmetric positive definite M (k x k), B (k x c), by M = L D L^T
    unrolled (symdyn.algorithms.derivatives.ldlt_factor), then L y = b, L^T x = D^-1 y; entries
    named; D the pivots."""
    k = M.rows
    L, D = ldlt_factor(M, program, hint)
    X = sp.zeros(k, B.cols)
    for c in range(B.cols):
        y: list[sp.Expr] = []
        for i in range(k):
            y.append(program.let(B[i, c] - sum((L[i, j] * y[j] for j in range(i)), sp.S.Zero), f"{hint}y"))
        for i in reversed(range(k)):
            s = y[i] / D[i] - sum((L[j, i] * X[j, c] for j in range(i + 1, k)), sp.S.Zero)
            X[i, c] = program.let(s, f"{hint}x")
    return X, D


def solve_columns(A: sp.Matrix, B: sp.Matrix, program: Program, hint: str) -> tuple[sp.Matrix, list[sp.Expr]]:
    """(X, r): X = A^-1 B for a square invertible A (k x k) and B (k x c), through the normal
    equations A^T A X = A^T B (`spd_solve`; module docstring), entries named; r the relative
    pivots D_j / (A^T A)_jj, in (0, 1] and near 0 only where A is near singular."""
    k = A.rows

    def product(P: sp.Matrix, i: int, j: int) -> sp.Expr:
        return program.let(sum((A[r, i] * P[r, j] for r in range(k)), sp.S.Zero), f"{hint}N")

    N = sp.Matrix(k, k, lambda i, j: product(A, i, j))
    X, D = spd_solve(N, sp.Matrix(k, B.cols, lambda i, j: product(B, i, j)), program, hint)
    return X, [program.let(d / N[j, j], f"{hint}r") for j, d in enumerate(D)]
