"""Computed-torque control (lecture slide 20) on Roger's arm (m1 = m2 = 0.2 kg, l1 = l2 = 0.25 m).

Expected values come from elsewhere: the closed-loop linear error ODE
e'' + Kd e' + Kp e = eta solved by hand, the lecture's closed-form M, V, G (slide 18),
and the numeric oracle symdyn.rnea.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest
import yaml

from symdyn import cli
from symdyn.apps.simulation.control import ComputedTorque, Reference, SampledReference, pd_gains, track
from symdyn.apps.simulation.simulate import with_parameters
from symdyn.errors import SymdynError
from symdyn.parsers import load_robot, robot_from_data

rn = importlib.import_module("symdyn.rnea")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ROGER = EXAMPLES / "roger_arm_values.yaml"
M1 = M2 = 0.2
L1 = L2 = 0.25
G0 = 9.81
REF = ["0.5*sin(2*t)", "0.8 + 0.3*cos(3*t)"]
OMEGA, ZETA = 10.0, 0.8  # Kp = 100, Kd = 16: the error decays like exp(-8 t)
Q0 = np.array([0.1, 1.0])  # initial error e(0) = q_ref(0) - q0 = (-0.1, 0.1)


@pytest.fixture(scope="module")
def roger():
    return load_robot(ROGER)


def run_cli(argv, monkeypatch=None) -> int:
    """The symdyn command in-process (symdyn.cli.main, which registers simulate/analyze/check)."""
    return cli.main([str(a) for a in argv])


def lecture_terms(q, qd):
    """Slide 18: M, V, G of Roger's arm written out (gravity along +x)."""
    q1, q2 = q
    qd1, qd2 = qd
    c2, s2 = np.cos(q2), np.sin(q2)
    M = np.array(
        [
            [M2 * L2**2 + 2 * M2 * L1 * L2 * c2 + (M1 + M2) * L1**2, M2 * L2**2 + M2 * L1 * L2 * c2],
            [M2 * L2**2 + M2 * L1 * L2 * c2, M2 * L2**2],
        ]
    )
    V = np.array([-M2 * L1 * L2 * s2 * (qd2**2 + 2 * qd1 * qd2), M2 * L1 * L2 * s2 * qd1**2])
    G = np.array(
        [(M1 + M2) * G0 * L1 * np.sin(q1) + M2 * G0 * L2 * np.sin(q1 + q2), M2 * G0 * L2 * np.sin(q1 + q2)]
    )
    return M, V, G


def homogeneous(t, e0, ed0, omega=OMEGA, zeta=ZETA):
    """Solution of e'' + 2 zeta omega e' + omega^2 e = 0 (zeta < 1), and its amplitude factor."""
    wd = omega * np.sqrt(1 - zeta**2)
    t = np.asarray(t)[:, None]
    return np.exp(-zeta * omega * t) * (e0 * np.cos(wd * t) + (ed0 + zeta * omega * e0) / wd * np.sin(wd * t))


def test_reference_derivatives_are_symbolic():
    ref = Reference(REF)
    t = np.array([0.0, 0.3, 1.7])
    q, qd, qdd = ref(t)
    assert q.shape == (3, 2)
    assert np.allclose(q[:, 0], 0.5 * np.sin(2 * t)) and np.allclose(q[:, 1], 0.8 + 0.3 * np.cos(3 * t))
    assert np.allclose(qd[:, 0], np.cos(2 * t)) and np.allclose(qd[:, 1], -0.9 * np.sin(3 * t))
    assert np.allclose(qdd[:, 0], -2 * np.sin(2 * t)) and np.allclose(qdd[:, 1], -2.7 * np.cos(3 * t))
    q1, qd1, qdd1 = Reference(["1", "t**2"])(0.5)
    assert np.allclose(q1, [1, 0.25]) and np.allclose(qd1, [0, 1]) and np.allclose(qdd1, [0, 2])
    with pytest.raises(SymdynError, match="call of 'exp'"):
        Reference(["exp(t)", "0"])
    with pytest.raises(SymdynError, match="expected 2 values"):
        Reference(["t"], 2)


