"""A single floating rigid body (no joint: NQ = 7, NV = 6), the simplest floating robot: a
quadrotor's frame, a satellite.

One derivation and one generation of every floating group (C, NumPy, CasADi) of a body with its
centre of mass off the base origin and a full inertia tensor. M is checked against the rigid
body's spatial inertia written by hand, [[m 1, -m [c]], [m [c], I_o]] with I_o = I_c - m [c]^2
(about the base origin, base frame); the generated forward dynamics against free fall (the centre
of mass accelerates at g whatever the body's motion) and Euler's equations (I_c dw + w x I_c w =
0: gravity has no moment about the centre of mass); the other groups against the oracle
(symdyn.rnea, the regressor on another body too) and finite differences.
"""

from __future__ import annotations

import ctypes
import importlib.util
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from cbuild import compile_shared, header_macros, write_files

import symdyn
from symdyn.codegen import render
from symdyn.model.parameters import numeric_parameters
from symdyn.oracle.centroidal import floating_frame_jacobian
from symdyn.rnea import mass_matrix

MASS = 2.0
COM = np.array([0.05, -0.02, 0.1])
I_COM = np.array([[0.1, 0.01, 0.0], [0.01, 0.12, 0.0], [0.0, 0.0, 0.2]])
IMU = ([0.1, 0.0, 0.05], 0.3)  # the frame imu on the base: xyz, and a yaw
BODY = f"""\
name: body
base: {{floating: true, mass: {MASS}, com: {COM.tolist()},
       inertia: {{ixx: 0.1, iyy: 0.12, izz: 0.2, ixy: 0.01}}}}
links: []
frames:
  - {{name: imu, link: base, xyz: {IMU[0]}, rpy: [0, 0, {IMU[1]}]}}
"""
G = np.array([0.0, 0.0, -9.81])
#: every floating group but `configuration` (integrate and difference: three seconds to generate
#: for two functions whose base part is the same for any floating robot, tests/test_lie_group.py)
GROUPS = ("dynamics", "regressor", "derivatives", "kinematics", "operational_space", "centroidal")


def cross(a) -> np.ndarray:
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def rotation(quat) -> np.ndarray:
    x, y, z, w = quat / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def states(count: int, seed: int):
    """(q, v) with random positions, unit quaternions and twists."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        quat = rng.normal(size=4)
        yield np.concatenate([rng.normal(size=3), quat / np.linalg.norm(quat)]), rng.normal(size=6)


def _module(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class _C:
    """The compiled C file's functions: f(name, inputs, output sizes) -> outputs (p is NULL)."""

    def __init__(self, library: Path, prefix: str, takes_p: set[str]):
        self.lib, self.prefix, self.takes_p = ctypes.CDLL(str(library)), prefix, takes_p
        self.ptr = ctypes.POINTER(ctypes.c_double)

    def __call__(self, name: str, inputs, *sizes: int):
        ins = [np.ascontiguousarray(x, dtype=float) for x in inputs]
        outs = [np.full(size, np.nan) for size in sizes]
        args = [a.ctypes.data_as(self.ptr) for a in ins] + ([None] if name in self.takes_p else [])
        getattr(self.lib, f"{self.prefix}_{name}")(*args, *(o.ctypes.data_as(self.ptr) for o in outs))
        return outs[0] if len(outs) == 1 else outs


