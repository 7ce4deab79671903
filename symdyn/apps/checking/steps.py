"""The derivation step by step: Craig's Newton-Euler iterations or the Lagrangian's terms, per link.

Newton-Euler (J. J. Craig, Introduction to Robotics (3rd ed., 2005), sec. 6.5, eqs. 6.45-6.53;
R. Grupen, "Dynamics" (2015), slides 14-15). Every vector of link i is expressed in link i's
body frame {i} (`frame_description`), R = parent_R_i(q_i) and P the origin of {i} in its
parent's frame, a_i the joint axis and c_i the centre of mass in {i}; outward from a base at
rest with vdot_0 = -g:

    omega_i    = R^T omega_p + qd_i a_i                                   (prismatic: no qd term)
    omegadot_i = R^T omegadot_p + (R^T omega_p) x qd_i a_i + qdd_i a_i     (prismatic: R^T omegadot_p)
    vdot_i     = R^T (omegadot_p x P + omega_p x (omega_p x P) + vdot_p)
                 (prismatic: + 2 omega_i x qd_i a_i + qdd_i a_i)
    vdot_Ci    = omegadot_i x c_i + omega_i x (omega_i x c_i) + vdot_i
    F_i = m_i vdot_Ci,   N_i = I_i omegadot_i + omega_i x I_i omega_i

and inward, summing over the links j carried by link i (the next one of a chain):

    f_i = F_i + sum_j R_j f_j,   n_i = N_i + c_i x F_i + sum_j (R_j n_j + P_j x R_j f_j)
    tau_i = a_i . n_i (a_i . f_i for a prismatic joint) + motor and friction terms.

Lagrange (M. W. Spong, S. Hutchinson, M. Vidyasagar, Robot Modeling and Control (2006),
sec. 7.2): per link the kinetic energy T_i = 1/2 m_i v_Ci . v_Ci + 1/2 omega_i . I_i omega_i
(+ 1/2 gear_ratio^2 J_m qd_i^2 of joint i's rotor) and the potential energy U_i = -m_i g . p_Ci
(base frame), L = sum_i (T_i - U_i), and per joint the terms of
tau_j = d/dt (dL/dqd_j) - dL/dq_j (+ the friction term).

The steps are symbolic over q, qd, qdd and the free parameters (simplified for up to
AUTO_SIMPLIFY_MAX_JOINTS joints), or numbers at a state given by `at`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from ...algorithms.kinematics import forward_kinematics, point_jacobian
from ...dynamics import AUTO_SIMPLIFY_MAX_JOINTS, friction_vector, simplify_entry
from ...errors import SymdynError
from ...model.robot import Robot
from ...model.symbols import joint_symbols
from ...model.tendons import refuse_tendons
from ...model.topology import children

__all__ = [
    "NEWTON_EULER_STEPS",
    "LAGRANGE_STEPS",
    "Step",
    "Steps",
    "derivation_steps",
    "frame_description",
]

#: Craig's quantities in the order the recursion computes them (outward, then inward)
NEWTON_EULER_STEPS = ("omega", "omegadot", "vdot", "vdotC", "F", "N", "f", "n", "tau")
LAGRANGE_STEPS = ("T", "U", "dL_dqd", "ddt_dL_dqd", "dL_dq", "tau")
OUTWARD = ("omega", "omegadot", "vdot", "vdotC", "F", "N")


@dataclass(frozen=True)
class Step:
    """One quantity of one link (1-based `link`): a 3x1 vector in `frame`, or a 1x1 scalar."""

    link: int
    name: str
    value: sp.Matrix
    phase: str  # "outward", "inward", "energy" or "joint"
    frame: str  # where a vector is expressed ("" for a scalar)


@dataclass
class Steps:
    """All steps of one derivation, in the order they are computed."""

    robot: Robot
    method: str
    steps: list[Step]
    numeric: bool

    def get(self, name: str, link: int) -> Step:
        for s in self.steps:
            if s.name == name and s.link == link:
                return s
        raise KeyError((name, link))


def frame_description(robot: Robot, i: int) -> str:
    """In words, link i's body frame (1-based i), the frame its Newton-Euler vectors are in."""
    return {
        "modified": f"{{{i}}}: Craig's (modified DH) frame {i}, at joint {i}",
        "standard": f"{{{i}}}: standard-DH frame {i - 1} turned by theta_{i} and moved by d_{i} along its z "
        f"(origin on joint axis {i}, axes those of DH frame {i - 1} rotated with link {i})",
        "poe": f"{{{i}}}: Modern Robotics' frame {{{i}}} moved along its axes onto joint axis {i}",
        "urdf": f"{{{i}}}: the URDF frame of link {i} (its joint's child frame)",
    }.get(robot.convention, f"{{{i}}}: the body frame of link {i}")


