"""Identification (symdyn.apps.identification: identify, excite; `symdyn identify`, `symdyn excite`).

The round trip: torques computed by the numeric RNEA symdyn.rnea (independent of the regressor and
of the generated code) along an exciting trajectory of `excite` must give back the base parameters
K pi of the robot file: noise-free to 1e-8 relative (1e-10 of the largest for the ones that are
zero), with Gaussian noise within 3 standard deviations, and the torques to the noise level. The
trajectory must respect its limits, its CSV must be what `identify` reads, its --track expressions
must be its q(t), and velocities and accelerations estimated from q alone (Savitzky-Golay) must
match the exact ones of the Fourier series.
"""

from __future__ import annotations

import json
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from robots import (
    ASYMMETRIC_PARAMS,
    EXAMPLES_DIR,
    FLYER,
    asymmetric_friction,
    derived,
    derived_robot,
    example,
)
from timebound import refused, within

import symdyn
from symdyn.apps.identification.excite import excite
from symdyn.apps.identification.identify import base_regressor_samples, identify
from symdyn.apps.identification.measurements import (
    Measurements,
    differentiate,
    log_columns,
    read_measurements,
)
from symdyn.apps.simulation.simulate import time_expressions
from symdyn.cli.main import main
from symdyn.errors import SymdynError
from symdyn.model.parameters import numeric_parameters

ROBOT = "scara"  # revolute and prismatic joints, friction, rotor inertia


@cache
def trajectory():
    return excite(example(ROBOT), evaluations=60, harmonics=4, samples=60)


def truth(name: str = ROBOT) -> np.ndarray:
    return derived(name, "newton-euler").linear_compact()[1].matrix() @ numeric_parameters(example(name))


def measurements(noise: float = 0.0, seed: int = 0) -> Measurements:
    traj, robot = trajectory(), example(ROBOT)
    t = np.arange(0.0, traj.period, 0.01)
    q, qd, qdd = traj(t)
    tau = symdyn.rnea(robot, q, qd, qdd)
    tau = tau + np.random.default_rng(seed).normal(0.0, 1.0, tau.shape) * noise * np.std(tau, axis=0)
    return Measurements(t, q, qd, qdd, tau)


def test_noise_free_round_trip():
    data = measurements()
    result = identify(example(ROBOT), data, derived(ROBOT, "newton-euler").base_parameters)
    want = truth()
    big = np.abs(want) > 1e-10 * np.abs(want).max()
    assert np.all(np.abs(result.estimate - want)[big] <= 1e-8 * np.abs(want)[big])
    assert np.all(np.abs(result.estimate - want)[~big] <= 1e-10 * np.abs(want).max())
    assert np.allclose(result.predicted, data.tau, rtol=0, atol=1e-9 * np.abs(data.tau).max())
    assert result.samples == len(data.t) and result.residual_rms.shape == (4,)


def test_noisy_round_trip_within_three_standard_deviations():
    data = measurements(noise=0.02, seed=3)
    result = identify(example(ROBOT), data, derived(ROBOT, "newton-euler").base_parameters)
    z = np.abs(result.estimate - truth()) / result.std
    assert z.max() < 3.0, z
    clean = measurements().tau
    assert np.all(np.sqrt(np.mean((result.predicted - clean) ** 2, axis=0)) < 0.02 * np.std(clean, axis=0))
    assert np.all(result.residual_rms < 0.03 * np.std(clean, axis=0))


