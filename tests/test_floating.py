"""The Newton-Euler route on a floating base (symdyn.algorithms.floating, through symdyn.derive)
against the numeric oracle (symdyn.oracle.floating) and Pinocchio's free flyer.

Derived once per module: the small floating arm of tests/data (friction, rotor inertia, a
prismatic joint, products of inertia) and Solo-12 (whose dynamics Pinocchio computes too)."""

from __future__ import annotations

import ctypes
import types
from pathlib import Path

import numpy as np
import pytest
from cbuild import compile_shared, header_macros, write_files

import symdyn
from symdyn import SymdynError
from symdyn.cli.main import main
from symdyn.codegen import render
from symdyn.codegen.functions import build_functions
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import bias_torque, friction_torque, gravity_torque, mass_matrix

pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")

ARM = Path(__file__).parent / "data" / "floating_arm.yaml"
ROBOTS = example_robot_data_folder()
SOLO = ROBOTS / "solo_description/robots/solo12.urdf" if ROBOTS else None


@pytest.fixture(scope="module")
def arm():
    robot = symdyn.load_robot(ARM)
    return robot, symdyn.derive(robot, simplify=False)


@pytest.fixture(scope="module")
def solo():
    if SOLO is None:
        pytest.skip("example-robot-data is not installed")
    robot = symdyn.load_urdf(SOLO, floating=True)
    return robot, symdyn.derive(robot)


def _state(robot, rng, scale=1.0):
    x = rng.normal(size=4)
    quat = scale * x / np.linalg.norm(x)
    q = np.concatenate([rng.normal(size=3), quat, rng.uniform(-1, 1, robot.n)])
    return q, rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def test_derivation_equals_the_oracle(arm):
    """Solo-12's derivation is compared with Pinocchio below (the oracle equals Pinocchio on it:
    tests/test_oracle_floating.py)."""
    robot, dyn = arm
    assert dyn.q.shape == (robot.n + 7, 1) and dyn.qd.shape == (robot.n + 6, 1)
    assert [str(s) for s in dyn.q[:7]] == ["x_b", "y_b", "z_b", "qx_b", "qy_b", "qz_b", "qw_b"]
    rng = np.random.default_rng(11)
    for _ in range(2):
        q, v, a = _state(robot, rng)
        expected = {
            "M": mass_matrix(robot, q),
            "G": gravity_torque(robot, q),
            "V": bias_torque(robot, q, v),
            "F": friction_torque(robot, v),
            "tau": symdyn.rnea(robot, q, v, a),
            "bias": symdyn.rnea(robot, q, v, np.zeros_like(v)),
        }
        for name, value in expected.items():
            np.testing.assert_allclose(dyn.evaluate(name, q, v, a), value, atol=1e-11, err_msg=name)
        # C qd = V, and dM/dt = C + C^T with dM/dt through the tangent space (M depends on the
        # joints only: a central difference along the joint rates)
        C = dyn.evaluate("C", q, v)
        np.testing.assert_allclose(C @ v, expected["V"], atol=1e-11)
        h = 1e-6
        step = np.concatenate([np.zeros(7), h * v[6:]])
        dM = (mass_matrix(robot, q + step) - mass_matrix(robot, q - step)) / (2 * h)
        np.testing.assert_allclose(dM, C + C.T, atol=1e-8)


def test_solo_against_pinocchio(solo):
    robot, dyn = solo
    model = pin.buildModelFromUrdf(str(SOLO), pin.JointModelFreeFlyer())
    data = model.createData()
    assert [model.names[j] for j in range(2, model.njoints)] == [lk.joint_name for lk in robot.links]
    q, v, a = _state(robot, np.random.default_rng(5))
    M = pin.crba(model, data, q)
    np.testing.assert_allclose(dyn.evaluate("M", q), np.triu(M) + np.triu(M, 1).T, atol=1e-12)
    np.testing.assert_allclose(dyn.evaluate("tau", q, v, a), pin.rnea(model, data, q, v, a), atol=1e-11)
    np.testing.assert_allclose(
        dyn.evaluate("G", q), pin.computeGeneralizedGravity(model, data, q), atol=1e-11
    )
    np.testing.assert_allclose(
        dyn.evaluate("bias", q, v), pin.nonLinearEffects(model, data, q, v), atol=1e-11
    )


