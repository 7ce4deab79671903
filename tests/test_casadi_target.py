"""The CasADi target (NAME_casadi.py and NAME_<function>.casadi) against the numeric oracle.

Every example robot is derived once per session (tests/robots.py) and rendered
once per module; the files are written to a temporary folder, the module is
imported and the serialised functions are loaded with casadi.Function.load.
At 50 random states (free parameters random and positive, in dyn.params order)
all seven functions, from the module and from the .casadi files, must match
the RNEA/CRBA oracle symdyn.rnea to a relative 1e-9. Then the functions are
used where users need them: inside an Opti/IPOPT problem, a Newton
rootfinder and casadi's own C code generation.
"""

from __future__ import annotations

import ast
import hashlib
import importlib
import importlib.util
import math
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from types import ModuleType

import casadi as ca
import numpy as np
import pytest
from robots import (
    ASYMMETRIC_PARAMS,
    EXAMPLE_NAMES,
    assert_close,
    asymmetric_friction,
    derived_robot,
    example,
    example_context,
    friction_closed_form,
    friction_states,
    random_params,
    random_state,
    regressor_oracle,
)

from symdyn.codegen import FUNCTION_NAMES
from symdyn.codegen import casadi as casadi_backend
from symdyn.codegen import render as render_targets
from symdyn.codegen.derivative_functions import DERIVATIVE_FUNCTION_NAMES
from symdyn.codegen.functions import build_functions
from symdyn.codegen.render import RenderContext

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
N_STATES = 50
RTOL = 1e-9
ROOT = Path(__file__).resolve().parents[1]


def _context(name: str) -> RenderContext:
    """What symdyn.codegen.context builds, over the session-wide cached derivation."""
    return example_context(name)


@cache
def _files(name: str) -> dict[str, str | bytes]:
    return casadi_backend.render(_context(name))


