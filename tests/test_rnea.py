"""The numeric oracle (symdyn.rnea) against closed forms and physical identities.

Expected values are computed another way: the lecture's closed forms (slides 17-18),
hand-derived closed forms for prismatic chains, energy and Lagrange identities by
finite differences, and the mutual consistency of RNEA, CRBA and energies.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from robots import (
    ASYMMETRIC_PARAMS,
    ZERO3,
    Z,
    asymmetric_friction,
    branch_pairs,
    friction_closed_form,
    friction_states,
    mat,
    roger_arm_robot,
    rotation,
    solo_robot,
    tree_robot,
    vec,
    y_robot,
)

import symdyn
from symdyn import rnea as rn
from symdyn.errors import SymdynError
from symdyn.model.robot import Friction, Link, Motor, Robot
from symdyn.model.topology import Mimic
from symdyn.spatial.transform import Transform, rot_x, rot_y

# --- Roger's eye and arm (slides 17-18) -------------------------------------------------


def roger_closed_form(p, q, qd, qdd):
    M1, M2, L1, L2, G = p
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    s1, s12 = np.sin(q[0]), np.sin(q[0] + q[1])
    M = np.array(
        [
            [
                M2 * L2**2 + 2 * M2 * L1 * L2 * c2 + (M1 + M2) * L1**2,
                M2 * L2**2 + M2 * L1 * L2 * c2,
            ],
            [M2 * L2**2 + M2 * L1 * L2 * c2, M2 * L2**2],
        ]
    )
    V = np.array([-M2 * L1 * L2 * s2 * (qd[1] ** 2 + 2 * qd[0] * qd[1]), M2 * L1 * L2 * s2 * qd[0] ** 2])
    Gv = np.array([(M1 + M2) * G * L1 * s1 + M2 * G * L2 * s12, M2 * G * L2 * s12])
    return M, V, Gv


@pytest.mark.parametrize("seed", range(5))
def test_roger_arm_matches_lecture_closed_form(seed):
    rng = np.random.default_rng(seed)
    robot = roger_arm_robot()
    p = rng.uniform(0.1, 2.0, 5)
    p[4] = rng.uniform(-10, 10)
    named = dict(zip(("m1", "m2", "l1", "l2", "g"), p, strict=True))
    for _ in range(4):
        q, qd, qdd = rng.uniform(-3, 3, (3, 2))
        M, V, G = roger_closed_form(p, q, qd, qdd)
        np.testing.assert_allclose(rn.rnea(robot, q, qd, qdd, p), M @ qdd + V + G, atol=1e-10)
        np.testing.assert_allclose(rn.rnea(robot, q, qd, qdd, named), M @ qdd + V + G, atol=1e-10)
        np.testing.assert_allclose(rn.mass_matrix(robot, q, p), M, atol=1e-12)
        np.testing.assert_allclose(rn.bias_torque(robot, q, qd, p), V, atol=1e-10)
        np.testing.assert_allclose(rn.gravity_torque(robot, q, p), G, atol=1e-10)
        tip = rn.forward_kinematics(robot, q, p)[1] @ np.array([p[3], 0, 0, 1])
        expect = [
            p[2] * np.cos(q[0]) + p[3] * np.cos(q[0] + q[1]),
            p[2] * np.sin(q[0]) + p[3] * np.sin(q[0] + q[1]),
        ]
        np.testing.assert_allclose(tip[:2], expect, atol=1e-12)
        np.testing.assert_allclose(rn.link_com_positions(robot, q, p)[1], tip[:3], atol=1e-12)


def test_roger_eye_pendulum():
    m, ll, gg = 0.7, 0.4, 9.81
    eye = Link("eye", "revolute", Transform.identity(), Z, sp.Float(m), vec([ll, 0, 0]), ZERO3)
    robot = Robot("roger_eye", (eye,), vec([gg, 0, 0]))
    for q, qd, qdd in [(0.3, 1.0, -2.0), (-2.0, 0.0, 0.5)]:
        expect = m * ll**2 * qdd + m * gg * ll * np.sin(q)
        np.testing.assert_allclose(rn.rnea(robot, [q], [qd], [qdd]), [expect], atol=1e-12)


# --- prismatic joints -----------------------------------------------------------------


def test_vertical_slider():
    m, gg = 1.3, 9.81
    inertia = mat(np.diag([0.1, 0.2, 0.25]))
    slider = Link("s", "prismatic", Transform.tx(0.5), Z, sp.Float(m), vec([0.1, -0.2, 0.3]), inertia)
    robot = Robot("slider", (slider,), vec([0, 0, -gg]))
    for q, qd, qdd in [(0.2, 0.5, 1.5), (-1.0, -3.0, -0.4)]:
        np.testing.assert_allclose(rn.rnea(robot, [q], [qd], [qdd]), [m * (qdd + gg)], atol=1e-12)
    np.testing.assert_allclose(rn.potential_energy(robot, [0.7]), m * gg * (0.7 + 0.3), atol=1e-12)


def polar_arm(I1, m, c, gg):
    """Revolute joint about the vertical, carrying a radial slider; placements rotated."""
    # Body frame 1: base z is the body's y axis (Rx(pi/2)), origin shifted.
    pl1 = Transform(sp.ImmutableMatrix(rot_x(sp.pi / 2)), vec([0.3, -0.2, 0.5]))
    inertia1 = mat(np.diag([0.4, I1, 0.3]))  # Iyy = I1 about the joint axis
    link1 = Link("turn", "revolute", pl1, vec([0, 1, 0]), sp.Float(2.0), vec([0, 0.1, 0]), inertia1)
    # Body frame 2: rotated about the joint-1 axis and lifted along it; the slide
    # direction, written in body 2's axes, is body 1's x axis (radial).
    Ry = rot_y(sp.Rational(7, 10))
    pl2 = Transform(sp.ImmutableMatrix(Ry), vec([0, 0.2, 0]))
    axis2 = sp.ImmutableMatrix(Ry.T * sp.Matrix([1, 0, 0]))
    link2 = Link("slide", "prismatic", pl2, axis2, sp.Float(m), sp.ImmutableMatrix(axis2 * c), ZERO3)
    return Robot("polar", (link1, link2), vec([0, 0, -gg]))


def test_polar_arm_closed_form():
    rng = np.random.default_rng(7)
    I1, m, c = 0.35, 1.7, 0.15
    robot = polar_arm(I1, m, c, 9.81)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        r = q[1] + c
        tau1 = (I1 + m * r**2) * qdd[0] + 2 * m * r * qd[0] * qd[1]
        tau2 = m * qdd[1] - m * r * qd[0] ** 2
        np.testing.assert_allclose(rn.rnea(robot, q, qd, qdd), [tau1, tau2], atol=1e-10)


# --- random robots --------------------------------------------------------------------


def random_robot(seed: int, n: int | None = None, *, extras: bool = True) -> Robot:
    """A seeded random chain: rotated placements, unit axes, mixed joints, valid inertias."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 8)) if n is None else n
    links = []
    for i in range(n):
        if rng.random() < 0.3:
            axis = np.zeros(3)
            axis[rng.integers(3)] = rng.choice([-1.0, 1.0])
        else:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
        # principal moments a = y+z, b = x+z, c = x+y satisfy the triangle inequality
        x, y, z = rng.uniform(0.01, 0.3, 3)
        R = rotation(rng)
        inertia = R @ np.diag([y + z, x + z, x + y]) @ R.T
        friction = Friction(*(sp.Float(v) for v in rng.uniform(0, 0.5, 2)))
        motor = Motor(sp.Float(rng.uniform(0, 0.01)), sp.Float(rng.uniform(1, 50)))
        links.append(
            Link(
                name=f"link{i + 1}",
                joint="revolute" if rng.random() < 0.65 else "prismatic",
                placement=Transform(mat(rotation(rng)), mat(rng.uniform(-0.5, 0.5, (3, 1)))),
                axis=mat(axis.reshape(3, 1)),
                mass=sp.Float(rng.uniform(0.2, 3.0)),
                com=mat(rng.uniform(-0.3, 0.3, (3, 1))),
                inertia=mat(inertia),
                friction=friction if extras else Friction(),
                motor=motor if extras else Motor(),
            )
        )
    gravity = rng.normal(size=3) * 4
    return Robot(f"random{seed}", tuple(links), mat(gravity.reshape(3, 1)))


