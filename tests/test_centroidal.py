"""Centroidal quantities (symdyn.algorithms.centroidal, the generated `centroidal` group and the
numeric oracle symdyn.oracle.centroidal): the total mass, the centre of mass, the centroidal
momentum matrix A_g and its drift Adot_g v, against Pinocchio (computeCentroidalMap,
computeCentroidalMapTimeVariation, centerOfMass, jacobianCenterOfMass, computeTotalMass) with a
JointModelFreeFlyer root on the legged, humanoid and flying robots of example-robot-data (the
oracle on every one, the generated code on Solo-12), and the generated code against the oracle
on a floating tree with prismatic and mimic joints and on a fixed base."""

from __future__ import annotations

import ctypes
import dataclasses
import importlib.util
import warnings
from functools import cache

import numpy as np
import pytest
import sympy as sp
from cbuild import compile_shared, compilers, write_files
from octave_run import OCTAVE, octave_numbers, octave_values
from robots import example, tree_robot

import symdyn
from symdyn.codegen import c as c_target
from symdyn.codegen import casadi as casadi_target
from symdyn.codegen import context
from symdyn.codegen import matlab as matlab_target
from symdyn.codegen import python as numpy_target
from symdyn.errors import SymdynError
from symdyn.model.free_flyer import BaseBody
from symdyn.model.topology import Mimic
from symdyn.oracle.centroidal import centroidal
from symdyn.regenerate import example_robot_data_folder

pin = pytest.importorskip("pinocchio")
RTOL = 1e-11
#: against Pinocchio on the published URDFs: symdyn snaps printed right angles (within 1e-9 rad,
#: symdyn.parsers.urdf), which moves the geometry by about 1e-9 where Pinocchio takes them as given
RTOL_URDF = 1e-9

#: every legged, humanoid and flying robot of example-robot-data whose URDF symdyn and Pinocchio
#: both load with the same joints (Talos' full model has mimic joints Pinocchio counts as its own)
FLOATING_URDFS = (
    "a1_description/urdf/a1.urdf",
    "alex_description/urdf/alex_nub_hands.urdf",
    "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
    "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "anymal_c_simple_description/urdf/anymal.urdf",
    "b1_description/urdf/b1.urdf",
    "b1_description/urdf/b1-z1.urdf",
    "bolt_description/robots/bolt.urdf",
    "borinot_description/urdf/borinot_flying_arm_2.urdf",
    "centauro_description/urdf/centauro.urdf",
    "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "go1_description/urdf/go1.urdf",
    "go2_description/urdf/go2.urdf",
    "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
    "human_description/robots/human.urdf",
    "hyq_description/robots/hyq_no_sensors.urdf",
    "icub_description/robots/icub.urdf",
    "iris_description/robots/iris.urdf",
    "laikago_description/urdf/laikago.urdf",
    "quadruped_description/urdf/quadruped.urdf",
    "romeo_description/urdf/romeo_small.urdf",
    "simple_humanoid_description/urdf/simple_humanoid.urdf",
    "solo_description/robots/solo.urdf",
    "solo_description/robots/solo12.urdf",
    "talos_data/robots/talos_reduced.urdf",
)


def _folder():
    folder = example_robot_data_folder()
    if folder is None:
        pytest.skip("example-robot-data is not installed")
    return folder


