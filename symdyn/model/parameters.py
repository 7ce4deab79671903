"""The standard dynamic parameters of a robot: 13 per body, in Pinocchio's order.

Per link i (body frame i), the 10 inertial parameters of `pinocchio.Inertia.toDynamicParameters`

    m_i, m_i c_x, m_i c_y, m_i c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz

with c the centre of mass in body frame i and I the inertia tensor about the ORIGIN of body
frame i, I = I_c + m (c^T c 1 - c c^T) (parallel-axis theorem; I_c about the centre of mass,
`Link.inertia`; off-diagonal entries are the tensor's, minus the product-of-inertia integrals);
then the joint's 3: Ia_i = gear_ratio^2 J_m (reflected rotor inertia), fv_i (viscous friction),
fc_i (Coulomb friction). A link with direction-dependent Coulomb friction (symdyn.model.friction)
calls its 13th parameter fcp_i (the magnitude for qd_i > 0) and adds fcn_i (the magnitude for
qd_i < 0); these extra parameters follow the 13 nb others, in link order, so that column 13 i + k
is always parameter k of body i + 1. A floating robot's base body (`Robot.base_body`, body 0)
adds its 10 inertial parameters last, named m0, mx0, ..., Izz0 (base frame, about its origin).
The equations of motion are linear in this vector, tau = Y(q, qd, qdd) pi (symdyn.oracle.regressor;
Atkeson, An and Hollerbach 1986).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

__all__ = [
    "INERTIAL_NAMES",
    "JOINT_NAMES",
    "PER_BODY",
    "standard_parameters",
    "numeric_parameters",
    "asymmetric_bodies",
]

#: the 10 inertial parameters of a body, Pinocchio's order (toDynamicParameters)
INERTIAL_NAMES = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
#: the 3 parameters of a body's joint: reflected rotor inertia, viscous and Coulomb friction
JOINT_NAMES = ("Ia", "fv", "fc")
#: parameters per body
PER_BODY = len(INERTIAL_NAMES) + len(JOINT_NAMES)


def asymmetric_bodies(robot) -> list[int]:
    """The 0-based indices of the links with direction-dependent Coulomb friction, in link order:
    their fcn parameters are the columns 13 nb, 13 nb + 1, ... of the regressor."""
    return [i for i, link in enumerate(robot.links) if link.friction.asymmetric]


def _body_names(i: int, asymmetric: bool) -> list[str]:
    """The 13 parameter names of body i (1-based)."""
    joint = ("Ia", "fv", "fcp") if asymmetric else JOINT_NAMES
    return [f"{p}{i}" for p in (*INERTIAL_NAMES, *joint)]


def _inertial_parameters(body) -> list[sp.Expr]:
    """[m, m c, I_O (6 entries)] of a body (a link or a floating robot's base body), its own frame."""
    m = sp.sympify(body.mass)
    c = sp.Matrix(body.com)
    I_origin = sp.Matrix(body.inertia) + m * ((c.T * c)[0, 0] * sp.eye(3) - c * c.T)
    inertial = [m, *(m * c), *(I_origin[i, j] for i, j in ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)))]
    return [sp.sympify(x) for x in inertial]


def _body_parameters(link) -> list[sp.Expr]:
    """[m, m c, I_O (6 entries), Ia, fv, fc] of one link, all in its body frame."""
    joint = [link.motor.reflected_inertia, link.friction.viscous, link.friction.coulomb]
    return [*_inertial_parameters(link), *(sp.sympify(x) for x in joint)]


def standard_parameters(robot) -> tuple[tuple[str, ...], tuple[sp.Expr, ...]]:
    """The standard parameter vector pi of a robot: 13 per body, link 1 first, then one per link
    with direction-dependent Coulomb friction.

    Per body i (1-based, every link including mimic joints' bodies): m_i, m_i c_i (body frame i),
    the inertia tensor about body frame i's origin (I_xx, I_xy, I_yy, I_xz, I_yz, I_zz: Pinocchio's
    `Inertia.toDynamicParameters` order), then Ia_i = gear_ratio^2 J_m, fv_i, fc_i (fcp_i when
    the link's Coulomb friction depends on the direction); then fcn_i of each such link; then, on a
    floating base, the base body's 10 inertial parameters m0, mx0, ..., Izz0.

    Args:
        robot: a `symdyn.Robot`; its valued parameters are substituted (`Robot.resolved`).

    Returns:
        (names, values): names such as "m1", "mx1", ..., "fc1", "m2", ...; values SymPy
        expressions in which only the robot's free parameters stay symbols.
    """
    resolved = robot.resolved()
    links = resolved.links
    extra = asymmetric_bodies(robot)
    names = [name for i, link in enumerate(links, 1) for name in _body_names(i, link.friction.asymmetric)]
    names += [f"fcn{i + 1}" for i in extra]
    values = [x for link in links for x in _body_parameters(link)]
    values += [sp.sympify(links[i].friction.coulomb_minus) for i in extra]
    if robot.floating:
        names += [f"{p}0" for p in INERTIAL_NAMES]
        values += _inertial_parameters(resolved.base_body)
    return tuple(names), tuple(values)


def numeric_parameters(robot, params=None) -> np.ndarray:
    """The standard parameter vector pi (13 nb + fcn columns,) as floats, with the free parameters'
    values.

    Args:
        robot: a `symdyn.Robot`.
        params: values of its free parameters (`Robot.param_values`); None when it has none.

    Raises:
        SymdynError: missing, extra or non-numeric parameter values.
    """
    return np.array([float(x) for x in standard_parameters(robot.numeric(params))[1]])
