"""Simulation (lecture slide 19): integrators, torque inputs, CSV output and the `simulate` command.

Expected values come from elsewhere: energies from the numeric oracle symdyn.rnea
(kinetic_energy + potential_energy), accelerations from rnea.forward_dynamics, and
the lecture's update rule written out by hand.
"""

from __future__ import annotations

import importlib
import io
import os
from pathlib import Path

import numpy as np
import pytest

from symdyn import cli, progress
from symdyn.apps.simulation.simulate import (
    CompiledDynamics,
    simulate,
    time_expressions,
    torque_function,
    with_parameters,
)
from symdyn.errors import SymdynError
from symdyn.parsers import load_robot

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ROGER = EXAMPLES / "roger_arm_values.yaml"  # m1 = m2 = 0.2, l1 = l2 = 0.25, g = 9.81
Q0, QD0 = np.array([1.0, -0.5]), np.array([0.5, 1.0])


@pytest.fixture(scope="module")
def roger():
    return load_robot(ROGER)


def run_cli(argv, monkeypatch=None) -> int:
    """The symdyn command in-process (symdyn.cli.main, which registers simulate/analyze/check)."""
    return cli.main([str(a) for a in argv])


def energy(robot, q, qd):
    return rn.kinetic_energy(robot, q, qd) + rn.potential_energy(robot, q)


def test_compiled_dynamics_match_the_oracle(roger):
    dyn = CompiledDynamics(roger)
    rng = np.random.default_rng(1)
    q, qd, tau = rng.uniform(-2, 2, (3, 20, 2))
    assert np.allclose(dyn.forward_dynamics(q, qd, tau), rn.forward_dynamics(roger, q, qd, tau), rtol=1e-10)
    assert np.allclose(dyn.mass_matrix(q), rn.mass_matrix(roger, q), rtol=1e-12)


def test_rk4_keeps_the_energy_of_the_unforced_arm(roger):
    """Unforced, frictionless: total energy constant to 1e-6 relative over 3 s at dt = 1e-3."""
    traj = simulate(roger, Q0, QD0, duration=3.0, dt=1e-3)
    assert traj.t.shape == (3001,) and traj.t[-1] == pytest.approx(3.0)
    E = energy(roger, traj.q, traj.qd)
    assert abs(E[0]) > 0.5  # (-0.935 J) so a relative error means something
    assert np.max(np.abs(E - E[0])) / abs(E[0]) < 1e-6
    assert np.ptp(traj.q[:, 0]) > 1.0  # and the arm really swung


def test_lecture_scheme_is_one_step_of_the_slide_19_rule(roger):
    h = 0.01
    traj = simulate(roger, Q0, QD0, duration=h, dt=h, integrator="euler")
    a = rn.forward_dynamics(roger, Q0, QD0, np.zeros(2))
    assert np.allclose(traj.q[1], Q0 + QD0 * h + 0.5 * a * h * h, rtol=1e-12)
    assert np.allclose(traj.qd[1], QD0 + a * h, rtol=1e-12)
    lecture = simulate(roger, Q0, QD0, duration=0.05, dt=h, integrator="lecture")
    euler = simulate(roger, Q0, QD0, duration=0.05, dt=h, integrator="euler")
    assert np.array_equal(lecture.q, euler.q)


def test_semi_implicit_step(roger):
    h = 0.01
    traj = simulate(roger, Q0, QD0, duration=h, dt=h, integrator="semi-implicit")
    a = rn.forward_dynamics(roger, Q0, QD0, np.zeros(2))
    assert np.allclose(traj.qd[1], QD0 + a * h, rtol=1e-12)
    assert np.allclose(traj.q[1], Q0 + (QD0 + a * h) * h, rtol=1e-12)


@pytest.mark.parametrize("integrator", ["euler", "semi-implicit"])
def test_euler_schemes_are_first_order(roger, integrator):
    """The global error at t = 0.5 s halves when dt halves (ratio 2 within 10 %)."""
    exact = simulate(roger, Q0, QD0, duration=0.5, dt=1e-3)  # RK4 error ~1e-9, far below
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        tr = simulate(roger, Q0, QD0, duration=0.5, dt=dt, integrator=integrator)
        errors.append(np.max(np.abs(np.r_[tr.q[-1] - exact.q[-1], tr.qd[-1] - exact.qd[-1]])))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 1.8) & (ratios < 2.2)), ratios


