"""Frames and task space (symdyn.algorithms.frame_kinematics, .operational_space, Dynamics' frame
methods) against the numeric oracle symdyn.oracle.frames, Pinocchio, Modern Robotics, finite
differences and identities."""

from __future__ import annotations

import warnings
from functools import cache

import numpy as np
import pytest
from robots import EXAMPLES_DIR, example, pinocchio_model, rpy, y_robot
from scipy.linalg import logm

import symdyn
from symdyn.errors import SymdynError
from symdyn.oracle.frames import center_of_mass, frame_state
from symdyn.regenerate import example_robot_data_folder

TOL = 1e-9
URDFS = {
    "panda": ("panda_description/urdf/panda.urdf", ("panda_hand", "panda_link8", "panda_rightfinger")),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", ("tool0",)),
    "solo12": ("solo_description/robots/solo12.urdf", ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")),
}


@cache
def urdf_dynamics(name: str):
    folder = example_robot_data_folder()
    if folder is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = symdyn.load_urdf(folder / URDFS[name][0])
    return str(folder / URDFS[name][0]), symdyn.derive(robot, simplify=False)


@cache
def dynamics(name: str):
    robot = y_robot() if name == "ytree" else example(name)
    return symdyn.derive(robot, simplify=False)


def _state(robot, seed: int):
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.5, 1.5, len(robot.params)) if robot.params else None
    return rng.uniform(-1.2, 1.2, robot.n), rng.uniform(-1, 1, robot.n), p


# --------------------------------------------------------------------------- the numeric oracle


@pytest.mark.parametrize("name", ["puma560", "stanford", "scara", "mr_ur5", "ytree"])
def test_every_frame_agrees_with_the_oracle(name):
    dyn = dynamics(name)
    r = dyn.robot
    for seed in range(1):
        q, qd, p = _state(r, seed)
        for f in r.frame_names[-3:]:
            s = frame_state(r, f, q, qd, p)
            np.testing.assert_allclose(dyn.frame_pose(f, q, p), s.pose, atol=TOL)
            np.testing.assert_allclose(dyn.frame_jacobian(f, q=q, params=p), s.jacobian, atol=TOL)
            np.testing.assert_allclose(dyn.frame_jacobian(f, "local", q, p), s.jacobian_local, atol=TOL)
            np.testing.assert_allclose(dyn.frame_jacobian_dot_qd(f, q, qd, p), s.drift, atol=TOL)
        c, Jc, a = center_of_mass(r, q, qd, p)
        np.testing.assert_allclose(dyn.com(q, p), c, atol=TOL)
        np.testing.assert_allclose(dyn.com_jacobian(q, p), Jc, atol=TOL)
        np.testing.assert_allclose(dyn.com_jacobian_dot_qd(q, qd, p), a, atol=TOL)


# --------------------------------------------------------------------------- Pinocchio


def _pin_state(pin, model, data, robot, q, qd):
    S = np.array(robot.selection(), dtype=float)
    qb, qdb = S @ q, S @ qd
    pin.forwardKinematics(model, data, qb, qdb, np.zeros(robot.nb))
    pin.updateFramePlacements(model, data)
    pin.computeJointJacobians(model, data, qb)
    return S, qb, qdb


def _check_pinocchio(pin, model, dyn, frames, seeds=2):
    data = model.createData()
    r = dyn.robot
    for seed in range(seeds):
        q, qd, p = _state(r, seed)
        S, qb, qdb = _pin_state(pin, model, data, r, q, qd)
        for f in frames:
            fid = model.getFrameId(f)
            assert fid < model.nframes, f
            np.testing.assert_allclose(dyn.frame_pose(f, q, p), data.oMf[fid].homogeneous, atol=TOL)
            for ref, pref in (("world", pin.LOCAL_WORLD_ALIGNED), ("local", pin.LOCAL)):
                want = pin.getFrameJacobian(model, data, fid, pref) @ S
                np.testing.assert_allclose(dyn.frame_jacobian(f, ref, q, p), want, atol=TOL)
            acc = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            want = np.r_[acc.linear, acc.angular]
            np.testing.assert_allclose(dyn.frame_jacobian_dot_qd(f, q, qd, p), want, atol=TOL)
        pin.centerOfMass(model, data, qb, qdb, np.zeros(r.nb))
        np.testing.assert_allclose(dyn.com(q, p), data.com[0], atol=TOL)
        np.testing.assert_allclose(dyn.com_jacobian_dot_qd(q, qd, p), data.acom[0], atol=TOL)
        np.testing.assert_allclose(
            dyn.com_jacobian(q, p), pin.jacobianCenterOfMass(model, data, qb) @ S, atol=TOL
        )


@pytest.mark.parametrize("name", sorted(URDFS))
def test_urdf_frames_agree_with_pinocchio(name):
    pin = pytest.importorskip("pinocchio")
    path, dyn = urdf_dynamics(name)
    _check_pinocchio(pin, pin.buildModelFromUrdf(path), dyn, URDFS[name][1])