def test_non_unit_quaternion_reads_its_normalised_orientation(arm):
    """Every function reads q / |q|: a quaternion of norm 2.5 gives the unit one's values; the
    zero quaternion has no orientation (the values are not finite)."""
    robot, dyn = arm
    rng = np.random.default_rng(2)
    q, v, a = _state(robot, rng)
    scaled = q.copy()
    scaled[3:7] *= 2.5
    for name in ("G", "tau", "bias"):
        np.testing.assert_allclose(dyn.evaluate(name, scaled, v, a), dyn.evaluate(name, q, v, a), atol=1e-12)
    np.testing.assert_allclose(symdyn.rnea(robot, scaled, v, a), symdyn.rnea(robot, q, v, a), atol=1e-12)
    zero = q.copy()
    zero[3:7] = 0
    with np.errstate(all="ignore"):
        assert not np.isfinite(dyn.evaluate("G", zero)).all()
        assert not np.isfinite(gravity_torque(robot, zero)).all()


def test_mass_matrix_depends_on_the_joints_only(arm):
    robot, dyn = arm
    free = set().union(*(e.free_symbols for e in dyn.M))
    assert free <= set(dyn.q[7:]), free
    G_free = set().union(*(e.free_symbols for e in dyn.G))
    assert not G_free & set(dyn.q[:3]) and G_free & set(dyn.q[3:7])


def test_lagrange_route_in_the_tangent_space_equals_newton_euler(arm):
    """Boltzmann-Hamel / Euler-Poincare (symdyn.algorithms.floating_lagrange) against the recursion."""
    robot, newton_euler = arm
    lagrange = symdyn.derive(robot, method="lagrange", simplify=False)
    rng = np.random.default_rng(21)
    for _ in range(2):
        q, v, a = _state(robot, rng)
        for name in ("M", "tau", "G", "V", "bias"):
            np.testing.assert_allclose(
                lagrange.evaluate(name, q, v, a),
                newton_euler.evaluate(name, q, v, a),
                atol=1e-11,
                err_msg=name,
            )


def test_bad_input(arm):
    robot, dyn = arm
    with pytest.raises(SymdynError, match=r"q has shape \(5,\), expected \(10,\)"):
        dyn.evaluate("M", np.zeros(5))
    with pytest.raises(SymdynError, match=r"rnea: v has 3 entries, expected 9 \(NV = 6 \+ joints"):
        symdyn.rnea(robot, np.zeros(10), np.zeros(3), np.zeros(9))


# --------------------------------------------------------------------------- generated code

SIGNATURES = {
    "inverse_dynamics": (("q", "qd", "qdd"), "v"),
    "mass_matrix": (("q",), "M"),
    "coriolis_matrix": (("q", "qd"), "M"),
    "coriolis": (("q", "qd"), "v"),
    "gravity": (("q",), "v"),
    "friction": (("qd",), "v"),
    "forward_dynamics": (("q", "qd", "tau"), "v"),
}


def _module(text: str, name: str) -> types.ModuleType:
    module = types.ModuleType(name)
    exec(compile(text, name, "exec"), module.__dict__)  # symdyn's own output
    return module


