"""PyTorch: the torch target (NAME_torch.py) and the NumPy module on torch tensors, on the CPU.

generated/ holds NAME_torch.py beside NAME_numpy.py for roger_arm, puma560, panda and the legs of
solo12 (kept up to date by tests/test_generated.py), so no robot is derived for most tests here
(the PUMA 560 is left out: it adds nothing the Panda does not test).
Every function of each torch module, on a batch of torch tensors, must equal the NumPy module's
(itself checked against the oracle by tests/test_numpy_target.py) to 1e-12, and its dynamics the
oracle's; torch.func.vmap must equal the batch call, torch.func.jacrev and jacfwd of the inverse
and forward dynamics the generated derivative functions, and the gradient in p central
differences; torch.compile (fullgraph: no graph break) must give the eager values. The NumPy
module (array API) is run on torch tensors too: its values, vmap and jacrev. A GPU test runs when
torch sees one (none on the machine these tests were written on).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import warnings
from pathlib import Path

import numpy as np
import pytest
from test_c_config import robot_with_parameters

from symdyn import load_robot
from symdyn.algorithms.closed_loops import analyse
from symdyn.cli import main
from symdyn.codegen import render
from symdyn.errors import SymdynWarning
from symdyn.generated_modules import load_module
from symdyn.regenerate import example_robot

torch = pytest.importorskip("torch")
torch_func = pytest.importorskip("torch.func")

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
ROOT = Path(__file__).resolve().parents[1]
GENERATED = ROOT / "generated"
ROBOTS = ("roger_arm", "panda", "solo12")
#: sizes of the inputs that are not one value per joint (the tip wrench of tip_wrench_torque)
SIZES = {"F": 6}
#: torch.asarray (called by array-api-compat for the NumPy module) warns about an input that
#: requires a gradient; the gradient flows all the same (the torch module converts with Tensor.to)
ASARRAY_WARNING = "ignore:torch.asarray. unspecified requires_grad"
#: torch.compile imports parts of torch that warn of their own deprecation
pytestmark = pytest.mark.filterwarnings("ignore:`torch.jit.script:DeprecationWarning")


@pytest.fixture(scope="module")
def modules():
    """robot -> (its torch module, its NumPy module, its Robot), from generated/."""
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)  # the published data of puma560.yaml
        for name in ROBOTS:
            torch_mod = load_module(GENERATED / name / f"{name}_torch.py", f"_symdyn_test_{name}_torch")
            numpy_mod = load_module(GENERATED / name / f"{name}_numpy.py", f"_symdyn_test_{name}_numpy_t")
            out[name] = (torch_mod, numpy_mod, example_robot(ROOT, name))
    return out


def _functions(mod) -> list[str]:
    return [n for n, f in vars(mod).items() if inspect.isfunction(f) and f.__module__ == mod.__name__]


def _public(mod) -> list[str]:
    return [n for n in _functions(mod) if not n.startswith("_")]


def _inputs(mod, name: str, rng, batch=()) -> list[np.ndarray]:
    names = [a for a in inspect.signature(getattr(mod, name)).parameters if a != "p"]
    return [rng.uniform(-2.0, 2.0, (*batch, SIZES.get(a, mod.NDOF))) for a in names]


def _params(mod, rng):
    return rng.uniform(0.5, 2.0, mod.NPARAM) if mod.NPARAM else None


def _tensor(x):
    return None if x is None else torch.as_tensor(x)


def _tuple(x):
    return x if isinstance(x, tuple) else (x,)


def _close(actual, expected, rtol=1e-12):
    """Relative agreement, measured against the size of the expected array."""
    actual = actual.detach().cpu().numpy() if isinstance(actual, torch.Tensor) else np.asarray(actual)
    expected = expected.detach().cpu().numpy() if isinstance(expected, torch.Tensor) else np.asarray(expected)
    assert actual.shape == expected.shape
    scale = max(1.0, float(np.max(np.abs(expected), initial=0.0)))
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * scale)


@pytest.mark.parametrize("robot", ROBOTS)
def test_every_function_matches_numpy_and_the_oracle(robot, modules):
    """Each function on a batch of 3 states of float64 tensors (and on one state) gives float64
    tensors equal to the NumPy module's values; inverse dynamics, M and forward dynamics the oracle's."""
    tm, nm, model = modules[robot]
    assert _public(tm) == _public(nm) and (tm.NDOF, tm.PARAM_NAMES) == (nm.NDOF, nm.PARAM_NAMES)
    assert tm.DTYPE is torch.float64
    rng = np.random.default_rng(37)
    p = _params(tm, rng)
    for name in _public(tm):
        args = _inputs(tm, name, rng, (3,))
        want = _tuple(getattr(nm, name)(*args, p))
        got = _tuple(getattr(tm, name)(*map(_tensor, args), _tensor(p)))
        one = _tuple(getattr(tm, name)(*(torch.as_tensor(a[1]) for a in args), _tensor(p)))
        for g, o, w in zip(got, one, want, strict=True):
            assert type(g) is torch.Tensor and g.dtype == torch.float64 and g.device.type == "cpu", name
            _close(g, w)
            _close(o, w[1])
    params = dict(zip(tm.PARAM_NAMES, p, strict=True)) if p is not None else None
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, tm.NDOF))
    _close(tm.inverse_dynamics(*map(_tensor, (q, qd, qdd, p))), rn.rnea(model, q, qd, qdd, params), 1e-10)
    _close(tm.mass_matrix(_tensor(q), _tensor(p)), rn.mass_matrix(model, q, params), 1e-10)
    _close(
        tm.forward_dynamics(*map(_tensor, (q, qd, qdd, p))),
        rn.forward_dynamics(model, q, qd, qdd, params),
        1e-9,
    )


@pytest.mark.filterwarnings(ASARRAY_WARNING)
def test_the_numpy_module_runs_on_torch_tensors(modules):
    """The NumPy module (array API, through array-api-compat) on torch tensors: every function
    gives float64 tensors with the NumPy values (those of the dynamics and derivatives groups);
    torch.func.vmap equals the batch call, and jacrev of its inverse dynamics equals its own
    inverse_dynamics_derivatives."""
    _, nm, _ = modules["panda"]
    rng = np.random.default_rng(38)
    for name in _public(nm)[: _public(nm).index("regressor")] + ["forward_dynamics_derivatives"]:
        args = _inputs(nm, name, rng, (2,))
        for g, w in zip(
            _tuple(getattr(nm, name)(*map(_tensor, args))), _tuple(getattr(nm, name)(*args)), strict=True
        ):
            assert type(g) is torch.Tensor and g.dtype == torch.float64, name
            _close(g, w)
    q, qd, qdd = (torch.as_tensor(a) for a in rng.uniform(-2.0, 2.0, (3, 4, nm.NDOF)))
    _close(torch_func.vmap(nm.inverse_dynamics)(q, qd, qdd), nm.inverse_dynamics(q, qd, qdd))
    jac = torch_func.vmap(torch_func.jacrev(nm.inverse_dynamics, argnums=(0, 1)))(q, qd, qdd)
    for j, d in zip(jac, nm.inverse_dynamics_derivatives(q.numpy(), qd.numpy(), qdd.numpy()), strict=True):
        _close(j, d, 1e-10)


@pytest.mark.parametrize("robot", ["panda", "solo12"])
def test_vmap_and_autograd_equal_the_generated_derivatives(robot, modules):
    """torch.func.vmap of one-state calls equals the batch call; vmap(jacrev) of the inverse
    dynamics equals inverse_dynamics_derivatives (d tau/d q, d tau/d qd) and its d/d qdd M;
    jacfwd of the forward dynamics equals forward_dynamics_derivatives (d qdd/d q, d qdd/d qd,
    M^-1); torch.autograd's backward pass through tensors that require a gradient gives the
    vector-Jacobian product of the same matrices, without a warning."""
    tm, nm, _ = modules[robot]
    rng = np.random.default_rng(39)
    q, qd, qdd, tau = rng.uniform(-2.0, 2.0, (4, 5, tm.NDOF))
    tq, tqd, tqdd, ttau = map(_tensor, (q, qd, qdd, tau))
    _close(torch_func.vmap(tm.inverse_dynamics)(tq, tqd, tqdd), nm.inverse_dynamics(q, qd, qdd))
    _close(torch_func.vmap(tm.forward_dynamics)(tq, tqd, ttau), nm.forward_dynamics(q, qd, tau))
    jac = torch_func.vmap(torch_func.jacrev(tm.inverse_dynamics, argnums=(0, 1, 2)))(tq, tqd, tqdd)
    want = (*nm.inverse_dynamics_derivatives(q, qd, qdd), nm.mass_matrix(q))
    for j, w in zip(jac, want, strict=True):
        _close(j, w, 1e-10)
    jac = torch_func.vmap(torch_func.jacfwd(tm.forward_dynamics, argnums=(0, 1, 2)))(tq, tqd, ttau)
    for j, w in zip(jac, nm.forward_dynamics_derivatives(q, qd, tau), strict=True):
        _close(j, w, 1e-9)
    leaf = torch.tensor(q, requires_grad=True)
    weights = rng.normal(size=tau.shape)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        (tm.inverse_dynamics(leaf, tqd, tqdd) * _tensor(weights)).sum().backward()
    dtau_dq = nm.inverse_dynamics_derivatives(q, qd, qdd)[0]
    _close(leaf.grad, np.einsum("ni,nij->nj", weights, dtau_dq), 1e-10)


def test_gradient_in_the_parameters_equals_central_differences(modules):
    """p is an argument: d (sum tau^2)/d p of Roger's arm (its five free parameters) by autograd
    equals central differences of the NumPy module."""
    tm, nm, _ = modules["roger_arm"]
    rng = np.random.default_rng(40)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 6, tm.NDOF))
    p = rng.uniform(0.5, 2.0, tm.NPARAM)
    grad = torch.func.grad(lambda pp: (tm.inverse_dynamics(*map(_tensor, (q, qd, qdd)), pp) ** 2).sum())(
        torch.as_tensor(p)
    )
    h, want = 1e-6, []
    for k in range(tm.NPARAM):
        step = np.eye(tm.NPARAM)[k] * h
        plus, minus = (np.sum(nm.inverse_dynamics(q, qd, qdd, p + s) ** 2) for s in (step, -step))
        want.append((plus - minus) / (2 * h))
    _close(grad, np.array(want), 1e-6)


def test_torch_compile_gives_the_eager_values_without_a_graph_break(modules):
    """torch.compile(fullgraph=True: no graph break) with inductor, the default backend, of Roger's
    arm's gravity equals the eager call on a batch. The smallest body, and inductor's check of the
    CPU's vector instructions off (it compiles a test program per instruction set): inductor
    compiles C++ with the system compiler, about 7 s of CPU even so. bench/torch.py compiles the
    Panda's functions with inductor's defaults and checks them against the oracle."""
    tm, _, _ = modules["roger_arm"]
    inductor = pytest.importorskip("torch._inductor.config")
    rng = np.random.default_rng(41)
    q, p = _tensor(rng.uniform(-2.0, 2.0, (16, tm.NDOF))), _tensor(_params(tm, rng))
    with inductor.patch({"compile_threads": 1, "cpp.vec_isa_ok": False}):
        got = torch.compile(tm.gravity, fullgraph=True, dynamic=False)(q, p)
    _close(got, tm.gravity(q, p))


def test_inputs_devices_and_bad_arguments(modules):
    """Lists and NumPy arrays become CPU tensors; tensors on two devices, wrong shapes, batch
    shapes that do not broadcast, complex tensors and a missing p are refused with one
    ValueError naming the argument; the meta device (shapes without data) works."""
    tm, nm, _ = modules["roger_arm"]
    p = [1.0, 1.2, 0.5, 0.4, 9.81]
    got = tm.gravity([0.1, 0.2], p)
    assert type(got) is torch.Tensor and got.device.type == "cpu"
    _close(got, nm.gravity([0.1, 0.2], p))
    _close(tm.friction(np.ones((4, 2)), torch.as_tensor(p)), nm.friction(np.ones((4, 2)), p))
    with pytest.raises(ValueError, match="different devices: cpu, meta"):
        tm.coriolis(torch.zeros(2), torch.zeros(2, device="meta"), p)
    with pytest.raises(ValueError, match="p is required"):
        tm.mass_matrix(torch.zeros(2))
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\); got \(3,\)"):
        tm.mass_matrix(torch.zeros(3), p)
    with pytest.raises(ValueError, match=r"p must have shape \(5,\)"):
        tm.gravity(torch.zeros(2), torch.ones(4))
    with pytest.raises(ValueError, match=r"qd must have shape"):
        tm.friction(torch.tensor(1.0), p)
    with pytest.raises(ValueError, match=r"q must be real; got a tensor of torch.complex128"):
        tm.gravity(torch.zeros(2, dtype=torch.complex128), p)
    with pytest.raises(ValueError, match=r"batch shapes \(3,\), \(4,\), \(\) do not broadcast"):
        tm.coriolis(torch.zeros(3, 2), torch.zeros(4, 2), p)
    meta = tm.inverse_dynamics(
        *(torch.zeros(7, 2, device="meta") for _ in range(3)), torch.ones(5, device="meta")
    )
    assert (meta.shape, meta.device.type, meta.dtype) == ((7, 2), "meta", torch.float64)


def test_float32_module_and_parameter_names_that_clash(tmp_path):
    """--precision float gives float32 tensors from any input dtype (oracle to 1e-4); parameters
    named like the module's own names (torch, DTYPE, device, NDOF) are renamed and work."""
    robot = robot_with_parameters(["torch", "DTYPE", "device", "NDOF", "m", "izz"])
    files = render(robot, targets=("torch",), precision="float", functions=("dynamics",))
    ((name, text),) = files.items()
    assert name == "reserved_torch.py" and "DTYPE = torch.float32" in text
    tree = ast.parse(text)
    assert [a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names] == [
        "torch"
    ]
    assert not any(isinstance(node, ast.ImportFrom) for node in ast.walk(tree))
    (tmp_path / name).write_text(text)
    mod = load_module(tmp_path / name, "_symdyn_test_reserved_torch")
    rng = np.random.default_rng(42)
    p = rng.uniform(0.5, 1.5, mod.NPARAM)
    values = dict(zip(mod.PARAM_NAMES, p, strict=True))
    q, qd, qdd = rng.uniform(-2, 2, (3, 4, 1))
    got = mod.inverse_dynamics(_tensor(q), _tensor(qd), _tensor(qdd).float(), _tensor(p))
    assert got.dtype == torch.float32
    _close(got.double(), rn.rnea(robot, q, qd, qdd, values), 1e-4)


