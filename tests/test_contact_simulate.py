"""Simulation with contacts (symdyn.apps.simulation.contact_simulate, `symdyn simulate --contacts`)
and symdyn.compile's checks of the contact inputs (symdyn.apps.compilation.contact_check).

- Solo-12 (example-robot-data, floating) in its SRDF "standing" pose on its four feet, under a
  joint PD controller for 5 s: the feet drift less than 1 mm (the oracle's frame positions) and the
  contact forces sum to the weight (the oracle's mass) within 1 % at rest;
- a small floating robot (a point foot on the base, a point hand on its link): the samples' forces
  and accelerations solve the KKT system of the oracle (symdyn.oracle.contacts) with Baumgarte's
  term Jc qdd + gamma = -Kd Jc qd - Kp e(q); a touchdown impulse equals the oracle's and stops
  the contacts; the stabilised run's contacts return to their anchors; the CSV's force columns,
  --plot and --animate (the forces' arrows); hostile options, one line each.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import symdyn
from symdyn.algorithms.contact_dynamics import DAMPING as GENERATED_DAMPING
from symdyn.algorithms.drawing import scene_function
from symdyn.apps.simulation.contact_simulate import DAMPING, joint_pd, simulate_contacts
from symdyn.cli.main import main
from symdyn.errors import SymdynError
from symdyn.oracle.contact_kinematics import contact_poses, contact_rows
from symdyn.oracle.contacts import contact_drift, contact_jacobian, impulse_dynamics
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import mass_matrix

sys.path.insert(0, str(Path(__file__).parent))
from test_contact_functions import FLYER2  # noqa: E402
from timebound import refused, within  # noqa: E402

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")

# test_contact_functions' small floating robot with its point foot (on the base) and hand (on l1)
ROBOT = FLYER2.replace("flyer2", "hopper").replace("  - {name: grip, frame: hand, type: 6d}\n", "")
Q0 = np.r_[0.1, -0.2, 0.5, 0.1, 0.2, -0.1, 0.97, 0.4]


@pytest.fixture(scope="module")
def hopper(tmp_path_factory):
    path = tmp_path_factory.mktemp("hopper") / "hopper.yaml"
    path.write_text(ROBOT)
    robot = symdyn.load_robot(path)
    return (
        path,
        robot,
        symdyn.compile(robot, functions=("dynamics", "configuration", "contacts", "contact_baumgarte")),
    )


def _positions(robot, q) -> np.ndarray:
    """The contact frames' origins by symdyn.algorithms.drawing's kinematics (checked against
    Pinocchio's on Solo-12 below)."""
    frames = scene_function(robot)(q).frames
    return np.array([next(f.origin for f in frames if f.name == c.name) for c in robot.contacts])


@pytest.fixture(scope="module")
def solo():
    """Solo-12 with its four feet, its SRDF's standing pose and its plant (compiled once: the
    standing and the stance tests share it)."""
    folder = example_robot_data_folder()
    if folder is None:
        pytest.skip("example-robot-data is not installed")
    robot = symdyn.load_urdf(folder / "solo_description/robots/solo12.urdf", floating=True, contacts=FEET)
    srdf = ET.parse(folder / "solo_description/srdf/solo.srdf").getroot()
    pose = next(s for s in srdf.iter("group_state") if s.get("name") == "standing")
    values = {j.get("name"): [float(x) for x in j.get("value").split()] for j in pose.iter("joint")}
    q0 = np.r_[values["root_joint"], [values[link.joint_name][0] for link in robot.links]]
    plant = symdyn.compile(robot, functions=("configuration", "contacts"))
    return folder, robot, q0, plant


def test_solo12_stands_on_its_four_feet_under_a_joint_pd_controller(solo):
    folder, robot, q0, plant = solo
    with within(60):
        traj = simulate_contacts(
            plant, robot, q0, duration=5.0, dt=0.004, tau=joint_pd(q0, 5.0, 0.2, robot.nv)
        )
    # the feet: where they started, by Pinocchio's kinematics (not the simulation's own)
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(
        str(folder / "solo_description/robots/solo12.urdf"), pin.JointModelFreeFlyer()
    )
    data = model.createData()

    def feet(q):
        pin.framesForwardKinematics(model, data, q)
        return np.array([data.oMf[model.getFrameId(f)].translation for f in FEET])

    start, end = feet(traj.q[0]), feet(traj.q[-1])
    assert np.abs(end - start).max() < 1e-3
    assert np.allclose(traj.contact_positions()[[0, -1]], [start, end], atol=1e-12)
    weight = 9.81 * mass_matrix(robot, q0)[0, 0]  # the total mass, by the oracle
    total = traj.contact_forces[-1].sum(axis=0)
    assert abs(total[2] - weight) < 0.01 * weight and np.abs(total[:2]).max() < 0.01 * weight
    assert np.abs(traj.qd[-1]).max() < 1e-3  # at rest
    assert traj.lam.shape == (len(traj.t), 12) and np.all(traj.active == 1)


def test_solo12_lifts_a_foot_and_puts_it_down(solo):
    """--stance: four feet, then three (FL lifted by its hip), then four again with a touchdown
    impulse. The held feet stay within 1 mm, the lifted foot moves, and the
    touchdown is the oracle's impulse, which stops the foot."""
    _, robot, q0, plant = solo
    hold = joint_pd(q0, 5.0, 0.2, robot.nv)
    hip = 7  # FL_HFE's velocity row (the base's six, then FL_HAA)

    def tau(t, q, v):
        out = hold(t, q, v)
        out[hip] += 0.3 if 0.04 <= t < 0.12 else 0.0  # lift the free foot
        return out

    three = ("FR_FOOT", "HL_FOOT", "HR_FOOT")
    stance = [(0.04, three), (0.16, FEET)]
    with within(20):
        traj = simulate_contacts(plant, robot, q0, duration=0.24, dt=0.002, tau=tau, stance=stance)
    k1, k2 = 20, 80  # the samples of the changes
    assert (
        np.all(traj.active[:k1] == 1) and np.all(traj.active[k1:k2, 0] == 0) and np.all(traj.active[k2:] == 1)
    )
    feet = contact_poses(robot, contact_rows(robot, robot.contacts), traj.q)[:, :, :3, 3]  # the oracle's
    assert np.abs(feet[:, 1:] - feet[0, 1:]).max() < 1e-3  # the held feet
    assert np.linalg.norm(feet[k2, 0] - feet[k1, 0]) > 0.02  # the lifted one moved
    assert np.abs(feet[k2:, 0] - feet[k2, 0]).max() < 1e-3  # and holds where it touched down
    assert np.all(traj.lam[k1 + 1 : k2, :3] == 0)  # free while lifted
    ((time, impulse, before),) = traj.touchdowns
    assert time == pytest.approx(0.16) and traj.impulse_time == time
    want_v, want_p = impulse_dynamics(robot, None, traj.q[k2], before, restitution=0.0, damping=DAMPING)
    assert np.allclose(traj.qd[k2], want_v, atol=1e-9) and np.allclose(impulse, want_p, atol=1e-9)
    Jc = contact_jacobian(robot, None, traj.q[k2])
    assert np.linalg.norm(Jc[:3] @ before) > 1e-2 and np.abs(Jc @ traj.qd[k2]).max() < 1e-9


def test_the_samples_solve_the_stabilised_kkt_system_of_the_oracle(hopper):
    _, robot, plant = hopper
    assert DAMPING == GENERATED_DAMPING
    qd0 = np.r_[0.3, -0.2, 0.1, 0.5, -0.4, 0.2, 1.0]  # the contacts move: Jc qd0 != 0
    kp, kd = 400.0, 40.0
    traj = simulate_contacts(plant, robot, Q0, qd0, duration=0.6, dt=1e-3, tau=[0.0] * 7, baumgarte=(kp, kd))
    anchors = _positions(robot, Q0)
    for k in (0, 1, 250):
        q, v, a, lam = traj.q[k], traj.qd[k], traj.qdd[k], traj.lam[k]
        Jc = contact_jacobian(robot, None, q)
        error = (_positions(robot, q) - anchors).reshape(-1)
        # M a + b = tau + Jc^T lam (symdyn.rnea: the oracle's inverse dynamics, friction included)
        assert np.allclose(symdyn.rnea(robot, q, v, a) - Jc.T @ lam, traj.tau[k], atol=1e-8)
        assert np.allclose(Jc @ a + contact_drift(robot, None, q, v), -kd * Jc @ v - kp * error, atol=1e-6)
    # stabilised: the contacts come back to their anchors and stop; without the gains they do not
    assert np.abs(traj.contact_positions()[-1] - anchors).max() < 1e-3
    free = simulate_contacts(plant, robot, Q0, qd0, duration=0.6, dt=1e-3, tau=[0.0] * 7)
    assert np.abs(free.contact_positions()[-1] - anchors).max() > 0.05


def test_a_touchdown_impulse_is_the_oracles_and_stops_the_contacts(hopper):
    _, robot, plant = hopper
    qd0 = np.r_[0.0, 0.0, -1.0, 0.2, 0.0, 0.0, 0.5]
    traj = simulate_contacts(plant, robot, Q0, qd0, duration=0.2, dt=1e-3, impulse_at=0.1, restitution=0.5)
    k = int(np.flatnonzero(traj.t == traj.impulse_time)[0])
    assert (
        traj.impulse_time == pytest.approx(0.1)
        and np.all(traj.active[:k] == 0)
        and np.all(traj.active[k:] == 1)
    )
    want_v, want_p = impulse_dynamics(
        robot, None, traj.q[k], traj.qd_before, restitution=0.5, damping=DAMPING
    )
    assert np.allclose(traj.qd[k], want_v, atol=1e-9) and np.allclose(traj.impulse, want_p, atol=1e-9)
    Jc = contact_jacobian(robot, None, traj.q[k])
    assert np.allclose(Jc @ traj.qd[k], -0.5 * Jc @ traj.qd_before, atol=1e-9)
    assert np.all(traj.lam[:k] == 0)  # free before the touchdown


def test_simulate_contacts_cli_writes_forces_plot_and_animation(hopper, tmp_path, capsys):
    path, robot, _ = hopper
    out, plot, page = tmp_path / "run.csv", tmp_path / "forces.png", tmp_path / "run.html"
    args = ["simulate", path, "--contacts", "foot", "hand", "--duration", "0.05", "--dt", "0.01"]
    more = ["--pd", "2", "0.1", "--baumgarte", "100", "20", "--integrator", "euler"]
    with within(60):
        assert main([str(a) for a in [*args, *more, "--out", out, "--plot", plot, "--animate", page]]) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert header[-6:] == ["foot_fx", "foot_fy", "foot_fz", "hand_fx", "hand_fy", "hand_fz"]
    assert plot.read_bytes()[:4] == b"\x89PNG" and page.read_bytes().startswith(b"<!DOCTYPE html>")
    assert "contact forces at t = 0.05 s" in capsys.readouterr().out


def test_simulate_cli_changes_the_stance(hopper, tmp_path, capsys):
    path, robot, _ = hopper
    out = tmp_path / "run.csv"
    args = ["simulate", path, "--contacts", "foot", "hand", "--duration", "0.05", "--dt", "0.01"]
    more = [
        "--stance",
        "0=hand",
        "0.02=foot,hand",
        "0.04=",
        "--restitution",
        "0.5",
        "--baumgarte",
        "100",
        "20",
    ]
    with within(60):
        assert main([str(a) for a in [*args, *more, "--out", out]]) == 0
    assert "touchdown at t = 0.02 s" in capsys.readouterr().out
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.all(rows[:2, -6:-3] == 0) and np.any(rows[2:4, -6:-3] != 0) and np.all(rows[4:, -6:] == 0)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--contacts", "nose"], "nose"),
        (["--contacts", "foot", "--impulse-at", "-1"], "--impulse-at"),
        (["--contacts", "foot", "--impulse-at", "nan"], "--impulse-at"),
        (["--contacts", "foot", "--impulse-at", "5"], "--impulse-at"),
        (["--contacts", "foot", "--baumgarte", "nan", "1"], "--baumgarte"),
        (["--contacts", "foot", "--pd", "1", "inf"], "--pd"),
        (["--contacts", "foot", "--impulse-at", "0.5", "--restitution", "2"], "--restitution"),
        (["--contacts", "foot", "--restitution", "0.5"], "--impulse-at"),
        (["--contacts", "foot", "--pd", "1", "1", "--tau", "0"], "--pd and --tau"),
        (["--impulse-at", "0.5"], "--contacts"),
        (["--contacts", "foot:7d"], "7d"),
        (["--contacts", "foot", "--stance", "x"], "--stance 'x'"),
        (["--contacts", "foot", "--stance", "nan=foot"], "--stance"),
        (["--contacts", "foot", "--stance", "2=foot"], "--stance 2"),
        (["--contacts", "foot", "--stance", "0.5=foot", "0.2="], "must increase"),
        (["--contacts", "foot", "--stance", "0.5=nose"], "no contact is named 'nose'"),
        (["--contacts", "foot", "--stance", "0.5=\x1b[2J"], "no contact is named"),
        (["--contacts", "foot", "--stance", "0.51=foot", "0.55="], "changes twice"),
        (["--contacts", "foot", "--stance", "0.5=foot", "--impulse-at", "0.5"], "exclude each other"),
        (["--stance", "0.5=foot"], "--contacts"),
    ],
)
def test_simulate_refuses_bad_contact_options(hopper, tmp_path, capsys, extra, message):
    path = hopper[0]
    line = refused(
        capsys, "simulate", path, "--duration", "1", "--dt", "0.1", "--out", tmp_path / "x.csv", *extra
    )
    assert message in line and not (tmp_path / "x.csv").exists()


