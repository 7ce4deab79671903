"""Frames of a floating robot (symdyn.algorithms.floating_frames through the generated
`kinematics` group): the feet of Solo-12 on a free flyer, their poses, Jacobians (6 x NV,
world-aligned and local) and drifts, and the centre of mass with its Jacobian and drift, against
Pinocchio (oMf, getFrameJacobian in LOCAL_WORLD_ALIGNED and LOCAL, getFrameClassicalAcceleration
at a = 0, centerOfMass, jacobianCenterOfMass) at random configurations and unit quaternions, in
NumPy and C.

The operational-space group of a floating robot (the small floating chain of `small_floating`):
Lambda^-1 equals J M^-1 J^T with Pinocchio's computeFrameJacobian and computeMinverse and with the
oracle's M (the generated Jacobians equal Pinocchio's above), and Lambda a + mu equals the task
force F whose J^T F drives Pinocchio's aba to the frame's classical acceleration a; Dynamics'
frame and operational-space methods give the same numbers."""

from __future__ import annotations

import ctypes
import importlib.util
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from cbuild import compile_shared, compilers, write_files
from test_centroidal import RTOL_URDF, _close, floating_urdf

import symdyn
from symdyn.codegen import c as c_target
from symdyn.codegen import context
from symdyn.codegen import python as numpy_target
from symdyn.codegen.frame_functions import identifier
from symdyn.rnea import mass_matrix

pin = pytest.importorskip("pinocchio")
SOLO = "solo_description/robots/solo12.urdf"
FEET = ("FL_FOOT", "HR_FOOT", "base_link")


@cache
def ctx():
    return context(floating_urdf(SOLO)[0], functions=("kinematics",), frames=list(FEET))


def expected(q, v) -> dict[str, np.ndarray]:
    model = floating_urdf(SOLO)[1]
    data = model.createData()
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    pin.computeJointJacobians(model, data, q)
    out = {}
    for f in FEET:
        fid, ident = model.getFrameId(f), identifier(f)
        acc = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        out |= {
            f"{ident}_pose": data.oMf[fid].homogeneous.copy(),
            f"{ident}_jacobian": pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED),
            f"{ident}_jacobian_local": pin.getFrameJacobian(model, data, fid, pin.LOCAL),
            f"{ident}_jacobian_dot_qd": np.r_[acc.linear, acc.angular],
        }
    pin.centerOfMass(model, data, q, v, np.zeros(model.nv))
    return out | {
        "com": data.com[0].copy(),
        "com_jacobian": pin.jacobianCenterOfMass(model, data, q),
        "com_jacobian_dot_qd": data.acom[0].copy(),
    }


def states():
    model = floating_urdf(SOLO)[1]
    pin.seed(11)
    rng = np.random.default_rng(11)
    return [
        (pin.randomConfiguration(model, -np.ones(19), np.ones(19)), rng.normal(size=18)) for _ in range(2)
    ]


def _check(call, where: str) -> None:
    for q, v in states():
        want = expected(q, v)
        assert sorted(want) == sorted(f.name for f in ctx().functions)
        for f in ctx().functions:
            values = {"q": q, "v": v}
            _close(
                call(f, [values[i.name] for i in f.inputs if i.name != "p"]),
                want[f.name],
                f"{where} {f.name}",
                RTOL_URDF,
            )