HUNG = """
name: hung
base: {xyz: [0.1, -0.2, 2.5], rpy: [pi, 0, 0.3]}
gravity: [0, 0, -9.81]
links:
  - {name: l1, joint: revolute, a: 0.3, alpha: pi/2, d: 0.1, mass: 2, com: [-0.1, 0.01, 0.02],
     inertia: {ixx: 0.05, iyy: 0.04, izz: 0.03, ixy: 0.001}}
  - {name: l2, joint: revolute, a: 0.25, mass: 1.5, com: [-0.1, 0, 0.01],
     inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}}
  - {name: l3, joint: prismatic, alpha: -pi/2, theta: pi/2, mass: 0.5, com: [0, 0, -0.05],
     inertia: {ixx: 0.002, iyy: 0.002, izz: 0.001}}
frames:
  - {name: tool, link: l3, xyz: [0.01, 0.02, 0.15], rpy: [0.1, -0.4, 1.2]}
  - {name: camera, link: base, xyz: [0.5, 0, 0.3], rpy: [0, 0.5, 0]}
"""


@cache
def hung_dynamics():
    return symdyn.derive(
        symdyn.robot_from_data(__import__("yaml").safe_load(HUNG), "hung.yaml"), simplify=False
    )


def test_a_dh_robot_hung_from_the_ceiling_agrees_with_pinocchio():
    pin = pytest.importorskip("pinocchio")
    dyn = hung_dynamics()
    model = pinocchio_model(pin, dyn.robot)
    _check_pinocchio(pin, model, dyn, ("tool", "camera", "l2"))
    data = model.createData()
    for seed in range(3):
        q, qd, _ = _state(dyn.robot, seed)
        np.testing.assert_allclose(
            dyn.evaluate("G", q), pin.computeGeneralizedGravity(model, data, q), atol=TOL
        )
        qdd = np.random.default_rng(seed).normal(size=3)
        want = pin.rnea(model, data, q, qd, qdd)
        np.testing.assert_allclose(dyn.evaluate("tau", q, qd, qdd), want, atol=TOL)
        np.testing.assert_allclose(symdyn.rnea.rnea(dyn.robot, q, qd, qdd), want, atol=TOL)
    lagrange = symdyn.derive(dyn.robot, "lagrange", simplify=False)
    q = _state(dyn.robot, 5)[0]
    np.testing.assert_allclose(lagrange.evaluate("G", q), dyn.evaluate("G", q), atol=TOL)


def test_the_poe_end_effector_agrees_with_pinocchio_and_modern_robotics():
    pin = pytest.importorskip("pinocchio")
    mr = pytest.importorskip("modern_robotics")
    dyn = dynamics("mr_ur5")
    _check_pinocchio(pin, pinocchio_model(pin, dyn.robot), dyn, ("end_effector", "wrist_3_link"))
    raw = __import__("yaml").safe_load((EXAMPLES_DIR / "mr_ur5.yaml").read_text())
    M = np.eye(4)
    for lk in [*raw["links"], {"frame": raw["end_effector"]}]:
        T = np.eye(4)
        T[:3, :3] = np.array(lk["frame"].get("rotation", np.eye(3)), dtype=float)
        T[:3, 3] = lk["frame"].get("position", [0, 0, 0])
        M = M @ T
    S = np.array([lk["screw"] for lk in raw["links"]], dtype=float).T
    q = _state(dyn.robot, 7)[0]
    T = mr.FKinSpace(M, S, q)
    np.testing.assert_allclose(dyn.frame_pose("end_effector", q), T, atol=TOL)
    Jb = mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q)  # B_i = [Ad_M^-1] S_i
    np.testing.assert_allclose(
        dyn.frame_jacobian("end_effector", "local", q), np.r_[Jb[3:], Jb[:3]], atol=TOL
    )


# --------------------------------------------------------------------------- differences, identities


def _vee(W):
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


@pytest.mark.parametrize("name", ["puma560", "ytree", "hung"])
def test_jacobians_are_the_derivatives_of_the_pose_and_the_drift_that_of_the_jacobian(name):
    dyn = hung_dynamics() if name == "hung" else dynamics(name)
    r = dyn.robot
    q, qd, p = _state(r, 11)
    h = 1e-6
    for f in r.frame_names[-2:]:
        T = dyn.frame_pose(f, q, p)
        J = dyn.frame_jacobian(f, q=q, params=p)
        for j in range(r.n):
            e = np.eye(r.n)[j] * h
            Tp, Tm = dyn.frame_pose(f, q + e, p), dyn.frame_pose(f, q - e, p)
            v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            w = (
                _vee(np.real(logm(T[:3, :3].T @ Tp[:3, :3]))) - _vee(np.real(logm(T[:3, :3].T @ Tm[:3, :3])))
            ) / (2 * h)
            np.testing.assert_allclose(J[:, j], np.r_[v, T[:3, :3] @ w], atol=1e-6)
        dJ = (
            dyn.frame_jacobian(f, q=q + h * qd, params=p) - dyn.frame_jacobian(f, q=q - h * qd, params=p)
        ) / (2 * h)
        np.testing.assert_allclose(dyn.frame_jacobian_dot_qd(f, q, qd, p), dJ @ qd, atol=1e-6)
        R = np.kron(np.eye(2), T[:3, :3])
        np.testing.assert_allclose(dyn.frame_jacobian(f, "local", q, p), R.T @ J, atol=TOL)
    dJc = (dyn.com_jacobian(q + h * qd, p) - dyn.com_jacobian(q - h * qd, p)) / (2 * h)
    np.testing.assert_allclose(dyn.com_jacobian_dot_qd(q, qd, p), dJc @ qd, atol=1e-6)


