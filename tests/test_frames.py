"""Joint frames and the rotation of symmetric tensors into the parent frame (symdyn.algorithms.frames)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from robots import assert_matrix_zero, mat

from symdyn.algorithms.frames import joint_frames
from symdyn.model.robot import Link, Robot
from symdyn.spatial.transform import Transform, rot_x, rot_z
from symdyn.symbolic.program import Program

a, b, c, d, e, f = sp.symbols("a b c d e f")
J = ((a, d, e), (d, b, f), (e, f, c))
q1 = sp.Symbol("q1")
AXES = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
PLACEMENTS = {
    "identity": sp.eye(3),
    "dh_twist": rot_x(sp.pi / 2),
    "general": rot_z(sp.pi / 3) * rot_x(-sp.pi / 4),
}


def _robot(axis, placement, joint: str = "revolute") -> Robot:
    link = Link(
        name="link1",
        joint=joint,
        placement=Transform(sp.ImmutableMatrix(placement), mat([[0.1], [0], [0.2]])),
        axis=sp.ImmutableMatrix([[x] for x in axis]),
        mass=sp.S.One,
        com=mat([[0], [0], [0]]),
        inertia=sp.ImmutableMatrix(sp.eye(3)),
    )
    return Robot("one", (link,), mat([[0], [0], [-9.81]]))


def _rotated(robot: Robot, tensor) -> sp.Matrix:
    program = Program()
    frame = joint_frames(robot, [q1])[0]
    out = frame.rotate_symmetric(tensor, program, "t")
    return sp.Matrix(3, 3, program.expand([x for row in out for x in row]))


@pytest.mark.parametrize("placement", list(PLACEMENTS))
@pytest.mark.parametrize("axis", AXES)
def test_rotate_symmetric_is_R_J_RT(axis, placement):
    robot = _robot(axis, PLACEMENTS[placement])
    R = robot.links[0].joint_transform(q1).R  # independent of symdyn.algorithms.frames
    assert_matrix_zero(_rotated(robot, J) - R * sp.Matrix(J) * R.T, 1, f"axis {axis}, {placement}")


def test_general_axis_and_prismatic_joint_numerically():
    rng = np.random.default_rng(5)
    Jn = rng.normal(size=(3, 3))
    Jn = Jn + Jn.T
    tensor = tuple(tuple(sp.Float(x) for x in row) for row in Jn)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    for joint in ("revolute", "prismatic"):
        robot = _robot(axis, PLACEMENTS["general"], joint)
        R = robot.links[0].joint_transform(q1).R
        got = sp.lambdify(q1, _rotated(robot, tensor))(0.7)
        Rn = np.array(sp.lambdify(q1, R)(0.7), dtype=float)
        np.testing.assert_allclose(np.array(got, dtype=float), Rn @ Jn @ Rn.T, atol=1e-12)


def test_tensor_symmetric_about_the_axis_needs_no_trigonometry():
    robot = _robot((0, 0, 1), PLACEMENTS["identity"])
    tensor = ((a, 0, 0), (0, a, 0), (0, 0, c))
    assert _rotated(robot, tensor) == sp.Matrix(tensor)
