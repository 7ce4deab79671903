"""The derivative functions (symdyn.codegen.derivative_functions) in C, NumPy and CasADi.

inverse_dynamics_derivatives, forward_dynamics_derivatives, mass_matrix_inverse and linearize
are judged by independent routes, for every example robot (revolute and prismatic joints,
symbolic parameters) and a kinematic tree with a prismatic and a mimic joint:

- central finite differences of the numeric RNEA symdyn.rnea (dtau/dq, dtau/dqd) and of the
  generated forward_dynamics (dqdd/dq, dqdd/dqd, dqdd/dtau), relative 1e-6;
- CasADi's automatic differentiation of the generated CasADi inverse_dynamics and
  forward_dynamics, relative 1e-10;
- M^-1 M = I with M from the numeric CRBA of symdyn.rnea;
- the C of every robot compiled with warnings as errors and called through ctypes (against the
  CasADi derivatives), and once under -fsanitize=address,undefined.
"""

from __future__ import annotations

import ctypes
import importlib
import importlib.util
import subprocess
import types
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
import sympy as sp
from cbuild import SANITIZE_FLAGS, STRICT_FLAGS, compile_program, compile_shared, write_files
from robots import EXAMPLE_NAMES, example, example_context, random_params, tree_robot

from symdyn.codegen import c as c_backend
from symdyn.codegen import casadi as casadi_backend
from symdyn.codegen import context, render
from symdyn.codegen import python as python_backend
from symdyn.codegen.derivative_functions import DERIVATIVE_FUNCTION_NAMES
from symdyn.model.topology import Mimic

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

FD_TOL = 1e-6
AD_TOL = 1e-10
STATES = 2


def _gripper():
    """Two fingers on a wrist, the second following the first (a tree with a mimic joint)."""
    mimic = {3: Mimic(2, sp.Float(-1), sp.Float(0.02))}
    return tree_robot("gripper", (-1, 0, 1, 1), ("revolute", "revolute", "prismatic", "prismatic"), 7, mimic)


ROBOTS = {**{name: (lambda name=name: example(name)) for name in EXAMPLE_NAMES}, "gripper": _gripper}


def _module(text: str, name: str) -> types.ModuleType:
    module = types.ModuleType(name)
    exec(compile(text, name, "exec"), module.__dict__)  # symdyn's own output
    return module


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def generated(request, tmp_path_factory):
    """Each robot rendered once for the module: C (compiled), NumPy and CasADi."""
    robot = ROBOTS[request.param]()
    # what render(robot, targets=("c", "python", "casadi")) gives, over one context: for the
    # example robots the one derived once per test process (tests/robots.py)
    ctx = example_context(request.param) if request.param in EXAMPLE_NAMES else context(robot)
    files = {k: v for t in (c_backend, python_backend, casadi_backend) for k, v in t.render(ctx).items()}
    out = tmp_path_factory.mktemp(request.param)
    write_files({k: v for k, v in files.items() if k.startswith(f"{robot.name}_dynamics.")}, out)
    lib = compile_shared([out / f"{robot.name}_dynamics.c"], out / "lib.so", opt="-O0")  # fast to build
    numpy_module = _module(files[f"{robot.name}_numpy.py"], "gen")
    casadi_functions = _module(files[f"{robot.name}_casadi.py"], "gen_casadi").functions()
    rng = np.random.default_rng(13)
    p = random_params(robot, rng)
    states = []
    for _ in range(STATES):
        q = rng.uniform(-1, 1, robot.n)
        qd = rng.uniform(-1, 1, robot.n)
        qd[np.abs(qd) < 1e-2] = 0.5  # away from the jump of the Coulomb sign
        states.append((q, qd, rng.uniform(-1, 1, robot.n)))
    return types.SimpleNamespace(
        robot=robot, files=files, out=out, lib=ctypes.CDLL(str(lib)), np=numpy_module,
        ca=casadi_functions, p=p, states=states,
    )  # fmt: skip


