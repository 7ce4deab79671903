"""Closed kinematic loops (symdyn.model.loops, symdyn.algorithms.closed_loops,
symdyn.codegen.loop_functions): robot files, bad input, and the generated functions against the
NumPy oracle (symdyn.oracle.closed_loops), the four-bar's textbook closed forms, virtual work,
finite differences of the solved loop, energy conservation and Pinocchio's constrained dynamics."""

from __future__ import annotations

import ctypes
import math
import shutil
import subprocess
import warnings
from functools import cache

import numpy as np
import pytest
import sympy as sp
import yaml
from cbuild import compile_shared, write_files
from robots import EXAMPLES_DIR, pinocchio_model
from timebound import refused

import symdyn
from symdyn.algorithms.closed_loops import analyse
from symdyn.cli.main import main
from symdyn.codegen import render
from symdyn.errors import SymdynError
from symdyn.generated_modules import load_module
from symdyn.oracle import closed_loops as oc
from symdyn.parsers import robot_from_data
from symdyn.rnea import kinetic_energy, mass_matrix, potential_energy, rnea

EXAMPLES = ("fourbar", "fivebar", "delta", "parallelogram_arm")
LOOPS_DIR = EXAMPLES_DIR / "closed_loops"
#: The targets each example is rendered to, once per test process (the derivation is shared).
TARGETS = {
    "fourbar": ("python", "casadi", "matlab", "latex"),
    "delta": ("python", "c", "matlab"),
}


@cache
def loaded(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_robot(LOOPS_DIR / f"{name}.yaml")


@cache
def analysis(name: str):
    """The example's loop analysis (its assembled configurations, rows and split)."""
    return analyse(loaded(name).resolved())


@cache
def generated(name: str):
    """The example's robot and its files of every target of TARGETS (the NumPy module by default)."""
    robot = loaded(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        files = render(robot, targets=TARGETS.get(name, ("python",)))
    return robot, files


@pytest.fixture(scope="module")
def numpy_module(tmp_path_factory):
    """numpy_module(name) -> (Robot, its generated NumPy module), written and imported once."""
    folder, modules = tmp_path_factory.mktemp("loops"), {}

    def get(name: str):
        if name not in modules:
            robot, files = generated(name)
            path = folder / f"{name}_numpy.py"
            path.write_text(files[path.name])
            modules[name] = (robot, load_module(path, f"_loops_{name}"))
        return modules[name]

    return get


def closed_state(robot, module, seed: int, an=None):
    """A closed q near an assembled configuration, and random actuated rates and accelerations."""
    rng = np.random.default_rng(seed)
    an = an or analysis(robot.name)
    q0 = np.array(an.assembled[0])
    act, _ = oc.split(robot)
    it, q = module.solve_loops(q0[act] + 0.05 * rng.standard_normal(len(act)), q0)
    assert it >= 0
    return q, rng.standard_normal(len(act)), rng.standard_normal(len(act))


# -- robot files and bad input


def _fourbar_data() -> dict:
    return yaml.safe_load((LOOPS_DIR / "fourbar.yaml").read_text())


def test_the_four_bar_file_gives_its_loop_and_actuated_joint():
    robot = loaded("fourbar")
    (loop,) = robot.loops
    assert (loop.name, loop.link, loop.to, loop.type) == ("B", 1, 2, "point")
    assert robot.actuated == (0,) and robot.actuated_links == (0,)
    an = analysis("fourbar")
    assert an.rows == (0, 1) and an.actuated == (0,) and an.passive == (1, 2)
    assert an.notes == ("robot 'fourbar': closure rows B.z depend on the others and are dropped",)


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda d: d["loops"][0].update(link="nope"), ("loops[0] (B).link", "no link named 'nope'")),
        (lambda d: d["loops"][0].update(to="rockr"), ("loops[0] (B).to", "did you mean 'rocker'")),
        (lambda d: d["loops"][0].update(point=[1, 2]), ("loops[0] (B).point", "got 2 entries")),
        (lambda d: d["loops"][0].update(type="hinge"), ("loops[0] (B).type", "point, weld")),
        (
            lambda d: d["loops"][0].update(to="coupler"),
            ("loops[0] (B).to", "closes link 'coupler' on itself"),
        ),
        (lambda d: d["loops"][0].pop("to_point"), ("loops[0] (B).to_point", "missing required field")),
        (lambda d: d["loops"][0].update(colour="red"), ("loops[0].colour",)),
        (lambda d: d.update(loops={"B": 1}), ("'loops'", "expected a list of loops")),
        (lambda d: d.update(actuated=["crank", "crank"]), ("actuated[1]", "listed twice")),
        (lambda d: d.update(actuated=["arm"]), ("actuated[0]", "no link named 'arm'")),
    ],
)
def test_bad_loops_and_actuated_fields_are_refused_naming_file_loop_and_field(change, words):
    data = _fourbar_data()
    change(data)
    with pytest.raises(SymdynError) as err:
        robot_from_data(data, "fourbar.yaml")
    text = str(err.value)
    assert text.startswith("fourbar.yaml: ") and "\n" not in text
    for w in words:
        assert w in text, text