@dataclass
class Generated:
    name: str
    robot: object
    ctx: RenderContext
    files: dict[str, str | bytes]
    module: ModuleType
    functions: dict[str, ca.Function]  # from the module's functions()
    loaded: dict[str, ca.Function]  # from the .casadi files


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """robot name -> Generated (rendered, written and imported once per robot)."""
    cache_: dict[str, Generated] = {}

    def get(name: str) -> Generated:
        if name not in cache_:
            ctx = _context(name)
            files = _files(name)
            folder = tmp_path_factory.mktemp(f"casadi_{name}")
            for file, content in files.items():
                data = content.encode() if isinstance(content, str) else content
                (folder / file).write_bytes(data)
            path = folder / f"{ctx.name}_casadi.py"
            spec = importlib.util.spec_from_file_location(f"_symdyn_casadi_{name}", path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            names = [spec.name for spec in ctx.functions]  # the seven, tip_wrench_torque (PoE), derivatives
            loaded = {f: ca.Function.load(str(folder / f"{ctx.name}_{f}.casadi")) for f in names}
            cache_[name] = Generated(name, example(name), ctx, files, module, module.functions(), loaded)
        return cache_[name]

    return get


def _oracle(robot, params, q, qd, qdd, tau) -> dict[str, np.ndarray]:
    """The seven functions from symdyn.rnea alone (C by polarisation of V, see below)."""
    n = len(q)
    V = rn.bias_torque(robot, q, qd, params)
    # V_k(qd) = qd^T Gamma_k qd is a quadratic form with Gamma_k symmetric (Christoffel
    # symbols), and C_kj = (Gamma_k qd)_j, so C e_j = (V(qd + e_j) - V(qd - e_j)) / 4 exactly.
    E = np.eye(n)
    C = np.column_stack(
        [
            (rn.bias_torque(robot, q, qd + E[j], params) - rn.bias_torque(robot, q, qd - E[j], params)) / 4
            for j in range(n)
        ]
    )
    return {
        "inverse_dynamics": rn.rnea(robot, q, qd, qdd, params),
        "mass_matrix": rn.mass_matrix(robot, q, params),
        "coriolis_matrix": C,
        "coriolis": V,
        "gravity": rn.gravity_torque(robot, q, params),
        "friction": rn.friction_torque(robot, qd, params),
        "forward_dynamics": rn.forward_dynamics(robot, q, qd, tau, params),
    }


def _call(f: ca.Function, values: dict[str, np.ndarray]) -> np.ndarray:
    """Call f with its inputs by name; vectors come back flat, M and C as n x n, Y and Yb as matrices."""
    out = f.call({f.name_in(i): values[f.name_in(i)] for i in range(f.n_in())})[f.name_out(0)]
    out = np.asarray(out.full())
    return out if f.name_out(0) in ("M", "C", "Y", "Yb") else out[:, 0]


# --------------------------------------------------------------------------- the files


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_files_signatures_and_module_text(name, generated):
    g = generated(name)
    robot, dyn = g.ctx.robot, g.ctx.dynamics
    n, k = robot.n, len(dyn.params)
    names = [spec.name for spec in g.ctx.functions]
    assert names[: len(FUNCTION_NAMES)] == list(FUNCTION_NAMES)
    tip = ["tip_wrench_torque"] if robot.convention == "poe" else []
    assert names[len(FUNCTION_NAMES) :] == tip + list(DERIVATIVE_FUNCTION_NAMES)
    expected = {f"{robot.name}_casadi.py"} | {f"{robot.name}_{f}.casadi" for f in names}
    assert set(g.files) == expected
    text = g.files[f"{robot.name}_casadi.py"]
    assert isinstance(text, str)
    assert all(isinstance(g.files[f"{robot.name}_{f}.casadi"], bytes) for f in names)

    # header comments, standalone (only casadi and math), a docstring for every function
    assert text.startswith("# Generated by symdyn")
    tree = ast.parse(text)
    imports = {a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names}
    assert imports <= {"casadi", "math"} and "casadi" in imports
    assert not any(isinstance(node, ast.ImportFrom) for node in ast.walk(tree))
    defs = [node for node in tree.body if isinstance(node, ast.FunctionDef)]
    assert [d.name for d in defs] == [f"build_{f}" for f in names] + ["functions"]
    assert all(ast.get_docstring(d) for d in defs) and ast.get_docstring(tree)
    # one Python statement per eliminated temporary
    for d, spec in zip(defs, g.ctx.functions, strict=False):
        temps = [
            s
            for s in d.body
            if isinstance(s, ast.Assign)
            and isinstance(s.targets[0], ast.Name)
            and re.fullmatch(r"x\d+", s.targets[0].id)
        ]
        assert len(temps) == len(spec.temporaries), spec.name
    assert "**" not in text  # small integer powers are products
    assert (n, k) == (g.module.NDOF, g.module.NPARAM)
    assert tuple(str(p) for p in dyn.params) == g.module.PARAMETERS

    # names, inputs, outputs, sizes; module and file agree
    assert list(g.functions) == names
    sizes = {"q": n, "qd": n, "qdd": n, "tau": n, "p": k, "F": 6}
    for spec in g.ctx.functions:
        for f in (g.functions[spec.name], g.loaded[spec.name]):
            assert f.name() == spec.name
            assert f.name_in() == [inp.name for inp in spec.inputs]
            assert [f.size_in(i) for i in range(f.n_in())] == [(sizes[x], 1) for x in f.name_in()]
            assert f.name_out() == [r.name for r in spec.results]
            for i, r in enumerate(spec.results):
                assert f.size_out(i) == (r.rows, r.cols)
                assert f.sparsity_out(i).is_dense()
        assert g.functions[spec.name].serialize() == g.loaded[spec.name].serialize()


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_matches_rnea_module_and_loaded_files(name, generated):
    g = generated(name)
    robot, dyn = g.robot, g.ctx.dynamics
    rng = np.random.default_rng(sum(map(ord, name)))
    p = random_params(robot, rng)
    assert len(p) == len(dyn.params)
    params = p if len(p) else None
    for _ in range(N_STATES):
        q, qd, qdd = random_state(robot, rng)
        tau = rng.uniform(-5, 5, robot.n)
        values = {"q": q, "qd": qd, "qdd": qdd, "tau": tau, "p": p}
        want = _oracle(robot, params, q, qd, qdd, tau) | regressor_oracle(dyn, q, qd, qdd, params)
        for f in FUNCTION_NAMES:
            got = _call(g.functions[f], values)
            assert_close(got, want[f], RTOL, what=f"{name}.{f}")
            np.testing.assert_array_equal(_call(g.loaded[f], values), got, err_msg=f"{name}.{f} loaded")
        # C is the Christoffel matrix: C qd = V
        C = _call(g.functions["coriolis_matrix"], values).reshape(robot.n, robot.n)
        assert_close(C @ qd, want["coriolis"], RTOL, what=f"{name}: C qd = V")


# --------------------------------------------------------------------------- determinism

_HASH_SCRIPT = """
import hashlib, sys, warnings
warnings.simplefilter("ignore")
from symdyn.codegen import render
from symdyn.parsers import load_robot
files = render(load_robot(sys.argv[1]), targets=("casadi",))
for name in sorted(files):
    data = files[name]
    data = data.encode() if isinstance(data, str) else data
    print(name, hashlib.sha256(data).hexdigest())
"""


def _digests(files) -> str:
    lines = []
    for name in sorted(files):
        data = files[name].encode() if isinstance(files[name], str) else files[name]
        lines.append(f"{name} {hashlib.sha256(data).hexdigest()}")
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("name", ["roger_arm", "planar_3r"])
def test_render_twice_gives_identical_bytes(name):
    """The public render path, twice in this process, equals the fixture's files byte for byte."""
    first = render_targets(example(name), targets=("casadi",))
    second = render_targets(example(name), targets=("casadi",))
    assert first == second == _files(name)


def test_serialised_bytes_do_not_depend_on_the_process():
    """Other processes with other hash seeds write the same bytes (text and .casadi)."""
    path = ROOT / "examples" / "roger_arm.yaml"
    want = _digests(_files("roger_arm"))
    for seed in ("0", "12345"):
        env = dict(os.environ, PYTHONHASHSEED=seed)
        out = subprocess.run(
            [sys.executable, "-c", _HASH_SCRIPT, str(path)],
            capture_output=True,
            text=True,
            env=env,
            check=True,
            timeout=120,
        )
        assert out.stdout == want


# --------------------------------------------------------------------------- in use


def test_opti_minimum_effort_static_pose(generated):
    """planar_3r: the pose of least squared gravity torque with the hand at a given height.

    min ||G(q)||^2 subject to y_hand(q) = 0.3, -pi <= q <= pi, solved by IPOPT over the
    loaded .casadi gravity function from a folded guess (link 1 up, link 2 down). Heights
    0.4 or 0.2 could be reached with every link vertical (G = 0); 0.3 cannot, so the
    optimum is a genuine trade-off, inside the bounds.
    """
    g = generated("planar_3r")
    robot = g.robot
    G = g.loaded["gravity"]
    lengths = (0.5, 0.4, 0.3)  # DH a of examples/planar_3r.yaml; gravity along -y
    height_goal = 0.3

    def hand_height(q):
        return sum(a * ca.sin(ca.sum1(q[: i + 1])) for i, a in enumerate(lengths))

    opti = ca.Opti()
    q = opti.variable(3)
    torque = G(q, ca.DM.zeros(0, 1))
    opti.minimize(ca.sumsqr(torque))
    opti.subject_to(hand_height(q) == height_goal)
    opti.subject_to(opti.bounded(-math.pi, q, math.pi))
    q0 = np.array([1.5, -2.5, -2.5])
    opti.set_initial(q, q0)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes", "tol": 1e-10})
    sol = opti.solve()
    assert sol.stats()["success"] and sol.stats()["return_status"] == "Solve_Succeeded"

    q_star = np.asarray(sol.value(q)).ravel()
    G_star = rn.gravity_torque(robot, q_star)
    assert_close(np.asarray(sol.value(torque)).ravel(), G_star, RTOL)
    # the hand formula reads the robot as the oracle does: link 3's centre of mass (base
    # frame) is half its length back from the hand along the link
    angles = np.cumsum(q_star)
    hand = np.array([sum(a * f(t) for a, t in zip(lengths, angles, strict=True)) for f in (np.cos, np.sin)])
    com3 = hand - lengths[2] / 2 * np.array([np.cos(angles[2]), np.sin(angles[2])])
    np.testing.assert_allclose(rn.link_com_positions(robot, q_star)[2], [*com3, 0.0], atol=1e-12)
    assert abs(hand[1] - height_goal) < 1e-8
    assert G_star @ G_star < rn.gravity_torque(robot, q0) @ rn.gravity_torque(robot, q0)
    assert 0.1 < G_star @ G_star < 1.0  # the height cannot be reached with G = 0
    assert np.all(np.abs(q_star) < math.pi - 0.1)  # no bound active
    # first-order optimality: grad ||G||^2 is parallel to grad y_hand at the solution
    x = ca.SX.sym("x", 3)
    J = ca.Function(
        "J", [x], [ca.gradient(ca.sumsqr(G(x, ca.DM.zeros(0, 1))), x), ca.gradient(hand_height(x), x)]
    )
    df, dh = (np.asarray(v.full()).ravel() for v in J(q_star))
    assert np.linalg.norm(df - (df @ dh) / (dh @ dh) * dh) < 1e-6 * max(np.linalg.norm(df), 1.0)


def test_rootfinder_implicit_euler_step(generated):
    """puma560: one implicit Euler step qd1 = qd0 + h FD(q0 + h qd1, qd1, tau), by Newton."""
    g = generated("puma560")
    robot = g.robot
    FD = g.functions["forward_dynamics"]
    h = 0.01
    rng = np.random.default_rng(3)
    q0, _, _ = random_state(robot, rng)
    qd0 = rng.choice([-1.0, 1.0], robot.n) * rng.uniform(1.0, 2.0, robot.n)  # sign(qd) stays put
    tau = rng.uniform(-20, 20, robot.n)
    v = ca.SX.sym("v", robot.n)
    residual = v - qd0 - h * FD(q0 + h * v, v, tau, ca.DM.zeros(0, 1))
    step = ca.rootfinder("step", "newton", ca.Function("r", [v], [residual]), {"abstol": 1e-13})
    qd1 = np.asarray(step(qd0).full()).ravel()
    assert step.stats()["success"]
    q1 = q0 + h * qd1
    assert np.all(np.sign(qd1) == np.sign(qd0))
    assert_close((qd1 - qd0) / h, rn.forward_dynamics(robot, q1, qd1, tau), RTOL)
    assert not np.allclose(qd1, qd0 + h * rn.forward_dynamics(robot, q0, qd0, tau), rtol=1e-6)


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")
def test_casadi_codegen_compiles(generated, tmp_path):
    """casadi.CodeGenerator on a generated function gives C that compiles and agrees."""
    g = generated("roger_arm")
    f = g.loaded["inverse_dynamics"]
    cg = ca.CodeGenerator("roger_arm_id.c")
    cg.add(f)
    cg.generate(str(tmp_path) + os.sep)
    lib = tmp_path / "roger_arm_id.so"
    subprocess.run(
        ["gcc", "-shared", "-fPIC", "-O1", "-o", str(lib), str(tmp_path / "roger_arm_id.c")],
        check=True,
        capture_output=True,
        timeout=120,
    )
    compiled = ca.external("inverse_dynamics", str(lib))
    rng = np.random.default_rng(5)
    p = random_params(g.robot, rng)
    for _ in range(5):
        q, qd, qdd = random_state(g.robot, rng)
        values = {"q": q, "qd": qd, "qdd": qdd, "p": p}
        assert_close(_call(compiled, values), _call(f, values), 1e-13)


def test_direction_dependent_friction_against_rnea(tmp_path):
    """c+ [qd > 0] - c- [qd < 0] as casadi comparisons: F, tau, qdd, Y and dtau/dqd of the module's
    functions equal the oracle (F the hand-written closed form) at rates of both signs and exactly 0."""
    robot = asymmetric_friction()
    dyn = derived_robot(robot, "newton-euler")
    ctx = RenderContext(robot, dyn, tuple(build_functions(dyn)), "double")
    for file, content in casadi_backend.render(ctx).items():
        (tmp_path / file).write_bytes(content.encode() if isinstance(content, str) else content)
    spec = importlib.util.spec_from_file_location("_symdyn_casadi_asym", tmp_path / f"{ctx.name}_casadi.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    functions = module.functions()
    p = np.array([ASYMMETRIC_PARAMS[str(s)] for s in dyn.params])
    for k, (q, qd, qdd, tau) in enumerate(zip(*friction_states(), strict=True)):
        values = {"q": q, "qd": qd, "qdd": qdd, "tau": tau, "p": p}
        want = _oracle(robot, ASYMMETRIC_PARAMS, q, qd, qdd, tau) | regressor_oracle(dyn, q, qd, qdd, p)
        np.testing.assert_allclose(_call(functions["friction"], values), friction_closed_form(qd), atol=1e-15)
        for f in FUNCTION_NAMES:
            assert_close(_call(functions[f], values), want[f], RTOL, what=f"asymmetric_friction.{f}")
        if k < 2:  # every rate away from 0: dtau/dqd by central differences of the oracle
            f = functions["inverse_dynamics_derivatives"]
            out = f.call({f.name_in(i): values[f.name_in(i)] for i in range(f.n_in())})
            E = np.eye(3) * 1e-6
            fd = [(rn.rnea(robot, q, qd + e, qdd, p) - rn.rnea(robot, q, qd - e, qdd, p)) / 2e-6 for e in E]
            got = np.asarray(out[f.name_out(1)].full()).reshape(3, 3)
            np.testing.assert_allclose(got, np.column_stack(fd), rtol=1e-6, atol=1e-7)


def test_a_killed_runs_temporary_folder_is_removed_by_the_next(tmp_path, monkeypatch):
    """Issue 34 item 9: serialise's TMPDIR/symdyn-casadi-* of a run killed by kill -9 stayed; the
    next run removes those whose process is gone, and keeps a live run's."""
    import os
    import tempfile

    from symdyn.codegen.casadi import target

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    dead = tmp_path / f"{target.TEMPORARY_PREFIX}999999999-abcdefgh"  # no such process
    live = tmp_path / f"{target.TEMPORARY_PREFIX}{os.getpid()}-abcdefgh"
    for folder in (dead, live):
        folder.mkdir()
        (folder / "arm_casadi.py").write_text("x = 1\n")
    from robots import example_context

    files = target.render(example_context("roger_arm"))
    assert "roger_arm_mass_matrix.casadi" in files
    assert sorted(tmp_path.iterdir()) == [live]  # and its own folder is gone
