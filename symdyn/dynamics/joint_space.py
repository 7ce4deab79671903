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

On a kinematic tree both routes run over the nb links (symdyn.model.topology). With
mimic joints the Newton-Euler route runs on the nb bodies with q_b = Robot.body_positions(q),
qd_b = S qd and qdd_b = S qdd over the n independent symbols, and projects
(symdyn.algorithms.coordinates): M = S^T M_b S, C = S^T C_b S, V = S^T V_b, G = S^T G_b,
F = S^T F_b(qd_b), tau = S^T tau_b, a mimic joint's reflected rotor inertia on M_b's
diagonal; the Lagrange route differentiates by the independent coordinates directly.

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

import warnings
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import sympy as sp
from sympy.core.parameters import distribute

from ..algorithms.base_parameters import BaseParameters, find_base_parameters
from ..algorithms.configuration_space import (
    READABLE_TERMS,
    ConfigurationSpace,
    FormTooLargeError,
    configuration_space,
)
from ..algorithms.coordinates import project_matrix, project_vector
from ..algorithms.coriolis import coriolis_matrix_composite
from ..algorithms.crba import composite_inertias, gravity_composite, mass_matrix_crba
from ..algorithms.floating import floating_lagrange_terms, floating_newton_euler_terms
from ..algorithms.floating_frames import FloatingFrames
from ..algorithms.frame_kinematics import FrameKinematics
from ..algorithms.frames import joint_frames
from ..algorithms.lagrange import lagrange
from ..algorithms.newton_euler import newton_euler
from ..algorithms.product_form import ProductForm, check_product_size, product_form
from ..algorithms.regressor import regressor as regressor_matrix
from ..algorithms.singular import SingularJoint, describe_singular, singular_joints
from ..algorithms.tendons import tendon_terms
from ..errors import SymdynError, SymdynWarning
from ..model.free_flyer import NV_BASE, base_symbols
from ..model.names import latex_text
from ..model.parameters import standard_parameters
from ..model.robot import Robot
from ..model.symbols import joint_symbols
from ..model.tendons import refuse_tendons
from ..symbolic.program import Program
from .frames import FrameFacade
from .numeric import NumericEvaluation
from .quantities import ALL_QUANTITIES, QUANTITIES, check_quantity, simplify_entry

__all__ = ["Dynamics", "derive", "METHODS", "QUANTITIES", "ALL_QUANTITIES", "friction_vector"]

METHODS = ("newton-euler", "lagrange")
AUTO_SIMPLIFY_MAX_JOINTS = 3
#: how many random states decide a floating base's pivots (Dynamics.singular_joints), and their seed
SINGULAR_SAMPLES = 3
SINGULAR_SEED = 20231


def friction_vector(robot: Robot, qd) -> sp.Matrix:
    """F_i = viscous_i qd_i + coulomb_i sign(qd_i) (Grupen (2015), slide 16), or with
    direction-dependent Coulomb friction viscous_i qd_i + c+_i H(qd_i) - c-_i H(-qd_i), H the
    Heaviside step with H(0) = 0 (`symdyn.model.robot.Friction`).

    Per body at its joint rate qd_b = S qd; a mimic joint's friction is projected onto
    the coordinate it follows, F = S^T F_b(qd_b).

    Args:
        robot: the model, n independent joints.
        qd: n joint velocities (symbols or numbers).

    Returns:
        The n x 1 friction vector (joint space).
    """
    if len(qd) != robot.n:
        raise SymdynError(f"friction_vector: qd has length {len(qd)}, expected {robot.n} (one per joint)")
    rates = robot.body_rates(list(qd))
    F_b = [link.friction.effort(rate) for link, rate in zip(robot.links, rates, strict=True)]
    if robot.n == robot.nb:
        return sp.Matrix(F_b)
    F = [sp.S.Zero] * robot.n
    for f, c in zip(F_b, robot.coordinates, strict=True):
        F[c.index] += c.multiplier * f
    return sp.Matrix(F)