def test_loops_on_a_floating_base_are_refused_in_one_line():
    data = _fourbar_data()
    data["base"] = "floating"
    for make in (lambda: robot_from_data(data, "fourbar.yaml"), lambda: _load_floating("fourbar")):
        with pytest.raises(SymdynError) as err:
            make()
        text = str(err.value)
        assert "fourbar.yaml" in text and "\n" not in text
        assert "closed loops (field 'loops') on a floating base are not handled yet" in text


def _load_floating(name: str):
    return symdyn.load_robot(LOOPS_DIR / f"{name}.yaml", floating=True)


def _refused_generate(capsys, tmp_path, data: dict) -> str:
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        line = refused(capsys, "generate", str(path), "--target", "c", "--out", str(out), seconds=60)
    assert not out.exists()
    return line


def test_a_loop_whose_lengths_never_meet_is_refused_and_nothing_written(capsys, tmp_path):
    data = _fourbar_data()
    data["parameters"]["d"] = 2.0  # ground longer than the other three bars together
    line = _refused_generate(capsys, tmp_path, data)
    assert "bad.yaml" in line and "loop 'B': cannot close" in line and "'loops'" in line


def test_an_actuated_list_that_does_not_match_the_mobility_is_refused(capsys, tmp_path):
    data = _fourbar_data()
    data["actuated"] = ["crank", "rocker"]
    line = _refused_generate(capsys, tmp_path, data)
    assert "field 'actuated': 2 actuated joints (crank, rocker)" in line and "leave 1 degrees" in line
    data["actuated"] = None  # the default: the joints on no loop (none here)
    assert "0 actuated joints (none)" in _refused_generate(capsys, tmp_path, data)


# -- symdyn derive


def _derived_json(capsys, name: str) -> dict:
    import json

    from symdyn.cli.main import main

    capsys.readouterr()
    assert main(["derive", str(LOOPS_DIR / f"{name}.yaml"), "--format", "json"]) == 0
    return json.loads(capsys.readouterr().out)


def _matrix(rows, q) -> np.ndarray:
    import sympy as sp

    subs = {sp.Symbol(f"q{i + 1}"): x for i, x in enumerate(q)}
    return np.array([[float(sp.sympify(e).evalf(subs=subs)) for e in row] for row in rows])