def random_state(robot: Robot, seed: int, N: int | None = None):
    rng = np.random.default_rng(1000 + seed)
    shape = (robot.n,) if N is None else (N, robot.n)
    return rng.uniform(-2, 2, (3, *shape))


SEEDS = range(12)


def any_robot(seed: int) -> Robot:
    """A random chain (SEEDS) or a tree (TREES): the Y tree, the solo legs, or a tree of two
    branches on the base whose first branch forks, link 4 mimicking link 2 across the fork."""
    if seed not in TREES:
        return random_robot(seed)
    if seed == TREES[0]:
        return y_robot()
    if seed == TREES[1]:
        return solo_robot()
    parents = (-1, 0, 0, 2, -1, 4)
    joints = ("revolute", "prismatic", "revolute", "revolute", "prismatic", "revolute")
    return tree_robot("tree6", parents, joints, seed, mimic={3: Mimic(1, sp.Float(1.5), sp.Float(-0.2))})


#: the trees among the robots of the oracle's identities (seeds of any_robot)
TREES = (100, 101, 102)
ROBOTS = [*SEEDS, *TREES]


@pytest.mark.parametrize("seed", ROBOTS)
def test_mass_matrix_spd_and_equals_unit_acceleration_columns(seed):
    robot = any_robot(seed)
    q, _, _ = random_state(robot, seed)
    M = rn.mass_matrix(robot, q)
    np.testing.assert_allclose(M, M.T, atol=1e-12)
    assert np.linalg.eigvalsh(M).min() > 0
    zero = np.zeros(robot.n)
    cols = [rn.rnea(robot, q, zero, e, gravity=False, friction=False) for e in np.eye(robot.n)]
    np.testing.assert_allclose(np.array(cols).T, M, atol=1e-10)
    if robot.n == robot.nb:  # joints on different branches: exact zeros
        assert all(M[i, j] == M[j, i] == 0.0 for i, j in branch_pairs(robot.parents))