def test_rk4_is_fourth_order(roger):
    exact = simulate(roger, Q0, QD0, duration=0.5, dt=2.5e-4)
    errors = [
        np.max(np.abs(simulate(roger, Q0, QD0, duration=0.5, dt=dt).q[-1] - exact.q[-1]))
        for dt in (4e-3, 2e-3)
    ]
    assert 12 < errors[0] / errors[1] < 20


def test_holding_torque_keeps_the_arm_still(roger):
    """tau = G(q0) as constants (from the oracle): the arm stays at q0."""
    q0 = np.array([0.7, 0.4])
    G = rn.gravity_torque(roger, q0)
    traj = simulate(roger, q0, None, duration=0.2, dt=1e-3, tau=[repr(float(g)) for g in G])
    assert np.max(np.abs(traj.q - q0)) < 1e-9
    assert np.allclose(traj.tau, G)


def test_torque_expressions_of_t(roger):
    """tau(t) = (0.1 sin(2 pi t), 0.05 t): each RK4 stage sees its own t."""
    f = torque_function(["0.1*sin(2*pi*t)", "0.05*t"], 2)
    assert np.allclose(f(0.25, None, None), [0.1, 0.0125])
    h = 1e-3
    traj = simulate(roger, Q0, QD0, duration=h, dt=h, tau=["0.1*sin(2*pi*t)", "0.05*t"])

    def acc(t, q, qd):
        return rn.forward_dynamics(roger, q, qd, np.array([0.1 * np.sin(2 * np.pi * t), 0.05 * t]))

    k1v = acc(0, Q0, QD0)
    k2q, k2v = QD0 + h / 2 * k1v, acc(h / 2, Q0 + h / 2 * QD0, QD0 + h / 2 * k1v)
    k3q, k3v = QD0 + h / 2 * k2v, acc(h / 2, Q0 + h / 2 * k2q, QD0 + h / 2 * k2v)
    k4q, k4v = QD0 + h * k3v, acc(h, Q0 + h * k3q, QD0 + h * k3v)
    assert np.allclose(traj.q[1], Q0 + h / 6 * (QD0 + 2 * k2q + 2 * k3q + k4q), rtol=1e-12)
    assert np.allclose(traj.qd[1], QD0 + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v), rtol=1e-12)


@pytest.mark.parametrize(
    "text, why",
    [
        ("exp(t)", "call of 'exp'"),
        ("__import__('os').system('true')", "not allowed"),
        ("x + t", "unknown name"),
        ("t.real", "attribute"),
        ("q1", "reserved"),
    ],
)
def test_torque_expressions_are_parsed_safely(text, why):
    with pytest.raises(SymdynError, match=why):
        time_expressions([text, "0"], 2)


def test_batch_equals_single_runs(roger):
    q0 = np.array([Q0, [0.2, 0.3]])
    batch = simulate(roger, q0, np.zeros((2, 2)), duration=0.1, dt=1e-2)
    for k in range(2):
        single = simulate(roger, q0[k], np.zeros(2), duration=0.1, dt=1e-2)
        assert np.allclose(batch.q[:, k], single.q, rtol=1e-13, atol=1e-15)


def test_duration_not_a_multiple_of_dt(roger):
    traj = simulate(roger, Q0, QD0, duration=0.0105, dt=1e-3)
    assert len(traj.t) == 12 and traj.t[-1] == pytest.approx(0.0105)


def test_with_parameters_makes_free_parameters_values():
    free = load_robot(EXAMPLES / "roger_arm.yaml")
    valued = with_parameters(free, {"g": 9.81, "m1": 0.2, "m2": 0.2, "l1": 0.25, "l2": 0.25})
    assert valued.params == ()
    a = CompiledDynamics(valued).forward_dynamics(Q0, QD0, np.zeros(2))
    b = CompiledDynamics(free, {"g": 9.81, "m1": 0.2, "m2": 0.2, "l1": 0.25, "l2": 0.25})
    assert np.allclose(a, b.forward_dynamics(Q0, QD0, np.zeros(2)), rtol=1e-12)
    with pytest.raises(SymdynError, match="unknown parameter"):
        with_parameters(free, {"mass": 1})


def test_bad_input(roger):
    with pytest.raises(SymdynError, match="integrator"):
        simulate(roger, Q0, QD0, duration=0.1, dt=1e-2, integrator="verlet")
    with pytest.raises(SymdynError, match="dt"):
        simulate(roger, Q0, QD0, duration=0.1, dt=0)
    with pytest.raises(SymdynError, match="q0"):
        simulate(roger, [1, 2, 3], None, duration=0.1, dt=1e-2)
    with pytest.raises(SymdynError, match="free parameters"):
        simulate(load_robot(EXAMPLES / "roger_arm.yaml"), Q0, QD0, duration=0.1, dt=1e-2)


