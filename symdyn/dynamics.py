"""`derive`: the equations of motion tau = M(q) qdd + V(q, qd) + G(q) + F(qd) (slide 16).

Two independent routes fill the same `Dynamics`:
- "newton-euler" (algorithms.newton_euler, .crba, .coriolis): V = NE(q, qd, 0)
  with gravity off; M by the composite-rigid-body algorithm and G from the same
  composite bodies (both equal to NE with unit accelerations, resp. NE(q, 0, 0));
  tau from one full pass; C = 1/2 dV/dqd from composite inertias, momenta and
  inertia rates, which equals the Christoffel-symbol matrix because
  V_k = sum_ij Gamma^k_ij qd_i qd_j with Gamma^k_ij symmetric in i, j.
- "lagrange" (symdyn.algorithms.lagrange): M from the link Jacobians, C from the
  Christoffel symbols of M, G from the potential energy, V = C qd.

Both keep their results as expressions over named intermediates
(symdyn.symbolic.program); `Dynamics.M` etc. give closed forms over q, qd, qdd and the
free parameters, simplified with trigonometric identities when requested
(by default for robots of up to 3 joints).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from sympy.core.parameters import distribute

from .algorithms.coriolis import coriolis_matrix_composite
from .algorithms.crba import composite_inertias, gravity_composite, mass_matrix_crba
from .algorithms.frames import joint_frames
from .algorithms.lagrange import lagrange
from .algorithms.newton_euler import newton_euler
from .errors import SymdynError
from .model.robot import Robot
from .model.symbols import joint_symbols
from .symbolic.program import Program
from .symbolic.simplify import chop_float_noise

__all__ = ["Dynamics", "derive", "METHODS", "QUANTITIES", "friction_vector"]

METHODS = ("newton-euler", "lagrange")
QUANTITIES = ("M", "C", "V", "G", "F", "tau")
AUTO_SIMPLIFY_MAX_JOINTS = 3


def friction_vector(robot: Robot, qd) -> sp.Matrix:
    """F_i = viscous_i qd_i + coulomb_i sign(qd_i) (slide 16)."""
    return sp.Matrix(
        [
            link.friction.viscous * qd[i] + link.friction.coulomb * sp.sign(qd[i])
            for i, link in enumerate(robot.links)
        ]
    )


def simplify_entry(expr: sp.Expr) -> sp.Expr:
    """A readable closed form: expanded, trigonometric identities applied, float rounding
    residues dropped, common factors pulled out."""
    if expr == 0 or expr.is_Atom:
        return expr
    e = sp.trigsimp(sp.expand(expr))
    return sp.factor_terms(chop_float_noise(e))


@dataclass
class Dynamics:
    """The equations of motion of a robot, compact (over intermediates) and closed-form.

    `compact[name]` holds each of M, C, V, G, F, tau, and bias = V + G + F (one
    Newton-Euler pass with qdd = 0, for forward dynamics), as a SymPy Matrix over
    the named intermediates of `program`; the attributes `M`, `C`, `V`, `G`, `F`,
    `tau` are closed forms over q, qd, qdd and `params` only.
    """

    robot: Robot
    method: str
    q: sp.Matrix
    qd: sp.Matrix
    qdd: sp.Matrix
    params: tuple[sp.Symbol, ...]
    program: Program
    compact: dict[str, sp.Matrix]
    simplified: bool
    _closed: dict[str, sp.Matrix] = field(default_factory=dict, repr=False)
    _compiled: dict[str, object] = field(default_factory=dict, repr=False)

    @property
    def n(self) -> int:
        return self.robot.n

    def closed_form(self, name: str) -> sp.Matrix:
        """Quantity `name` with the intermediates substituted back (and simplified if requested)."""
        if name not in QUANTITIES:
            raise SymdynError(f"unknown quantity '{name}' (one of {', '.join(QUANTITIES)})")
        if name not in self._closed:
            m = self.compact[name]
            entries = self.program.expand(list(m))
            if self.simplified:
                entries = [simplify_entry(e) for e in entries]
            self._closed[name] = sp.ImmutableMatrix(m.rows, m.cols, entries)
        return self._closed[name]

    @property
    def M(self) -> sp.Matrix:
        return self.closed_form("M")

    @property
    def C(self) -> sp.Matrix:
        return self.closed_form("C")

    @property
    def V(self) -> sp.Matrix:
        return self.closed_form("V")

    @property
    def G(self) -> sp.Matrix:
        return self.closed_form("G")

    @property
    def F(self) -> sp.Matrix:
        return self.closed_form("F")

    @property
    def tau(self) -> sp.Matrix:
        return self.closed_form("tau")

    def assignments(self, names=QUANTITIES) -> list[tuple[sp.Symbol, sp.Expr]]:
        """The intermediates the given quantities need, in evaluation order."""
        outs = [e for name in names for e in self.compact[name]]
        return self.program.needed(outs)

    def _numeric(self, name: str):
        """NumPy function of quantity `name` over the eliminated form, compiled on first use."""
        f = self._compiled.get(name)
        if f is None:
            m = self.compact[name]
            steps = self.program.needed(list(m))
            args = [list(self.q), list(self.qd), list(self.qdd), list(self.params)]
            f = sp.lambdify(args, sp.Matrix(m), modules="numpy", cse=lambda exprs: (steps, exprs))
            self._compiled[name] = f
        return f

    def evaluate(self, name: str, q=None, qd=None, qdd=None, params=None) -> np.ndarray:
        """Numeric value of quantity `name` at a state (missing vectors are zero)."""
        n = self.n
        vec = [np.zeros(n) if v is None else np.asarray(v, dtype=float) for v in (q, qd, qdd)]
        values = self.robot.param_values(params) if self.params else {}
        p = [values[s] for s in self.params]
        shape = self.compact[name].shape
        out = np.asarray(self._numeric(name)(*vec, p), dtype=float).reshape(shape)
        return out[:, 0] if name not in ("M", "C") else out


def _newton_euler_terms(robot: Robot, q, qd, qdd, program: Program) -> dict[str, sp.Matrix]:
    n = robot.n
    rot = joint_frames(robot, q)
    zeros = [0] * n
    with distribute(True):  # numbers times sums fold into the coefficients of the composites
        composites = composite_inertias(robot, rot, program)
        G = sp.Matrix(gravity_composite(robot, rot, composites, program))
        M = mass_matrix_crba(robot, rot, composites, program)
        C = coriolis_matrix_composite(robot, rot, composites, list(qd), program)
    V = sp.Matrix(newton_euler(robot, q, list(qd), zeros, program, gravity=False, tag="V", rotations=rot))
    Vn = [program.let(v, "V") for v in V]
    bias = newton_euler(robot, q, list(qd), zeros, program, gravity=True, tag="B", rotations=rot)
    body = newton_euler(robot, q, list(qd), list(qdd), program, gravity=True, tag="T", rotations=rot)
    tau = sp.Matrix([body[i] + link.motor.reflected_inertia * qdd[i] for i, link in enumerate(robot.links)])
    return {"M": M, "C": C, "V": sp.Matrix(Vn), "G": G, "tau": tau, "bias": sp.Matrix(bias)}


def derive(robot: Robot, method: str = "newton-euler", simplify: bool | None = None) -> Dynamics:
    """Derive M, C, V, G, F and tau of `robot` by Newton-Euler or Lagrange.

    Parameters that have values in the robot file are substituted first; the
    others stay symbolic and are listed in `Dynamics.params`. `simplify`:
    closed forms with trigonometric simplification (default: up to 3 joints).
    """
    if method not in METHODS:
        raise SymdynError(f"unknown method '{method}' (use {' or '.join(METHODS)})")
    r = robot.resolved()
    q, qd, qdd = joint_symbols(r.n)
    program = Program()
    with distribute(False):
        if method == "newton-euler":
            terms = _newton_euler_terms(r, q, qd, qdd, program)
        else:
            terms = lagrange(r, q, qd, program)
            terms["V"] = sp.Matrix([program.let(v, "V") for v in terms["C"] * qd])
        F = friction_vector(r, qd)
        terms["F"] = F
        if method == "lagrange":
            terms["tau"] = terms["M"] * qdd + terms["V"] + terms["G"] + F
            terms["bias"] = terms["V"] + terms["G"] + F
        else:
            terms["tau"] = terms["tau"] + F
            terms["bias"] = terms["bias"] + F
    if simplify is None:
        simplify = r.n <= AUTO_SIMPLIFY_MAX_JOINTS
    return Dynamics(
        robot=r,
        method=method,
        q=q,
        qd=qd,
        qdd=qdd,
        params=r.params,
        program=program,
        compact={k: sp.Matrix(terms[k]) for k in (*QUANTITIES, "bias")},
        simplified=bool(simplify),
    )