def test_cli_writes_the_torch_module(tmp_path):
    """`symdyn generate --target torch` writes NAME_torch.py, the bytes of generated/ for the
    same function groups."""
    assert (
        main(
            [
                "generate",
                str(ROOT / "examples" / "roger_arm.yaml"),
                "--target",
                "torch",
                "--out",
                str(tmp_path),
                "--quiet",
            ]
        )
        == 0
    )
    assert [p.name for p in tmp_path.iterdir()] == ["roger_arm_torch.py"]
    mod = load_module(tmp_path / "roger_arm_torch.py", "_symdyn_test_cli_roger_arm_torch")
    assert "inverse_dynamics" in _public(mod) and mod.NPARAM == 5


def test_solve_loops_equals_numpy(tmp_path):
    """solve_loops of the four-bar (a Python loop of Newton steps on tensors, no in-place write of
    an input) takes the NumPy module's steps to the same q, and gives -1 where NumPy does."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(ROOT / "examples" / "closed_loops" / "fourbar.yaml")
        files = render(robot, targets=("python", "torch"), functions=("dynamics",))
    mods = []
    for kind in ("torch", "numpy"):
        (tmp_path / f"fourbar_{kind}.py").write_text(files[f"fourbar_{kind}.py"])
        mods.append(load_module(tmp_path / f"fourbar_{kind}.py", f"_symdyn_test_fourbar_{kind}_t"))
    tm, nm = mods
    assert (tm.ACTUATED, tm.PASSIVE, tm.LOOP_TOL) == (nm.ACTUATED, nm.PASSIVE, nm.LOOP_TOL)
    q0 = np.array(analyse(robot.resolved()).assembled[0])
    guess = torch.as_tensor(q0)
    for qa, g in ((q0[nm.ACTUATED] + 0.3, guess), ([0.0], [0.0, 1.0, 1.0]), ([0.5], [0.5, np.nan, 1.0])):
        it, q = tm.solve_loops(torch.as_tensor(qa), g)
        it_numpy, q_numpy = nm.solve_loops(qa, np.asarray(g))
        assert it == it_numpy
        if it >= 0:
            assert it > 0
            _close(q, q_numpy)
    assert torch.equal(guess, torch.as_tensor(q0))  # the guess is not written


@pytest.mark.accelerator
@pytest.mark.skipif(not torch.cuda.is_available(), reason="no CUDA device")
def test_a_gpu_gives_the_cpu_values(modules):
    """On a CUDA device: outputs stay on it and equal the CPU's (float64)."""
    tm, nm, _ = modules["panda"]
    rng = np.random.default_rng(43)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 64, tm.NDOF))
    got = tm.inverse_dynamics(*(torch.as_tensor(a, device="cuda") for a in (q, qd, qdd)))
    assert got.device.type == "cuda"
    _close(got, nm.inverse_dynamics(q, qd, qdd), 1e-10)