def test_step_count_and_time_expressions_are_checked(roger):
    """dt = 5e-324 made duration / dt infinite (OverflowError); 1/t raised ZeroDivisionError."""
    with pytest.raises(SymdynError, match="too many"):
        simulate(roger, Q0, QD0, duration=1.0, dt=5e-324)
    for bad in (float("nan"), float("inf"), -1.0, 0, True, "0.1"):
        with pytest.raises(SymdynError, match="dt must be a positive number"):
            simulate(roger, Q0, QD0, duration=0.1, dt=bad)
        with pytest.raises(SymdynError, match="duration must be a positive number"):
            simulate(roger, Q0, QD0, duration=bad, dt=0.01)
    with pytest.raises(SymdynError, match=r"tau\[2\] = 1/t is not a finite real number at t = 0 s"):
        simulate(roger, Q0, QD0, duration=0.1, dt=0.01, tau=["0", "1/t"])
    with pytest.raises(
        SymdynError, match=r"tau\[1\] = sqrt\(t - 0.05\) is not a finite real number at t = 0 s"
    ):
        simulate(roger, Q0, QD0, duration=0.1, dt=0.01, tau=["sqrt(t - 0.05)", "0"])
    # a finite expression of t is evaluated as before: tau = sqrt(t) against the oracle's step
    good = simulate(roger, Q0, QD0, duration=0.02, dt=0.01, tau=["sqrt(t)", "0"], integrator="euler")
    qdd = rn.forward_dynamics(roger, Q0, QD0, np.array([0.0, 0.0]))
    np.testing.assert_allclose(good.qd[1], QD0 + 0.01 * qdd, rtol=1e-12)


def test_divergence_is_an_error(roger):
    with pytest.raises(SymdynError, match="diverged"):
        # 1e150 N m: the largest number an expression may hold (symdyn.model.bounded)
        simulate(roger, Q0, QD0, duration=2.0, dt=0.5, tau=["1e150", "0"], integrator="euler")
    with pytest.raises(SymdynError, match=r"field 'tau\[1\]': number 1e\+300 is too large"):
        simulate(roger, Q0, QD0, duration=1.0, dt=0.5, tau=["1e300", "0"], integrator="euler")


def test_a_singular_mass_matrix_is_named_as_the_cause(tmp_path, capsys):
    """m1 = 0 makes Roger's arm (point masses) singular at q = 0 (det M = l1^2 l2^2 m2^2 (1 -
    cos^2 q2) = 0): no step size helps, so the error names M, not the integrator, in C and in the
    Python loop alike."""
    params = ["m1=0", "m2=1", "l1=1", "l2=1", "g=9.81"]
    status = run_cli(["simulate", ROGER, "--params", *params, "--duration", "0.01", "--dt", "0.001",
                      "--out", tmp_path / "x.csv"])  # fmt: skip
    line = capsys.readouterr().err.strip()
    assert status == 1 and "\n" not in line and not (tmp_path / "x.csv").exists()
    assert "the mass matrix M(q) is singular at q = [0, 0]" in line, line


def test_the_progress_bar_leaves_the_run_unchanged(roger, monkeypatch):
    """progress=True (--progress): the bar of symdyn.progress (Steps) on stderr even when it is not
    a terminal and the suite silences reports; the C loop then runs in 100 chunks and the Python
    loop (a callable torque) reports every step, both with the result of a run without a bar."""
    log = io.StringIO()
    monkeypatch.setattr(progress, "_stream", lambda: log)
    plain = simulate(roger, Q0, QD0, duration=0.2, dt=1e-3)
    assert log.getvalue() == ""  # 200 steps: no bar by default
    for tau in (None, lambda t, q, qd: np.zeros(2)):
        log.seek(0)
        log.truncate()
        shown = simulate(roger, Q0, QD0, duration=0.2, dt=1e-3, tau=tau, progress=True)
        assert np.array_equal(shown.q, plain.q) and np.array_equal(shown.qd, plain.qd)
        text = log.getvalue()
        assert text.startswith("\rsymdyn: simulate:") and text.endswith("\n"), text
        assert "100%" in text and "200/200" in text and "t = 0.200 / 0.200 s" in text, text