@pytest.mark.parametrize("name", ["fourbar", "fivebar"])
def test_derive_says_it_prints_the_tree_and_prints_the_closure_that_projects_it(capsys, name):
    """derive prints the spanning tree's M, says so, and prints phi and K: with them the printed
    M projects (W = [I; -K_p^-1 K_a], M_a = W^T M W) onto the oracle's actuated mass matrix."""
    doc = _derived_json(capsys, name)
    robot = loaded(name)
    loops = doc["loops"]
    assert "the equations below are the spanning tree's" in loops["note"][0]
    assert "M_a = W^T M W" in loops["note"][2] and "actuated_mass_matrix" in loops["note"][3]
    an = analysis(name)
    assert loops["rows"] == [f"{robot.loops[0].name}.{r}" for r in "xy"]
    rng = np.random.default_rng(3)
    q_any = rng.uniform(-np.pi, np.pi, robot.n)
    phi_o, K_o, _ = oc.closure(robot, q_any)
    np.testing.assert_allclose(_matrix([loops["phi"]], q_any)[0], phi_o[list(an.rows)], atol=1e-12)
    np.testing.assert_allclose(_matrix(loops["K"], q_any), K_o[list(an.rows)], atol=1e-12)
    act, pas = oc.split(robot)
    q = oc.solve_loops(robot, np.array(an.assembled[0])[act] + 0.1, an.assembled[0])
    M, K = _matrix(doc["M"], q), _matrix(loops["K"], q)
    W = np.zeros((robot.n, len(act)))
    W[act] = np.eye(len(act))
    W[pas] = -np.linalg.solve(K[:, pas], K[:, act])
    np.testing.assert_allclose(W.T @ M @ W, oc.loop_state(robot, q, np.zeros(len(act))).Ma, atol=1e-12)
    np.testing.assert_allclose(M, mass_matrix(robot, q), atol=1e-12)  # the tree's, as it says


def test_derive_text_and_steps_carry_the_header_and_latex_the_closure(capsys):
    from symdyn.cli.main import main

    path = str(LOOPS_DIR / "fourbar.yaml")
    for args in ([], ["--steps"], ["--form", "compact"], ["--format", "latex"]):
        capsys.readouterr()
        assert main(["derive", path, *args]) == 0
        out = capsys.readouterr().out
        mark = "%" if "latex" in args else "#"
        assert out.startswith(f"{mark} closed loops B (point): the equations below are the spanning tree's")
        assert (
            f"{mark} closure phi(q) = 0: rows B.x, B.y (B.z dropped: dependent on the others); 1 degree"
            in out
        )
        assert ("\\phi_{2} &=" if "latex" in args else "phi[2] = ") in out


@pytest.mark.parametrize("args", [(), ("--steps",), ("--format", "json")])
def test_derive_refuses_a_loop_whose_links_are_too_short_as_generate_does(capsys, tmp_path, args):
    data = _fourbar_data()
    data["parameters"].update(b=0.05, c=0.1)  # coupler and rocker cannot reach across the ground
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump(data))
    line = refused(capsys, "derive", path, *args, seconds=30)
    assert line == (
        f"symdyn: error: {path}: robot 'fourbar': loop 'B': cannot close: no configuration brings "
        "its points together from 12 starts (check the lengths and points of field 'loops')"
    )
    assert line == _refused_generate(capsys, tmp_path, data).replace("bad.yaml", "short.yaml")


def test_derive_of_a_four_bar_in_symbols_prints_its_closure_unchecked(capsys, tmp_path):
    """A student's four-bar with a symbolic crank: the loops cannot be checked (that needs
    numbers), so derive says so and prints every closure row; phi is Freudenstein's loop of
    vectors written by hand in the rocker's axes."""
    data = _fourbar_data()
    del data["parameters"]["a"]
    path = tmp_path / "symbolic.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["derive", str(path)]) == 0
    out = capsys.readouterr().out
    assert "rows B.x, B.y, B.z, not checked" in out and "free parameters (a)" in out
    phi = dict(line.split("    # ")[::-1] for line in out.splitlines() if line.startswith("phi["))
    a, q1, q2, q3 = sp.symbols("a q1 q2 q3")
    b, c, d = (sp.nsimplify(FOURBAR[k]) for k in "bcd")
    x = a * sp.cos(q1) + b * sp.cos(q1 + q2) - d - c * sp.cos(q3)
    y = a * sp.sin(q1) + b * sp.sin(q1 + q2) - c * sp.sin(q3)
    want = {"B.x": sp.cos(q3) * x + sp.sin(q3) * y, "B.y": -sp.sin(q3) * x + sp.cos(q3) * y}
    for row, value in want.items():
        got = sp.nsimplify(sp.sympify(phi[row].split(" = ")[1]))
        assert sp.simplify(sp.expand_trig(got - value)) == 0, row
    assert phi["B.z"] == "phi[3] = 0"