class _C:
    """The compiled functions of a floating robot, called with NumPy arrays (q of NQ, others NV)."""

    def __init__(self, files, out: Path, name: str):
        write_files({k: v for k, v in files.items() if k.startswith(f"{name}_dynamics.")}, out)
        self.macros = header_macros((out / f"{name}_dynamics.h").read_text())
        lib = ctypes.CDLL(str(compile_shared([out / f"{name}_dynamics.c"], out / f"lib{name}.so")))
        self.nq, self.nv = int(self.macros[f"{name}_NQ"]), int(self.macros[f"{name}_NV"])
        ptr = ctypes.POINTER(ctypes.c_double)
        self.functions = {}
        for fname, (args, _) in SIGNATURES.items():
            f = getattr(lib, f"{name}_{fname}")
            f.argtypes = [ptr] * (len(args) + 2)
            self.functions[fname] = f
        self.ptr = ptr

    def __call__(self, fname, *args):
        names, kind = SIGNATURES[fname]
        arrays = [np.ascontiguousarray(x, dtype=float) for x in args]
        for name, a in zip(names, arrays, strict=True):
            assert a.shape == ((self.nq,) if name == "q" else (self.nv,))
        out = np.full((self.nv, self.nv) if kind == "M" else (self.nv,), np.nan)
        self.functions[fname](
            *(a.ctypes.data_as(self.ptr) for a in arrays), None, out.ctypes.data_as(self.ptr)
        )
        return out


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    robot = symdyn.load_robot(ARM)
    files = render(robot, targets=("c", "python", "casadi", "matlab"), functions=["dynamics"])
    return robot, files, _C(files, tmp_path_factory.mktemp("floating_c"), robot.name)


def test_generated_functions_equal_the_oracle(generated, arm):
    robot, files, c = generated
    assert (c.nq, c.nv, int(c.macros["floating_arm_NDOF"])) == (robot.n + 7, robot.n + 6, robot.n + 6)
    numpy_module = _module(files["floating_arm_numpy.py"], "floating_numpy")
    assert (numpy_module.NQ, numpy_module.NV, numpy_module.NDOF) == (10, 9, 9)
    casadi_functions = _module(files["floating_arm_casadi.py"], "floating_casadi").functions()
    rng = np.random.default_rng(8)
    q, v, a = _state(robot, rng)
    tau = symdyn.rnea(robot, q, v, a)
    expected = {
        "inverse_dynamics": ((q, v, a), tau),
        "mass_matrix": ((q,), mass_matrix(robot, q)),
        "coriolis_matrix": ((q, v), arm[1].evaluate("C", q, v)),
        "coriolis": ((q, v), bias_torque(robot, q, v)),
        "gravity": ((q,), gravity_torque(robot, q)),
        "friction": ((v,), friction_torque(robot, v)),
        "forward_dynamics": ((q, v, tau), a),
    }
    for fname, (args, value) in expected.items():
        np.testing.assert_allclose(c(fname, *args), value, atol=1e-10, err_msg=f"C {fname}")
        np.testing.assert_allclose(getattr(numpy_module, fname)(*args), value, atol=1e-10, err_msg=fname)
        got = np.array(casadi_functions[fname](*args, np.zeros(0))).reshape(np.shape(value))
        np.testing.assert_allclose(got, value, atol=1e-10, err_msg=f"CasADi {fname}")
    assert "floating_arm_forward_dynamics.m" in files


def test_the_tip_wrench_group_is_empty_on_a_dh_floating_robot(arm):
    """As on a fixed base, tip_wrench_torque is for product-of-exponentials robots only
    (tests/test_floating_body.py checks it on a floating one)."""
    _, dyn = arm
    assert [spec.name for spec in build_functions(dyn, ["tip_wrench"])] == []


def test_command_line(tmp_path, capsys):
    """derive, generate and simulate (docs/centroidal.md) take --floating; the other commands refuse
    a floating robot in one line."""
    assert main(["derive", str(ARM)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("# floating_arm: 3 joints and a floating base (NV = 9), method newton-euler\n")
    assert "C[9,9] = " in out and "M[9,9] = " in out
    urdf = Path(__file__).parent / "data" / "urdf" / "bad_floating.urdf"
    assert main(["generate", str(urdf), "--floating", "--target", "python", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "bad_numpy.py").read_text()
    assert "NQ = 8\n" in text and "NDOF = 7\n" in text
    for argv, message in (
        (["derive", str(ARM), "--form", "configuration"], "derive: a floating robot prints --form compact"),
        (["derive", str(ARM), "--steps"], "derive --steps: robot 'floating_arm' has a floating base"),
        (["excite", str(ARM), "--out", str(tmp_path / "e.csv")],
         "symdyn excite: robot 'floating_arm' has a floating base, which this command does not handle"),
    ):  # fmt: skip
        assert main(argv) == 1
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and message in err, err