def test_compiled_contact_functions_check_active_and_restitution(hopper):
    _, _, plant = hopper
    q, v = Q0, np.zeros(7)
    for active in ([1.0, 0.5], [1.0, np.nan], [1.0], [[1.0, 1.0, 1.0]], "ab"):
        with pytest.raises(SymdynError, match="active") as info:
            plant.contact_forward_dynamics(q, v, v, active)
        assert "\n" not in str(info.value)
    for e in ([2.0], [np.nan], [-0.1], [0.1, 0.2]):
        with pytest.raises(SymdynError, match="restitution"):
            plant.impulse_dynamics(q, v, [1.0, 1.0], e)
    qdd, lam = plant.contact_forward_dynamics(
        np.tile(q, (3, 1)), np.zeros((3, 7)), np.zeros((3, 7)), [[1, 0]] * 3
    )
    assert np.all(lam[:, 3:] == 0) and np.all(np.isfinite(qdd))
    with pytest.raises(SymdynError, match="active"):  # a batch: every state's mask is checked
        plant.contact_forward_dynamics(
            np.tile(q, (2, 1)), np.zeros((2, 7)), np.zeros((2, 7)), [[1, 0], [1, 2]]
        )


def test_compiled_baumgarte_functions_check_anchor_and_gains(hopper):
    _, robot, plant = hopper
    q, v = Q0, np.zeros(7)
    poses = contact_poses(robot, contact_rows(robot, robot.contacts), Q0[None])[0]
    anchor = np.concatenate([np.r_[T[:3, 3], T[:3, :3].reshape(-1)] for T in poses])
    flat = plant.contact_forward_dynamics_baumgarte(q, v, v, [1, 1], anchor, [10.0, 2.0])
    shaped = plant.contact_forward_dynamics_baumgarte(q, v, v, [1, 1], anchor.reshape(2, 12), [10.0, 2.0])
    assert all(np.array_equal(a, b) for a, b in zip(flat, shaped, strict=True))
    assert np.abs(plant.contact_error(q, anchor)).max() < 1e-12  # at its anchors
    scaled, mirrored, skewed = anchor.copy(), anchor.copy(), anchor.copy()
    scaled[3:12] *= 1.001
    mirrored[15:24] = -mirrored[15:24]  # det -1
    skewed[4] += 1e-5
    for bad, message in (
        (anchor[:12], "anchor must be 2 x 12"),
        (np.r_[anchor, 0.0], "anchor must be 2 x 12"),
        (np.where(np.arange(24) == 5, np.nan, anchor), "not finite"),
        (np.where(np.arange(24) == 0, np.inf, anchor), "not finite"),
        (scaled, "contact 0 is not a rotation"),
        (mirrored, "contact 1 is not a rotation"),
        (skewed, "contact 0 is not a rotation"),
        ("ab", "anchor must be"),
        (None, "anchor must be"),
    ):
        for call in (
            lambda a: plant.contact_error(q, a),
            lambda a: plant.contact_forward_dynamics_baumgarte(q, v, v, [1, 1], a, [1.0, 1.0]),
        ):
            with pytest.raises(SymdynError, match=message) as info:
                call(bad)
            assert "\n" not in str(info.value)
    for gains in ([-1.0, 0.0], [np.nan, 1.0], [1.0, np.inf], [1.0], [1.0, 2.0, 3.0], "ab", [[1.0, -2.0]] * 2):
        with pytest.raises(SymdynError, match="gains") as info:
            plant.contact_forward_dynamics_baumgarte(q, v, v, [1, 1], anchor, gains)
        assert "\n" not in str(info.value)