@dataclass
class Dynamics(FrameFacade, NumericEvaluation):
    """The equations of motion tau = M(q) qdd + V(q, qd) + G(q) + F(qd) of a robot (slide 16),
    compact (over intermediates) and closed-form, all in joint space.

    `compact[name]` holds each of M, C, V, G, F, tau, and bias = V + G + F (one
    Newton-Euler pass with qdd = 0, for forward dynamics), as a SymPy Matrix over
    the named intermediates of `program`; the attributes `M`, `C`, `V`, `G`, `F`,
    `tau` and `bias` are closed forms over q, qd, qdd and `params` only. M and C are
    n x n, the others n x 1. The frame and task-space methods come from `FrameFacade`
    (symdyn.dynamics.frames), `evaluate` from `NumericEvaluation` (symdyn.dynamics.numeric).
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
    _linear: dict[str, object] = field(default_factory=dict, repr=False)
    _configuration: ConfigurationSpace | None = field(default=None, repr=False)
    #: the configuration-space form was found larger than READABLE_TERMS before it was built
    _too_large: bool = field(default=False, repr=False)
    _frames: FrameKinematics | FloatingFrames | None = field(default=None, repr=False)

    @property
    def n(self) -> int:
        """The size of qd, qdd, tau and of M: the number of joints, or NV = 6 + joints on a
        floating base (whose q has NQ = 7 + joints entries)."""
        return self.robot.nv

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
        check_quantity(name, "Dynamics.closed_form")
        return self._expanded(name, self.compact[name])

    def _expanded(self, name: str, m: sp.Matrix) -> sp.Matrix:
        """The closed form of compact matrix m, cached under `name`: M, C, V, G, tau and bias of
        an unsimplified derivation from the configuration-space form (canonical, the same from
        either method; symdyn.algorithms.configuration_space) when it is readable (at most
        READABLE_TERMS terms), anything else by substituting the program's intermediates back."""
        if name not in self._closed:
            if (
                not self.simplified
                and not self.robot.floating
                and name in ALL_QUANTITIES
                and name != "F"
                and self.readable_configuration_space() is not None
            ):
                entries = self.configuration_space.closed(name, self.qd, self.qdd, self.compact["F"])
            else:
                entries = self.program.expand(list(m))
                if self.simplified:
                    entries = [simplify_entry(e) for e in entries]
            self._closed[name] = sp.ImmutableMatrix(m.rows, m.cols, list(entries))
        return self._closed[name]

    def expanded(self, name: str) -> list[sp.Expr]:
        """Quantity `name` by substituting the program's intermediates back (simplified if
        requested): the full expansion of the recursion, entries in row-major order."""
        check_quantity(name, "Dynamics.expanded")
        entries = self.program.expand(list(self.compact[name]))
        return [simplify_entry(e) for e in entries] if self.simplified else entries

    @cached_property
    def singular_joints(self) -> tuple[SingularJoint, ...]:
        """The joints that make M(q) singular for every q, with the cause: the exactly zero
        pivots of M = L D L^T and the joints that move no mass (symdyn.algorithms.singular);
        on a floating base also the base's coordinates that can move while no body with mass
        does, decided on M at three random states (SINGULAR_SAMPLES). Empty when M can be
        inverted as far as its numbers tell."""
        return singular_joints(self.robot, self.compact["M"], self._singular_samples())

    def _singular_samples(self) -> list[np.ndarray]:
        """A floating robot's M at SINGULAR_SAMPLES random joint positions, the free parameters at
        random values in [0.5, 1.5] (seeded: the same every time); a fixed base's: none."""
        if not self.robot.floating:
            return []
        rng = np.random.default_rng(SINGULAR_SEED)
        base = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])  # M does not read the base's pose
        f = self._numeric("M")
        zero = np.zeros(len(self.qd))
        out = []
        for _ in range(SINGULAR_SAMPLES):
            q = np.concatenate([base, rng.uniform(-np.pi, np.pi, self.n - NV_BASE)])
            p = list(rng.uniform(0.5, 1.5, len(self.params)))
            out.append(np.asarray(f(q, zero, zero, p), dtype=float))
        return out

    @property
    def configuration_space(self) -> ConfigurationSpace:
        """tau = M qdd + B [qd qd] + Csq [qd^2] + G + F with M, G and the Christoffel symbols
        as canonical trigonometric polynomials (the same from either method)."""
        if self._configuration is None:
            c = self.compact
            self._configuration = configuration_space(self.program, c["M"], list(c["G"]), list(self.q))
        return self._configuration

    def readable_configuration_space(self) -> ConfigurationSpace | None:
        """The configuration-space form when it is readable (at most READABLE_TERMS terms), else
        None, found without building a form that is not: its building stops once it is too large
        (symdyn.algorithms.configuration_space.FormTooLargeError)."""
        if self._configuration is None and not self._too_large:
            c = self.compact
            try:
                self._configuration = configuration_space(
                    self.program, c["M"], list(c["G"]), list(self.q), budget=READABLE_TERMS
                )
            except FormTooLargeError:
                self._too_large = True
        if self._configuration is None or not self._configuration.readable:
            return None
        return self._configuration

    @cached_property
    def _product(self) -> ProductForm:
        check_product_size(self.robot)  # before the configuration form is built
        return product_form(self.robot, self.configuration_space, self.closed_form("F"))

    def product_form(self) -> ProductForm:
        """The configuration-space form over the trig atoms c_i, s_i (and c_23, s_23 for
        consecutive parallel axes), factored and with equal or opposite pieces shared
        (symdyn.algorithms.product_form; `derive --form product`)."""
        return self._product

    @property
    def B(self) -> sp.Matrix:
        """Coriolis coefficients, n x n(n-1)/2: B[k, (i, j)] = 2 Gamma^k_ij, columns (1,2), (1,3), ..."""
        return self.configuration_space.matrix("B")

    @property
    def Csq(self) -> sp.Matrix:
        """Centrifugal coefficients, n x n: Csq[k, i] = Gamma^k_ii (V = B [qd qd] + Csq [qd^2])."""
        return self.configuration_space.matrix("Csq")

    @property
    def christoffel(self) -> dict[tuple[int, int, int], sp.Expr]:
        """The nonzero Christoffel symbols Gamma^k_ij of M, i <= j, keyed by 0-based (k, i, j)."""
        return self.configuration_space.christoffel()

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

    def regressor_compact(self) -> sp.Matrix:
        """The regressor Y (n x 13 nb) over the intermediates of `program`, tau = Y pi with pi the
        standard parameters (symdyn.standard_parameters; symdyn.algorithms.regressor)."""
        if "Y" not in self._linear:
            refuse_tendons(
                self.robot,
                "the regressor (and the base parameters and identification built on it)",
                "their terms are not linear in the inertial parameters; derive M, G, F and tau, "
                "or identify the robot without them",
            )
            self._linear["Y"] = regressor_matrix(self.robot, self.q, self.qd, self.qdd, self.program)
        return self._linear["Y"]  # type: ignore[return-value]

    def linear_compact(self) -> tuple[sp.Matrix, BaseParameters]:
        """`regressor_compact()` and the base parameters found from it
        (symdyn.algorithms.base_parameters); computed on first use.

        Raises:
            SymdynError: the base parameters depend on free parameters and some angle enters other
                than as sin(q) and cos(q) (a mimic joint's multiplier, a joint offset).
        """
        Y = self.regressor_compact()
        if "base" not in self._linear:
            names = standard_parameters(self.robot)[0]
            self._linear["base"] = find_base_parameters(
                self.robot, Y, self.program, self.q, self.qd, self.qdd, names
            )
        return Y, self._linear["base"]  # type: ignore[return-value]

    @property
    def regressor(self) -> sp.Matrix:
        """Y(q, qd, qdd), n x 13 nb, closed form: tau = Y pi (pi: symdyn.standard_parameters)."""
        return self._expanded("regressor", self.regressor_compact())

    @property
    def base_parameters(self) -> tuple[tuple[str, sp.Expr], ...]:
        """(name, expression) per base parameter: exact linear combinations of the standard
        parameters' symbols (m1, mx1, ...), in the order of `base_regressor`'s columns."""
        base = self.linear_compact()[1]
        return tuple(zip(base.names, base.expressions, strict=True))

    @property
    def base_regressor(self) -> sp.Matrix:
        """Y_b(q, qd, qdd), n x (number of base parameters), closed form: tau = Y_b pi_b."""
        Y, base = self.linear_compact()
        return self._expanded("base_regressor", Y.extract(list(range(Y.rows)), list(base.columns)))

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
            check_quantity(name, "Dynamics.assignments")
        outs = [e for name in names for e in self.compact[name]]
        return self.program.needed(outs)

    def __repr__(self) -> str:
        """One line: robot, joints, method and free parameters (the robot's table: `table()`)."""
        k, r = len(self.params), self.robot
        joints = f"{r.n} joint{'s' * (r.n != 1)}" + (f" ({r.nb} bodies)" if r.nb != r.n else "")
        listed = f" ({', '.join(map(str, self.params))})" if 0 < k <= 6 else ""
        return f"<Dynamics of {r.name}: {joints}, {self.method}, {k} free parameter{'s' * (k != 1)}{listed}>"

    def table(self) -> str:
        """The robot's table, one row per link (symdyn.model.table)."""
        return repr(self.robot)

    def latex(self, name: str) -> str:
        """Closed form of quantity `name` (ALL_QUANTITIES) in LaTeX, joint space, with q_{i},
        \\dot{q}_{i}, \\ddot{q}_{i} for the joint symbols (as in docs/generated-code.md)."""
        check_quantity(name, "Dynamics.latex")
        names = {}
        for head, v in (("q", self.q), ("\\dot{q}", self.qd), ("\\ddot{q}", self.qdd)):
            names.update({s: f"{head}_{{{i + 1}}}" for i, s in enumerate(v)})
        return sp.latex(self.closed_form(name), symbol_names=names)

    def _repr_latex_(self) -> str:
        """tau = M(q) qdd + V(q, qd) + G(q) + F(qd) (slide 16) for notebooks, with the closed
        forms of M, V and G for robots of up to AUTO_SIMPLIFY_MAX_JOINTS joints."""
        n, name = self.n, latex_text(self.robot.name)
        q = ", ".join(f"q_{{{i}}}" for i in (range(1, n + 1) if n <= 3 else (1, "\\dots", n)))
        lines = [
            f"\\text{{{name}}}:\\ \\tau = M(q)\\,\\ddot{{q}} + V(q, \\dot{{q}}) + G(q) + F(\\dot{{q}})",
            f"q = ({q}),\\quad M \\in \\mathbb{{R}}^{{{n} \\times {n}}}",
        ]
        if n <= AUTO_SIMPLIFY_MAX_JOINTS:
            lines += [f"{k} = {self.latex(k)}" for k in ("M", "V", "G")]
        return "$$\\begin{aligned}" + " \\\\ ".join(f"& {line}" for line in lines) + "\\end{aligned}$$"


