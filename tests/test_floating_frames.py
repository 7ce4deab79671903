"""Frames of a floating robot (symdyn.algorithms.floating_frames through the generated
`kinematics` group): the feet of Solo-12 on a free flyer, their poses, Jacobians (6 x NV,
world-aligned and local) and drifts, and the centre of mass with its Jacobian and drift, against
Pinocchio (oMf, getFrameJacobian in LOCAL_WORLD_ALIGNED and LOCAL, getFrameClassicalAcceleration
at a = 0, centerOfMass, jacobianCenterOfMass) at random configurations and unit quaternions, in
NumPy and C."""

from __future__ import annotations

import ctypes
import importlib.util
from functools import cache

import numpy as np
import pytest
from cbuild import compile_shared, compilers, write_files
from test_centroidal import RTOL_URDF, _close, floating_urdf

from symdyn.codegen import c as c_target
from symdyn.codegen import context
from symdyn.codegen import python as numpy_target
from symdyn.codegen.frame_functions import identifier

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
