"""Configuration arithmetic of a floating robot (symdyn.algorithms.lie_group and the generated
integrate and difference of symdyn.codegen.configuration_functions) against Pinocchio's
integrate and difference with a JointModelFreeFlyer root, in NumPy, CasADi, C and Octave: random
states, large rotations (more than pi: the quaternion stays on q's side), angles near pi, tiny
steps, and exactly v = 0 and q0 = q_next (no division by zero)."""

from __future__ import annotations

import ctypes
import dataclasses
import importlib.util
from functools import cache

import numpy as np
import pytest
from cbuild import compile_shared, compilers, write_files
from octave_run import OCTAVE, octave_numbers, octave_values
from robots import example

from symdyn.codegen import c as c_target
from symdyn.codegen import casadi as casadi_target
from symdyn.codegen import context
from symdyn.codegen import matlab as matlab_target
from symdyn.codegen import python as numpy_target

pin = pytest.importorskip("pinocchio")
TOL = 1e-12


@cache
def ctx():
    robot = dataclasses.replace(example("roger_arm"), floating=True)
    return context(robot, functions=("configuration",))


def pin_model():
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
    model.addJoint(1, pin.JointModelRZ(), pin.SE3.Identity(), "j1")
    model.addJoint(2, pin.JointModelRY(), pin.SE3.Identity(), "j2")
    return model


@cache
def cases() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(q, v, q_next) triples: q_next a random configuration, pinocchio.integrate's, or q itself."""
    model = pin_model()
    pin.seed(23)
    rng = np.random.default_rng(23)
    out = []
    for k in range(12):
        q = pin.randomConfiguration(model, -np.ones(9), np.ones(9))
        scale = (0.0, 1e-12, 1e-5, 0.05, 1.0, 3.0, 7.0)[k % 7]
        v = rng.normal(size=8) * scale
        if k % 4 == 1:  # a rotation by an angle near pi about a random axis
            axis = rng.normal(size=3)
            v[3:6] = axis / np.linalg.norm(axis) * (np.pi - 10.0 ** -rng.uniform(2, 8))
        q_next = q.copy() if k % 5 == 0 else pin.randomConfiguration(model, -np.ones(9), np.ones(9))
        if k % 3 == 2:
            q_next = pin.integrate(model, q, rng.normal(size=8) * 1e-6)
        out.append((q, v, q_next))
    return out


def _check(integrate, difference, where: str) -> None:
    model = pin_model()
    for q, v, q_next in cases():
        got = np.ravel(integrate(q, v, np.array([1.0])))
        np.testing.assert_allclose(got, pin.integrate(model, q, v), atol=TOL, err_msg=f"{where} integrate")
        got = np.ravel(difference(q, q_next))
        want = pin.difference(model, q, q_next)
        np.testing.assert_allclose(got, want, atol=TOL * 10, err_msg=f"{where} difference")
    q = cases()[0][0]
    # no 0/0: zero up to the rounding of the relative quaternion's products (exactly 0 in C)
    assert np.abs(np.ravel(difference(q, q))).max() < 1e-15, (where, difference(q, q))
    assert np.all(np.isfinite(np.ravel(integrate(q, np.zeros(8), np.array([0.0]))))), where


def test_dt_scales_the_velocity():
    """q (+) v dt with dt = 0.25 equals q (+) (v / 4) with dt = 1 (Pinocchio's definition)."""
    module = _numpy_module()
    model = pin_model()
    for q, v, _ in cases():
        got = module.integrate(q, v, np.array([0.25]))
        np.testing.assert_allclose(got, pin.integrate(model, q, v * 0.25), atol=TOL)


@cache
def _numpy_module():
    import tempfile
    from pathlib import Path

    ((file, text),) = numpy_target.render(ctx()).items()
    folder = Path(tempfile.mkdtemp())
    (folder / file).write_text(text)
    spec = importlib.util.spec_from_file_location("lie_group_numpy", folder / file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_numpy_and_casadi_agree_with_pinocchio():
    module = _numpy_module()
    _check(module.integrate, module.difference, "numpy")
    ca = pytest.importorskip("casadi")
    namespace: dict = {}
    text = casadi_target.render(ctx())[f"{ctx().name}_casadi.py"]
    exec(compile(text, "casadi_module", "exec"), namespace)
    built = namespace["functions"]()

    def call(name):
        return lambda *a: np.asarray(ca.DM(built[name](*a)).full())

    _check(call("integrate"), call("difference"), "casadi")


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_c_agrees_with_pinocchio(tmp_path):
    paths = write_files(c_target.render(ctx()), tmp_path)
    lib = ctypes.CDLL(str(compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so")))
    ptr = ctypes.POINTER(ctypes.c_double)

    def call(name: str, size: int):
        f = getattr(lib, f"{ctx().name}_{name}")
        f.restype = None

        def run(*args):
            args = [np.ascontiguousarray(a, dtype=np.float64) for a in args]
            out = np.full(size, np.nan)
            f(*[a.ctypes.data_as(ptr) for a in args], out.ctypes.data_as(ptr))
            return out

        return run

    _check(call("integrate", 9), call("difference", 8), "C")


@pytest.mark.skipif(OCTAVE is None, reason="GNU Octave (octave-cli) is not installed")
def test_octave_agrees_with_pinocchio(tmp_path):
    write_files(matlab_target.render(ctx()), tmp_path)
    name = ctx().name
    q0 = cases()[0][0]
    calls, want = {}, {}
    model = pin_model()
    for k, (q, v, q_next) in enumerate(cases()):
        calls[f"i{k}"] = f"{name}_integrate({octave_numbers(q)}, {octave_numbers(v)}, 1)"
        want[f"i{k}"] = pin.integrate(model, q, v)
        calls[f"d{k}"] = f"{name}_difference({octave_numbers(q)}, {octave_numbers(q_next)})"
        want[f"d{k}"] = pin.difference(model, q, q_next)
    calls["same"] = f"{name}_difference({octave_numbers(q0)}, {octave_numbers(q0)})"
    calls["rest"] = f"{name}_integrate({octave_numbers(q0)}, zeros(1, 8), 0)"
    got = octave_values(tmp_path, calls)
    for label, value in want.items():
        np.testing.assert_allclose(got[label], value, atol=TOL * 10, err_msg=f"octave {label}")
    assert np.abs(got["same"]).max() < 1e-15
    np.testing.assert_allclose(got["rest"], pin.integrate(model, q0, np.zeros(8)), atol=TOL)


def test_a_fixed_robot_has_no_configuration_functions():
    assert context(example("roger_arm"), functions=("configuration",)).functions == ()


def test_a_quaternion_of_another_norm_reads_as_its_unit_quaternion():
    """Both functions read the orientation of q / |q| (docs/centroidal.md); integrate returns a
    unit quaternion."""
    module = _numpy_module()
    for q, v, q_next in cases()[2:6]:
        scaled = q.copy()
        scaled[3:7] *= 3.0
        got = module.integrate(scaled, v, np.array([1.0]))
        np.testing.assert_allclose(got, module.integrate(q, v, np.array([1.0])), atol=TOL)
        assert abs(np.linalg.norm(got[3:7]) - 1.0) < 1e-15
        np.testing.assert_allclose(
            module.difference(scaled, q_next), module.difference(q, q_next), atol=TOL * 10
        )
