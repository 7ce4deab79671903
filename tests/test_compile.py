"""symdyn.compile, its cache and the applications on it, against the generated NumPy module.

The compiled C (through cffi, the stepping loop in C) must give what the generated NumPy module
gives (the NumPy backend, chosen by pointing CC at no compiler), to 1e-12: every generated
function, simulated trajectories of a serial arm and a tree robot with every fixed-step
integrator, computed-torque tracking, and the energy drift of a frictionless free swing. The
forward dynamics is also checked against the numeric oracle symdyn.rnea. The cache must rebuild
a corrupt or foreign entry and never trust it. Every test uses a temporary cache folder.
"""

from __future__ import annotations

import inspect
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from cbuild import compilers
from robots import (
    ASYMMETRIC_PARAMS,
    asymmetric_friction,
    example,
    friction_closed_form,
    friction_states,
    regressor_oracle,
    y_robot,
)

import symdyn
from symdyn.apps.compilation import cache
from symdyn.apps.compilation.calling import numpy_solve_loops
from symdyn.apps.compilation.compile import CompiledDynamics, compile
from symdyn.apps.simulation.control import ComputedTorque, Reference, track
from symdyn.apps.simulation.simulate import simulate
from symdyn.cli.main import main
from symdyn.codegen import functions as fn
from symdyn.errors import SymdynError, SymdynWarning
from symdyn.oracle.closed_loops import closure
from symdyn.rnea import forward_dynamics as oracle_forward
from symdyn.rnea import rnea as oracle_rnea

PLANAR = Path(__file__).resolve().parent.parent / "examples" / "planar_3r.yaml"
pytestmark = pytest.mark.skipif(not compilers(), reason="needs a C compiler")


@pytest.fixture(autouse=True, scope="module")
def module_cache(tmp_path_factory):
    """One temporary cache for the module's tests (each robot is built once)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(cache.CACHE_ENV, str(tmp_path_factory.mktemp("cache")))
        mp.delenv("CC", raising=False)
        yield


@pytest.fixture
def temporary_cache(tmp_path, monkeypatch):
    """An empty cache of its own, for the tests of the cache itself."""
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def _numpy_backend(robot, monkeypatch, params=None):
    """The same robot on the generated NumPy module (no C compiler found)."""
    with monkeypatch.context() as mp:
        mp.setenv("CC", "no-such-compiler-symdyn")
        with pytest.warns(SymdynWarning, match="times slower"):
            mp.setattr("symdyn.apps.compilation.compile._warned", False)
            slow = compile(robot, params)
    assert slow.backend == "numpy"
    return slow


ROBOTS = {"arm": lambda: example("puma560"), "tree": y_robot}


def _params(robot):
    return {str(p): 0.3 + 0.1 * k for k, p in enumerate(robot.params)} or None


@pytest.mark.parametrize("name", ROBOTS)
def test_every_function_equals_the_numpy_module(name, monkeypatch):
    robot = ROBOTS[name]()
    fast = compile(robot, _params(robot))
    assert fast.backend == "c" and "forward_dynamics" in fast.functions
    rng = np.random.default_rng(3)
    n = robot.n
    args = {
        "q": rng.uniform(-2, 2, (4, n)),
        "qd": rng.uniform(-2, 2, (4, n)),
        "qdd": rng.uniform(-2, 2, (4, n)),
    }
    args["tau"] = rng.uniform(-5, 5, (4, n))
    for f in fast._entry.meta["functions"]:
        inputs = [args[i] for i, _ in f["inputs"] if i != "p"]
        batch = getattr(fast, f["name"])(*inputs)
        want = getattr(fast.module, f["name"])(*inputs, fast.p)
        one = getattr(fast, f["name"])(*(x[1] for x in inputs))
        # output by output: a function with several outputs returns a tuple (of several shapes)
        for b, o, w in zip(*((x if isinstance(x, tuple) else (x,)) for x in (batch, one, want)), strict=True):
            np.testing.assert_allclose(b, w, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(o, w[1], rtol=1e-12, atol=1e-12)
    for k in range(4):
        qdd = fast.forward_dynamics(args["q"][k], args["qd"][k], args["tau"][k])
        want = oracle_forward(robot, args["q"][k], args["qd"][k], args["tau"][k], fast.p)
        np.testing.assert_allclose(qdd, want, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", ROBOTS)
@pytest.mark.parametrize("integrator", ["rk4", "euler", "semi-implicit"])
def test_simulation_in_c_equals_the_numpy_path(name, integrator, monkeypatch):
    robot = ROBOTS[name]()
    params = _params(robot)
    fast, slow = compile(robot, params), _numpy_backend(robot, monkeypatch, params)
    q0 = np.linspace(0.2, -0.4, robot.n)
    for tau in (None, ["0.5*sin(3*t)"] * robot.n):
        a = simulate(fast, q0, duration=0.25, dt=2e-3, tau=tau, integrator=integrator)
        b = simulate(slow, q0, duration=0.25, dt=2e-3, tau=tau, integrator=integrator)
        for x, y in ((a.q, b.q), (a.qd, b.qd), (a.tau, b.tau)):
            np.testing.assert_allclose(x, y, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", ROBOTS)
def test_energy_along_a_swing_equals_the_numpy_path(name, monkeypatch):
    """The kinetic energy 1/2 qd^T M(q) qd along a free swing (its drift) is the NumPy path's."""
    robot = ROBOTS[name]()
    params = _params(robot)
    fast, slow = compile(robot, params), _numpy_backend(robot, monkeypatch, params)
    q0, qd0 = np.linspace(0.1, 0.5, robot.n), np.linspace(1.0, -0.5, robot.n)
    drift = []
    for plant in (fast, slow):
        traj = simulate(plant, q0, qd0, duration=0.3, dt=1e-3)
        M = plant.mass_matrix(traj.q)
        kinetic = 0.5 * np.einsum("ki,kij,kj->k", traj.qd, M, traj.qd)
        drift.append(kinetic - kinetic[0])
    np.testing.assert_allclose(drift[0], drift[1], rtol=1e-12, atol=1e-12)