def test_numpy_agrees_with_pinocchio(tmp_path):
    ((file, text),) = numpy_target.render(ctx()).items()
    (tmp_path / file).write_text(text)
    spec = importlib.util.spec_from_file_location("floating_frames_numpy", tmp_path / file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    _check(lambda f, args: getattr(module, f.name)(*args), "numpy")


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_c_agrees_with_pinocchio(tmp_path):
    c = ctx()
    paths = write_files(c_target.render(c), tmp_path)
    lib = ctypes.CDLL(str(compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so")))
    ptr = ctypes.POINTER(ctypes.c_double)

    def call(f, args):
        args = [np.ascontiguousarray(a, dtype=np.float64) for a in args] + [np.zeros(0)]
        out = np.full(f.results[0].size, np.nan)
        fn = getattr(lib, f"{c.name}_{f.name}")
        fn.restype = None
        fn(*[a.ctypes.data_as(ptr) for a in args], out.ctypes.data_as(ptr))
        return out

    _check(call, "C")


# --------------------------------------------------------------------------- operational space

RPY_CHAIN = Path(__file__).parent / "data" / "urdf" / "rpy_chain.urdf"


def small_floating(folder: Path):
    """(robot, Pinocchio model) of tests/data/urdf/rpy_chain.urdf on a free flyer, written to
    `folder`, with two changes: its continuous joint made revolute (Pinocchio gives a continuous
    joint two coordinates), and a base body with mass (a massless base could turn about the first
    joint's axis while the links stand still: M would be singular)."""
    limit = '<limit effort="10" lower="-3" upper="3" velocity="1"/>'
    body = (
        '<link name="base"><inertial><origin xyz="0.02 -0.01 0.05" rpy="0.1 0.2 0.3"/><mass value="2"/>'
        '<inertia ixx="0.05" ixy="0.002" ixz="0" iyy="0.04" iyz="0.001" izz="0.06"/></inertial></link>'
    )
    text = RPY_CHAIN.read_text().replace('type="continuous">', f'type="revolute">\n    {limit}')
    text = text.replace('<link name="base"/>', body)
    path = folder / "rpy_chain_revolute.urdf"
    path.write_text(text)
    return symdyn.load_urdf(path, floating=True), pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """(robot, Pinocchio model, render context, NumPy module) of the small floating chain's
    operational-space group for its last link `c`, derived and rendered once."""
    folder = tmp_path_factory.mktemp("chain")
    robot, model = small_floating(folder)
    c = context(robot, functions=("operational_space",), frames=["c"])
    ((file, text),) = numpy_target.render(c).items()
    (folder / file).write_text(text)
    spec = importlib.util.spec_from_file_location("small_floating_numpy", folder / file)
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    return robot, model, c, gen


def test_operational_space_agrees_with_pinocchio_and_the_oracle(chain):
    robot, model, c, gen = chain
    data = model.createData()
    fid = model.getFrameId("c")
    pin.seed(9)
    rng = np.random.default_rng(9)
    for _ in range(2):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, F = rng.normal(size=model.nv), rng.normal(size=6)
        Lam, mu = gen.c_operational_space_inertia(q), gen.c_operational_space_bias(q, v)
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        Minv = pin.computeMinverse(model, data, q)
        Minv = np.triu(Minv) + np.triu(Minv, 1).T  # Pinocchio fills the upper triangle
        _close(np.linalg.inv(Lam), J @ Minv @ J.T, "Lambda^-1 = J M^-1 J^T (Pinocchio)", RTOL_URDF)
        oracle = J @ np.linalg.solve(mass_matrix(robot, q), J.T)
        _close(np.linalg.inv(Lam), oracle, "Lambda^-1 = J M^-1 J^T (oracle)", RTOL_URDF)
        # tau = J^T F drives the frame to a with Lambda a + mu = F (Pinocchio's aba, no other force)
        vdot = pin.aba(model, data, q, v, J.T @ F)
        pin.forwardKinematics(model, data, q, v, vdot)
        pin.updateFramePlacements(model, data)
        acc = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        _close(Lam @ np.r_[acc.linear, acc.angular] + mu, F, "Lambda a + mu = F (Pinocchio's aba)", RTOL_URDF)
        # Dynamics' methods, on the same derivation: the Jacobian, Lambda (of three rows too), Jbar
        dyn = c.dynamics
        _close(dyn.frame_jacobian("c", q=q), J, "Dynamics.frame_jacobian", RTOL_URDF)
        _close(dyn.operational_space_inertia("c", q), Lam, "Dynamics Lambda", RTOL_URDF)
        _close(dyn.operational_space_bias("c", q, v), mu, "Dynamics mu", RTOL_URDF)
        L3 = dyn.operational_space_inertia("c", q, axes="x,y,z")
        _close(np.linalg.inv(L3), J[:3] @ Minv @ J[:3].T, "Lambda^-1 of x, y, z", RTOL_URDF)
        _close(J @ dyn.dynamically_consistent_inverse("c", q), np.eye(6), "J Jbar = 1", RTOL_URDF)


def test_operational_space_of_a_floating_robot_refuses_bad_vectors(chain):
    dyn = chain[2].dynamics
    q = np.r_[np.zeros(6), 1.0, np.zeros(3)]
    for bad, message in (
        (q[:7], r"Dynamics.operational_space_inertia: q has shape \(7,\), expected \(10,\)"),
        ("q", "Dynamics.operational_space_inertia: q must hold numbers"),
    ):
        with pytest.raises(symdyn.SymdynError, match=message):
            dyn.operational_space_inertia("c", bad)
    with pytest.raises(symdyn.SymdynError, match=r"Dynamics.operational_space_bias: qd has shape \(3,\)"):
        dyn.operational_space_bias("c", q, np.zeros(3))