@pytest.fixture(scope="module")
def body(tmp_path_factory):
    """(robot, Dynamics, NumPy module, CasADi functions, C functions, header macros): one
    derivation, one generation of every floating group."""
    tmp = tmp_path_factory.mktemp("body")
    path = tmp / "body.yaml"
    path.write_text(BODY)
    robot = symdyn.load_robot(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dyn = symdyn.derive(robot, simplify=False)
        files = render(robot, targets=("c", "python", "casadi"), functions=GROUPS)
    write_files(files, tmp)
    header = files["body_dynamics.h"]
    assert not re.search(r"double \w+\[0\]", header + files["body_dynamics.c"])  # no array of size 0
    takes_p = {
        line.split("(")[0].split("body_")[1] for line in header.splitlines() if "const double p[]" in line
    }
    c = _C(compile_shared([tmp / "body_dynamics.c"], tmp / "body.so"), "body", takes_p)
    numpy_module = _module(tmp / "body_numpy.py", "body_numpy")
    casadi_functions = _module(tmp / "body_casadi.py", "body_casadi").functions()
    return robot, dyn, numpy_module, casadi_functions, c, header_macros(header)


def test_sizes(body):
    robot, dyn, numpy_module, _, _, macros = body
    assert (robot.n, robot.nq, robot.nv, dyn.n) == (0, 7, 6, 6)
    assert (macros["body_NQ"], macros["body_NV"], macros["body_NDOF"]) == ("7", "6", "6")
    assert (numpy_module.NQ, numpy_module.NV) == (7, 6)
    assert dyn.singular_joints == ()


def test_mass_matrix_is_the_rigid_bodys_spatial_inertia(body):
    robot, dyn, numpy_module, casadi_functions, c, _ = body
    I_origin = I_COM - MASS * cross(COM) @ cross(COM)
    by_hand = np.block([[MASS * np.eye(3), -MASS * cross(COM)], [MASS * cross(COM), I_origin]])
    for q, _ in states(2, 1):
        np.testing.assert_allclose(dyn.evaluate("M", q), by_hand, atol=1e-14)
        np.testing.assert_allclose(mass_matrix(robot, q), by_hand, atol=1e-14)
        np.testing.assert_allclose(c("mass_matrix", [q], 36).reshape(6, 6), by_hand, atol=1e-14)
        np.testing.assert_allclose(np.reshape(numpy_module.mass_matrix(q), (6, 6)), by_hand, atol=1e-14)
        got = np.array(casadi_functions["mass_matrix"](q, np.zeros(0))).reshape(6, 6)
        np.testing.assert_allclose(got, by_hand, atol=1e-14)


def test_free_fall_and_eulers_equations(body):
    """With no wrench on it, the body's centre of mass falls at g, R (dv + w x v + dw x c +
    w x (w x c)) = g, and it turns as Euler's equations say, I_c dw + w x I_c w = 0 (base frame:
    the twist is the base's, about its origin)."""
    _, _, numpy_module, casadi_functions, c, _ = body
    for q, v in states(4, 2):
        a = c("forward_dynamics", [q, v, np.zeros(6)], 6)
        np.testing.assert_allclose(numpy_module.forward_dynamics(q, v, np.zeros(6)), a, atol=1e-12)
        got = np.array(casadi_functions["forward_dynamics"](q, v, np.zeros(6), np.zeros(0))).ravel()
        np.testing.assert_allclose(got, a, atol=1e-12)
        lin, w, dlin, dw = v[:3], v[3:], a[:3], a[3:]
        com_acceleration = dlin + np.cross(w, lin) + np.cross(dw, COM) + np.cross(w, np.cross(w, COM))
        np.testing.assert_allclose(rotation(q[3:]) @ com_acceleration, G, atol=1e-12)
        np.testing.assert_allclose(I_COM @ dw + np.cross(w, I_COM @ w), 0, atol=1e-12)


def test_the_other_groups_agree_with_the_oracle(body, tmp_path):
    robot, _, numpy_module, _, c, _ = body
    pi = numeric_parameters(robot)
    # another body (Y does not depend on the inertial parameters: tau = Y pi for it too)
    path = tmp_path / "other.yaml"
    path.write_text(BODY.replace("mass: 2.0", "mass: 0.7").replace("ixy: 0.01", "ixy: -0.02, iyz: 0.005"))
    other = symdyn.load_robot(path)
    h = 1e-6
    for q, v in states(2, 3):
        a = np.random.default_rng(4).normal(size=6)
        tau = symdyn.rnea(robot, q, v, a)
        np.testing.assert_allclose(c("inverse_dynamics", [q, v, a], 6), tau, atol=1e-12)
        Y = c("regressor", [q, v, a], 6 * len(pi)).reshape(6, -1)
        np.testing.assert_allclose(Y @ pi, tau, atol=1e-12)
        np.testing.assert_allclose(Y @ numeric_parameters(other), symdyn.rnea(other, q, v, a), atol=1e-12)
        _, dtau_dv = c("inverse_dynamics_derivatives", [q, v, a], 36, 36)
        E = np.eye(6) * h
        by_differences = np.stack(
            [symdyn.rnea(robot, q, v + e, a) - symdyn.rnea(robot, q, v - e, a) for e in E], 1
        ) / (2 * h)
        np.testing.assert_allclose(dtau_dv.reshape(6, 6), by_differences, atol=1e-7)
        R = rotation(q[3:])
        np.testing.assert_allclose(c("com", [q], 3), q[:3] + R @ COM, atol=1e-14)
        np.testing.assert_allclose(c("total_mass", [], 1), [MASS])
        momentum = c("centroidal_momentum_matrix", [q], 36).reshape(6, 6) @ v
        np.testing.assert_allclose(momentum[:3], MASS * R @ (v[:3] + np.cross(v[3:], COM)), atol=1e-12)
        np.testing.assert_allclose(momentum[3:], R @ I_COM @ v[3:], atol=1e-12)
        T = c("imu_pose", [q], 16).reshape(4, 4)
        yaw = IMU[1]
        Rz = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
        np.testing.assert_allclose(T[:3, :3], R @ Rz, atol=1e-14)
        np.testing.assert_allclose(T[:3, 3], q[:3] + R @ IMU[0], atol=1e-14)


QUADROTOR = """<robot name="quad">
  <link name="frame"><inertial><origin xyz="0 0 0.01"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial></link>
  <joint name="rotor_mount" type="fixed"><parent link="frame"/><child link="rotor"/>
    <origin xyz="0.2 0 0.05"/></joint>
  <link name="rotor"><inertial><mass value="0.05"/>
    <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="2e-5"/></inertial></link>
</robot>
"""


def test_a_single_body_loads_when_floating_only(tmp_path):
    """A URDF or a robot file with no movable joint is a floating rigid body; on a fixed base
    there is nothing to derive, refused as before."""
    urdf = tmp_path / "quad.urdf"
    urdf.write_text(QUADROTOR)
    robot = symdyn.load_urdf(urdf, floating=True)
    assert (robot.n, robot.nq, robot.nv) == (0, 7, 6)
    assert np.isclose(float(robot.base_body.mass), 1.55)
    assert np.isclose(mass_matrix(robot, [0, 0, 0, 0, 0, 0, 1])[0, 0], 1.55)
    with pytest.raises(symdyn.SymdynError, match="no movable joint below the base link 'frame'"):
        symdyn.load_urdf(urdf)
    fixed = tmp_path / "fixed.yaml"
    fixed.write_text("name: nothing\nlinks: []\n")
    with pytest.raises(symdyn.SymdynError, match="a robot needs at least one link \\(or a floating base\\)"):
        symdyn.load_robot(fixed)


#: a two-joint product-of-exponentials arm on a floating base with mass
POE_ARM = """\
name: poe_arm
convention: poe
base: {floating: true, mass: 3, com: [0, 0.01, 0.05], inertia: {ixx: 0.05, iyy: 0.06, izz: 0.08}}
links:
  - name: l1
    frame: {position: [0, 0, 0.1], rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}
    spatial_inertia: [0.01, 0.012, 0.005, 1, 1, 1]
    screw: [0, 0, 1, 0, 0, 0]
  - name: l2
    frame: {position: [0.45, 0, 0.1], rotation: [[1, 0, 0], [0, 0, -1], [0, 1, 0]]}
    spatial_inertia: [0.004, 0.02, 0.02, 0.8, 0.8, 0.8]
    screw: [0, 1, 0, -0.2, 0, 0.3]
end_effector:
  position: [0.2, 0, 0.05]
  rotation: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
"""


def test_tip_wrench_on_a_floating_base(tmp_path):
    """tau_tip = J_b^T F with the base's six columns in J_b: J_b from the oracle's world-aligned
    frame Jacobian (floating_frame_jacobian) turned into the end-effector frame, angular rows
    first; virtual work tau_tip . v = F . V_tip; the generated NumPy function gives the same."""
    path = tmp_path / "poe_arm.yaml"
    path.write_text(POE_ARM)
    robot = symdyn.load_robot(path)
    dyn = symdyn.derive(robot, simplify=False)
    files = render(robot, targets=("python",), functions=["tip_wrench"])
    write_files(files, tmp_path)
    numpy_module = _module(tmp_path / "poe_arm_numpy.py", "poe_arm_numpy")
    rng = np.random.default_rng(6)
    for q, v in states(3, 7):
        q = np.concatenate([q, rng.uniform(-np.pi, np.pi, robot.n)])
        v = np.concatenate([v, rng.normal(size=robot.n)])
        F = rng.normal(size=6)
        T, J = floating_frame_jacobian(robot, q, "end_effector")
        R = T[:3, :3]
        J_b = np.vstack([R.T @ J[3:], R.T @ J[:3]])
        tau_tip = dyn.tip_wrench_torque(F, q)
        assert tau_tip.shape == (robot.nv,)
        np.testing.assert_allclose(tau_tip, J_b.T @ F, atol=1e-12)
        assert np.isclose(tau_tip @ v, F @ (J_b @ v), atol=1e-12)
        np.testing.assert_allclose(numpy_module.tip_wrench_torque(q, F), tau_tip, atol=1e-12)


def test_compile_builds_the_groups_asked_for(body):
    """symdyn.compile(..., functions=): the groups named (a floating robot's centroidal functions
    reachable from Python), each set of groups its own cache entry; an unknown group is one line."""
    robot = body[0]
    centroidal = symdyn.compile(robot, functions=("centroidal",))
    assert centroidal.functions == (
        "centroidal_momentum_matrix",
        "centroidal_momentum_drift",
        "com",
        "total_mass",
    )
    dynamics = symdyn.compile(robot, functions="dynamics")
    assert "forward_dynamics" in dynamics.functions and "com" not in dynamics.functions
    for q, v in states(2, 9):
        np.testing.assert_allclose(centroidal.com(q), q[:3] + rotation(q[3:]) @ COM, atol=1e-14)
        np.testing.assert_allclose(centroidal.total_mass(), [MASS])
        np.testing.assert_allclose(
            dynamics.inverse_dynamics(q, v, v), symdyn.rnea(robot, q, v, v), atol=1e-12
        )
    with pytest.raises(
        symdyn.SymdynError, match=r"^symdyn.compile: unknown function group\(s\) 'centroid' \("
    ):
        symdyn.compile(robot, functions=["dynamics", "centroid"])


SATELLITE = """<mujoco model="sat">
  <worldbody>
    <body name="bus" pos="0 0 1">
      <freejoint/>
      <geom type="box" size="0.2 0.3 0.4" mass="5"/>
      <body name="panel" pos="0.5 0 0.1" euler="0 0 30">
        <geom type="box" size="0.3 0.01 0.2" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_an_mjcf_free_body_alone(tmp_path):
    """A free body with a body welded to it and no hinge: a floating rigid body whose M equals
    MuJoCo's at the identity orientation (where MuJoCo's world-frame linear velocity is the
    base frame's)."""
    mujoco = pytest.importorskip("mujoco", reason="the test extra installs mujoco")
    path = tmp_path / "sat.xml"
    path.write_text(SATELLITE)
    robot = symdyn.load_robot(path)
    assert (robot.floating, robot.n) == (True, 0)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    theirs = np.zeros((6, 6))
    mujoco.mj_fullM(model, data, theirs)
    np.testing.assert_allclose(mass_matrix(robot, [0, 0, 1, 0, 0, 0, 1]), theirs, atol=1e-12)
