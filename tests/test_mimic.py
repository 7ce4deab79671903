"""Mimic joints: derive (both routes) and the oracle against the full robot, projected by hand.

A robot with mimic joints is compared with its *full* robot (the same links, every joint
independent): with S and o written out here from the relations the robot is built with,
q_b = S q + o, qd_b = S qd, qdd_b = S qdd, the dynamics must be tau = S^T tau_full(q_b, qd_b,
qdd_b), M = S^T M_full(q_b) S, and so on (virtual work). The full robot's values come from
the numeric oracle, which has no mimic joint to handle there.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from robots import assert_close, derived_robot, ev, fd_jacobian, tree_robot

from symdyn import rnea as rn
from symdyn.algorithms.kinematics import forward_kinematics, numeric_jacobian, point_jacobian
from symdyn.dynamics import METHODS, derive, friction_vector
from symdyn.model.robot import Motor, Robot
from symdyn.model.topology import Mimic

K, O = sp.symbols("k o")


def full(robot: Robot) -> Robot:
    """The same links with every joint independent."""
    return replace(
        robot, name=robot.name + "_full", links=tuple(replace(lk, mimic=None) for lk in robot.links)
    )


#: name -> (robot, S, o): S and o written out from the mimic relation each robot is built with
CASES = {
    # a 3-body chain, body 3 follows body 1: q_3 = -2 q_1 + 0.3
    "chain": (
        tree_robot(
            "mimic3",
            (-1, 0, 1),
            ("revolute", "prismatic", "revolute"),
            31,
            {2: Mimic(0, sp.Float(-2), sp.Float(0.3))},
        ),
        [[1, 0], [0, 1], [-2, 0]],
        [0, 0, 0.3],
    ),
    # a gripper: two fingers hang from the wrist (link 2), finger b follows finger a
    "gripper": (
        tree_robot(
            "gripper",
            (-1, 0, 1, 1),
            ("revolute", "revolute", "prismatic", "prismatic"),
            7,
            {3: Mimic(2, sp.Float(-1), sp.Float(0.02))},
        ),
        [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, -1]],
        [0, 0, 0, 0.02],
    ),
    # the Y tree with the right arm's second joint following its first: q_5 = 0.5 q_4
    "ytree": (
        tree_robot(
            "ymimic",
            (-1, 0, 1, 0, 3),
            ("revolute", "revolute", "prismatic", "revolute", "revolute"),
            2015,
            {4: Mimic(3, sp.Float(0.5))},
        ),
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0.5]],
        [0, 0, 0, 0, 0],
    ),
}


def states(n: int, seed: int, count: int = 4):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q, qd, qdd = rng.uniform(-1, 1, (3, n))
        qd[np.abs(qd) < 1e-3] = 0.5  # keep sign(qd) away from its jump
        yield q, qd, qdd


def expected(case: str, q, qd, qdd) -> dict[str, np.ndarray]:
    """tau, M, V, G, F of the mimic robot from the full robot's oracle values, projected."""
    robot, S, o = CASES[case]
    S, o = np.array(S, dtype=float), np.array(o, dtype=float)
    body = full(robot)
    qb, qdb, qddb = S @ q + o, S @ qd, S @ qdd
    return {
        "tau": S.T @ rn.rnea(body, qb, qdb, qddb),
        "M": S.T @ rn.mass_matrix(body, qb) @ S,
        "V": S.T @ rn.bias_torque(body, qb, qdb),
        "G": S.T @ rn.gravity_torque(body, qb),
        "F": S.T @ rn.friction_torque(body, qdb),
        "T": rn.kinetic_energy(body, qb, qdb),
    }


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("case", CASES)
def test_derive_is_the_projected_full_robot(case, method):
    robot, S, _ = CASES[case]
    dyn = derived_robot(robot, method)
    n = len(S[0])
    assert dyn.n == robot.n == n and robot.nb == len(S)
    assert list(dyn.q) == list(sp.symbols(f"q1:{n + 1}"))
    for q, qd, qdd in states(n, 1):
        want = expected(case, q, qd, qdd)
        what = f"{case} {method} q={q} qd={qd} qdd={qdd}"
        assert_close(dyn.evaluate("tau", q, qd, qdd), want["tau"], what=what)
        assert_close(ev(dyn, "M", q), want["M"], what=what)
        assert_close(dyn.evaluate("V", q, qd), want["V"], what=what)
        assert_close(ev(dyn, "C", q, qd) @ qd, want["V"], what=what)
        assert_close(dyn.evaluate("G", q), want["G"], what=what)
        assert_close(dyn.evaluate("F", q, qd), want["F"], what=what)
        assert_close(dyn.evaluate("bias", q, qd), want["V"] + want["G"] + want["F"], what=what)
        assert np.linalg.eigvalsh(ev(dyn, "M", q)).min() > 0


@pytest.mark.parametrize("case", CASES)
def test_oracle_is_the_projected_full_robot(case):
    robot, S, _ = CASES[case]
    for q, qd, qdd in states(len(S[0]), 2):
        want = expected(case, q, qd, qdd)
        assert_close(rn.rnea(robot, q, qd, qdd), want["tau"])
        assert_close(rn.mass_matrix(robot, q), want["M"])
        assert_close(rn.bias_torque(robot, q, qd), want["V"])
        assert_close(rn.gravity_torque(robot, q), want["G"])
        assert_close(rn.friction_torque(robot, qd), want["F"])
        assert rn.kinetic_energy(robot, q, qd) == pytest.approx(want["T"], rel=1e-12)
        assert_close(rn.forward_dynamics(robot, q, qd, want["tau"]), qdd, rtol=1e-8)