def test_control_law_is_the_lecture_formula(roger):
    rng = np.random.default_rng(3)
    Kp, Kd = np.diag([100.0, 50.0]), np.diag([20.0, 14.0])
    ct = ComputedTorque(roger, Kp, Kd)
    for _ in range(5):
        q, qd, r, rd, rdd = rng.uniform(-2, 2, (5, 2))
        M, V, G = lecture_terms(q, qd)
        expected = M @ (rdd + Kp @ (r - q) + Kd @ (rd - qd)) + V + G
        assert np.allclose(ct.torque(q, qd, r, rd, rdd), expected, rtol=1e-12)
        assert np.allclose(ct(q, qd, r, rd, rdd), rn.rnea(roger, q, qd, ct.command(q, qd, r, rd, rdd)))


def test_exact_model_error_decays_as_the_linear_ode_predicts(roger):
    """e'' + Kd e' + Kp e = 0: e(t) follows the analytic solution, decays like exp(-zeta omega t)
    and is below 1e-6 at the end (2 s)."""
    Kp, Kd = pd_gains(OMEGA, ZETA)
    ref = Reference(REF)
    traj = track(roger, ref, ComputedTorque(roger, Kp, Kd), Q0, [0, 0], duration=2.0, dt=2e-3)
    e, ed = traj.q_ref - traj.q, traj.qd_ref - traj.qd
    assert np.allclose(e[0], [-0.1, 0.1]) and np.allclose(ed[0], ref(0.0)[1])
    assert np.max(np.abs(e - homogeneous(traj.t, e[0], ed[0]))) < 1e-8
    assert np.max(np.abs(e[-1])) < 1e-6
    # the amplitude sqrt(e^2 + ((e' + zeta omega e) / omega_d)^2) is exactly C exp(-zeta omega t)
    wd = OMEGA * np.sqrt(1 - ZETA**2)
    amplitude = np.sqrt(e**2 + ((ed + ZETA * OMEGA * e) / wd) ** 2)
    keep = traj.t <= 1.5  # amplitude > 1e-6, far above the integration error
    for i in range(2):
        slope, _ = np.polyfit(traj.t[keep], np.log(amplitude[keep, i]), 1)
        assert slope == pytest.approx(-ZETA * OMEGA, rel=1e-3)


def test_ten_percent_mass_error_stays_bounded(roger):
    """Model masses 10 % too large (m1 = m2 = 0.22 kg), one full period (2 pi s) of the reference.

    The error obeys e'' + Kd e' + Kp e = eta with eta = a - qdd (commanded minus actual
    acceleration), so |e_i(t)| <= |e_hom,i(t)| + ||g||_1 max_{s <= t} |eta_i(s)|, g the impulse
    response of s^2 + Kd s + Kp (||g||_1 = 0.0103 s^2 for omega = 10, zeta = 0.8). Checked with
    5 % slack for eta sampled every 4 ms; and the stated bound: |e_i| <= 0.06 rad after 0.5 s.
    """
    Kp, Kd = pd_gains(OMEGA, ZETA)
    model = with_parameters(roger, {"m1": 0.22, "m2": 0.22})
    ct = ComputedTorque(model, Kp, Kd)
    ref = Reference(REF)
    traj = track(roger, ref, ct, Q0, [0, 0], duration=2 * np.pi, dt=4e-3)
    e, ed = traj.q_ref - traj.q, traj.qd_ref - traj.qd
    _, _, rdd = ref(traj.t)
    eta = ct.command(traj.q, traj.qd, traj.q_ref, traj.qd_ref, rdd) - rn.forward_dynamics(
        roger, traj.q, traj.qd, traj.tau
    )
    wd = OMEGA * np.sqrt(1 - ZETA**2)
    s = np.linspace(0, 10, 200001)
    g_l1 = np.trapezoid(np.abs(np.exp(-ZETA * OMEGA * s) * np.sin(wd * s) / wd), s)
    bound = np.abs(homogeneous(traj.t, e[0], ed[0])) + g_l1 * np.maximum.accumulate(np.abs(eta), axis=0)
    assert np.all(np.abs(e) <= 1.05 * bound + 1e-9)
    late = traj.t >= 0.5
    assert np.max(np.abs(e[late])) <= 0.06
    assert np.max(np.abs(e[late])) > 0.01  # the model error is visible: not tracked exactly