@pytest.mark.parametrize("seed", ROBOTS)
def test_gravity_is_gradient_of_potential(seed):
    robot = any_robot(seed)
    q, _, _ = random_state(robot, seed)
    h = 1e-6
    grad = [
        (rn.potential_energy(robot, q + h * e) - rn.potential_energy(robot, q - h * e)) / (2 * h)
        for e in np.eye(robot.n)
    ]
    np.testing.assert_allclose(rn.gravity_torque(robot, q), grad, atol=1e-7)


@pytest.mark.parametrize("seed", ROBOTS)
def test_kinetic_energy_is_quadratic_form_of_mass_matrix(seed):
    robot = any_robot(seed)
    q, qd, _ = random_state(robot, seed)
    expect = 0.5 * qd @ rn.mass_matrix(robot, q) @ qd
    assert rn.kinetic_energy(robot, q, qd) == pytest.approx(expect, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("seed", ROBOTS)
def test_power_identity_along_trajectory(seed):
    """d/dt T = qd^T (tau - G) with friction off: T differentiated along q(t) by differences."""
    robot = any_robot(seed)
    q, qd, qdd = random_state(robot, seed)
    h = 1e-5

    def T(t):
        return rn.kinetic_energy(robot, q + qd * t + 0.5 * qdd * t**2, qd + qdd * t)

    dT = (T(h) - T(-h)) / (2 * h)
    tau = rn.rnea(robot, q, qd, qdd, friction=False)
    assert dT == pytest.approx(qd @ (tau - rn.gravity_torque(robot, q)), rel=1e-7, abs=1e-7)


@pytest.mark.parametrize("seed", ROBOTS)
def test_bias_equals_christoffel_form_of_mass_matrix(seed):
    """Lagrange: V_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k, dM by differences."""
    robot = any_robot(seed)
    q, qd, _ = random_state(robot, seed)
    h = 1e-6
    dM = np.array(
        [
            (rn.mass_matrix(robot, q + h * e) - rn.mass_matrix(robot, q - h * e)) / (2 * h)
            for e in np.eye(robot.n)
        ]
    )  # dM[k, i, j] = dM_ij / dq_k
    V = np.einsum("kij,j,k->i", dM, qd, qd) - 0.5 * np.einsum("ijk,j,k->i", dM, qd, qd)
    np.testing.assert_allclose(rn.bias_torque(robot, q, qd), V, atol=1e-6)


@pytest.mark.parametrize("seed", ROBOTS)
def test_forward_dynamics_inverts_rnea(seed):
    robot = any_robot(seed)
    q, qd, qdd = random_state(robot, seed)
    tau = rn.rnea(robot, q, qd, qdd)
    np.testing.assert_allclose(rn.forward_dynamics(robot, q, qd, tau), qdd, atol=1e-8)


@pytest.mark.parametrize("seed", SEEDS)
def test_decomposition_friction_and_motor(seed):
    robot = random_robot(seed)
    bare = random_robot(seed, extras=False)
    q, qd, qdd = random_state(robot, seed)
    M, V, G, F = (
        rn.mass_matrix(robot, q),
        rn.bias_torque(robot, q, qd),
        rn.gravity_torque(robot, q),
        rn.friction_torque(robot, qd),
    )
    np.testing.assert_allclose(rn.rnea(robot, q, qd, qdd), M @ qdd + V + G + F, atol=1e-9)
    links = robot.links
    np.testing.assert_allclose(
        F,
        [
            float(lk.friction.viscous) * v + float(lk.friction.coulomb) * np.sign(v)
            for lk, v in zip(links, qd, strict=True)
        ],
    )
    reflected = [float(lk.motor.reflected_inertia) for lk in links]
    np.testing.assert_allclose(M - rn.mass_matrix(bare, q), np.diag(reflected), atol=1e-12)
    np.testing.assert_allclose(rn.bias_torque(bare, q, qd), V, atol=1e-12)


def test_batch_equals_loop():
    robot = random_robot(3, n=6)
    q, qd, qdd = random_state(robot, 3, N=5)
    tau = rn.rnea(robot, q, qd, qdd)
    assert tau.shape == (5, 6)
    for k in range(5):
        np.testing.assert_allclose(tau[k], rn.rnea(robot, q[k], qd[k], qdd[k]), atol=1e-12)
        np.testing.assert_allclose(rn.mass_matrix(robot, q)[k], rn.mass_matrix(robot, q[k]))
        np.testing.assert_allclose(rn.forward_dynamics(robot, q, qd, tau)[k], qdd[k], atol=1e-8)
        assert rn.kinetic_energy(robot, q, qd)[k] == pytest.approx(rn.kinetic_energy(robot, q[k], qd[k]))
        assert rn.potential_energy(robot, q)[k] == pytest.approx(rn.potential_energy(robot, q[k]))
        np.testing.assert_allclose(
            rn.forward_kinematics(robot, q)[5][k], rn.forward_kinematics(robot, q[k])[5]
        )


def test_forward_kinematics_composes_joint_transforms():
    """Poses agree with the model's own SymPy joint transforms evaluated at q."""
    robot = random_robot(5, n=4)
    q, _, _ = random_state(robot, 5)
    T = np.eye(4)
    for link, qi, pose in zip(robot.links, q, rn.forward_kinematics(robot, q), strict=True):
        T = T @ np.array(link.joint_transform(sp.Float(qi)).matrix().evalf(), dtype=float)
        np.testing.assert_allclose(pose, T, atol=1e-12)


def test_params_errors_and_cache():
    robot = roger_arm_robot()
    with pytest.raises(SymdynError):
        rn.rnea(robot, [0, 0], [0, 0], [0, 0])
    with pytest.raises(SymdynError):
        rn.rnea(robot, [0, 0], [0, 0], [0, 0], {"m1": 1.0})
    with pytest.raises(SymdynError):
        rn.rnea(robot, [0, 0, 0], [0, 0], [0, 0], [1, 1, 1, 1, 1])
    p = [1.0, 2.0, 0.5, 0.5, 9.81]
    assert rn.numeric_model(robot, p) is rn.numeric_model(robot, tuple(p))


P_ARM = [1.0, 2.0, 0.5, 0.5, 9.81]  # m1, m2, l1, l2, g of roger_arm_robot()
Z2 = [0.0, 0.0]
# every public function; `x` is the joint vector under test, the others are single states
CALLS = {
    "rnea": lambda r, x, p: rn.rnea(r, x, Z2, Z2, p),
    "mass_matrix": lambda r, x, p: rn.mass_matrix(r, x, p),
    "gravity_torque": lambda r, x, p: rn.gravity_torque(r, x, p),
    "bias_torque": lambda r, x, p: rn.bias_torque(r, Z2, x, p),
    "friction_torque": lambda r, x, p: rn.friction_torque(r, x, p),
    "forward_dynamics": lambda r, x, p: rn.forward_dynamics(r, Z2, Z2, x, p),
    "kinetic_energy": lambda r, x, p: rn.kinetic_energy(r, x, Z2, p),
    "potential_energy": lambda r, x, p: rn.potential_energy(r, x, p),
    "forward_kinematics": lambda r, x, p: rn.forward_kinematics(r, x, p),
    "link_com_positions": lambda r, x, p: rn.link_com_positions(r, x, p),
}
ARGUMENT = {"bias_torque": "qd", "friction_torque": "qd", "forward_dynamics": "tau"}  # else q
FREE = "m1, m2, l1, l2, g"


@pytest.mark.parametrize("name", list(CALLS))
def test_every_public_function_checks_its_arguments(name):
    call, robot, arg = CALLS[name], roger_arm_robot(), ARGUMENT.get(name, "q")
    call(robot, Z2, P_ARM)  # right as given
    bad = {
        "three entries": (([0, 0, 0], P_ARM), f"{name}: {arg} has 3 entries, expected 2 (one per joint)"),
        "one entry": (([0], P_ARM), f"{name}: {arg} has 1 entry, expected 2 (one per joint)"),
        "wide batch": (
            ([[0, 0, 0]], P_ARM),
            f"{name}: {arg} has shape (1, 3), expected (2,) or (N, 2) (one column per joint)",
        ),
        "not numbers": ((["a", 0], P_ARM), f"{name}: {arg} must hold numbers, got ['a', 0]"),
        "no params": (
            (Z2, None),
            f"{name}: robot 'roger_arm' has free parameters ({FREE}); give their values",
        ),
        "too many params": (
            (Z2, [*P_ARM, 1.0]),
            f"{name}: params has 6 values, expected 5 (one per free parameter: {FREE})",
        ),
        "params missing": ((Z2, {"m1": 1.0}), f"{name}: no value for parameter(s) m2, l1, l2, g"),
        "unknown param": (
            (Z2, {**dict(zip(FREE.split(", "), P_ARM, strict=True)), "m3": 1.0}),
            f"{name}: unknown parameter(s) m3 (free parameters of robot 'roger_arm': {FREE})",
        ),
    }
    for case, (args, message) in bad.items():
        with pytest.raises(SymdynError) as err:
            call(robot, *args)
        assert str(err.value) == message, case
    with pytest.raises(SymdynError) as err:
        call("roger_arm", Z2, P_ARM)
    assert str(err.value) == f"{name}: robot must be a symdyn Robot, got str"
    batch = [Z2, Z2, Z2]
    if name in ("rnea", "bias_torque", "forward_dynamics", "kinetic_energy"):  # a batch among single states
        with pytest.raises(SymdynError, match=rf"^{name}: the joint vectors differ in shape \("):
            call(robot, batch, P_ARM)
    elif name == "forward_kinematics":
        assert [T.shape for T in call(robot, batch, P_ARM)] == [(3, 4, 4)] * robot.n
    else:
        assert np.shape(call(robot, batch, P_ARM))[0] == 3  # one result per state


@pytest.mark.parametrize(
    "module",
    [
        "oracle/rnea",
        "oracle/inputs",
        "oracle/spatial",
        "oracle/singular",
        "oracle/recursions",
        "oracle/floating",
        "oracle/tendons",
        "model/quaternion_norm",
        "rnea",
    ],
)
def test_oracle_is_independent_of_symbolic_derivation(module):
    """The oracle (symdyn/oracle: rnea.py, its input side inputs.py and its spatial kinematics
    spatial.py) and its public entry symdyn/rnea.py import NumPy, the error type and the
    oracle only: no SymPy, no symbolic derivation."""
    source = (Path(symdyn.__file__).parent / f"{module}.py").read_text()
    imported = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom):
            imported.add(node.module or "")
        elif isinstance(node, ast.Import):
            imported.update(a.name for a in node.names)
    assert imported <= {
        "__future__",
        "collections.abc",
        "dataclasses",
        "functools",
        "numpy",
        "errors",
        "inputs",
        "singular",
        "spatial",
        "recursions",
        "floating",
        "tendons",  # symdyn/oracle/tendons.py, itself checked here
        "model.quaternion_norm",  # the run-time range of a quaternion's norm, itself checked here
        "math",
        "oracle.rnea",  # symdyn/rnea.py re-exports it
        "sys",  # the callable-module hook that makes symdyn.rnea(...) a function too
        "types",
    }
    assert "sympy" not in source