def _close(got, want, rtol, what=""):
    got, want = np.asarray(got, float), np.asarray(want, float)
    scale = max(1.0, float(np.max(np.abs(want))))
    assert got.shape == want.shape, (what, got.shape, want.shape)
    err = float(np.max(np.abs(got - want))) / scale if got.size else 0.0
    assert err <= rtol, f"{what}: relative error {err:.2e} > {rtol:.0e}"


def _central(f, x, h=1e-6):
    """Columns (f(x + h e_j) - f(x - h e_j)) / 2h."""
    E = np.eye(len(x)) * h
    return np.column_stack([(f(x + E[j]) - f(x - E[j])) / (2 * h) for j in range(len(x))])


def _wrt(f, args, k):
    """x -> f(args with args[k] replaced by x)."""
    return lambda x: f(*args[:k], x, *args[k + 1 :])


def _params(g):
    return dict(zip(g.robot.params, g.p, strict=True))


def test_all_four_generated(generated):
    assert all(
        f"build_{name}" in generated.files[f"{generated.robot.name}_casadi.py"]
        for name in DERIVATIVE_FUNCTION_NAMES
    )


def test_inverse_dynamics_derivatives_against_the_rnea(generated):
    g = generated
    P = _params(g)
    for q, qd, qdd in g.states:
        dq, dqd = g.np.inverse_dynamics_derivatives(q, qd, qdd, g.p)
        args = (g.robot, q, qd, qdd, P)
        _close(dq, _central(_wrt(rn.rnea, args, 1), q), FD_TOL, "dtau/dq")
        _close(dqd, _central(_wrt(rn.rnea, args, 2), qd), FD_TOL, "dtau/dqd")


def test_forward_dynamics_derivatives_against_differences(generated):
    g = generated
    P = _params(g)
    fd = g.np.forward_dynamics
    for q, qd, qdd in g.states:
        tau = rn.rnea(g.robot, q, qd, qdd, P)
        dq, dqd, Minv = g.np.forward_dynamics_derivatives(q, qd, tau, g.p)
        args = (q, qd, tau, g.p)
        _close(dq, _central(_wrt(fd, args, 0), q), FD_TOL, "dqdd/dq")
        _close(dqd, _central(_wrt(fd, args, 1), qd), FD_TOL, "dqdd/dqd")
        _close(Minv, _central(_wrt(fd, args, 2), tau), FD_TOL, "dqdd/dtau")
        n = g.robot.n
        _close(Minv @ rn.mass_matrix(g.robot, q, P), np.eye(n), 1e-12, "M^-1 M")
        _close(g.np.mass_matrix_inverse(q, g.p), Minv, 1e-14, "mass_matrix_inverse")
        A, B = g.np.linearize(q, qd, tau, g.p)
        want_A = np.block([[np.zeros((n, n)), np.eye(n)], [dq, dqd]])
        _close(A, want_A, 1e-14, "A")
        _close(B, np.vstack([np.zeros((n, n)), Minv]), 1e-14, "B")


def _casadi_reference(g, q, qd, qdd):
    """dtau/dq, dtau/dqd, dqdd/dq, dqdd/dqd, dqdd/dtau by CasADi's AD of the generated functions."""
    n, k = g.robot.n, len(g.robot.params)
    Q, QD, QDD, T, Pp = (ca.SX.sym(s, m) for s, m in (("q", n), ("qd", n), ("qdd", n), ("tau", n), ("p", k)))
    tau = g.ca["inverse_dynamics"](Q, QD, QDD, Pp)
    qdd_fd = g.ca["forward_dynamics"](Q, QD, T, Pp)
    jac = ca.Function(
        "reference",
        [Q, QD, QDD, T, Pp],
        [ca.jacobian(tau, Q), ca.jacobian(tau, QD), ca.jacobian(qdd_fd, Q), ca.jacobian(qdd_fd, QD),
         ca.jacobian(qdd_fd, T), tau],
    )  # fmt: skip
    out = jac(q, qd, qdd, np.zeros(n), g.p)
    tau_num = np.asarray(out[5]).ravel()
    fd_out = jac(q, qd, qdd, tau_num, g.p)
    return [np.asarray(out[0]), np.asarray(out[1])] + [np.asarray(fd_out[i]) for i in (2, 3, 4)], tau_num