def _newton_euler_terms(robot: Robot, q, qd, qdd, program: Program) -> dict[str, sp.Matrix]:
    """M, C, V, G, tau and the rigid-body bias by Newton-Euler and the composite bodies.

    The recursions run on the nb bodies at q_b, qd_b = S qd, qdd_b = S qdd; the results are
    projected onto the n independent coordinates (the identity without mimic joints)."""
    q_b, qd_b, qdd_b = robot.body_positions(list(q)), robot.body_rates(list(qd)), robot.body_rates(list(qdd))
    rot = joint_frames(robot, q_b)
    zeros = [0] * robot.nb
    with distribute(True):  # numbers times sums fold into the coefficients of the composites
        composites = composite_inertias(robot, rot, program)
        G = gravity_composite(robot, rot, composites, program)
        M = mass_matrix_crba(robot, rot, composites, program)
        C = coriolis_matrix_composite(robot, rot, composites, qd_b, program)
    V = newton_euler(robot, q_b, qd_b, zeros, program, gravity=False, tag="V", rotations=rot)
    Vn = [program.let(v, "V") for v in V]
    bias = newton_euler(robot, q_b, qd_b, zeros, program, gravity=True, tag="B", rotations=rot)
    body = newton_euler(robot, q_b, qd_b, qdd_b, program, gravity=True, tag="T", rotations=rot)
    tau = [body[i] + link.motor.reflected_inertia * qdd_b[i] for i, link in enumerate(robot.links)]
    return {
        "M": project_matrix(robot, M, program, "M"),
        "C": project_matrix(robot, C, program, "C"),
        "V": sp.Matrix(project_vector(robot, Vn, program, "V")),
        "G": sp.Matrix(project_vector(robot, G, program, "G")),
        "tau": sp.Matrix(project_vector(robot, tau, program, "tau")),
        "bias": sp.Matrix(project_vector(robot, bias, program, "bias")),
    }


