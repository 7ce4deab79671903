"""The mass matrix by the composite-rigid-body algorithm, symbolically, in body frames.

Each body i carries, about its body-frame origin, its spatial inertia (m_i, h_i, I_i):
mass, first moment h_i = m_i c_i and rotational inertia I_i = I_ci + m_i (c_i^T c_i 1 - c_i c_i^T)
(symdyn.spatial.inertia). The composite body of the subtree rooted at i (a kinematic tree,
symdyn.model.topology) adds the composites of its children j, each moved into frame i
(R, p: child frame in parent frame, h' = R h):

    m += m_j,   h += R h_j + m_j p,
    I += R I_j R^T - [h' x][p x] - [p x][h' x] - m_j [p x]^2

A unit acceleration of joint j makes the composite j exert the spatial force
(moment n about the origin, force f) = (I^c a, a x h^c) for a revolute joint
with axis a, or (h^c x a, m^c a) for a prismatic one. Carried inward from each link to
its parent, n <- R n + p x R f, f <- R f, and projected on each joint i of the support of
j (j and its ancestors), it gives M_ij = a_i . n (revolute) or a_i . f (prismatic). Joints
on different branches move disjoint subtrees, so M_ij is an exact zero for them. O(nb d),
d the depth of the tree, against nb Newton-Euler passes.

References: Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 6.2 (the
composite-rigid-body algorithm); R. Grupen, "Dynamics" (2015), slide 16 (M in
tau = M qdd + V + G + F), slides 8 and 10 (moving and rotating an inertia tensor).
"""

from __future__ import annotations

import sympy as sp

from ..model.robot import Link, Robot
from ..model.topology import children
from ..spatial import vectors as v3
from ..spatial.inertia import SpatialInertia, apply_inertia, body_inertia, shifted_rotational_inertia
from ..spatial.motion import Force, Motion, motion_subspace, project
from ..symbolic.program import Program
from .frames import JointFrame

__all__ = [
    "link_inertia",
    "link_subspace",
    "shift_inertia",
    "composite_inertias",
    "mass_matrix_crba",
    "gravity_composite",
]


def link_inertia(link: Link) -> SpatialInertia:
    """The link's own spatial inertia.

    Args:
        link: mass m, centre of mass c and inertia I_c about c, in its body frame.

    Returns:
        (m, m c, I_o) about the body-frame origin, body axes (symdyn.spatial.inertia).
    """
    return body_inertia(link.mass, link.com, link.inertia)


def link_subspace(link: Link) -> Motion:
    """The motion subspace of the link's joint.

    Args:
        link: a revolute or prismatic joint with unit axis a in the link's body frame.

    Returns:
        (a, 0) revolute, (0, a) prismatic, in the body frame (Featherstone 2008, sec. 4.4).
    """
    return motion_subspace(link.joint, link.axis)


def shift_inertia(
    frame: JointFrame, child: SpatialInertia, own: SpatialInertia, program: Program, hint: str
) -> SpatialInertia:
    """own + child, the child's spatial inertia moved into the parent frame.

    Args:
        frame: the child's frame in the parent's (R, p: child frame i in parent frame i-1).
        child: (m_j, h_j, I_j) about the child's origin, child axes (frame i).
        own: (m_o, h_o, I_o) about the parent's origin, parent axes (frame i-1).

    Returns:
        (m, h, I) about the parent's origin, parent axes, every entry named:

            m = m_o + m_j,   h = h_o + R h_j + m_j p,
            I = I_o + R I_j R^T - [h' x][p x] - [p x][h' x] - m_j [p x]^2,   h' = R h_j
    """
    R, p = frame.R, frame.p
    Rh = program.let_vector(v3.mul(R, child.first_moment), f"{hint}Rh")
    m = program.let(v3.sum_terms((own.mass, child.mass)), f"{hint}m")
    h = program.let_vector(v3.add(own.first_moment, Rh, v3.scale(child.mass, p)), f"{hint}h")
    RIR = frame.rotate_symmetric(child.inertia, program, f"{hint}r")
    I = shifted_rotational_inertia(own.inertia, RIR, Rh, child.mass, p)
    return SpatialInertia(m, h, program.let_symmetric(I, f"{hint}I"))