# -- the four-bar against its textbook closed forms


def _freudenstein(a, b, c, d, t2):
    """The rocker angles theta4 of a four-bar at crank angle theta2, both branches (R. L.
    Norton, Design of Machinery (5th ed.), eq. 4.10: K1 = d/a, K2 = d/c, K3 = (a^2 - b^2 + c^2
    + d^2)/(2 a c); theta4 = 2 atan2(-B -+ sqrt(B^2 - 4 A C), 2 A))."""
    K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    A = math.cos(t2) - K1 - K2 * math.cos(t2) + K3
    B = -2 * math.sin(t2)
    C = K1 - (K2 + 1) * math.cos(t2) + K3
    root = math.sqrt(B * B - 4 * A * C)
    return [2 * math.atan2(-B - s * root, 2 * A) for s in (1, -1)]


FOURBAR = {"a": 0.1, "b": 0.35, "c": 0.3, "d": 0.4, "m2": 0.5, "m3": 1.2, "m4": 1.0}


def test_the_four_bar_closes_at_freudensteins_angle_with_the_textbook_inertia(numpy_module):
    robot, m = numpy_module("fourbar")
    a, b, c, d = (FOURBAR[k] for k in "abcd")
    m2, m3, m4 = FOURBAR["m2"], FOURBAR["m3"], FOURBAR["m4"]
    for t2 in np.linspace(0, 2 * np.pi, 7, endpoint=False):
        it, q = m.solve_loops([t2], [t2, 0.3 - t2, 1.8])
        assert 0 <= it <= 8
        t3, t4 = q[0] + q[1], q[2]
        assert min(abs(math.remainder(t4 - w, 2 * math.pi)) for w in _freudenstein(a, b, c, d, t2)) < 1e-12
        # velocity ratios (Norton eq. 6.18): w3/w2, w4/w2
        k3 = a * math.sin(t4 - t2) / (b * math.sin(t3 - t4))
        k4 = a * math.sin(t2 - t3) / (c * math.sin(t4 - t3))
        qd, _ = m.loop_motion(q, [1.0], [0.0])
        np.testing.assert_allclose(qd, [1.0, k3 - 1.0, k4], rtol=1e-12, atol=1e-12)
        # inertia reduced to the crank (bars about an end: m l^2/3):
        # I_O2 + m3 |v_G3/w2|^2 + I_G3 k3^2 + I_O4 k4^2
        vA = a * np.array([-math.sin(t2), math.cos(t2)])
        vG3 = vA + k3 * b / 2 * np.array([-math.sin(t3), math.cos(t3)])
        Ma = m2 * a * a / 3 + m3 * vG3 @ vG3 + m3 * b * b / 12 * k3**2 + m4 * c * c / 3 * k4**2
        np.testing.assert_allclose(m.actuated_mass_matrix(q), [[Ma]], rtol=1e-12)


def test_newton_gives_minus_one_at_a_singular_or_hopeless_guess(numpy_module):
    robot, m = numpy_module("fourbar")
    # coupler and rocker aligned (theta3 = theta4): K_p is singular
    assert m.solve_loops([0.0], [0.0, 1.0, 1.0])[0] == -1
    assert m.solve_loops([0.5], [0.5, np.nan, 1.0])[0] == -1