def test_gains_and_bad_input(roger):
    ct = ComputedTorque(roger, 4.0, [1.0, 2.0])
    assert np.array_equal(ct.Kp, 4 * np.eye(2)) and np.array_equal(ct.Kd, np.diag([1.0, 2.0]))
    with pytest.raises(SymdynError, match="Kp"):
        ComputedTorque(roger, [1, 2, 3], 1)
    with pytest.raises(SymdynError, match="joints"):
        ct.law(Reference(["t"]))
    assert pd_gains(10, 0.5) == (100, 10)


def test_friction_compensation_can_be_left_out():
    data = yaml.safe_load(ROGER.read_text())
    data["links"][0]["friction"] = {"viscous": 0.05, "coulomb": 0.02}
    data["links"][1]["friction"] = {"viscous": 0.03, "coulomb": 0.01}
    robot = robot_from_data(data, "roger_with_friction")
    with_f = ComputedTorque(robot, 1, 1)
    without = ComputedTorque(robot, 1, 1, friction=False)
    q, qd, z = np.array([0.1, 0.2]), np.array([0.5, -0.4]), np.zeros(2)
    diff = with_f.torque(q, qd, q, qd, z) - without.torque(q, qd, q, qd, z)
    assert np.allclose(diff, [0.05 * 0.5 + 0.02, -0.03 * 0.4 - 0.01])


def test_cli_track_with_model_error_and_plot(tmp_path, monkeypatch, capsys):
    out, png = tmp_path / "track.csv", tmp_path / "track.png"
    argv = [
        "simulate",
        ROGER,
        "--track",
        *REF,
        "--q0",
        "0.1",
        "1.0",
        "--qd0",
        "0",
        "0",
        "--kp",
        "100",
        "--kd",
        "16",
        "--model-params",
        "m1=0.22",
        "m2=0.22",
        "--duration",
        "0.2",
        "--dt",
        "2e-3",
        "--out",
        out,
        "--plot",
        png,
    ]
    assert run_cli(argv, monkeypatch) == 0
    text = capsys.readouterr().out
    assert "tracking error" in text
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (101, 5) and np.allclose(data[0, 1:3], [0.1, 1.0])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_track_defaults_start_on_the_reference(tmp_path, monkeypatch):
    out = tmp_path / "track.csv"
    argv = ["simulate", ROGER, "--track", ",".join(REF), "--duration", "0.1", "--dt", "1e-3", "--out", out]
    assert run_cli(argv, monkeypatch) == 0
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    t = data[:, 0]
    assert np.allclose(data[:, 1], 0.5 * np.sin(2 * t), atol=1e-9)  # exact model: stays on it
    assert np.allclose(data[:, 2], 0.8 + 0.3 * np.cos(3 * t), atol=1e-9)


def _reference_samples(h: float, duration: float):
    """REF's closed form and derivatives sampled every h on [0, duration]."""
    t = np.arange(0.0, duration + h / 2, h)
    q = np.stack([0.5 * np.sin(2 * t), 0.8 + 0.3 * np.cos(3 * t)], axis=1)
    qd = np.stack([np.cos(2 * t), -0.9 * np.sin(3 * t)], axis=1)
    qdd = np.stack([-2 * np.sin(2 * t), -2.7 * np.cos(3 * t)], axis=1)
    return t, q, qd, qdd