def composite_inertias(robot: Robot, frames: list[JointFrame], program: Program) -> list[SpatialInertia]:
    """The spatial inertia of the subtree rooted at each link (the link and everything outboard).

    Args:
        robot: the model, nb links in a tree.
        frames: `symdyn.algorithms.frames.joint_frames(robot, q)`.
        program: receives the named intermediates.

    Returns:
        nb composites (m^c_i, h^c_i, I^c_i), each about body i's origin, in body i's axes
        (Featherstone 2008, sec. 6.2).
    """
    nb = robot.nb
    parents = robot.parents
    composites: list[SpatialInertia] = [link_inertia(link) for link in robot.links]
    for j in reversed(range(nb)):
        body = composites[j]
        own = SpatialInertia(
            body.mass, program.let_vector(body.first_moment, "h"), program.let_symmetric(body.inertia, "Io")
        )
        for child in children(parents, j):  # complete: children come after their parent
            own = shift_inertia(frames[child], composites[child], own, program, "c")
        composites[j] = own
    return composites


def mass_matrix_crba(
    robot: Robot,
    frames: list[JointFrame],
    composites: list[SpatialInertia],
    program: Program,
    base_columns: list[Force] | None = None,
) -> sp.Matrix:
    """M(q) by the composite-rigid-body algorithm (Featherstone 2008, sec. 6.2), plus the
    reflected motor inertia gear_ratio^2 J_m on the diagonal (Grupen (2015), slide 16).

    Args:
        robot: the model, nb links in a tree.
        frames: `joint_frames(robot, q)`.
        composites: `composite_inertias(robot, frames, program)` (body frames).
        program: receives the named intermediates.
        base_columns: receives, per joint j, the force of its unit acceleration carried down to
            the base frame (n, f about the base origin): the base rows of a floating M.

    Returns:
        The symmetric nb x nb inertia matrix of the bodies' joints over the program's
        intermediates; M_ij is SymPy's zero unless i supports j or j supports i.
    """
    nb = robot.nb
    parents = robot.parents
    M = sp.zeros(nb, nb)
    for j in range(nb):
        force = apply_inertia(composites[j], link_subspace(robot.links[j]))  # frame j
        force = Force(program.let_vector(force.angular, "Fn"), program.let_vector(force.linear, "Ff"))
        i = j
        while True:  # force is in frame i, i = j and then down its support
            entry = project(link_subspace(robot.links[i]), force)
            if i == j:
                entry = entry + robot.links[j].motor.reflected_inertia
            M[i, j] = M[j, i] = program.let(entry, "M")
            if parents[i] < 0:
                if base_columns is not None:
                    base_columns.append(frames[i].force_to_parent(force, program, "Ff"))
                break
            force = frames[i].force_to_parent(force, program, "Ff")
            force = force._replace(angular=program.let_vector(force.angular, "Fn"))
            i = parents[i]
    return M


def gravity_composite(
    robot: Robot,
    frames: list[JointFrame],
    composites: list[SpatialInertia],
    program: Program,
    g_base: v3.Vec | None = None,
) -> list[sp.Expr]:
    """G(q) from the composite bodies (Grupen (2015), slide 16: the G of tau = M qdd + V + G + F).

    With g_k the gravitational acceleration in frame k (g_k = R_k^T g_lambda(k), the robot's
    gravity in the base frame for a link on the base) and m^c_k, h^c_k the subtree's mass and
    first moment about origin k,

        G_k = a_k . (g_k x h^c_k)   (revolute: minus gravity's torque about joint k)
        G_k = -m^c_k (a_k . g_k)    (prismatic: minus gravity's force along joint k)

    which is dP/dq_k for P = -sum_i m_i g^T p_ci (Spong, Hutchinson, Vidyasagar, Robot
    Modeling and Control (2006), sec. 7.3). One rotation per link and no inward force
    recursion, against a Newton-Euler pass with qd = qdd = 0.

    Args:
        robot: the model, nb links in a tree (gravity in the base frame).
        frames: `joint_frames(robot, q)`.
        composites: `composite_inertias(robot, frames, program)` (body frames).
        program: receives the named intermediates (the g_k).
        g_base: gravity in the base frame when it is not the robot's `base_gravity` (a floating
            base: R^T g with R its orientation).

    Returns:
        nb expressions (the bodies' joints) over the program's intermediates.
    """
    g_base = v3.vec(robot.base_gravity) if g_base is None else g_base
    g: list[v3.Vec] = []  # g_k, frame k
    G: list[sp.Expr] = []
    for k, link in enumerate(robot.links):
        p = robot.parents[k]
        g_k = program.let_vector(v3.mul_t(frames[k].R, g_base if p < 0 else g[p]), f"gk{k + 1}_")
        g.append(g_k)  # type: ignore[arg-type]
        a = v3.vec(link.axis)
        c = composites[k]
        if link.joint == "revolute":
            G.append(v3.dot(a, v3.cross(g_k, c.first_moment)))
        else:
            G.append(-v3.product(c.mass, v3.dot(a, g_k)))
    return G