def test_simulate_contacts_refuses_bad_arguments(hopper):
    _, robot, plant = hopper
    unstabilised = SimpleNamespace(functions=("contact_forward_dynamics", "impulse_dynamics"))
    for kwargs, message in (
        ({"baumgarte": (np.nan, 1.0)}, "Kp"),
        ({"baumgarte": (1.0, -1.0)}, "Kd"),
        ({"impulse_at": 2.0}, "impulse time"),
        ({"restitution": 1.5}, "restitution"),
        ({"integrator": "rk45"}, "integrator"),
        ({"dt": 2.0}, "dt"),
        ({"stance": "foot"}, "stance must be a non-empty list"),
        ({"stance": []}, "stance must be a non-empty list"),
        ({"stance": [(0.5,)]}, "stance entry 0 must be a pair"),
        ({"stance": [(True, ["foot"])]}, "the time must be a number"),
        ({"stance": [(0.5, "foot")]}, "a list of names"),
        ({"stance": [(0.5, ["foot"]), (0.5, [])]}, "must increase"),
        ({"stance": [(-0.1, ["foot"])]}, r"\[0, 1\]"),
        ({"stance": [(0.5, [3])]}, "no contact is named 3"),
        ({"stance": [(0.5, ["foot"])], "impulse_at": 0.5}, "not both"),
        ({"baumgarte": (1.0, 1.0), "plant": "unstabilised"}, "contact_baumgarte"),
    ):
        given = plant if kwargs.pop("plant", None) is None else unstabilised
        with pytest.raises(SymdynError, match=message) as info:
            simulate_contacts(given, robot, Q0, **({"duration": 1.0, "dt": 0.1} | kwargs))
        assert "\n" not in str(info.value)