@cache
def floating_urdf(path: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the published files' printed right angles
        robot = symdyn.load_urdf(_folder() / path, floating=True)
    model = pin.buildModelFromUrdf(str(_folder() / path), pin.JointModelFreeFlyer())
    return robot, model


def pinocchio_centroidal(model, q, v) -> dict[str, np.ndarray]:
    data = model.createData()
    pin.computeCentroidalMapTimeVariation(model, data, q, v)
    return {
        "Ag": pin.computeCentroidalMap(model, data, q),
        "drift": data.dAg @ v,
        "com": np.array(pin.centerOfMass(model, data, q)),
        "com_jacobian": pin.jacobianCenterOfMass(model, data, q),
        "mass": np.array([pin.computeTotalMass(model)]),
    }


def _close(got, want, what: str, rtol: float = RTOL) -> float:
    """The error relative to the largest entry (at least 1); asserted below rtol."""
    err = float(np.abs(np.reshape(got, np.shape(want)) - want).max() / max(1.0, np.abs(want).max()))
    assert err < rtol, f"{what}: {err:.2e}"
    return err


def test_the_oracle_agrees_with_pinocchio_on_every_floating_urdf():
    pin.seed(23)
    rng = np.random.default_rng(23)
    worst = {}
    for path in FLOATING_URDFS:
        robot, model = floating_urdf(path)
        assert (robot.nq, robot.nv) == (model.nq, model.nv), path
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v = rng.normal(size=model.nv)
        st, want = centroidal(robot, q, v), pinocchio_centroidal(model, q, v)
        got = {
            "Ag": st.Ag,
            "drift": st.drift,
            "com": st.com,
            "com_jacobian": st.com_jacobian,
            "mass": [st.mass],
        }
        worst[path] = max(_close(got[k], want[k], f"{path} {k}", RTOL_URDF) for k in want)
    print("worst relative error per URDF:", {k.split("/", 1)[0]: f"{e:.1e}" for k, e in worst.items()})


def test_the_oracle_refuses_vectors_of_the_wrong_size():
    robot, _ = floating_urdf("solo_description/robots/solo12.urdf")
    with pytest.raises(SymdynError, match=r"q must be 19 finite numbers"):
        centroidal(robot, np.zeros(18))
    with pytest.raises(SymdynError, match=r"v must be 18 finite numbers"):
        centroidal(robot, np.r_[np.zeros(6), 1.0, np.zeros(12)], np.zeros(19))
    with pytest.raises(SymdynError, match=r"quaternion q\[3:7\] is zero"):
        centroidal(robot, np.zeros(19))


# --------------------------------------------------------------------------- generated code


def floating_tree():
    """A floating tree with a prismatic joint and a mimic joint, and a base body off its origin."""
    robot = tree_robot(
        "ftree",
        (-1, 0, 1, 0, 3),
        ("revolute", "revolute", "prismatic", "revolute", "revolute"),
        seed=5,
        mimic={4: Mimic(1, sp.Float(-1.5), sp.Float(0.2))},
    )
    body = BaseBody(
        "torso",
        sp.Float(3.5),
        sp.ImmutableMatrix([0.1, -0.05, 0.2]),
        sp.ImmutableMatrix(np.diag([0.2, 0.3, 0.25])),
    )
    return dataclasses.replace(
        robot, floating=True, base_body=body, gravity=sp.ImmutableMatrix([0, 0, -9.81])
    )


@cache
def robot(name: str):
    if name == "solo12":
        return floating_urdf("solo_description/robots/solo12.urdf")[0]
    return floating_tree() if name == "ftree" else example(name)


@cache
def ctx(name: str):
    return context(robot(name), functions=("centroidal",))


def states(name: str) -> list[tuple[np.ndarray, np.ndarray]]:
    r = robot(name)
    rng = np.random.default_rng(7)
    out = []
    for _ in range(2):
        q, v = rng.uniform(-1.5, 1.5, r.nq), rng.normal(size=r.nv)
        if r.floating:
            quat = rng.normal(size=4)
            q[3:7] = quat / np.linalg.norm(quat)
        out.append((q, v))
    return out


def expected(name: str, q, v) -> dict[str, np.ndarray]:
    """Pinocchio on Solo-12, the oracle on the others."""
    if name == "solo12":
        want = pinocchio_centroidal(floating_urdf("solo_description/robots/solo12.urdf")[1], q, v)
    else:
        st = centroidal(robot(name), q, v)
        want = {"Ag": st.Ag, "drift": st.drift, "com": st.com, "mass": np.array([st.mass])}
    return {
        "centroidal_momentum_matrix": want["Ag"],
        "centroidal_momentum_drift": want["drift"],
        "com": want["com"],
        "total_mass": want["mass"],
    }


def _check_all(name: str, call, where: str) -> None:
    for q, v in states(name):
        want = expected(name, q, v)
        for f in ctx(name).functions:
            values = {"q": q, "v": v, "p": np.zeros(0)}
            got = call(f, [values[i.name] for i in f.inputs])
            _close(got, want[f.name], f"{where} {name} {f.name}", RTOL_URDF if name == "solo12" else RTOL)


CASES = ("solo12", "ftree", "puma560")


@pytest.mark.parametrize("name", CASES)
def test_numpy_and_casadi_agree(name, tmp_path):
    """NumPy on the three, CasADi on the floating tree and the PUMA."""
    ((file, text),) = numpy_target.render(ctx(name)).items()
    (tmp_path / file).write_text(text)
    spec = importlib.util.spec_from_file_location(f"centroidal_{name}", tmp_path / file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    _check_all(name, lambda f, args: getattr(module, f.name)(*[a for a in args if len(a)]), "numpy")
    if name == "solo12":
        return  # CasADi on the two others (Solo-12's C: test_c_agrees_on_solo12)
    ca = pytest.importorskip("casadi")
    namespace: dict = {}
    exec(
        compile(casadi_target.render(ctx(name))[f"{ctx(name).name}_casadi.py"], "casadi_module", "exec"),
        namespace,
    )
    built = namespace["functions"]()
    _check_all(name, lambda f, args: np.asarray(ca.DM(built[f.name](*args)).full()), "casadi")


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_c_agrees_on_solo12(tmp_path):
    c = ctx("solo12")
    paths = write_files(c_target.render(c), tmp_path)
    lib = ctypes.CDLL(str(compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so")))
    ptr = ctypes.POINTER(ctypes.c_double)

    def call(f, args):
        args = [np.ascontiguousarray(a, dtype=np.float64) for a in args]
        out = np.full(f.results[0].size, np.nan)
        fn = getattr(lib, f"{c.name}_{f.name}")
        fn.restype = None
        fn(*[a.ctypes.data_as(ptr) for a in args], out.ctypes.data_as(ptr))
        return out

    _check_all("solo12", call, "C")


@pytest.mark.skipif(OCTAVE is None, reason="GNU Octave (octave-cli) is not installed")
def test_octave_agrees_on_the_floating_tree(tmp_path):
    c = ctx("ftree")
    write_files(matlab_target.render(c), tmp_path)
    calls, want = {}, {}
    for s, (q, v) in enumerate(states("ftree")):
        values = {"q": q, "v": v, "p": np.zeros(0)}
        for f in c.functions:
            args = ", ".join(octave_numbers(values[i.name]) for i in f.inputs)
            calls[(f.name, s)] = f"{c.name}_{f.name}({args})"
            want[(f.name, s)] = expected("ftree", q, v)[f.name]
    got = octave_values(tmp_path, calls)
    for key, value in want.items():
        _close(got[key], value, f"octave {key}")


def test_com_is_built_once_with_the_kinematics():
    """With kinematics and centroidal, com is built once (generated/, which tests/test_generated.py
    keeps unchanged, shows that centroidal is built only when named)."""
    both = context(example("roger_arm"), functions=("kinematics", "centroidal"), frames=["forearm"])
    names = [f.name for f in both.functions]
    assert names.count("com") == 1 and "total_mass" in names
