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

Besides the six quantities of QUANTITIES, every derivation has the bias
bias = V + G + F = tau(q, qd, qdd = 0): what forward dynamics subtracts from the joint
efforts before solving M qdd = tau - bias. It is public under the name "bias" in
`Dynamics.closed_form`, `Dynamics.evaluate` and `Dynamics.bias` (not to be confused with
symdyn.rnea.bias_torque, which is V alone).

References: R. Grupen, "Dynamics" (2015), slides 14-16; Craig, Introduction to Robotics
(3rd ed., 2005), sec. 6.5; Featherstone, Rigid Body Dynamics Algorithms (2008), secs. 5.3
and 6.2; Spong, Hutchinson, Vidyasagar, Robot Modeling and Control (2006), sec. 7.3.
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

__all__ = ["Dynamics", "derive", "METHODS", "QUANTITIES", "ALL_QUANTITIES", "friction_vector"]

METHODS = ("newton-euler", "lagrange")
#: the terms of tau = M qdd + V + G + F (slide 16), and tau itself
QUANTITIES = ("M", "C", "V", "G", "F", "tau")
#: every name `Dynamics.closed_form` and `Dynamics.evaluate` accept: QUANTITIES and the bias V + G + F
ALL_QUANTITIES = (*QUANTITIES, "bias")
AUTO_SIMPLIFY_MAX_JOINTS = 3


def _check_quantity(name, where: str) -> str:
    if name not in ALL_QUANTITIES:
        raise SymdynError(f"{where}: unknown quantity {name!r} (one of {', '.join(ALL_QUANTITIES)})")
    return name


def friction_vector(robot: Robot, qd) -> sp.Matrix:
    """F_i = viscous_i qd_i + coulomb_i sign(qd_i) (Grupen (2015), slide 16).

    Args:
        robot: the model, n links.
        qd: n joint velocities (symbols or numbers).

    Returns:
        The n x 1 friction vector (joint space).
    """
    if len(qd) != robot.n:
        raise SymdynError(f"friction_vector: qd has length {len(qd)}, expected {robot.n} (one per joint)")
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
    """The equations of motion tau = M(q) qdd + V(q, qd) + G(q) + F(qd) of a robot (slide 16),
    compact (over intermediates) and closed-form, all in joint space.

    `compact[name]` holds each of M, C, V, G, F, tau, and bias = V + G + F (one
    Newton-Euler pass with qdd = 0, for forward dynamics), as a SymPy Matrix over
    the named intermediates of `program`; the attributes `M`, `C`, `V`, `G`, `F`,
    `tau` and `bias` are closed forms over q, qd, qdd and `params` only. M and C are
    n x n, the others n x 1.
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
        """Quantity `name` with the intermediates substituted back (and simplified if requested).

        Args:
            name: one of M, C, V, G, F, tau, bias (ALL_QUANTITIES).

        Returns:
            An immutable SymPy matrix over q, qd, qdd and `params`: n x n for M and C,
            n x 1 otherwise.

        Raises:
            SymdynError: an unknown name.
        """
        _check_quantity(name, "Dynamics.closed_form")
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

    @property
    def bias(self) -> sp.Matrix:
        """V + G + F = tau at qdd = 0, closed form."""
        return self.closed_form("bias")

    def assignments(self, names=QUANTITIES) -> list[tuple[sp.Symbol, sp.Expr]]:
        """The intermediates the given quantities need, in evaluation order.

        Args:
            names: names out of ALL_QUANTITIES.

        Returns:
            (symbol, expression) pairs of `program`, each using earlier ones only.
        """
        if isinstance(names, str):
            raise SymdynError(f"Dynamics.assignments: names must be a sequence of names, got {names!r}")
        for name in names:
            _check_quantity(name, "Dynamics.assignments")
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
        """Numeric value of quantity `name` at one state (missing vectors are zero).

        Args:
            name: one of M, C, V, G, F, tau, bias (ALL_QUANTITIES).
            q, qd, qdd: n numbers each (joint positions, velocities, accelerations) or None.
            params: values of the free parameters `params`: a sequence in that order or a
                name -> number map; None when there are none.

        Returns:
            An (n, n) array for M and C, an (n,) array otherwise (joint space).

        Raises:
            SymdynError: an unknown name, a vector without n numbers, missing, extra or
                unknown parameters.
        """
        where = "Dynamics.evaluate"
        _check_quantity(name, where)
        vec = [self.robot.joint_values(v, label, where) for v, label in ((q, "q"), (qd, "qd"), (qdd, "qdd"))]
        values = self.robot.param_values(params, where)
        p = [values[s] for s in self.params]
        shape = self.compact[name].shape
        out = np.asarray(self._numeric(name)(*vec, p), dtype=float).reshape(shape)
        return out[:, 0] if name not in ("M", "C") else out


def _newton_euler_terms(robot: Robot, q, qd, qdd, program: Program) -> dict[str, sp.Matrix]:
    """M, C, V, G, tau and the rigid-body bias by Newton-Euler and the composite bodies."""
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
    """Derive M, C, V, G, F, tau and the bias V + G + F of `robot` (slide 16).

    Parameters that have values in the robot file are substituted first; the
    others stay symbolic and are listed in `Dynamics.params`.

    Args:
        robot: the model (symdyn.load_robot, symdyn.load_urdf, symdyn.robot_from_data).
        method: "newton-euler" (Grupen (2015), slides 14-15; Craig (2005), sec. 6.5;
            Featherstone (2008), secs. 5.3 and 6.2) or "lagrange" (Spong, Hutchinson,
            Vidyasagar (2006), secs. 7.2-7.3).
        simplify: closed forms with trigonometric simplification; None: for robots of up
            to AUTO_SIMPLIFY_MAX_JOINTS joints.

    Returns:
        The `Dynamics`, in joint space.

    Raises:
        SymdynError: not a Robot, an unknown method or a simplify that is not True, False or None.
    """
    if not isinstance(robot, Robot):
        raise SymdynError(
            f"derive: robot must be a symdyn Robot (from load_robot or load_urdf), got {type(robot).__name__}"
        )
    if not isinstance(method, str) or method not in METHODS:
        raise SymdynError(f"derive: unknown method {method!r} (use {' or '.join(METHODS)})")
    if simplify is not None and not isinstance(simplify, bool):
        raise SymdynError(f"derive: simplify must be True, False or None, got {simplify!r}")
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
        compact={k: sp.Matrix(terms[k]) for k in ALL_QUANTITIES},
        simplified=bool(simplify),
    )