#: How every message about a singular M starts after the robot's name (codegen repeats it).
SINGULAR_M = "M(q) is singular"


def singular_message(dyn: Dynamics) -> str:
    """ "robot 'X': M(q) is singular: the joint of link 'Y' (link k) <why>" for a derivation
    whose M is singular by construction (Dynamics.singular_joints; empty there: "")."""
    joints = dyn.singular_joints
    if not joints:
        return ""
    return f"robot '{dyn.robot.name}': {SINGULAR_M}: {describe_singular(dyn.robot, joints)}"


def state_symbols(robot: Robot) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """(q, qd, qdd) symbols: the joints' (symdyn.model.symbols), after the free flyer's on a
    floating base (symdyn.model.free_flyer: q of NQ = 7 + n, qd and qdd of NV = 6 + n)."""
    q, qd, qdd = joint_symbols(robot.n)
    if not robot.floating:
        return q, qd, qdd
    bq, bv, ba = base_symbols()
    if robot.n == 0:  # a single rigid body: the base's coordinates only
        return bq, bv, ba
    return sp.Matrix.vstack(bq, q), sp.Matrix.vstack(bv, qd), sp.Matrix.vstack(ba, qdd)


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

    Warns:
        SymdynWarning: M is singular for every q (Dynamics.singular_joints: a joint that moves
            no mass, or only mass on its own axis, ...), naming the joints and why; forward
            dynamics is undefined. Decided on numbers: a pivot that depends on a free
            parameter is not zero.
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
    q, qd, qdd = state_symbols(r)
    program = Program()
    with distribute(False):
        if r.floating:
            route = floating_newton_euler_terms if method == "newton-euler" else floating_lagrange_terms
            terms = route(r, q, qd, qdd, program)
        elif method == "newton-euler":
            terms = _newton_euler_terms(r, q, qd, qdd, program)
        else:
            terms = lagrange(r, q, qd, program)
            terms["V"] = sp.Matrix([program.let(v, "V") for v in terms["C"] * qd])
        F = friction_vector(r, qd[6:, :] if r.floating else qd)
        if r.floating:
            F = sp.Matrix([*[sp.S.Zero] * 6, *F])  # (a list: F of no joints is 0 x 0)
        if r.tendons:  # fixed tendons and joint springs, for both routes (symdyn.algorithms.tendons)
            extra = tendon_terms(r, q, qd)
            terms["M"], terms["G"], F = terms["M"] + extra.M, terms["G"] + extra.G, F + extra.F
            if method == "newton-euler":
                terms["tau"] = terms["tau"] + extra.M * qdd + extra.G
                terms["bias"] = terms["bias"] + extra.G
        terms["F"] = F
        if method == "lagrange" and not r.floating:
            terms["tau"] = terms["M"] * qdd + terms["V"] + terms["G"] + F
            terms["bias"] = terms["V"] + terms["G"] + F
        else:  # the Newton-Euler route, or the floating Lagrange route (tau and bias without F)
            terms["tau"] = terms["tau"] + F
            terms["bias"] = terms["bias"] + F
    if simplify is None:
        simplify = r.n <= AUTO_SIMPLIFY_MAX_JOINTS
    dyn = Dynamics(
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
    if dyn.singular_joints:
        warnings.warn(f"{singular_message(dyn)}; forward dynamics is undefined", SymdynWarning, stacklevel=2)
    return dyn