def test_chunks_give_the_least_squares_of_the_whole_regressor():
    """identify in chunks of 37 samples (27 chunks) equals Gautier's weighted least squares done
    with numpy.linalg on the whole stacked regressor (lstsq, the normal matrix's pinv, cond)."""
    data = measurements(noise=0.02, seed=5)
    robot, base = example(ROBOT), derived(ROBOT, "newton-euler").base_parameters
    result = identify(robot, data, base, chunk=37)
    W3 = base_regressor_samples(robot, data.q, data.qd, data.qdd)
    N, n, nb = W3.shape
    W, y = W3.reshape(N * n, nb), data.tau.reshape(N * n)
    x0 = np.linalg.lstsq(W, y, rcond=None)[0]
    sigma = np.sqrt(np.sum((y - W @ x0).reshape(N, n) ** 2, axis=0) / (N - nb / n))
    g = np.tile(1.0 / sigma, N)
    x = np.linalg.lstsq(W * g[:, None], y * g, rcond=None)[0]
    s2 = np.sum((g * (y - W @ x)) ** 2) / (N * n - nb)
    std = np.sqrt(np.diag(s2 * np.linalg.pinv((W * g[:, None]).T @ (W * g[:, None]))))
    assert N > 20 * 37
    np.testing.assert_allclose(result.estimate, x, rtol=1e-9, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(result.std, std, rtol=1e-7)
    assert abs(result.condition_number / np.linalg.cond(W) - 1) < 1e-9
    rms = np.sqrt(np.mean((y - W @ x).reshape(N, n) ** 2, axis=0))
    np.testing.assert_allclose(result.residual_rms, rms, rtol=1e-9)
    np.testing.assert_allclose(result.predicted, (W @ x).reshape(N, n), rtol=0, atol=1e-12 * np.abs(y).max())
    assert identify(robot, data, base, chunk=37, predict=False).predicted is None


def test_excite_respects_its_limits_and_improves_the_condition():
    traj, robot = trajectory(), example(ROBOT)
    q, qd, qdd = traj(np.linspace(0.0, traj.period, 400))
    revolute = np.array([lk.joint == "revolute" for lk in robot.links])
    assert np.all(np.abs(q).max(axis=0) <= np.where(revolute, 1.0, 0.1) * 1.01)
    assert np.all(np.abs(qd).max(axis=0) <= np.where(revolute, 1.5, 0.3) * 1.01)
    assert np.all(np.abs(qdd).max(axis=0) <= np.where(revolute, 3.0, 1.0) * 1.01)
    start = excite(robot, evaluations=1, harmonics=4, samples=60)
    assert traj.condition_number <= start.condition_number


def test_track_expressions_are_the_trajectory():
    traj = trajectory()
    exprs = time_expressions(traj.expressions(), 4, "--track")
    t = np.linspace(0.0, 10.0, 7)
    got = np.array([[float(e.subs(sp.Symbol("t"), x)) for e in exprs] for x in t])
    np.testing.assert_allclose(got, traj(t)[0], atol=1e-9)


def test_savitzky_golay_velocities_and_accelerations():
    traj = trajectory()
    t = np.arange(0.0, traj.period, 0.005)
    q, qd, qdd = traj(t)
    fq, fqd, fqdd = differentiate(t, q)
    inner = slice(20, -20)
    np.testing.assert_allclose(fq[inner], q[inner], atol=1e-8)
    np.testing.assert_allclose(fqd[inner], qd[inner], atol=1e-5 * np.abs(qd).max())
    np.testing.assert_allclose(fqdd[inner], qdd[inner], atol=1e-3 * np.abs(qdd).max())


def test_cli_excite_then_identify_json(tmp_path, capsys):
    csv = tmp_path / "ex.csv"
    path = str(EXAMPLES_DIR / f"{ROBOT}.yaml")
    args = ["excite", path, "--out", str(csv), "--evaluations", "20", "--harmonics", "3", "--samples", "40"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "--track" in out and csv.is_file()
    assert main(["identify", path, str(csv), "--format", "json", "--plot", str(tmp_path / "id.png")]) == 0
    report = json.loads(capsys.readouterr().out)
    assert list(report) == ["base_parameters", "condition_number", "residual_rms", "samples"]
    names = [b["name"] for b in report["base_parameters"]]
    assert names == [name for name, _ in derived(ROBOT, "newton-euler").base_parameters]
    assert set(report["base_parameters"][0]) == {"name", "expression", "estimate", "std"}
    got = np.array([b["estimate"] for b in report["base_parameters"]])
    want = truth()
    assert np.abs(got - want).max() <= 1e-8 * np.abs(want).max()
    assert (tmp_path / "id.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_identify_from_positions_only(tmp_path, capsys):
    """Without qd and qdd columns they come from q by the Savitzky-Golay filter."""
    traj, robot = trajectory(), example(ROBOT)
    t = np.arange(0.0, traj.period, 0.005)
    q, qd, qdd = traj(t)
    tau = symdyn.rnea(robot, q, qd, qdd)
    header = "t," + ",".join(f"q{i}" for i in range(1, 5)) + "," + ",".join(f"tau{i}" for i in range(1, 5))
    rows = np.column_stack([t, q, tau])
    (tmp_path / "m.csv").write_text(
        header + "\n" + "\n".join(",".join(f"{x:.17g}" for x in r) for r in rows) + "\n"
    )
    assert main(["identify", str(EXAMPLES_DIR / f"{ROBOT}.yaml"), str(tmp_path / "m.csv")]) == 0
    captured = capsys.readouterr()
    assert "condition number" in captured.out and "Savitzky-Golay" in captured.err


@pytest.mark.parametrize(
    "text,match",
    [
        ("t,q1,q2,q3,q4,tau1,tau2,tau3\n0,0,0,0,0,0,0,0\n", "missing column.*tau4"),
        ("t,q1,q2,q3,q4,qd1,qd2,qd3,qd4,tau1,tau2,tau3,tau4\n", "give both"),
        (
            "t,q1,q2,q3,q4,tau1,tau2,tau3,tau4\n0,0,0,0,0,0,0,x,0\n",
            "line 2: not a number in column tau3: 'x'",
        ),
        (
            "t,q1,q2,q3,q4,tau1,tau2,tau3,tau4\n\n" + "0,0,0,0,0,0,0,0,0\n" * 3 + "0,0,nan,0,0,0,0,0,0\n",
            "line 6: column q2 is nan",
        ),
        (
            "t,q1,q2,q3,q4,tau1,tau2,tau3,tau4\n0,0,0,0,0,0,0,0,0\n0,0,0,0,0,0,0,0\n",
            "line 3 has 8 values, the header 9",
        ),
        ("\n\n", "empty file"),
        ("t,q1,q2,q3,q4,tau1,tau2,tau3,tau4\n0,0,0,0,0,0,0,0,0\n1,0,0,0,0,0,0,0,0\n", "at least 21"),
    ],
)
def test_bad_measurement_files_are_one_clear_message(tmp_path, text, match):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(SymdynError, match=match):
        read_measurements(path, 4)


def test_csv_values_read_back_exactly_with_blank_lines_and_python_spellings(tmp_path):
    """The fast reader (numpy.loadtxt) gives the doubles float() gives for "%.17g"; a file it
    refuses (a quoted number, 1_000) is read by Python as before; blank lines are skipped."""
    rng = np.random.default_rng(2)
    values = rng.normal(size=(30, 9)) * 10.0 ** rng.integers(-300, 300, size=(30, 9))
    header = "t,q1,q2,qd1,qd2,qdd1,qdd2,tau1,tau2"
    lines = [",".join(f"{x:.17g}" for x in row) for row in values]
    (tmp_path / "a.csv").write_text(
        "\n" + header + "\n" + "\n".join(lines[:10]) + "\n\n" + "\n".join(lines[10:])
    )
    got = read_measurements(tmp_path / "a.csv", 2)
    want = np.array([[float(c) for c in line.split(",")] for line in lines])
    assert np.array_equal(np.column_stack([got.t, got.q, got.qd, got.qdd, got.tau]), want)
    lines[3] = '"1_000",' + lines[3].split(",", 1)[1]
    (tmp_path / "b.csv").write_text(header + "\n" + "\n".join(lines) + "\n")
    got = read_measurements(tmp_path / "b.csv", 2)
    assert got.t[3] == 1000.0 and np.array_equal(got.tau, want[:, 7:])


def test_cli_bad_input_exits_1(tmp_path, capsys):
    path = str(EXAMPLES_DIR / f"{ROBOT}.yaml")
    assert main(["identify", path, str(tmp_path / "missing.csv")]) == 1
    assert "symdyn: error:" in capsys.readouterr().err
    assert main(["identify", str(EXAMPLES_DIR / "roger_arm.yaml"), str(tmp_path / "x.csv")]) == 1
    assert "free parameters" in capsys.readouterr().err


def test_direction_dependent_coulomb_friction_is_identified_per_direction():
    """With c+ != c- the base parameters hold fcp and fcn of each such joint on their own, and
    noise-free torques of the oracle at random states (rates of both signs) give back the file's
    magnitudes: 0.395 and 0.435 (the toolbox's PUMA 560 joint 1), cp3 and cm3, and fc2 = 0.3."""
    robot = asymmetric_friction().numeric(ASYMMETRIC_PARAMS)
    dyn = derived_robot(robot, "newton-euler")
    rng = np.random.default_rng(11)
    N = 120
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (N, 3)), rng.uniform(-2, 2, (N, 3)), rng.uniform(-3, 3, (N, 3))
    data = Measurements(np.arange(N) * 0.01, q, qd, qdd, symdyn.rnea(robot, q, qd, qdd))
    result = identify(robot, data, dyn.base_parameters)
    got = dict(zip(result.names, result.estimate, strict=True))
    want = {"fcp1": 0.395, "fcn1": 0.435, "fc2": 0.3, "fcp3": 0.2, "fcn3": 0.25, "fv1": 1.48e-3}
    for name, value in want.items():
        assert dict(dyn.base_parameters)[name] == sp.Symbol(name)  # a base parameter of its own
        assert got[name] == pytest.approx(value, rel=1e-8), name
    K = dyn.linear_compact()[1].matrix()
    np.testing.assert_allclose(result.estimate, K @ numeric_parameters(robot), rtol=1e-8, atol=1e-10)


FLOATING_ARM = Path(__file__).parent / "data" / "floating_arm.yaml"


def _floating_log(robot, N: int, rng) -> dict[str, np.ndarray]:
    """t, q (unit quaternions), qd, qdd and the oracle's tau (base wrench, joint efforts) at N states."""
    x = rng.normal(size=(N, 4))
    q = np.column_stack(
        [rng.normal(size=(N, 3)), x / np.linalg.norm(x, axis=1)[:, None], rng.uniform(-1, 1, (N, 3))]
    )
    qd, qdd = rng.normal(size=(N, robot.nv)), rng.normal(size=(N, robot.nv))
    tau = np.array([symdyn.rnea(robot, *state) for state in zip(q, qd, qdd, strict=True)])
    return {"t": np.arange(N) * 0.01, "q": q, "qd": qd, "qdd": qdd, "tau": tau}


def test_floating_robot_identified_from_a_csv_log_and_an_npz_log(tmp_path):
    """The small floating arm (base body with mass, friction, rotor inertia): noise-free torques of
    the oracle at random states with random unit quaternions, written with the columns `symdyn
    simulate` writes (log_columns), give back its base parameters (K pi) to 1e-8 relative, from a
    CSV and from the same values in a .npz; a log without the base's columns is one line naming
    the file, the header's line and NQ/NV."""
    robot = symdyn.load_robot(FLOATING_ARM)
    dyn = derived_robot(robot, "newton-euler")
    arrays = _floating_log(robot, 40, np.random.default_rng(4))
    columns = log_columns(robot.n, floating=True)
    header = [name for head in columns for name in columns[head]]
    values = np.column_stack(list(arrays.values()))
    lines = [",".join(f"{x:.17g}" for x in row) for row in values]
    (tmp_path / "log.csv").write_text(",".join(header) + "\n" + "\n".join(lines) + "\n")
    np.savez(tmp_path / "log.npz", **arrays)
    want = dyn.linear_compact()[1].matrix() @ numeric_parameters(robot)
    for name in ("log.csv", "log.npz"):
        data = read_measurements(tmp_path / name, robot.n, floating=True)
        assert np.array_equal(np.column_stack([data.t, data.q, data.qd, data.qdd, data.tau]), values)
        result = identify(robot, data, dyn.base_parameters)
        big = np.abs(want) > 1e-10 * np.abs(want).max()
        assert np.all(np.abs(result.estimate - want)[big] <= 1e-8 * np.abs(want)[big]), name
        assert np.all(np.abs(result.estimate - want)[~big] <= 1e-10 * np.abs(want).max()), name
        np.testing.assert_allclose(result.predicted, data.tau, rtol=0, atol=1e-9 * np.abs(data.tau).max())
    fixed = ["t", *(f"{h}{i}" for h in ("q", "qd", "qdd", "tau") for i in (1, 2, 3))]
    (tmp_path / "fixed.csv").write_text("\n" + ",".join(fixed) + "\n" + "0," * 12 + "0\n")
    with pytest.raises(SymdynError) as info:
        read_measurements(tmp_path / "fixed.csv", robot.n, floating=True)
    message = str(info.value)
    assert "\n" not in message and message.startswith(
        f"{tmp_path / 'fixed.csv'}: line 2: missing column(s) x_b"
    )
    assert "NQ = 10 position columns, NV = 9 for qd, qdd and tau" in message


def test_simulated_floating_log_is_identified(tmp_path, capsys):
    """`symdyn simulate` on a floating robot writes t, q (NQ), qd, qdd, tau (NV) (its qdd the forward
    dynamics at each sample), which `symdyn identify` reads as it is: its predictions are the
    simulated torques, base wrench (zero: free flight) included."""
    robot_file, out = tmp_path / "flyer1.yaml", tmp_path / "flight.csv"
    robot_file.write_text(FLYER)
    qd0, tau = "0.1 0 0 0.3 -0.2 0.1 1", "0 0 0 0 0 0 sin(9*t)+0.5*cos(4*t)"
    argv = ["simulate", str(robot_file), "--qd0", *qd0.split(" "), "--tau", *tau.split(" ")]
    assert main([*argv, "--duration", "0.5", "--dt", "0.005", "--out", str(out)]) == 0
    header = out.read_text().split("\n", 1)[0].split(",")
    columns = log_columns(1, floating=True)
    assert header == [name for head in columns for name in columns[head]]
    capsys.readouterr()
    assert main(["identify", str(robot_file), str(out), "--format", "json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["samples"] == 101 and len(report["residual_rms"]) == 7
    data = read_measurements(out, 1, floating=True)
    assert np.all(data.tau[:, :6] == 0)
    assert max(report["residual_rms"]) <= 1e-9 * np.abs(data.tau).max()


def test_values_that_overflow_the_least_squares_are_one_line(tmp_path, capsys):
    """Before: a CSV with a 1e308 acceleration ended in LAPACK's "DLASCL had an illegal value" and
    an internal LinAlgError; now a regressor entry or a torque beyond 1e150 (the bound of a robot
    file's numbers) is refused naming the sample and its time, and 1e140 still identifies."""
    rng = np.random.default_rng(5)
    N = 60
    columns = ["t", *(f"{h}{i}" for h in ("q", "qd", "qdd", "tau") for i in range(1, 5))]
    rows = np.column_stack([np.arange(N) * 0.01, rng.normal(size=(N, 16))])

    def write(k: int, column: str, value: float) -> Path:
        values = rows.copy()
        values[k, columns.index(column)] = value
        path = tmp_path / f"{column}.csv"
        path.write_text(
            ",".join(columns) + "\n" + "".join(",".join(f"{x:.17g}" for x in r) + "\n" for r in values)
        )
        return path

    robot = str(EXAMPLES_DIR / f"{ROBOT}.yaml")
    line = refused(capsys, "identify", robot, write(5, "qdd3", 1e308), seconds=60)
    assert line.startswith("symdyn: error: identify: the base regressor's row 3 at sample 5 (t = 0.05 s) is ")
    assert line.endswith(
        "more than 1e+150 in absolute value (the least squares would overflow): give the log in SI units"
    )
    line = refused(capsys, "identify", robot, write(7, "tau2", -1e200), seconds=60)
    assert line.startswith(
        "symdyn: error: identify: the torque tau2 at sample 7 (t = 0.07 s) is -1e+200, more than"
    )
    assert main(["identify", robot, str(write(7, "tau2", 1e140)), "--format", "json"]) == 0
    assert np.all(np.isfinite(json.loads(capsys.readouterr().out)["residual_rms"]))


@pytest.mark.parametrize(
    "options,message",
    [
        (["--period", "1e-300"], "--period 1e-300: must be from 1e-06 to 1e+06 s"),  # before: TypeError
        (["--period", "inf"], "--period inf: must be from 1e-06 to 1e+06 s"),  # before: ZeroDivisionError
        (["--period", "nan"], "--period nan: must be from 1e-06 to 1e+06 s"),
        (["--samples", "1e9"], "--samples 1000000000: must be from 2 to 10,000"),  # before: MemoryError
        (["--samples", "-5"], "--samples -5: must be from 2 to 10,000"),
        (["--harmonics", "100000"], "--harmonics 100000: must be from 1 to 100"),  # before: 2.6 TiB
        (["--evaluations", "0"], "--evaluations 0: must be at least 1"),
        (["--seed", "-1"], "--seed -1: must be at least 0"),  # before: numpy's ValueError
        (["--dt", "nan"], "--dt nan: must be positive and at most the period (10 s)"),
        (["--dt", "20"], "--dt 20: must be positive and at most the period (10 s)"),
        (
            ["--dt", "1e-300"],  # before: numpy's "Maximum allowed size exceeded"
            "excite: a period of 10 s every 1e-300 s is 1e+301 samples, more than the CSV may hold "
            "(MAX_ROWS = 1,000,000); increase dt",
        ),
        (["--qd-max", "inf"], "--qd-max: 'inf' is not a finite number"),
        (["--qd-max", "0"], "excite: qd_max must be positive and finite"),
    ],
)
def test_excite_options_out_of_range_are_one_line(tmp_path, capsys, options, message):
    """Each is refused before the optimisation runs, within seconds, and writes nothing."""
    out = tmp_path / "e.csv"
    line = refused(capsys, "excite", EXAMPLES_DIR / f"{ROBOT}.yaml", "--out", out, *options, seconds=20)
    assert line == f"symdyn: error: {message}" and not out.exists()


def test_excite_limits_too_small_for_double_precision_are_one_line():
    """Before: qd_max = 1e-300 left no trial with a finite condition number, and excite failed with
    an internal TypeError; the API refuses a period or counts out of range as the command does."""
    robot = example(ROBOT)
    with within(30), pytest.raises(SymdynError, match="excite: no trial gives a finite condition number"):
        excite(robot, qd_max=1e-300, evaluations=8, harmonics=2, samples=20)
    for settings, match in (
        ({"period": 1e-300}, r"the period must be from 1e-06 to 1e\+06 s, got 1e-300"),
        ({"samples": 10**9}, "samples must be a whole number from 2 to 10,000, got 1000000000"),
        ({"harmonics": 2.5}, "harmonics must be a whole number from 1 to 100, got 2.5"),
        ({"seed": -1}, "seed must be a whole number at least 0, got -1"),
    ):
        with within(5), pytest.raises(SymdynError, match=match):
            excite(robot, **settings)