def _vec(x) -> sp.Matrix:
    return sp.Matrix(3, 1, list(x))


def _newton_euler(robot: Robot, q, qd, qdd) -> list[Step]:
    g = _vec(robot.base_gravity)
    zero = sp.zeros(3, 1)
    frames, out = [], []
    motion: list[tuple[sp.Matrix, sp.Matrix, sp.Matrix]] = []
    wrench: list[tuple[sp.Matrix, sp.Matrix]] = []
    parents = robot.parents
    for i, link in enumerate(robot.links):
        T = link.joint_transform(q[i])
        R, P, a = sp.Matrix(T.R), _vec(T.p), _vec(link.axis)
        frames.append((R, P))
        w_p, wd_p, vd_p = motion[parents[i]] if parents[i] >= 0 else (zero, zero, -g)
        Rt = R.T
        vd = Rt * (wd_p.cross(P) + w_p.cross(w_p.cross(P)) + vd_p)
        if link.joint == "revolute":
            w = Rt * w_p + qd[i] * a
            wd = Rt * wd_p + (Rt * w_p).cross(qd[i] * a) + qdd[i] * a
        else:
            w, wd = Rt * w_p, Rt * wd_p
            vd = vd + 2 * w.cross(qd[i] * a) + qdd[i] * a
        c, I = _vec(link.com), sp.Matrix(link.inertia)
        vc = wd.cross(c) + w.cross(w.cross(c)) + vd
        F, N = link.mass * vc, I * wd + w.cross(I * w)
        motion.append((w, wd, vd))
        wrench.append((F, N))
        where = frame_description(robot, i + 1)
        out += [
            Step(i + 1, k, v, "outward", where) for k, v in zip(OUTWARD, (w, wd, vd, vc, F, N), strict=True)
        ]
    f_all: list[sp.Matrix] = [zero] * robot.nb
    n_all: list[sp.Matrix] = [zero] * robot.nb
    friction = friction_vector(robot, qd)
    for i in reversed(range(robot.nb)):
        link = robot.links[i]
        F, N = wrench[i]
        f, n = F, N + _vec(link.com).cross(F)
        for j in children(parents, i):
            R, P = frames[j]
            f = f + R * f_all[j]
            n = n + R * n_all[j] + P.cross(R * f_all[j])
        f_all[i], n_all[i] = f, n
        a = _vec(link.axis)
        tau = (
            a.dot(n if link.joint == "revolute" else f) + link.motor.reflected_inertia * qdd[i] + friction[i]
        )
        where = frame_description(robot, i + 1)
        out += [Step(i + 1, "f", f, "inward", where), Step(i + 1, "n", n, "inward", where)]
        out.append(Step(i + 1, "tau", sp.Matrix([tau]), "inward", ""))
    return out