@pytest.mark.parametrize(
    "name,frame,axes", [("puma560", "link6", None), ("ytree", "ytree5", "x,y,rz"), ("hung", "tool", "x,y,z")]
)
def test_operational_space_identities(name, frame, axes):
    dyn = hung_dynamics() if name == "hung" else dynamics(name)
    r = dyn.robot
    q, qd, p = _state(r, 2)
    rows = [("x", "y", "z", "rx", "ry", "rz").index(a) for a in axes.split(",")] if axes else list(range(6))
    J = dyn.frame_jacobian(frame, q=q, params=p)[rows]
    M = dyn.evaluate("M", q, params=p)
    L = dyn.operational_space_inertia(frame, q, axes, p)
    Jbar = dyn.dynamically_consistent_inverse(frame, q, axes, p)
    np.testing.assert_allclose(L, L.T, atol=TOL)
    assert np.linalg.eigvalsh(L).min() > 0
    np.testing.assert_allclose(L @ (J @ np.linalg.solve(M, J.T)), np.eye(len(rows)), atol=1e-8)
    np.testing.assert_allclose(J @ Jbar, np.eye(len(rows)), atol=1e-8)
    np.testing.assert_allclose(Jbar, np.linalg.solve(M, J.T) @ L, atol=1e-8)
    h = dyn.evaluate("bias", q, qd, params=p)
    drift = dyn.frame_jacobian_dot_qd(frame, q, qd, p)[rows]
    want = L @ (J @ np.linalg.solve(M, h) - drift)
    np.testing.assert_allclose(dyn.operational_space_bias(frame, q, qd, axes, p), want, atol=1e-8)


# --------------------------------------------------------------------------- the model and bad input


def test_frames_are_written_in_the_link_frame_and_the_base_places_the_robot():
    dyn = hung_dynamics()
    r = dyn.robot
    q = _state(r, 3)[0]
    link = frame_state(r, "l3", q).pose
    T = np.eye(4)
    T[:3, :3] = rpy(0.1, -0.4, 1.2)
    T[:3, 3] = [0.01, 0.02, 0.15]
    np.testing.assert_allclose(dyn.frame_pose("tool", q), link @ T, atol=TOL)
    base = dyn.frame_pose("camera", q)
    np.testing.assert_allclose(
        base[:3, 3], [0.1 + 0.5 * np.cos(0.3), -0.2 + 0.5 * np.sin(0.3), 2.5 - 0.3], atol=TOL
    )
    np.testing.assert_allclose(dyn.frame_jacobian("camera", q=q), np.zeros((6, 3)), atol=0)
    g = np.array(r.base_gravity, dtype=float).reshape(3)
    np.testing.assert_allclose(g, [0, 0, 9.81], atol=TOL)  # upside down: gravity along the base's +z


def test_an_unknown_frame_names_the_near_matches():
    dyn = hung_dynamics()
    with pytest.raises(SymdynError, match=r"unknown frame 'tol' \(did you mean 'tool'"):
        dyn.frame_pose("tol")
    with pytest.raises(SymdynError, match="unknown axis w"):
        dyn.operational_space_inertia("tool", [0, 0, 0], axes="x,w")
    with pytest.raises(SymdynError, match="reference must be"):
        dyn.frame_jacobian("tool", "body")


PARAMETRIC = """
name: par
base: {xyz: [0, 0, h], rpy: [0, tilt, 0]}
parameters: {h: 1.5, tilt: null}
links:
  - {name: l1, joint: revolute, a: 0.4, mass: 1, com: [-0.2, 0, 0]}
  - {name: l2, joint: prismatic, alpha: pi/2, mass: 1, com: [0, 0, -0.1]}
frames:
  - {name: tool, link: l2, xyz: [0, 0, lt], rpy: [0, 0, 0.5]}
"""


def test_frames_and_base_may_name_free_parameters():
    robot = symdyn.robot_from_data(__import__("yaml").safe_load(PARAMETRIC), "par.yaml")
    assert [str(p) for p in robot.params] == ["tilt", "lt"]
    dyn = symdyn.derive(robot, simplify=False)
    q, qd, p = [0.3, 0.2], [0.5, -1.0], [0.2, 0.1]
    s = frame_state(robot, "tool", q, qd, p)
    np.testing.assert_allclose(dyn.frame_pose("tool", q, p), s.pose, atol=TOL)
    np.testing.assert_allclose(dyn.frame_jacobian_dot_qd("tool", q, qd, p), s.drift, atol=TOL)
    np.testing.assert_allclose(
        dyn.evaluate("G", q, params=p), symdyn.rnea.gravity_torque(robot, q, p), atol=TOL
    )