@pytest.mark.parametrize("case", CASES)
def test_lagrange_equals_newton_euler(case):
    robot, S, _ = CASES[case]
    ne, la = derived_robot(robot, "newton-euler"), derived_robot(robot, "lagrange")
    for q, qd, qdd in states(len(S[0]), 3):
        for quantity in ("M", "C", "V", "G", "F", "tau"):
            assert_close(la.evaluate(quantity, q, qd, qdd), ne.evaluate(quantity, q, qd, qdd), what=quantity)


@pytest.mark.parametrize("case", CASES)
def test_skew_symmetry(case):
    """dM/dt - 2C skew-symmetric, dM/dt by central differences along qd (the full robot's M)."""
    robot, S, o = CASES[case]
    dyn = derived_robot(robot, "newton-euler")
    h = 1e-6
    for q, qd, _ in states(len(S[0]), 4, count=2):
        M_at = [expected(case, q + s * h * qd, qd, qd)["M"] for s in (1, -1)]
        N = (M_at[0] - M_at[1]) / (2 * h) - 2 * ev(dyn, "C", q, qd)
        scale = max(1.0, np.abs(M_at[0]).max(), np.abs(N).max())
        np.testing.assert_allclose(N + N.T, 0.0, atol=1e-7 * scale)


def test_branches_stay_exact_zeros_after_projection():
    """In the Y tree with a mimic pair in the right arm, the left arm's coordinates (1, 2) and
    the right arm's (3) still couple only through the torso: SymPy zeros in M and C."""
    robot = CASES["ytree"][0]
    for method in METHODS:
        dyn = derived_robot(robot, method)
        for name in ("M", "C"):
            for i in (1, 2):
                assert dyn.compact[name][i, 3] is sp.S.Zero and dyn.compact[name][3, i] is sp.S.Zero


def test_rotor_of_a_mimic_joint_enters_with_the_multiplier_squared():
    """M gains multiplier^2 gear_ratio^2 J_m at its coordinate's diagonal, nothing else."""
    robot, S, _ = CASES["chain"]
    links = list(robot.links)
    links[2] = replace(links[2], motor=Motor())
    bare = replace(robot, links=tuple(links))
    reflected = float(robot.links[2].motor.reflected_inertia)
    q = np.array([0.3, -0.2])
    for method in METHODS:
        extra = ev(derived_robot(robot, method), "M", q) - ev(derived_robot(bare, method), "M", q)
        assert_close(extra, np.array([[4 * reflected, 0], [0, 0]]), rtol=1e-12)


def test_friction_of_a_mimic_joint():
    robot = CASES["chain"][0]
    qd = sp.symbols("qd1 qd2")
    v = [(float(lk.friction.viscous), float(lk.friction.coulomb)) for lk in robot.links]
    F = friction_vector(robot, qd)
    want = [
        v[0][0] * qd[0]
        + v[0][1] * sp.sign(qd[0])
        - 2 * (v[2][0] * (-2 * qd[0]) + v[2][1] * sp.sign(-2 * qd[0])),
        v[1][0] * qd[1] + v[1][1] * sp.sign(qd[1]),
    ]
    assert all(sp.simplify(F[i] - want[i]) == 0 for i in range(2))


def test_symbolic_multiplier_and_offset():
    """q_3 = k q_1 + o with k and o free parameters, evaluated at given values."""
    robot, _, _ = CASES["chain"]
    links = (*robot.links[:2], replace(robot.links[2], mimic=Mimic(0, K, O)))
    symbolic = replace(robot, name="mimic_ko", links=links, params=(K, O))
    dyn = derive(symbolic, simplify=False)
    assert dyn.params == (K, O)
    k, o = -0.7, 0.25
    S, off = np.array([[1, 0], [0, 1], [k, 0]]), np.array([0, 0, o])
    body = full(robot)
    for q, qd, qdd in states(2, 5, count=3):
        qb, qdb, qddb = S @ q + off, S @ qd, S @ qdd
        assert_close(dyn.evaluate("tau", q, qd, qdd, [k, o]), S.T @ rn.rnea(body, qb, qdb, qddb))
        assert_close(ev(dyn, "M", q, params=[k, o]), S.T @ rn.mass_matrix(body, qb) @ S)
        assert_close(rn.rnea(symbolic, q, qd, qdd, {"k": k, "o": o}), S.T @ rn.rnea(body, qb, qdb, qddb))


@pytest.mark.parametrize("case", CASES)
def test_kinematics_of_mimic_joints(case):
    """Poses are the full robot's at q_b; Jacobians over the independent q by differences of
    the oracle's poses (whose mimic expansion test_oracle_is_the_projected_full_robot checks)."""
    robot, S, o = CASES[case]
    S, o = np.array(S, dtype=float), np.array(o, dtype=float)
    q = np.random.default_rng(6).uniform(-1, 1, robot.n)
    oracle = rn.forward_kinematics(full(robot), S @ q + o)
    for k, T in enumerate(forward_kinematics(robot, [sp.Float(x) for x in q])):
        assert_close(np.array(T.matrix(), dtype=float), oracle[k])
        assert_close(rn.forward_kinematics(robot, q)[k], oracle[k])
    point = np.array([0.1, -0.2, 0.05])
    for k in range(robot.nb):
        J = numeric_jacobian(robot, q, link=k, point=tuple(point))
        assert J.shape == (6, robot.n)
        assert_close(J, fd_jacobian(robot, q, k, point, None), rtol=1e-6)
    assert point_jacobian(robot, 0).shape == (6, robot.n)