# --- kinematic trees ---------------------------------------------------------------------


@pytest.mark.parametrize("seed", TREES)
def test_tree_poses_compose_along_the_parents(seed):
    """Poses are the model's own SymPy joint transforms multiplied along each link's path."""
    robot = any_robot(seed)
    q, _, _ = random_state(robot, seed)
    poses = rn.forward_kinematics(robot, q)
    assert len(poses) == robot.nb
    qb = robot.body_positions([sp.Float(x) for x in q])
    for i, link in enumerate(robot.links):
        T = np.array(link.joint_transform(qb[i]).matrix().evalf(), dtype=float)
        p = robot.parents[i]
        np.testing.assert_allclose(poses[i], T if p < 0 else poses[p] @ T, atol=1e-12)
    coms = rn.link_com_positions(robot, q)
    for i, link in enumerate(robot.links):
        np.testing.assert_allclose(
            coms[i], poses[i][:3, :3] @ np.array(link.com, dtype=float)[:, 0] + poses[i][:3, 3]
        )


def test_tree_batch_equals_loop():
    robot = any_robot(TREES[2])
    q, qd, qdd = random_state(robot, 2, N=4)
    tau = rn.rnea(robot, q, qd, qdd)
    for k in range(4):
        np.testing.assert_allclose(tau[k], rn.rnea(robot, q[k], qd[k], qdd[k]), atol=1e-12)
        np.testing.assert_allclose(rn.mass_matrix(robot, q)[k], rn.mass_matrix(robot, q[k]))


def test_direction_dependent_coulomb_friction():
    """friction_torque and rnea's friction part are c+ at qd > 0, -c- at qd < 0 and 0 at rest,
    plus the viscous term (hand-written closed form), at single states and in a batch."""
    robot = asymmetric_friction()
    q, qd, qdd, _ = friction_states()
    want = friction_closed_form(qd)
    np.testing.assert_allclose(rn.friction_torque(robot, qd, ASYMMETRIC_PARAMS), want, rtol=0, atol=1e-15)
    for k in range(len(qd)):
        np.testing.assert_allclose(
            rn.friction_torque(robot, qd[k], ASYMMETRIC_PARAMS), want[k], rtol=0, atol=1e-15
        )
    diff = rn.rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS) - rn.rnea(
        robot, q, qd, qdd, ASYMMETRIC_PARAMS, friction=False
    )
    np.testing.assert_allclose(diff, want, rtol=0, atol=1e-12)