# -- every example against the oracle


@pytest.mark.parametrize("name", EXAMPLES)
def test_generated_numpy_agrees_with_the_oracle(name, numpy_module):
    robot, m = numpy_module(name)
    for seed in (1, 2):
        q, qda, qdda = closed_state(robot, m, seed)
        assert np.abs(oc.closure(robot, q)[0]).max() < 1e-12
        s = oc.loop_state(robot, q, qda, qdda)
        qd, qdd = m.loop_motion(q, qda, qdda)
        np.testing.assert_allclose(qd, s.qd, atol=1e-12)
        np.testing.assert_allclose(qdd, s.qdd, atol=1e-10)
        np.testing.assert_allclose(m.actuated_inverse_dynamics(q, qda, qdda), s.tau_a, atol=1e-10)
        np.testing.assert_allclose(m.actuated_mass_matrix(q), s.Ma, atol=1e-11)
        np.testing.assert_allclose(m.actuated_forward_dynamics(q, qda, s.tau_a), qdda, atol=1e-9)
        # the closure forces: K^T lambda are the tree's efforts the motors do not give
        applied = np.zeros(robot.n)
        applied[s.act] = s.tau_a
        K = m.loop_jacobian(q)
        np.testing.assert_allclose(K.T @ m.loop_forces(q, qda, qdda), s.tau - applied, atol=1e-10)
        # virtual work: the motors' power is the tree's power at the same motion
        assert s.tau_a @ qda == pytest.approx(rnea(robot, q, qd, qdd) @ qd, abs=1e-10)
        assert m.actuated_inverse_dynamics(q, qda, qdda) @ qda == pytest.approx(s.tau @ s.qd, abs=1e-10)


@pytest.mark.parametrize("name", ["fourbar", "delta"])
def test_finite_differences_of_the_solved_loop_give_W_and_the_passive_accelerations(name, numpy_module):
    robot, m = numpy_module(name)
    q, qda, qdda = closed_state(robot, m, 3)
    act, _ = oc.split(robot)

    def solved(t: float) -> np.ndarray:
        it, out = m.solve_loops(q[act] + qda * t + qdda * t * t / 2, q)
        assert it >= 0
        return out

    h = 2e-4
    qd, qdd = m.loop_motion(q, qda, qdda)
    np.testing.assert_allclose((solved(h) - solved(-h)) / (2 * h), qd, atol=1e-6)
    np.testing.assert_allclose(
        (solved(h) - 2 * q + solved(-h)) / h**2, qdd, atol=1e-4 * max(1, np.abs(qdd).max())
    )


# -- Pinocchio's constrained dynamics


def _pinocchio_forward(pin, robot, q, qd, tau):
    model = pinocchio_model(pin, robot)
    data = model.createData()
    num = robot.numeric()
    models = []
    for loop in num.loops:
        pa = pin.SE3(np.eye(3), np.array(loop.point, dtype=float).reshape(3))
        pb = pin.SE3(np.eye(3), np.array(loop.to_point, dtype=float).reshape(3))
        models.append(
            pin.RigidConstraintModel(
                pin.ContactType.CONTACT_3D,
                model,
                loop.link + 1,
                pa,
                loop.to + 1,
                pb,
                pin.ReferenceFrame.LOCAL,
            )
        )
    models = pin.StdVec_RigidConstraintModel(models)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(model, data, models, datas)
    settings = pin.ProximalSettings(1e-14, 1e-10, 100)
    return pin.constraintDynamics(model, data, q, qd, tau, models, datas, settings)