def _lagrange(robot: Robot, q, qd, qdd) -> list[Step]:
    qs, qds, _ = joint_symbols(robot.n)  # differentiate by symbols, substitute the state after
    poses = forward_kinematics(robot, list(qs))
    g = _vec(robot.base_gravity)
    out, L = [], sp.S.Zero
    for i, link in enumerate(robot.links):
        J = point_jacobian(robot, i, list(link.com), poses=poses)
        v, w_base = J[:3, :] * qds, J[3:, :] * qds
        w = sp.Matrix(poses[i].R).T * w_base
        T = sp.Rational(1, 2) * link.mass * v.dot(v) + sp.Rational(1, 2) * w.dot(sp.Matrix(link.inertia) * w)
        T += sp.Rational(1, 2) * link.motor.reflected_inertia * qds[i] ** 2  # joint i's rotor
        U = -link.mass * g.dot(_vec(poses[i].apply(link.com)))
        L += T - U
        out += [
            Step(i + 1, "T", sp.Matrix([T]), "energy", ""),
            Step(i + 1, "U", sp.Matrix([U]), "energy", ""),
        ]
    friction = friction_vector(robot, qd)
    state = {**dict(zip(qs, q, strict=True)), **dict(zip(qds, qd, strict=True))}
    for j in range(robot.n):
        p = sp.diff(L, qds[j])
        ddt = sum(sp.diff(p, qs[k]) * qd[k] + sp.diff(p, qds[k]) * qdd[k] for k in range(robot.n))
        dq = sp.diff(L, qs[j])
        tau = ddt - dq.xreplace(state) + friction[j]
        out += [
            Step(j + 1, "dL_dqd", sp.Matrix([p.xreplace(state)]), "joint", ""),
            Step(j + 1, "ddt_dL_dqd", sp.Matrix([sp.sympify(ddt).xreplace(state)]), "joint", ""),
            Step(j + 1, "dL_dq", sp.Matrix([dq.xreplace(state)]), "joint", ""),
            Step(j + 1, "tau", sp.Matrix([sp.sympify(tau).xreplace(state)]), "joint", ""),
        ]
    return [
        Step(s.link, s.name, s.value.xreplace(state), s.phase, s.frame) if s.phase == "energy" else s
        for s in out
    ]


def _state(robot: Robot, at: Mapping | None):
    """q, qd, qdd (symbols, or the numbers of `at`) and the parameter values `at` gives."""
    if at is None:
        return (*(list(v) for v in joint_symbols(robot.n)), {})
    at = dict(at)
    vectors = []
    for name in ("q", "qd", "qdd"):
        if name not in at:
            raise SymdynError(f"--at: give {name} (one number per joint), e.g. {name}=0.1,0.2")
        vectors.append([sp.Float(x) for x in robot.joint_values(at.pop(name), name, "--at")])
    names = {str(p): p for p in robot.params}
    unknown = sorted(k for k in at if k not in names)
    if unknown:
        listed = ", ".join(names) or "none"
        raise SymdynError(f"--at: unknown name(s) {', '.join(unknown)} (free parameters: {listed})")
    return (*vectors, {names[k]: sp.Float(float(v)) for k, v in at.items()})


def derivation_steps(
    robot: Robot, method: str = "newton-euler", at: Mapping | None = None, simplify: bool | None = None
) -> Steps:
    """The steps of the derivation of `robot`'s equations of motion (module docstring).

    Args:
        robot: a robot without mimic joints (valued parameters are substituted first).
        method: "newton-euler" (Craig's iterations) or "lagrange" (energies and derivatives).
        at: numbers: q, qd, qdd (n each) and optionally values of free parameters by name;
            None for symbolic steps.
        simplify: simplify symbolic entries; None: for up to AUTO_SIMPLIFY_MAX_JOINTS joints.

    Raises:
        SymdynError: mimic joints, an unknown method, a state without n numbers per vector.
    """
    if method not in ("newton-euler", "lagrange"):
        raise SymdynError(f"unknown method {method!r} (use newton-euler or lagrange)")
    r = robot.resolved()
    if r.n != r.nb:
        raise SymdynError(f"robot '{r.name}': the steps are shown for robots without mimic joints")
    refuse_tendons(r, "derive --steps", "the steps show the rigid bodies' recursion; derive without --steps")
    q, qd, qdd, values = _state(r, at)
    steps = (_newton_euler if method == "newton-euler" else _lagrange)(r, q, qd, qdd)
    if simplify is None:
        simplify = r.n <= AUTO_SIMPLIFY_MAX_JOINTS
    numeric = at is not None
    if numeric:
        steps = [Step(s.link, s.name, s.value.xreplace(values), s.phase, s.frame) for s in steps]
    tidy = sp.expand if numeric else (simplify_entry if simplify else (lambda e: e))
    steps = [Step(s.link, s.name, s.value.applyfunc(tidy), s.phase, s.frame) for s in steps]
    return Steps(r, method, steps, numeric)