def test_contact_functions_equal_numpy(tmp_path):
    """A robot with a contact (Roger's arm, a point at its forearm): the torch module has NCONTACT,
    NLAMBDA and CONTACT_NAMES, and its six contact functions give the NumPy module's values, the
    free contact's rows of lam and of the impulse exactly zero."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(ROOT / "examples" / "roger_arm_values.yaml", contacts=["forearm:point"])
        files = render(robot, targets=("python", "torch"), functions=("contacts", "contact_derivatives"))
    mods = []
    for kind in ("torch", "numpy"):
        (tmp_path / f"rc_{kind}.py").write_text(files[f"roger_arm_values_{kind}.py"])
        mods.append(load_module(tmp_path / f"rc_{kind}.py", f"_symdyn_test_contacts_{kind}_t"))
    tm, nm = mods
    assert (
        (tm.NCONTACT, tm.NLAMBDA, tm.CONTACT_NAMES)
        == (nm.NCONTACT, nm.NLAMBDA, nm.CONTACT_NAMES)
        == (
            1,
            3,
            ("forearm",),
        )
    )
    rng = np.random.default_rng(7)
    q, qd, tau = rng.uniform(-1.0, 1.0, (3, tm.NDOF))
    for active in ([1.0], [0.0]):
        cases = {
            "contact_jacobian": (q,),
            "contact_drift": (q, qd),
            "contact_forward_dynamics": (q, qd, tau, active),
            "impulse_dynamics": (q, qd, active, [0.5]),
            "contact_forward_dynamics_derivatives": (q, qd, tau, active),
            "impulse_dynamics_derivatives": (q, qd, active, [0.5]),
        }
        for name, args in cases.items():
            got = _tuple(getattr(tm, name)(*(_tensor(a) for a in args)))
            want = _tuple(getattr(nm, name)(*(np.asarray(a, dtype=float) for a in args)))
            for g, w in zip(got, want, strict=True):
                _close(g, w)
        if not active[0]:
            assert not tm.contact_forward_dynamics(*(_tensor(a) for a in (q, qd, tau, active)))[1].any()
            assert not tm.impulse_dynamics(*(_tensor(a) for a in (q, qd, active, [0.5])))[1].any()