def test_casadi_functions_against_casadi_ad(generated):
    g = generated
    for q, qd, qdd in g.states:
        (dq, dqd, fq, fqd, Minv), tau = _casadi_reference(g, q, qd, qdd)
        got = g.ca["inverse_dynamics_derivatives"](q, qd, qdd, g.p)
        _close(np.asarray(got[0]), dq, AD_TOL, "dtau/dq")
        _close(np.asarray(got[1]), dqd, AD_TOL, "dtau/dqd")
        got = g.ca["forward_dynamics_derivatives"](q, qd, tau, g.p)
        for a, b, what in zip(got, (fq, fqd, Minv), ("dqdd/dq", "dqdd/dqd", "Minv"), strict=True):
            _close(np.asarray(a), b, AD_TOL, what)
        _close(np.asarray(g.ca["mass_matrix_inverse"](q, g.p)), Minv, AD_TOL, "mass_matrix_inverse")
        A, B = g.ca["linearize"](q, qd, tau, g.p)
        _close(np.asarray(A)[g.robot.n :], np.hstack([fq, fqd]), AD_TOL, "A")
        _close(np.asarray(B)[g.robot.n :], Minv, AD_TOL, "B")


def _c_call(g, fname, args, shapes):
    ptr = ctypes.POINTER(ctypes.c_double)
    keep = [np.ascontiguousarray(a, dtype=float) for a in args]
    outs = [np.full(s, np.nan) for s in shapes]
    f = getattr(g.lib, f"{g.robot.name}_{fname}")
    f.restype = None
    f(*[a.ctypes.data_as(ptr) for a in keep], *[o.ctypes.data_as(ptr) for o in outs])
    return outs


def test_c_against_casadi_ad(generated):
    """The C (compiled with -Werror by the fixture) gives CasADi's derivatives."""
    g = generated
    n = g.robot.n
    p = g.p if len(g.p) else np.zeros(1)
    for q, qd, qdd in g.states:
        (dq, dqd, fq, fqd, Minv), tau = _casadi_reference(g, q, qd, qdd)
        got = _c_call(g, "inverse_dynamics_derivatives", (q, qd, qdd, p), [(n, n), (n, n)])
        _close(got[0], dq, AD_TOL, "C dtau/dq")
        _close(got[1], dqd, AD_TOL, "C dtau/dqd")
        got = _c_call(g, "forward_dynamics_derivatives", (q, qd, tau, p), [(n, n)] * 3)
        for a, b, what in zip(got, (fq, fqd, Minv), ("dqdd/dq", "dqdd/dqd", "Minv"), strict=True):
            _close(a, b, AD_TOL, f"C {what}")
        (inv,) = _c_call(g, "mass_matrix_inverse", (q, p), [(n, n)])
        _close(inv, Minv, AD_TOL, "C mass_matrix_inverse")
        A, B = _c_call(g, "linearize", (q, qd, tau, p), [(2 * n, 2 * n), (2 * n, n)])
        _close(A, np.block([[np.zeros((n, n)), np.eye(n)], [fq, fqd]]), AD_TOL, "C A")
        _close(B, np.vstack([np.zeros((n, n)), Minv]), AD_TOL, "C B")