def test_a_fixed_base_arm_holds_its_tip_with_rk4(tmp_path):
    """planar_3r with a point contact at its last link (the z row is empty: the damped solve):
    the samples solve the stabilised KKT system of the oracle, q integrated in a vector space."""
    robot = symdyn.load_robot(Path(__file__).parent.parent / "examples/planar_3r.yaml", contacts=["link3"])
    plant = symdyn.compile(robot, functions=("dynamics", "contacts", "contact_baumgarte"))
    kp, kd = 100.0, 20.0
    traj = simulate_contacts(
        plant, robot, [0.3, 0.5, 0.4], [0.2, -0.1, 0.3], duration=0.2, dt=1e-3, tau=[1, 0, 0],
        integrator="rk4", baumgarte=(kp, kd),
    )  # fmt: skip
    anchor = _positions(robot, traj.q[0])
    for k in (0, 100, 200):
        q, v, a, lam = traj.q[k], traj.qd[k], traj.qdd[k], traj.lam[k]
        Jc = contact_jacobian(robot, None, q)
        assert np.allclose(symdyn.rnea(robot, q, v, a) - Jc.T @ lam, traj.tau[k], atol=1e-8)
        error = (_positions(robot, q) - anchor).reshape(-1)
        assert np.allclose(Jc @ a + contact_drift(robot, None, q, v), -kd * Jc @ v - kp * error, atol=1e-6)
    assert traj.q.shape == (201, 3) and lam[2] == 0.0
