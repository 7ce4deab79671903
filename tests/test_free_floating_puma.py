"""The free-floating PUMA on a satellite (examples/free_floating/free_floating_puma.yaml) and the generalized
Jacobian of Umetani and Yoshida (1989), J* = J_m - J_b H_b^-1 H_bm (symdyn.oracle.centroidal):
checked against the end effector's velocity along a simulated motion with zero momentum (the
oracle's forward dynamics, integrated on the Lie group), which never uses J*; the physics checks
of a floating robot with no oracle (momentum conserved without gravity, the centre of mass in free
fall whatever the joints do) on the generated C through symdyn.simulate."""

from __future__ import annotations

import dataclasses
import warnings
from functools import cache

import numpy as np
import pytest
import sympy as sp
from robots import EXAMPLES_DIR, example

import symdyn
from symdyn.apps.simulation.floating_stepping import run_floating
from symdyn.apps.simulation.simulate import simulate
from symdyn.apps.simulation.stepping import sample_times
from symdyn.model.free_flyer import BaseBody
from symdyn.oracle.centroidal import centroidal, floating_frame_jacobian, generalized_jacobian
from symdyn.rnea import forward_dynamics

pin = pytest.importorskip("pinocchio")


@cache
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the published PUMA tensors (examples/puma560.yaml)
        return symdyn.load_robot(EXAMPLES_DIR / "free_floating" / "free_floating_puma.yaml")


class _OraclePlant:
    """The oracle's forward dynamics and Pinocchio's integrate, as run_floating calls a plant."""

    functions = ("forward_dynamics", "integrate")

    def __init__(self, robot):
        self.robot = robot
        self.model = pin.Model()
        self.model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
        for i in range(robot.n):
            self.model.addJoint(i + 1, pin.JointModelRZ(), pin.SE3.Identity(), f"j{i + 1}")

    def forward_dynamics(self, q, v, tau):
        return forward_dynamics(self.robot, q, v, tau)

    def integrate(self, q, xi, dt):
        return pin.integrate(self.model, q, xi * dt[0])


def test_the_generalized_jacobian_moves_the_tool_along_a_zero_momentum_motion():
    robot = puma()
    plant = _OraclePlant(robot)
    rng = np.random.default_rng(89)
    q0 = np.r_[0.1, -0.2, 0.3, 0, 0, 0, 1, rng.uniform(-1, 1, 6)]
    q0[3:7] = rng.normal(size=4)
    q0[3:7] /= np.linalg.norm(q0[3:7])
    qd0 = rng.uniform(-0.5, 0.5, 6)
    M = symdyn.rnea.mass_matrix(robot, q0)
    v0 = np.r_[-np.linalg.solve(M[:6, :6], M[:6, 6:] @ qd0), qd0]  # zero momentum
    t, h = sample_times(0.1, 1e-3)
    tau = np.r_[np.zeros(6), 2.0, -1.0, 0.5, 0.0, 0.0, 0.0]  # joint torques only, no base wrench
    Q, V, _ = run_floating(plant, "rk4", q0, v0, h, t, lambda row, tk, q, v: tau)
    for k in (0, len(t) // 2, len(t) - 1):
        st = centroidal(robot, Q[k], V[k])
        assert np.abs(st.Ag @ V[k]).max() < 1e-10  # the momentum stays zero
    for k in (1, len(t) // 2, len(t) - 2):
        x = [floating_frame_jacobian(robot, Q[j], "tool")[0] for j in (k - 1, k + 1)]
        rate = (x[1][:3, 3] - x[0][:3, 3]) / (2 * h[k])  # the tool's velocity, central difference
        spin = _angular_rate(x[0][:3, :3], x[1][:3, :3], 2 * h[k])
        Js = generalized_jacobian(robot, Q[k], "tool")
        want = Js @ V[k][6:]
        np.testing.assert_allclose(np.r_[rate, spin], want, atol=1e-5 * np.abs(want).max())
        fixed = floating_frame_jacobian(robot, Q[k], "tool")[1][:, 6:] @ V[k][6:]
        assert np.abs(fixed - want).max() > 1e-2 * np.abs(want).max()  # the satellite's reaction matters


def _angular_rate(R0: np.ndarray, R1: np.ndarray, dt: float) -> np.ndarray:
    """The world angular velocity taking R0 to R1 in dt (the midpoint's), by the matrix logarithm."""
    W = R1 @ R0.T
    angle = np.arccos(np.clip((np.trace(W) - 1) / 2, -1, 1))
    axis = np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / (2 * np.sin(angle))
    return axis * angle / dt


# --------------------------------------------------------------------------- physics, generated C


@cache
def flyer():
    """A floating two-link arm on a body of 5 kg (examples/roger_arm.yaml with base: floating)."""
    body = BaseBody(
        "body",
        sp.Float(5.0),
        sp.ImmutableMatrix([0.1, 0.05, -0.2]),
        sp.ImmutableMatrix(np.diag([0.3, 0.4, 0.5])),
    )
    return dataclasses.replace(example("roger_arm"), floating=True, base_body=body)


VALUES = {"l1": 0.5, "m1": 1.0, "l2": 0.4, "m2": 0.8}
Q0 = np.r_[0.3, -0.1, 2.0, 0.1, -0.3, 0.2, 0.9, 0.4, -0.7]
V0 = np.r_[0.2, -0.1, 0.3, 0.8, -1.2, 0.5, 1.5, -2.0]


def test_without_gravity_the_momentum_is_constant_and_the_com_moves_straight():
    params = VALUES | {"g": 0.0}
    traj = simulate(flyer(), Q0, V0, duration=1.0, dt=2e-3, params=params)
    every = slice(None, None, 25)
    states = [centroidal(flyer(), q, v, params) for q, v in zip(traj.q[every], traj.qd[every], strict=True)]
    h = np.array([s.Ag @ v for s, v in zip(states, traj.qd[every], strict=True)])
    assert np.abs(h - h[0]).max() < 1e-9 * np.abs(h[0]).max()
    c = np.array([s.com for s in states])
    line = c[0] + np.outer(traj.t[every], h[0][:3] / states[0].mass)  # c0 + (p0 / m) t
    np.testing.assert_allclose(c, line, atol=1e-10)


def test_with_gravity_the_com_falls_as_g_t2_over_2_whatever_the_joints_do():
    params = VALUES | {"g": 9.81}
    g = np.array([9.81, 0.0, 0.0])  # roger_arm.yaml: gravity [g, 0, 0]
    tau = [0, 0, 0, 0, 0, 0, "3 * sin(5 * t)", "-2 + t"]  # joint torques, no base wrench
    traj = simulate(flyer(), Q0, V0, duration=1.0, dt=2e-3, tau=tau, params=params)
    s0 = centroidal(flyer(), traj.q[0], traj.qd[0], params)
    c = np.array([centroidal(flyer(), q, None, params).com for q in traj.q[::25]])
    t = traj.t[::25, None]
    fall = s0.com + t * (s0.Ag @ traj.qd[0])[:3] / s0.mass + 0.5 * g * t**2
    # exact physics; the bound is rk4's error at dt = 2 ms (3e-8 m after 1 s, 4.9 m of fall)
    np.testing.assert_allclose(c, fall, atol=1e-7)
    assert np.abs(traj.q[-1][7:] - Q0[7:]).max() > 0.1  # the joints did move