@pytest.mark.parametrize("name", ["fourbar", "fivebar", "parallelogram_arm"])
def test_actuated_forward_dynamics_agrees_with_pinocchios_constraint_dynamics(name, numpy_module):
    pin = pytest.importorskip("pinocchio")
    robot, m = numpy_module(name)
    q, qda, _ = closed_state(robot, m, 4)
    tau_a = np.random.default_rng(5).standard_normal(len(qda))
    qd, _ = m.loop_motion(q, qda, np.zeros(len(qda)))
    tau = np.zeros(robot.n)
    act, _ = oc.split(robot)
    tau[act] = tau_a
    qdd = _pinocchio_forward(pin, robot, q, qd, tau)
    qdda = m.actuated_forward_dynamics(q, qda, tau_a)
    np.testing.assert_allclose(qdda, qdd[act], rtol=1e-7, atol=1e-7)
    _, qdd_all = m.loop_motion(q, qda, qdda)
    np.testing.assert_allclose(qdd_all, qdd, rtol=1e-7, atol=1e-7)


# -- the generated C


def _nan_in_leg_one(numpy_module):
    """The Delta, a closed q, and q with a NaN in an elbow of leg 1: the three legs share no passive
    joint, so legs 2 and 3 stay closed (|phi| <= LOOP_TOL) after leg 1's first row, NaN."""
    robot, m = numpy_module("delta")
    q, _, _ = closed_state(robot, m, 7)
    bad = q.copy()
    bad[[link.name for link in robot.links].index("rod1a")] = np.nan
    phi = m.loop_residual(bad)
    nan = np.isnan(phi)
    assert nan[0] and not nan[3:].any() and np.abs(phi[~nan]).max() <= m.LOOP_TOL
    assert m.solve_loops(bad[m.ACTUATED], bad)[0] == -1
    return robot, m, q, bad


def test_generated_c_compiles_strictly_and_agrees_with_the_oracle(tmp_path, numpy_module):
    """The Delta's C, compiled with warnings as errors: NAME_solve_loops closes the loops from the
    assembled configuration (by the oracle's closure), takes 0 steps at a closed q, and gives -1
    where a NaN row of leg 1 comes before the closed rows of legs 2 and 3 (its max |phi| keeps a
    NaN); the actuated inverse dynamics, mass matrix and forward dynamics equal the oracle's.
    (The four-bar's C, with its singular guess, is checked through symdyn.compile in
    tests/test_compile.py.)"""
    robot, m, q, bad = _nan_in_leg_one(numpy_module)
    _, files = generated("delta")
    write_files({k: v for k, v in files.items() if k.startswith("delta_dynamics.")}, tmp_path)
    lib = ctypes.CDLL(str(compile_shared([tmp_path / "delta_dynamics.c"], tmp_path / "libdelta.so")))
    header = files["delta_dynamics.h"]
    assert "#define delta_NACT 3" in header and "#define delta_NPAS 9" in header
    P = ctypes.POINTER(ctypes.c_double)

    def ptr(a):
        return np.ascontiguousarray(a).ctypes.data_as(P)

    out = np.zeros(robot.n)
    assembled = np.array(analysis("delta").assembled[0])
    assert lib.delta_solve_loops(ptr(q[m.ACTUATED]), ptr(assembled), None, ptr(out)) >= 0
    assert np.abs(oc.closure(robot, out)[0]).max() < 1e-12
    for guess, want in ((bad, -1), (q, 0)):
        assert lib.delta_solve_loops(ptr(guess[m.ACTUATED]), ptr(guess), None, ptr(out)) == want
    np.testing.assert_array_equal(out, q)
    qda, qdda = np.array([1.3, -0.2, 0.5]), np.array([-0.4, 0.8, 0.1])
    s = oc.loop_state(robot, q, qda, qdda)
    out = np.zeros(3)
    lib.delta_actuated_inverse_dynamics(ptr(q), ptr(qda), ptr(qdda), None, ptr(out))
    np.testing.assert_allclose(out, s.tau_a, atol=1e-10)
    Ma = np.zeros(9)
    lib.delta_actuated_mass_matrix(ptr(q), None, ptr(Ma))
    np.testing.assert_allclose(Ma, s.Ma.ravel(), atol=1e-11)
    lib.delta_actuated_forward_dynamics(ptr(q), ptr(qda), ptr(s.tau_a), None, ptr(out))
    np.testing.assert_allclose(out, qdda, atol=1e-9)