def test_sampled_reference_interpolates_within_the_hermite_bound():
    """Hermite error <= h^4/384 max|d^4 q/dt^4| (up to 81 * 0.3); qd_ref likewise; qdd_ref linear."""
    h = 0.01
    ref = SampledReference(*_reference_samples(h, 1.0))
    exact = Reference(REF)
    t = np.linspace(0.0, 1.0, 777)
    got, want = ref(t), exact(t)
    assert np.max(np.abs(got[0] - want[0])) <= h**4 / 384 * 81 * 0.3
    assert np.max(np.abs(got[1] - want[1])) <= h**4 / 384 * 243 * 0.3
    assert np.max(np.abs(got[2] - want[2])) <= h**2 / 8 * 81 * 0.3  # linear: h^2/8 max|q""""|
    q0, qd0, qdd0 = ref(0.3)
    assert q0.shape == (2,) and np.allclose(q0, exact(0.3)[0], atol=1e-15)
    with pytest.raises(SymdynError, match=r"covers t in \[0, 1\]"):
        ref(1.5)


def test_cli_track_follows_a_csv_reference_like_its_expressions(tmp_path, monkeypatch):
    """--track FILE.csv (t, q, qd, qdd columns) tracks as --track with the closed form does."""
    t, q, qd, qdd = _reference_samples(0.01, 0.5)
    path = tmp_path / "ref.csv"
    header = "t,q1,q2,qd1,qd2,qdd1,qdd2"
    np.savetxt(path, np.column_stack([t, q, qd, qdd]), delimiter=",", header=header, comments="", fmt="%.17g")
    runs = {}
    for name, track_arg in (("csv", [path]), ("exprs", REF)):
        out = tmp_path / f"{name}.csv"
        argv = ["simulate", ROGER, "--track", *track_arg, "--q0", *Q0, "--qd0", 0, 0, "--kp", 100, "--kd", 16]
        assert run_cli([*argv, "--duration", "0.4", "--dt", "1e-3", "--out", out], monkeypatch) == 0
        runs[name] = np.loadtxt(out, delimiter=",", skiprows=1)
    # with the exact model the difference d of the two runs obeys d'' + Kd d' + Kp d = u, u the
    # reference's error (qdd + Kd qd + Kp q of the interpolant minus the closed form's), so
    # |d| <= max|u| * int|h| and |d'| <= max|u| * int|h'|, h the impulse response of that ODE
    ts = np.linspace(0.0, 0.4, 40001)
    sampled, exact = SampledReference(t, q, qd, qdd)(ts), Reference(REF)(ts)
    u = np.max(np.abs(sum(k * (s - e) for k, s, e in zip((100.0, 16.0, 1.0), sampled, exact, strict=True))))
    wd = 10.0 * np.sqrt(1 - 0.8**2)
    h = np.exp(-8.0 * ts) * np.sin(wd * ts) / wd
    hd = np.exp(-8.0 * ts) * (np.cos(wd * ts) - 8.0 / wd * np.sin(wd * ts))
    bound_q, bound_qd = u * np.trapezoid(np.abs(h), ts), u * np.trapezoid(np.abs(hd), ts)
    diff = np.abs(runs["csv"] - runs["exprs"])
    assert 0 < np.max(diff[:, 1:3]) <= 1.01 * bound_q + 1e-12
    assert np.max(diff[:, 3:5]) <= 1.01 * bound_qd + 1e-12
    too_long = [
        "simulate",
        ROGER,
        "--track",
        path,
        "--duration",
        "1",
        "--dt",
        "1e-3",
        "--out",
        tmp_path / "x.csv",
    ]
    assert run_cli(too_long, monkeypatch) != 0 and not (tmp_path / "x.csv").exists()