def test_c_under_the_sanitizers(tmp_path):
    """A driver calls the four functions of the RPR arm; ASan/UBSan abort on any error."""
    robot = example("planar_prismatic_modified")
    name, n = robot.name, robot.n
    write_files({k: v for k, v in render(robot, targets=("c",)).items()}, tmp_path)
    driver = tmp_path / "driver.c"
    driver.write_text(
        f'#include "{name}_dynamics.h"\n#include <stdio.h>\n'
        "int main(void) {\n"
        f"    double q[{n}], qd[{n}], qdd[{n}], tau[{n}], a[{n * n}], b[{n * n}], c[{n * n}];\n"
        f"    double A[{4 * n * n}], B[{2 * n * n}];\n"
        f"    for (int i = 0; i < {n}; ++i) {{ q[i] = 0.1 * i; qd[i] = 0.2 - 0.05 * i; qdd[i] = 0.3; }}\n"
        f"    {name}_inverse_dynamics(q, qd, qdd, NULL, tau);\n"
        f"    {name}_inverse_dynamics_derivatives(q, qd, qdd, NULL, a, b);\n"
        f"    {name}_forward_dynamics_derivatives(q, qd, tau, NULL, a, b, c);\n"
        f"    {name}_mass_matrix_inverse(q, NULL, c);\n"
        f"    {name}_linearize(q, qd, tau, NULL, A, B);\n"
        f'    printf("%.17g\\n", A[{n}] + B[{2 * n * n - 1}] - c[{n * n - 1}]);\n'
        "    return 0;\n}\n"
    )
    exe = compile_program(
        [driver, tmp_path / f"{name}_dynamics.c"],
        tmp_path / "driver",
        "gcc",
        "-O1",
        (*STRICT_FLAGS, *SANITIZE_FLAGS, f"-I{tmp_path}"),
    )
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert abs(float(run.stdout) - 1.0) < 1e-12  # A's identity block, B's last entry is Minv's


# --------------------------------------------------------------------------- the examples

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "derivatives_control"
PANDA = ROOT / "generated" / "panda"  # up to date: tests/test_generated.py


def test_ilqr_example_converges_on_the_reference(tmp_path):
    """examples/derivatives_control/panda_ilqr.c: iLQR with panda_linearize tracks its reference.

    Compiled with warnings as errors against the committed generated/panda C. Newton-like
    convergence (the cost falls every iteration and stops falling within 30 iterations) needs
    correct derivatives; the rollout uses panda_forward_dynamics alone.
    """
    exe = compile_program(
        [EXAMPLE / "panda_ilqr.c", PANDA / "panda_dynamics.c"], tmp_path / "ilqr", "gcc", "-O0",
        (*STRICT_FLAGS, f"-I{PANDA}"),
    )  # fmt: skip
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    lines = run.stdout.splitlines()
    costs = [float(line.split()[3]) for line in lines if line.startswith("iter ")]
    summary = lines[-1].split()
    assert summary[0] == "converged" and int(summary[1]) <= 30, run.stdout
    assert all(b <= a for a, b in zip(costs, costs[1:], strict=False)), costs
    assert costs[-1] < 1e-3 * costs[0]
    final_error, late_error = float(summary[5]), float(summary[7])
    assert final_error < 2e-3 and late_error < 5e-3, run.stdout  # rad, from a 0.1 rad start offset


def test_opti_example_solves_with_the_generated_derivatives():
    """examples/derivatives_control/panda_opti.py: IPOPT with symdyn's Jacobians as CasADi's
    custom_jacobian; the torques it finds, rolled out with RK4 of the numeric oracle's forward
    dynamics (symdyn.rnea), bring the arm to the goal at rest."""
    spec = importlib.util.spec_from_file_location("panda_opti", EXAMPLE / "panda_opti.py")
    opti = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(opti)
    functions = opti.load_functions(str(PANDA / "panda_casadi.py"))
    q_start = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])
    q_goal = np.array([0.3, -0.2, -0.1, -2.0, 0.1, 1.9, 0.7])
    T, N = 0.5, 10
    X, U, stats = opti.solve(functions, q_start, q_goal, T, N)
    assert stats["success"], stats["return_status"]
    assert np.all(np.abs(U) <= opti.TAU_MAX[:, None] + 1e-6)
    robot = example("panda")
    n, h = robot.n, T / N

    def xdot(x, u):
        return np.concatenate([x[n:], rn.forward_dynamics(robot, x[:n], x[n:], u)])

    x = np.concatenate([q_start, np.zeros(n)])
    for k in range(N):
        u = U[:, k]
        k1 = xdot(x, u)
        k2 = xdot(x + h / 2 * k1, u)
        k3 = xdot(x + h / 2 * k2, u)
        k4 = xdot(x + h * k3, u)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    np.testing.assert_allclose(x, np.concatenate([q_goal, np.zeros(n)]), atol=1e-6)