def test_tracking_in_c_equals_the_python_callback(monkeypatch):
    robot = symdyn.load_robot(PLANAR)
    plant = compile(robot)
    reference = Reference(["0.3*sin(2*t)", "0.2*cos(t)", "t/4"])
    controller = ComputedTorque(plant, 100, 20)
    a = track(plant, reference, controller, duration=0.2, dt=1e-3)
    b = simulate(
        plant,
        *reference(0.0)[:2],
        duration=0.2,
        dt=1e-3,
        tau=lambda t, q, qd: controller.law(reference)(t, q, qd),
    )
    np.testing.assert_allclose(a.q, b.q, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a.tau, b.tau, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_adaptive_integrators_agree_with_fine_rk4(method):
    robot = symdyn.load_robot(PLANAR)
    a = simulate(robot, [0.1, 0.2, 0.3], duration=0.5, dt=1e-2, integrator=method, rtol=1e-10, atol=1e-12)
    b = simulate(robot, [0.1, 0.2, 0.3], duration=0.5, dt=1e-4)
    np.testing.assert_allclose(a.q[-1], b.q[-1], atol=1e-8)
    assert a.integrator == method and a.q.shape == (51, 3)


def _family(dyn, x):
    n, M, G = dyn.n, dyn.compact["M"], dyn.compact["G"]
    both = fn.FunctionRow(
        "mass_and_gravity", "M and G", (x.q, x.p),
        (fn.joint_matrix_output("M", n, "M"), fn.vector_output("G", n, "G")), (*M, *G),
    )  # fmt: skip
    tall = fn.FunctionRow(
        "stacked", "[M; 2M]", (x.q, x.p), (fn.Output("S", 2 * n, n, "S", ("2n", "n")),), (*M, *(2 * M))
    )
    return [both, tall]


def test_any_generated_function_becomes_a_method(monkeypatch):
    """Several outputs (a tuple) and a non-square output, one state and a batch."""
    monkeypatch.setattr(fn, "FAMILIES", (*fn.FAMILIES, _family))
    robot = symdyn.load_robot(PLANAR)
    c = compile(robot)
    q = np.array([[0.1, 0.2, 0.3], [-0.4, 0.5, 0.6]])
    M, G = c.mass_and_gravity(q)
    np.testing.assert_allclose(M, c.mass_matrix(q), rtol=1e-14)
    np.testing.assert_allclose(G, c.gravity(q), rtol=1e-14)
    S = c.stacked(q[0])
    assert S.shape == (6, 3)
    np.testing.assert_allclose(S[3:], 2 * c.mass_matrix(q[0]), rtol=1e-14)


def test_cache_hit_corrupt_and_foreign_entries(temporary_cache):
    robot = symdyn.load_robot(PLANAR)
    first = compile(robot)
    folder = first._entry.path
    assert compile(robot)._entry.path == folder
    library = folder / first._entry.meta["library"]
    library.write_bytes(library.read_bytes()[:100])  # truncated: the digest no longer matches
    assert cache.lookup(first._entry.key) is None and not folder.exists()
    again = compile(robot)
    assert again._entry.path == folder and again.mass_matrix([0, 0, 0]).shape == (3, 3)
    manifest = folder / "manifest.json"
    data = json.loads(manifest.read_text())
    data["key"] = "0" * 64  # a foreign entry under this key
    manifest.write_text(json.dumps(data))
    assert cache.lookup(first._entry.key) is None
    root, count, size = cache.usage()
    assert root == temporary_cache and count == 0 and size == 0
    compile(robot)
    assert cache.usage()[1] == 1 and cache.clear() == 1 and cache.usage()[1] == 0


def test_a_hit_verifies_what_it_loads_and_the_rest_on_first_use(temporary_cache):
    """A warm compile hashes the library it loads; a file it does not load is verified when first read."""
    robot = symdyn.load_robot(PLANAR)
    first = compile(robot)
    entry = first._entry
    library, module = entry.file(entry.meta["library"]), entry.file(entry.meta["numpy"])
    source = entry.path / "planar_3r_dynamics.c"
    source.write_text("/* edited */\n" + source.read_text())  # never loaded by a hit
    text = module.read_text()
    module.write_text(
        text.replace("def mass_matrix(", "def mass_matrix(*args):\n    return 0\n\n\ndef _old(")
    )
    warm = compile(robot)
    assert warm._entry.path == entry.path and source.read_text().startswith("/* edited */")
    q = np.array([0.3, -0.2, 0.5])
    assert np.array_equal(warm.module.mass_matrix(q, None), warm.mass_matrix(q))  # rebuilt, not trusted
    assert not source.read_text().startswith("/* edited */") and module.read_text() == text
    data = library.read_bytes()
    library.unlink()  # a new file: the loaded library (mapped by this process) stays intact
    library.write_bytes(data[:100])  # the file a hit loads, truncated: a miss, then a rebuild
    again = compile(robot)
    assert again._entry.path == entry.path and cache.lookup(entry.key) is not None
    assert np.array_equal(again.mass_matrix(q), warm.mass_matrix(q))
    lazy = cache.lookup(entry.key, lambda meta: [])
    (entry.path / "symdyn_step.c").write_text("int x;\n")
    with pytest.raises(cache.CorruptEntryError, match="symdyn_step.c"):
        lazy.file("symdyn_step.c")
    assert not entry.path.exists()


def test_parameters_bound_by_name_or_vector():
    robot = example("roger_arm")
    names = [str(p) for p in robot.params]
    values = [0.2 + 0.1 * k for k in range(len(names))]
    a = compile(robot, dict(zip(names, values, strict=True)))
    b = CompiledDynamics(robot, values)
    q = [0.3, -0.2]
    np.testing.assert_array_equal(a.mass_matrix(q), b.mass_matrix(q))


def test_cli_cache_and_a_warm_simulate(tmp_path, capsys, temporary_cache):
    out = tmp_path / "a.csv"
    argv = ["simulate", str(PLANAR), "--duration", "0.1", "--dt", "1e-2", "--out", str(out)]
    assert main(argv) == 0
    cold = out.read_text()
    assert main(argv) == 0 and out.read_text() == cold
    assert main([*argv[:-2], "--integrator", "dop853", "--rtol", "1e-9", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["cache"]) == 0
    assert "1 entry" in capsys.readouterr().out
    assert main(["cache", "--clear"]) == 0
    assert "removed 1 entry" in capsys.readouterr().out


def test_the_parser_methods_are_the_derivations():
    from symdyn.cli.common import METHODS
    from symdyn.dynamics import METHODS as DERIVED

    assert METHODS == DERIVED


def test_analyze_on_the_cached_plant_equals_the_robot_route():
    """analyze on a CompiledDynamics (its kinematics read back from the cache) is analyze on the Robot."""
    from symdyn.apps.analysis import analyze
    from symdyn.apps.compilation.compile import cached_dynamics

    robot = example("puma560")
    q, qd = np.linspace(0.1, 0.6, 6), np.linspace(-0.3, 0.2, 6)
    want = analyze(robot, q, qd, torque_limits=50)
    for _ in range(2):  # built, then read back from the cache without the Robot
        plant = cached_dynamics({"name": "puma"}, lambda: robot)
        got = analyze(plant, q, qd, torque_limits=50)
        np.testing.assert_allclose(got.J, want.J, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(got.Jdot_qd, want.Jdot_qd, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(got.polytope.vertices, want.polytope.vertices, rtol=1e-10, atol=1e-10)
        assert got.axes == want.axes
    assert not isinstance(plant.robot, type(robot))


def test_two_processes_building_one_entry(temporary_cache):
    """Concurrent builds of the same robot both succeed and leave one verified entry."""
    import subprocess
    import sys

    code = f"import symdyn; c = symdyn.compile(symdyn.load_robot({str(PLANAR)!r})); print(c.backend)"
    procs = [
        subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True) for _ in range(2)
    ]
    assert [p.communicate(timeout=300)[0].strip() for p in procs] == ["c", "c"]
    assert all(p.returncode == 0 for p in procs)
    root, count, _ = cache.usage()
    assert count == 1 and not list((root / "v1").glob(".build-*"))


def _urdf_declaring_xacro(folder: Path) -> Path:
    """The two-link URDF as exported URDFs are: declaring the xacro namespace, needing no expansion."""
    text = (Path(__file__).parent / "data" / "urdf" / "two_link.urdf").read_text()
    path = folder / "exported.urdf"
    path.write_text(
        text.replace(
            '<robot name="two_link">', '<robot name="two_link" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        )
    )
    return path


@pytest.mark.parametrize("kind", ["robot file", "URDF declaring xacro"])
def test_a_warm_simulate_imports_no_sympy(tmp_path, temporary_cache, kind):
    """The warm command-line path (cached library) runs without importing SymPy (docs/speed.md),
    for a URDF too when it only declares the xacro namespace (every example-robot-data URDF does)."""
    import subprocess
    import sys

    out = tmp_path / "a.csv"
    robot = PLANAR if kind == "robot file" else _urdf_declaring_xacro(tmp_path)
    argv = ["simulate", str(robot), "--duration", "0.1", "--dt", "1e-2", "--out", str(out)]
    assert main(argv) == 0  # builds the entry
    code = (
        "import sys; from symdyn.cli.main import main; "
        f"assert main({argv!r}) == 0; print(sorted(m for m in sys.modules if m.split('.')[0] == 'sympy')[:3])"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip().splitlines()[-1] == "[]"


def test_the_cached_plant_is_keyed_by_the_floating_base(tmp_path, monkeypatch):
    """--floating changes the robot, so it is part of the key (a floating run once found the fixed
    robot's entry); a xacro file, an MJCF file and --xacro-arg go to the uncached route."""
    import argparse

    import symdyn.apps.compilation.compile as compiled
    from symdyn.cli import cache as cli_cache

    keys, uncached = [], []
    monkeypatch.setattr(compiled, "cached_dynamics", lambda key, make: keys.append(key))
    monkeypatch.setattr(cli_cache, "_uncached", lambda make: uncached.append(make))
    plain = _urdf_declaring_xacro(tmp_path)
    xacro = tmp_path / "arm.urdf"
    xacro.write_text(plain.read_text().replace("</robot>", '<xacro:property name="a" value="1"/></robot>'))
    mjcf = tmp_path / "arm.xml"
    mjcf.write_text("<mujoco/>")
    for robot, floating, xacro_arg in [
        (plain, False, None),
        (plain, True, None),
        (plain, False, ["a:=1"]),
        (xacro, False, None),
        (mjcf, False, None),
    ]:
        args = argparse.Namespace(
            robot=str(robot), base=None, tip=None, floating=floating, xacro_arg=xacro_arg, package_dir=None
        )
        cli_cache.cached_plant(args, lambda: None)
    assert [k["floating"] for k in keys] == [False, True] and keys[0]["file"] == keys[1]["file"]
    assert len(uncached) == 3


def test_a_missing_or_unknown_parameter_is_named():
    """The missing and the unknown names are named, with the robot's free parameters: from the
    Robot (Robot.param_values, a cache miss) and from the cache entry alone (a hit)."""
    robot = example("roger_arm")
    names = [str(p) for p in robot.params]
    full = {n: 0.5 for n in names}
    assert compile(robot, full).param_names == tuple(names)  # the entry exists: the calls below hit it
    missing = {n: v for n, v in full.items() if n != "l2"}
    unknown = f"unknown parameter(s) l3 (free parameters of robot 'roger_arm': {', '.join(names)})"
    for bind in (lambda p: compile(robot, p), robot.param_values):
        with pytest.raises(SymdynError) as info:
            bind(missing)
        assert str(info.value).endswith("no value for parameter(s) l2")
        with pytest.raises(SymdynError) as info:
            bind({**missing, "l3": 1.0})
        assert str(info.value).endswith(f"{unknown}; no value for parameter(s) l2")
        with pytest.raises(SymdynError) as info:
            bind({**full, "l3": 1.0})
        assert str(info.value).endswith(unknown)


def test_direction_dependent_friction_in_c_and_numpy_against_the_oracle(monkeypatch):
    """The compiled C and the generated NumPy module of an arm with c+ != c- (and c+, c- over free
    parameters) give the oracle's F, tau, qdd and regressor at rates of both signs and exactly 0;
    dtau/dqd away from qd = 0 is the oracle's central difference (the Coulomb steps contribute 0);
    a simulation in C equals the NumPy path."""
    robot = asymmetric_friction()
    fast = compile(robot, ASYMMETRIC_PARAMS)
    q, qd, qdd, tau = friction_states()
    for plant in (fast, fast.module):
        extra = (fast.p,) if plant is fast.module else ()
        np.testing.assert_allclose(plant.friction(qd, *extra), friction_closed_form(qd), rtol=0, atol=1e-15)
        want = oracle_rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS)
        np.testing.assert_allclose(plant.inverse_dynamics(q, qd, qdd, *extra), want, rtol=1e-10, atol=1e-10)
        want = oracle_forward(robot, q, qd, tau, ASYMMETRIC_PARAMS)
        np.testing.assert_allclose(plant.forward_dynamics(q, qd, tau, *extra), want, rtol=1e-9, atol=1e-9)
    Y = regressor_oracle(symdyn.derive(robot), q, qd, qdd, ASYMMETRIC_PARAMS)["regressor"]
    np.testing.assert_allclose(fast.regressor(q, qd, qdd), Y, rtol=1e-10, atol=1e-12)
    h = 1e-6
    for k in (0, 1):  # every rate away from 0
        dqd = fast.inverse_dynamics_derivatives(q[k], qd[k], qdd[k])[1]
        for j in range(3):
            e = np.eye(3)[j] * h
            up = oracle_rnea(robot, q[k], qd[k] + e, qdd[k], ASYMMETRIC_PARAMS)
            down = oracle_rnea(robot, q[k], qd[k] - e, qdd[k], ASYMMETRIC_PARAMS)
            np.testing.assert_allclose(dqd[:, j], (up - down) / (2 * h), rtol=1e-6, atol=1e-7)
    slow = _numpy_backend(robot, monkeypatch, ASYMMETRIC_PARAMS)
    q0, qd0 = np.array([0.2, -0.3, 0.4]), np.array([0.5, -0.5, 0.0])
    a = simulate(fast, q0, qd0, duration=0.2, dt=2e-3, tau=["0.5*sin(9*t)"] * 3)
    b = simulate(slow, q0, qd0, duration=0.2, dt=2e-3, tau=["0.5*sin(9*t)"] * 3)
    np.testing.assert_allclose(a.q, b.q, rtol=1e-12, atol=1e-12)
    assert np.any(a.qd < 0) and np.any(a.qd > 0)


def test_a_robot_with_loops_gets_its_loop_functions_and_solve_loops_in_c():
    """symdyn.compile of the four-bar (examples/closed_loops): every loop function a method like
    the others, one state and a batch, equal to the generated NumPy module (plant.module);
    solve_loops(qa, q_guess) calls the generated C NAME_solve_loops: (int, q) for one state,
    (iterations, q) over a batch looped in C (threads give the same bits), the NumPy module's
    steps and q, closed by the oracle's closure, -1 at a singular or NaN guess."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)  # the dropped out-of-plane closure row
        robot = symdyn.load_robot(PLANAR.parent / "closed_loops" / "fourbar.yaml")
        plant = compile(robot)
    m = plant.module
    names = ("loop_residual", "loop_jacobian", "loop_newton_step", "loop_motion")
    names += ("actuated_inverse_dynamics", "actuated_mass_matrix", "actuated_forward_dynamics", "loop_forces")
    assert plant.backend == "c" and set(names) <= set(plant.functions)
    qa = np.linspace(0.0, 2 * np.pi, 21, endpoint=False)[:, None]
    guesses = np.tile([0.7, -0.2, 1.6], (len(qa), 1))
    guesses[3], guesses[5, 2] = [qa[3, 0], 1.0 - qa[3, 0], 1.0], np.nan  # coupler || rocker: K_p singular
    want = [m.solve_loops(a, g) for a, g in zip(qa, guesses, strict=True)]
    assert want[3][0] == want[5][0] == -1 and sum(i > 0 for i, _ in want) >= 15
    its, Q = plant.solve_loops(qa, guesses)
    assert its.shape == (21,) and Q.shape == (21, 3)
    np.testing.assert_array_equal(its, [i for i, _ in want])
    for it, q, (_, q_numpy) in zip(its, Q, want, strict=True):
        if it >= 0:
            np.testing.assert_allclose(q, q_numpy, rtol=0, atol=1e-12)
            assert np.abs(closure(robot, q)[0]).max() < 1e-12
    its2, Q2 = plant.solve_loops(qa, guesses, threads=2)
    assert np.array_equal(its2, its) and np.array_equal(Q2, Q, equal_nan=True)
    its3, Q3 = numpy_solve_loops(m, qa[:, None], guesses[:, None], None)  # without a C compiler
    assert its3.shape == (21, 1) and np.array_equal(its3[:, 0], its)
    np.testing.assert_allclose(Q3[:, 0][its >= 0], Q[its >= 0], rtol=0, atol=1e-12)
    it, q = plant.solve_loops(np.array([0.7]), guesses[0])
    it_numpy, q_numpy = m.solve_loops([0.7], guesses[0])
    assert isinstance(it, int) and it == it_numpy > 0
    np.testing.assert_allclose(q, q_numpy, rtol=0, atol=1e-12)
    closed = Q[its >= 0]
    rng = np.random.default_rng(8)
    for name in names:
        inputs = [a for a in inspect.signature(getattr(m, name)).parameters if a != "p"]
        args = [closed if a == "q" else rng.standard_normal((len(closed), 1)) for a in inputs]
        for state in (slice(None), 0):  # a batch, one state
            got = plant.function(name)(*(a[state] for a in args))
            exp = getattr(m, name)(*(a[state] for a in args))
            for g, e in zip(*(x if isinstance(x, tuple) else (x,) for x in (got, exp)), strict=True):
                np.testing.assert_allclose(g, e, rtol=1e-12, atol=1e-12, err_msg=name)
    with pytest.raises(ValueError, match=r"qa must have shape \(1,\)"):
        plant.solve_loops([0.1, 0.2], guesses[0])
    with pytest.raises(SymdynError, match="has no closed loops"):
        compile(example("roger_arm"), [9.81, 1, 1, 1, 1]).solve_loops([0.0], [0.0, 0.0])