# -- CasADi, MATLAB/Octave and LaTeX


def test_casadi_solves_the_loops_with_unrolled_steps_and_agrees_with_the_oracle(tmp_path):
    pytest.importorskip("casadi")
    robot, files = generated("fourbar")
    write_files({k: v for k, v in files.items() if k.endswith(".py")}, tmp_path)
    m = load_module(tmp_path / "fourbar_casadi.py", "_loops_fourbar_casadi")
    solve = m.build_solve_loops()
    q, it = solve([0.7], [0.7, -0.2, 1.6], [])
    q = np.array(q).ravel()
    assert 0 < int(it) <= 8 and np.abs(oc.closure(robot, q)[0]).max() < 1e-12
    assert int(solve([0.0], [0.0, 1.0, 1.0], [])[1]) == -1  # K_p singular
    assert int(solve([0.5], [0.5, np.nan, 1.0], [])[1]) == -1
    s = oc.loop_state(robot, q, [1.3], [-0.4])
    f = m.functions()
    assert float(f["actuated_inverse_dynamics"](q, 1.3, -0.4, [])) == pytest.approx(s.tau_a[0], abs=1e-12)
    assert float(f["actuated_forward_dynamics"](q, 1.3, s.tau_a, [])) == pytest.approx(-0.4, abs=1e-11)


