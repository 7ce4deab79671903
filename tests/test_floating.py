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
from robots import FLYER
from timebound import refused, within

import symdyn
import symdyn.apps.simulation.simulate
from symdyn import SymdynError
from symdyn.cli.main import main
from symdyn.codegen import render
from symdyn.codegen.functions import build_functions
from symdyn.model.quaternion_norm import QUATERNION_NORM
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
    zero quaternion has no orientation (the derivation's values are not finite; the oracle refuses
    it, as every norm outside QUATERNION_NORM: test_quaternion_norms_outside_the_bound_are_refused)."""
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
    with pytest.raises(
        SymdynError, match=r"gravity_torque: q: the base quaternion \(entries 4 to 7\) has norm 0,"
    ):
        gravity_torque(robot, zero)


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


def test_inertia_efforts_change_with_q_as_the_mass_matrix_times_x(arm):
    """The impulse derivatives differentiate M(q) x through one recursion at rest (inertia_efforts):
    between two configurations it changes as M(q) x (its constant rotor terms cancel), floating and
    fixed."""
    import sympy as sp

    from symdyn.algorithms.floating import inertia_efforts
    from symdyn.symbolic.program import Program

    planar = symdyn.load_robot(Path(__file__).parents[1] / "examples" / "planar_3r.yaml")
    rng = np.random.default_rng(5)
    for dyn in (arm[1], symdyn.derive(planar, simplify=False)):
        r, prog = dyn.robot, Program()
        xs = sp.symbols(f"x0:{r.nv}")
        f = sp.lambdify([list(dyn.q), xs], prog.expand(inertia_efforts(r, list(dyn.q), xs, prog)))
        x = rng.normal(size=r.nv)
        q1, q2 = (_state(r, rng)[0] if r.floating else rng.normal(size=r.n) for _ in range(2))
        got = np.ravel(f(q1, x)) - np.ravel(f(q2, x))
        np.testing.assert_allclose(got, (mass_matrix(r, q1) - mass_matrix(r, q2)) @ x, atol=1e-12)


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


def _scaled_quaternion(q: np.ndarray, norm: float, pair: bool = False) -> np.ndarray:
    """q with its quaternion scaled to `norm` (pair: (x, 0, 0, x) of that norm, a quarter turn
    about x: gravity turns with it, and its entries are those of the issue's (0, 0, x, x))."""
    out = q.copy()
    out[3:7] = (
        [norm / np.sqrt(2), 0.0, 0.0, norm / np.sqrt(2)] if pair else q[3:7] / np.linalg.norm(q[3:7]) * norm
    )
    return out


def test_generated_code_holds_the_quaternion_norms_of_its_bound(generated):
    """QUATERNION_NORM (docs/floating-base.md) is the generated C's own bound: at norms 1e-150 and
    1e150 (and between) it gives the unit quaternion's values; beyond, at 1e-160 and 1e160, |q|^2
    leaves the doubles and the values are NaN or wrong: without the run-time check,
    (0, 0, 1e-200, 1e-200) gave NaN, and 1e200 NaN (reported as a singular M) or R = 1."""
    robot, _, c = generated
    low, high = QUATERNION_NORM["double"]
    assert (low, high) == (1e-150, 1e150)
    q, v, a = _state(robot, np.random.default_rng(31))
    want = {
        name: c(name, q, *(v, a)[: len(SIGNATURES[name][0]) - 1]) for name in ("gravity", "inverse_dynamics")
    }
    for norm in (low, 1e-100, 1e-20, 1e20, 1e100, high):
        for name, expected in want.items():
            got = c(name, _scaled_quaternion(q, norm), *(v, a)[: len(SIGNATURES[name][0]) - 1])
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    with np.errstate(all="ignore"):
        assert not np.isfinite(c("gravity", _scaled_quaternion(q, 1e-160, pair=True))).all()
        far = c("gravity", _scaled_quaternion(q, 1e160, pair=True))
        assert not np.allclose(far, c("gravity", _scaled_quaternion(q, 1.0, pair=True)))


def test_float_bound_holds_in_the_generated_float_code(tmp_path):
    """QUATERNION_NORM["float"] = [1e-18, 1e18] for --precision float: gravity at those norms equals
    the unit quaternion's to float rounding, and at 1e-21 (|q|^2 below FLT_MIN) it does not."""
    robot = symdyn.load_robot(ARM)
    files = render(robot, targets=("c",), functions=["dynamics"], precision="float")
    write_files({k: v for k, v in files.items() if k.startswith("floating_arm_dynamics.")}, tmp_path)
    lib = ctypes.CDLL(str(compile_shared([tmp_path / "floating_arm_dynamics.c"], tmp_path / "libf.so")))
    ptr = ctypes.POINTER(ctypes.c_float)
    lib.floating_arm_gravity.argtypes = [ptr, ptr, ptr]

    def gravity(q):
        out, q32 = np.full(robot.nv, np.nan, dtype=np.float32), np.ascontiguousarray(q, dtype=np.float32)
        lib.floating_arm_gravity(q32.ctypes.data_as(ptr), None, out.ctypes.data_as(ptr))
        return out.astype(float)

    q = _state(robot, np.random.default_rng(32))[0]
    want = gravity(q)
    low, high = QUATERNION_NORM["float"]
    for norm in (low, 1e-9, 1e9, high):
        np.testing.assert_allclose(
            gravity(_scaled_quaternion(q, norm)), want, rtol=1e-5, atol=1e-5 * np.abs(want).max()
        )
    with np.errstate(all="ignore"):
        assert not np.allclose(
            gravity(_scaled_quaternion(q, 1e-21, pair=True)), gravity(_scaled_quaternion(q, 1.0, pair=True))
        )


def test_quaternion_norms_outside_the_bound_are_refused(tmp_path, capsys):
    """Before: simulate's q0 of norm 1e200 was reported as "singular M", 1e-200 as "zero", and the
    compiled functions and the oracle returned NaN or wrong values; now every run-time entry point
    refuses a finite quaternion outside QUATERNION_NORM in one line naming the function, the
    argument and the state, and takes any norm inside it (q0 normalised)."""
    (tmp_path / "flyer.yaml").write_text(FLYER)
    robot = symdyn.load_robot(tmp_path / "flyer.yaml")
    compiled = symdyn.compile(robot)
    q, v, a = _state(robot, np.random.default_rng(33))
    tiny, huge = _scaled_quaternion(q, 2e-200, pair=True), _scaled_quaternion(q, 2e200, pair=True)
    for bad, norm in ((tiny, "2e-200"), (huge, "2e+200"), (_scaled_quaternion(q, 0.0), "0")):
        outside = (
            f"has norm {norm}, outside [1e-150, 1e+150], the norms whose square the generated code forms"
        )
        with within(10):
            for call, where in (
                (lambda bad=bad: compiled.forward_dynamics(bad, v, a), "forward_dynamics: q: "),
                (
                    lambda bad=bad: compiled.gravity(np.stack([q, bad])),
                    "gravity: q: the base quaternion (entries 4 to 7) of state 1 ",
                ),
                (lambda bad=bad: compiled.difference(q, bad), "difference: q_next: "),
                (lambda bad=bad: symdyn.rnea(robot, bad, v, a), "rnea: q: "),
                (
                    lambda bad=bad: symdyn.apps.simulation.simulate.simulate(
                        compiled, bad, duration=0.1, dt=0.01
                    ),
                    "q0: ",
                ),
            ):
                with pytest.raises(SymdynError) as info:
                    call()
                assert str(info.value).startswith(where) and outside in str(info.value), str(info.value)
    q0, out = "--q0=" + ",".join(f"{x:.17g}" for x in huge), tmp_path / "s.csv"
    line = refused(
        capsys, "simulate", tmp_path / "flyer.yaml", q0, "--duration", "0.05", "--dt", "0.01", "--out", out
    )
    assert line.startswith("symdyn: error: q0: the base quaternion (entries 4 to 7) has norm 2e+200, outside")
    assert not out.exists()
    inside = _scaled_quaternion(q, 1e-120)
    want = compiled.forward_dynamics(q, v, v)
    np.testing.assert_allclose(compiled.forward_dynamics(inside, v, v), want, rtol=1e-10)
    np.testing.assert_allclose(
        symdyn.rnea(robot, inside, v, a), symdyn.rnea(robot, q, v, a), rtol=1e-10, atol=1e-12
    )
    run = symdyn.apps.simulation.simulate.simulate(compiled, inside, duration=0.02, dt=0.01)
    unit = symdyn.apps.simulation.simulate.simulate(compiled, q, duration=0.02, dt=0.01)
    assert np.allclose(np.linalg.norm(run.q[0, 3:7]), 1.0) and np.allclose(
        run.q, unit.q, rtol=1e-12, atol=1e-14
    )