def test_csv_columns_and_atomic_write(roger, tmp_path, monkeypatch):
    traj = simulate(roger, Q0, QD0, duration=0.01, dt=1e-3)
    path = traj.write_csv(tmp_path / "traj.csv")
    rows = path.read_text().splitlines()
    assert rows[0] == "t,q1,q2,qd1,qd2" and len(rows) == 12
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert np.array_equal(data[:, 0], traj.t) and np.array_equal(data[:, 1:3], traj.q)
    # a failing rename leaves the old file untouched and no temporary file behind
    old = path.read_text()

    def fail(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError):
        simulate(roger, Q0, QD0, duration=0.02, dt=1e-3).write_csv(path)
    assert path.read_text() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["traj.csv"]


def test_cli_simulate_writes_csv_and_plot(tmp_path, monkeypatch, capsys):
    out, png = tmp_path / "traj.csv", tmp_path / "traj.png"
    argv = [
        "simulate",
        ROGER,
        "--q0",
        "1",
        "-0.5",
        "--qd0",
        "0.5,1",
        "--tau",
        "0.1*sin(t)",
        "0",
        "--duration",
        "0.05",
        "--dt",
        "1e-3",
        "--integrator",
        "semi-implicit",
        "--out",
        out,
        "--plot",
        png,
    ]
    assert run_cli(argv, monkeypatch) == 0
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert out.read_text().splitlines()[0] == "t,q1,q2,qd1,qd2" and data.shape == (51, 5)
    assert np.allclose(data[0], [0, 1, -0.5, 0.5, 1])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "51 samples" in capsys.readouterr().out


def test_cli_free_parameters_via_params(tmp_path, monkeypatch):
    out = tmp_path / "traj.csv"
    argv = [
        "simulate",
        EXAMPLES / "roger_arm.yaml",
        "--q0=-pi/4,0",
        "--duration",
        "0.01",
        "--dt",
        "1e-3",
        "--params",
        "g=9.81",
        "m1=0.2,m2=0.2",
        "l1=0.25",
        "l2=1/4",
        "--out",
        out,
    ]
    assert run_cli(argv, monkeypatch) == 0
    assert np.loadtxt(out, delimiter=",", skiprows=1)[0, 1] == pytest.approx(-np.pi / 4)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--q0", "1"], "expected 2 values"),
        (["--q0", "1", "2", "--tau", "exp(t)", "0"], "call of 'exp'"),
        (["--q0", "1", "2", "--params", "m9=1"], "unknown parameter"),
        (["--q0", "1", "2", "--integrator", "lecture", "--tau", "0", "0", "--track", "t", "t"], "exclude"),
        (["--q0", "1", "2", "--kp", "5"], "--track only"),
        (["--q0", "1", "2", "--plot", "x.gif"], "not supported"),
        # hostile input (issue 21): no traceback, one line, nothing written
        (["--dt", "5e-324"], "is inf steps, too many (at most 10000000)"),
        (["--dt", "1e-300", "--duration", "1e300"], "is inf steps, too many"),
        (["--dt", "1e-10"], "too many (at most 10000000)"),
        (["--track", "1/t", "0"], "reference[1] = 1/t is not a finite real number at t = 0 s"),
        (
            ["--track", "0", "sqrt(t - 1)"],
            "reference[2] = sqrt(t - 1) is not a finite real number at t = 0 s",
        ),
        (["--track", "t**t**t", "0"], "d/dt reference[1] = "),
        (
            ["--tau", "1/(t - 0.005)", "0"],
            "tau[1] = 1/(t - 0.005) is not a finite real number at t = 0.005 s",
        ),
        (["--params", "m1=-1"], "parameter m1 = -1: link 1 (upper_arm): field 'mass': mass -1.0 is negative"),
        (["--params", "m2=-1e-300"], "parameter m2 = -1e-300: link 2 (forearm): field 'mass'"),
    ],
)
def test_cli_bad_input_one_line_no_output(extra, message, tmp_path, monkeypatch, capsys):
    out = tmp_path / "traj.csv"
    argv = ["simulate", ROGER, "--duration", "0.01", "--dt", "1e-3", "--out", out, *extra]
    assert run_cli(argv, monkeypatch) == 1
    err = capsys.readouterr().err
    assert err.startswith("symdyn: error: ") and message in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_cli_missing_output_folder_fails_before_simulating(tmp_path, monkeypatch, capsys):
    argv = [
        "simulate",
        ROGER,
        "--q0",
        "1",
        "2",
        "--duration",
        "100",
        "--dt",
        "1e-4",
        "--out",
        tmp_path / "no" / "t.csv",
    ]
    assert run_cli(argv, monkeypatch) == 1
    assert "does not exist" in capsys.readouterr().err