@pytest.mark.skipif(shutil.which("octave-cli") is None, reason="GNU Octave (octave-cli) is not installed")
def test_octave_solves_the_loops_and_agrees_with_the_oracle(tmp_path, numpy_module):
    robot, files = generated("fourbar")
    write_files({k: v for k, v in files.items() if k.endswith(".m")}, tmp_path)
    # the Delta with a NaN in leg 1 only: -1 (Octave's max would skip the NaN rows)
    _, m, _, nan_leg = _nan_in_leg_one(numpy_module)
    write_files({k: v for k, v in generated("delta")[1].items() if k.endswith(".m")}, tmp_path)
    delta = " ".join("NaN" if np.isnan(x) else repr(float(x)) for x in nan_leg)
    qa = " ".join(repr(float(x)) for x in nan_leg[m.ACTUATED])
    script = (
        "[q, it] = fourbar_solve_loops(0.7, [0.7 -0.2 1.6]); [~, bad] = fourbar_solve_loops(0, [0 1 1]);"
        f"[~, nan_leg] = delta_solve_loops([{qa}], [{delta}]);"
        "tau = fourbar_actuated_inverse_dynamics(q, 1.3, -0.4, []);"
        "printf('%d %d %d %.17g %.17g %.17g %.17g\\n', it, bad, nan_leg, q, tau);"
    )
    out = subprocess.run(
        ["octave-cli", "--no-gui", "-q", "--eval", script],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    it, bad, nan_leg, *values = out.stdout.split()
    assert 0 < int(it) <= 8 and int(bad) == int(nan_leg) == -1
    q, tau = np.array(values[:3], dtype=float), float(values[3])
    assert np.abs(oc.closure(robot, q)[0]).max() < 1e-12
    assert tau == pytest.approx(oc.loop_state(robot, q, [1.3], [-0.4]).tau_a[0], abs=1e-12)


def test_latex_prints_the_closure_and_its_jacobian():
    _, files = generated("fourbar")
    tex = files["fourbar_dynamics.tex"]
    assert "\\section*{Closed loops}" in tex and "Loop \\texttt{B}: a point of \\texttt{coupler}" in tex
    assert "phi_{2} &=" in tex and "K_{2,3} &=" in tex and "phi_{3}" not in tex


# -- symdyn simulate


def test_simulate_integrates_the_actuated_joints_and_closes_the_loops_every_step(capsys, tmp_path):
    from symdyn.cli.main import main

    robot = loaded("fourbar")
    out = tmp_path / "fb.csv"
    args = ["simulate", str(LOOPS_DIR / "fourbar.yaml"), "--q0", "0.7", "-0.2", "1.6", "--qd0", "2", "0", "0"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main([*args, "--tau", "0.05", "--duration", "0.2", "--dt", "0.005", "--out", str(out)]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].startswith(f"{out}: 41 samples") and "1 actuated joints" in printed[0]
    assert printed[1].startswith("largest closure residual max |phi|: ")
    assert float(printed[1].split()[-1]) <= 1e-12
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    for row in data[::10]:
        q, qd = row[1:4], row[4:7]
        phi, K, _ = oc.closure(robot, q)
        assert np.abs(phi).max() < 1e-11 and np.abs(K @ qd).max() < 1e-10
    # the crank's power equals the rate of change of the energy (no friction): E(t) - E(0) = tau int qd1
    energy = [kinetic_energy(robot, r[1:4], r[4:7]) + potential_energy(robot, r[1:4]) for r in data]
    work = 0.05 * (data[-1, 1] - data[0, 1])
    assert energy[-1] - energy[0] == pytest.approx(work, abs=1e-7)
    line = refused(
        capsys,
        *args,
        "--integrator",
        "rk45",
        "--duration",
        "0.1",
        "--dt",
        "0.01",
        "--out",
        str(out),
        seconds=60,
    )
    assert "integrated with rk4 or semi-implicit, not 'rk45'" in line


def test_a_weld_closes_position_and_orientation_and_agrees_with_the_oracle(tmp_path_factory):
    """Four planar bars from the base whose last frame is welded back to the base frame: 6
    closure rows, 3 out of the plane dropped, mobility 1 (the weld's rotation rows and drift)."""
    bar = {
        "joint": "revolute",
        "a": 0.3,
        "mass": 1.0,
        "com": [0.15, 0, 0],
        "inertia": {"iyy": 0.01, "izz": 0.01},
    }
    data = {
        "name": "welded",
        "convention": "modified",
        "links": [{"name": "b1", **{**bar, "a": 0}}]
        + [{"name": f"b{i}", "parent": f"b{i - 1}", **bar} for i in range(2, 5)],
        "loops": [
            {
                "name": "W",
                "link": "b4",
                "point": [0.3, 0, 0],
                "to": "base",
                "to_point": [0.5, 0, 0],
                "type": "weld",
            }
        ],
        "actuated": ["b1"],
    }
    robot = robot_from_data(data, "welded.yaml")
    an = analyse(robot.resolved())
    assert an.rows == (0, 1, 5) and an.passive == (1, 2, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        files = render(robot, targets=("python",))
    path = tmp_path_factory.mktemp("welded") / "welded_numpy.py"
    path.write_text(files["welded_numpy.py"])
    m = load_module(path, "_loops_welded")
    q, qda, qdda = closed_state(robot, m, 6, an)
    phi, _, _ = oc.closure(robot, q)
    assert np.abs(phi).max() < 1e-12  # the oracle's closure: positions and the rotation vector
    assert abs(math.remainder(q.sum(), 2 * math.pi)) < 1e-12  # the frames' orientations agree
    s = oc.loop_state(robot, q, qda, qdda)
    np.testing.assert_allclose(m.loop_motion(q, qda, qdda)[1], s.qdd, atol=1e-10)
    np.testing.assert_allclose(m.actuated_inverse_dynamics(q, qda, qdda), s.tau_a, atol=1e-10)
    np.testing.assert_allclose(m.actuated_forward_dynamics(q, qda, s.tau_a), qdda, atol=1e-9)
