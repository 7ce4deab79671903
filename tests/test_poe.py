"""Product-of-exponentials input (symdyn.parsers.poe, poe_file) and the end-effector wrench term.

Expected values come from the `modern_robotics` package (Lynch and Park's own code) fed the
same lists, from the same robot written as a DH robot file (its Modern Robotics lists built
here with NumPy DH matrices, not by symdyn) and as a URDF (written here from the lists), and
from the numeric oracle symdyn.rnea. The lists of a robot file are read with yaml.safe_load.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import itertools
import tempfile
from functools import cache
from pathlib import Path

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp
import yaml
from robots import assert_close

import symdyn
import symdyn.codegen
from symdyn.algorithms.kinematics import frame_poses
from symdyn.algorithms.tip_wrench import body_jacobian
from symdyn.apps.checking.check import check_answers
from symdyn.errors import SymdynError
from symdyn.parsers import load_urdf, robot_from_data
from symdyn.parsers.poe import robot_from_poe

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GRAVITY = np.array([0.0, 0.0, -9.81])


def lists_from_file(path: Path):
    """Mlist, Glist, Slist of a `convention: poe` robot file, straight from its YAML."""
    data = yaml.safe_load(path.read_text())
    frames = [link["frame"] for link in data["links"]] + [data["end_effector"]]
    Mlist = []
    for f in frames:
        T = np.eye(4)
        T[:3, 3] = f.get("position", [0, 0, 0])
        T[:3, :3] = np.array(f.get("rotation", np.eye(3)), dtype=float)
        Mlist.append(T)
    Glist = [np.diag(np.array(link["spatial_inertia"], dtype=float)) for link in data["links"]]
    Slist = np.array([link["screw"] for link in data["links"]], dtype=float).T
    return Mlist, Glist, Slist


def mr_three_link():
    """The 3-link robot of modern_robotics' InverseDynamics docstring, with S_1 = [0,0,1,0,0,0]
    (the docstring's [1,0,1,0,1,0] has |omega| = sqrt 2, refused below)."""
    M01 = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.089159], [0, 0, 0, 1]])
    M12 = np.array([[0, 0, 1, 0.28], [0, 1, 0, 0.13585], [-1, 0, 0, 0], [0, 0, 0, 1]])
    M23 = np.array([[1, 0, 0, 0], [0, 1, 0, -0.1197], [0, 0, 1, 0.395], [0, 0, 0, 1]])
    M34 = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.14225], [0, 0, 0, 1]])
    G1 = np.diag([0.010267, 0.010267, 0.00666, 3.7, 3.7, 3.7])
    G2 = np.diag([0.22689, 0.22689, 0.0151074, 8.393, 8.393, 8.393])
    G3 = np.diag([0.0494433, 0.0494433, 0.004095, 2.275, 2.275, 2.275])
    S = np.array([[0, 0, 1, 0, 0, 0], [0, 1, 0, -0.089, 0, 0], [0, 1, 0, -0.089, 0, 0.425]]).T
    return [M01, M12, M23, M34], [G1, G2, G3], S


# ------------------------------------------------------------------ the same robot as DH

RPR_DH = {
    "name": "rpr",
    "gravity": [0, 0, -9.81],
    "links": [
        {
            "joint": "revolute",
            "a": 0.1,
            "alpha": "pi/2",
            "d": 0.3,
            "mass": 2.0,
            "com": [-0.05, 0.02, 0.01],
            "inertia": {"ixx": 0.03, "iyy": 0.025, "izz": 0.02, "ixy": 0.002, "ixz": -0.001, "iyz": 0.003},
        },
        {
            "joint": "prismatic",
            "a": 0.05,
            "alpha": "-pi/2",
            "theta": "pi/2",
            "d": 0.2,
            "mass": 1.5,
            "com": [0.01, -0.03, -0.1],
            "inertia": {"ixx": 0.02, "iyy": 0.018, "izz": 0.006, "ixy": -0.001, "ixz": 0.002, "iyz": 0.0},
        },
        {
            "joint": "revolute",
            "a": 0.25,
            "alpha": 0,
            "d": 0.04,
            "theta": 0.3,
            "mass": 0.8,
            "com": [-0.12, 0.0, 0.01],
            "inertia": {"ixx": 0.002, "iyy": 0.009, "izz": 0.008, "ixy": 0.0005, "ixz": 0.0, "iyz": -0.0004},
        },
    ],
}


def _dh(a, alpha, d, theta):
    """Standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha), as a 4x4 NumPy matrix."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]]
    )


def dh_lists(data: dict):
    """Modern Robotics lists of a standard-DH robot at q = 0 (NumPy only): frame {i} is DH frame
    i moved to the centre of mass, joint i turns (slides) along z of DH frame i-1."""
    value = {"pi/2": np.pi / 2, "-pi/2": -np.pi / 2}
    T, prev, Mlist, Glist, S = np.eye(4), np.eye(4), [], [], []
    for link in data["links"]:
        z, o = T[:3, 2], T[:3, 3]
        S.append(np.r_[z, np.cross(o, z)] if link["joint"] == "revolute" else np.r_[0, 0, 0, z])
        row = [value.get(link.get(k, 0), link.get(k, 0)) for k in ("a", "alpha", "d", "theta")]
        T = T @ _dh(*row)
        C = T.copy()
        C[:3, 3] = T[:3, :3] @ np.array(link["com"]) + T[:3, 3]
        Mlist.append(np.linalg.inv(prev) @ C)
        prev = C
        i = link["inertia"]
        inertia = np.array(
            [[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]]
        )
        G = np.zeros((6, 6))
        G[:3, :3], G[3:, 3:] = inertia, link["mass"] * np.eye(3)
        Glist.append(G)
    Mlist.append(np.linalg.inv(prev) @ T)  # the end effector: DH frame n
    return Mlist, Glist, np.array(S).T


# ------------------------------------------------------------------ the same robot as URDF


def urdf_text(Mlist, Glist, Slist, name: str) -> str:
    """A URDF of a revolute chain: link i's frame on joint axis i (space axes), the inertia
    rotated into it by hand."""
    parts, parent, r_prev, C = [f'<robot name="{name}"><link name="base"/>'], "base", np.zeros(3), np.eye(4)
    for i, G in enumerate(Glist):
        C = C @ Mlist[i]
        w, v = Slist[:3, i], Slist[3:, i]
        r = np.cross(w, v)
        R = C[:3, :3]
        inertia = R @ G[:3, :3] @ R.T
        com = C[:3, 3] - r
        xyz, c = _words(r - r_prev), _words(com)
        ixx, iyy, izz, ixy, ixz, iyz = (
            float(inertia[k]) for k in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
        )
        parts.append(
            f'<joint name="j{i + 1}" type="continuous"><parent link="{parent}"/><child link="l{i + 1}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{_words(w)}"/></joint>'
            f'<link name="l{i + 1}"><inertial><origin xyz="{c}"/><mass value="{float(G[3, 3])!r}"/>'
            f'<inertia ixx="{ixx!r}" iyy="{iyy!r}" izz="{izz!r}" ixy="{ixy!r}" ixz="{ixz!r}" iyz="{iyz!r}"/>'
            "</inertial></link>"
        )
        parent, r_prev = f"l{i + 1}", r
    return "".join(parts) + "</robot>"


def _words(v) -> str:
    return " ".join(repr(float(x)) for x in v)


# ------------------------------------------------------------------ comparisons


@cache
def derived(key: str):
    if key == "ur5_file":
        return symdyn.derive(symdyn.load_robot(EXAMPLES / "mr_ur5.yaml"))
    if key == "ur5_lists":
        return symdyn.derive(robot_from_poe(*lists_from_file(EXAMPLES / "mr_ur5.yaml"), gravity=GRAVITY))
    if key == "three":
        return symdyn.derive(robot_from_poe(*mr_three_link(), gravity=GRAVITY))
    if key == "rpr_poe":
        return symdyn.derive(robot_from_poe(*dh_lists(RPR_DH), gravity=GRAVITY, name="rpr_poe"))
    assert key == "rpr_dh"
    return symdyn.derive(robot_from_data(RPR_DH))


LISTS = {
    "ur5_file": lambda: lists_from_file(EXAMPLES / "mr_ur5.yaml"),
    "ur5_lists": lambda: lists_from_file(EXAMPLES / "mr_ur5.yaml"),
    "three": mr_three_link,
    "rpr_poe": lambda: dh_lists(RPR_DH),
    "rpr_dh": lambda: dh_lists(RPR_DH),
}


@pytest.mark.parametrize("key", sorted(LISTS))
def test_matches_modern_robotics_at_random_states(key):
    """InverseDynamics (with and without F_tip), MassMatrix, VelQuadraticForces, GravityForces,
    EndEffectorForces and ForwardDynamics of modern_robotics, at random states."""
    Mlist, Glist, Slist = LISTS[key]()
    dyn = derived(key)
    rng = np.random.default_rng(14)
    for _ in range(4):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, size=(3, dyn.n))
        F = rng.normal(size=6)
        tau = dyn.evaluate("tau", q, qd, qdd)
        tip = dyn.tip_wrench_torque(F, q)
        assert_close(tau, mr.InverseDynamics(q, qd, qdd, GRAVITY, np.zeros(6), Mlist, Glist, Slist), 1e-9)
        assert_close(tau + tip, mr.InverseDynamics(q, qd, qdd, GRAVITY, F, Mlist, Glist, Slist), 1e-9)
        assert_close(tip, mr.EndEffectorForces(q, F, Mlist, Glist, Slist), 1e-9)
        assert_close(dyn.evaluate("M", q), mr.MassMatrix(q, Mlist, Glist, Slist), 1e-9)
        assert_close(dyn.evaluate("V", q, qd), mr.VelQuadraticForces(q, qd, Mlist, Glist, Slist), 1e-9)
        assert_close(dyn.evaluate("G", q), mr.GravityForces(q, GRAVITY, Mlist, Glist, Slist), 1e-9)
        applied = rng.normal(size=dyn.n) * 10
        forward = np.linalg.solve(dyn.evaluate("M", q), applied - tip - dyn.evaluate("bias", q, qd))
        assert_close(forward, mr.ForwardDynamics(q, qd, applied, GRAVITY, F, Mlist, Glist, Slist), 1e-8)


def test_poe_robot_equals_its_dh_and_urdf_forms():
    """The RPR arm from its DH file and from its PoE lists; the UR5 from its PoE file and from
    a URDF written from the lists: same torques (numeric oracle), same masses."""
    rng = np.random.default_rng(3)
    ur5 = symdyn.load_robot(EXAMPLES / "mr_ur5.yaml")
    lists = lists_from_file(EXAMPLES / "mr_ur5.yaml")
    pairs = [
        (robot_from_data(RPR_DH), robot_from_poe(*dh_lists(RPR_DH), gravity=GRAVITY)),
        (ur5, _load_urdf_text(urdf_text(*lists, "ur5_urdf"))),
    ]
    for a, b in pairs:
        for _ in range(3):
            q, qd, qdd = rng.uniform(-2, 2, size=(3, a.n))
            assert_close(symdyn.rnea(a, q, qd, qdd), symdyn.rnea(b, q, qd, qdd), 1e-9)


def _load_urdf_text(text: str):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "robot.urdf"
        path.write_text(text)
        robot = load_urdf(path)
    return dataclasses.replace(robot, gravity=sp.ImmutableMatrix(GRAVITY))


def test_file_and_lists_agree_and_the_file_loads_as_poe():
    a, b = derived("ur5_file"), derived("ur5_lists")
    assert a.robot.convention == "poe" and a.n == 6 and a.params == ()
    q, qd, qdd = np.random.default_rng(5).normal(size=(3, 6))
    assert_close(a.evaluate("tau", q, qd, qdd), b.evaluate("tau", q, qd, qdd), 1e-12)


def test_limits_in_a_poe_file_are_the_joint_ranges():
    data = yaml.safe_load((EXAMPLES / "mr_ur5.yaml").read_text())
    data["links"][1]["limits"] = ["-pi/2", "pi/2"]
    data["links"][5]["limits"] = [-6.28, 6.28]
    robot = robot_from_data(data, source="ur5.yaml")
    assert robot.links[1].limits == (-sp.pi / 2, sp.pi / 2)
    assert robot.links[5].limits == (sp.Float("-6.28"), sp.Float("6.28"))
    assert robot.joint_ranges() == (None, (-np.pi / 2, np.pi / 2), None, None, None, (-6.28, 6.28))
    plain = symdyn.load_robot(EXAMPLES / "mr_ur5.yaml")
    assert [dataclasses.replace(lk, limits=None) for lk in robot.links] == list(plain.links)


def test_symbolic_entries_become_free_parameters():
    """A two-link planar arm with symbolic length and masses: PoE with SymPy matrices against
    the DH robot file of the same arm (point masses at the link ends, Craig's example 6.3)."""
    L1, L2, m1, m2 = sp.symbols("L1 L2 m1 m2")
    M = [sp.Matrix([[1, 0, 0, L1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
         sp.Matrix([[1, 0, 0, L2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
         sp.eye(4)]  # fmt: skip
    G = [sp.diag(0, 0, 0, m1, m1, m1), sp.diag(0, 0, 0, m2, m2, m2)]
    S = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0]]).T
    poe = robot_from_poe(M, G, S, gravity=(0, -9.81, 0), name="craig_poe")
    assert set(poe.params) == {L1, L2, m1, m2}
    dh = robot_from_data(
        {
            "name": "craig_dh",
            "gravity": [0, -9.81, 0],
            "links": [
                {"joint": "revolute", "a": "L1", "mass": "m1", "com": [0, 0, 0]},
                {"joint": "revolute", "a": "L2", "mass": "m2", "com": [0, 0, 0]},
            ],
        }
    )
    a, b = symdyn.derive(poe), symdyn.derive(dh)
    assert sp.simplify(a.tau - b.tau.xreplace({s: sp.Symbol(str(s)) for s in b.params})) == sp.zeros(2, 1)


@pytest.mark.parametrize(
    "change,message",
    [
        (lambda M, G, S: (M, G, _with(S, (4, 1), 0.2)), "pitch"),
        (lambda M, G, S: (M, G, _with(S, (1, 0), 1.0)), "unit omega"),
        (lambda M, G, S: (M, [_with(G[0], (0, 3), 0.1)] + G[1:], S), "[[I, 0], [0, m*1]]"),
        (lambda M, G, S: (M, [_with(G[0], (4, 4), 2.0)] + G[1:], S), "[[I, 0], [0, m*1]]"),
        (lambda M, G, S: ([_with(M[0], (0, 1), 0.5)] + M[1:], G, S), "orthonormal"),
        (lambda M, G, S: (M[:-1], G, S), "end-effector"),
        (lambda M, G, S: (M, G, S[:5]), "6x3"),
    ],
)
def test_bad_lists_are_refused_with_one_clear_message(change, message):
    with pytest.raises(SymdynError, match="robot_from_poe") as err:
        robot_from_poe(*change(*mr_three_link()))
    assert message in str(err.value)


def test_prismatic_screw_needs_a_unit_direction():
    M, G, S = mr_three_link()
    S = S.copy()
    S[:, 2] = [0, 0, 0, 0, 0, 2.0]
    with pytest.raises(SymdynError, match="unit v"):
        robot_from_poe(M, G, S)


def _with(a, index, value):
    b = np.array(a, dtype=float)
    b[index] = value
    return b


@pytest.mark.parametrize(
    "edit,field",
    [
        (lambda d: d["links"][1].update(screw=[0, 1, 0, 1, 0.5, 0]), "screw"),
        (lambda d: d["links"][0].update(spatial_inertia=[1, 1, 1, 2, 2, 3]), "spatial_inertia"),
        (lambda d: d["links"][2].update(twist=1), "twist"),
        (lambda d: d["links"][2].pop("screw"), "screw"),
        (lambda d: d["links"][1]["frame"].update(rotation=[[1, 0], [0, 1]]), "frame.rotation"),
        (lambda d: d.update(end_effector={"position": [0, 0]}), "end_effector.position"),
        (lambda d: d["links"][3].update(limits=[1]), "limits"),
        (lambda d: d["links"][3].update(limits=["pi", "-pi"]), "limits"),
    ],
)
def test_bad_poe_files_name_link_and_field(edit, field):
    data = yaml.safe_load((EXAMPLES / "mr_ur5.yaml").read_text())
    edit(data)
    with pytest.raises(SymdynError) as err:
        robot_from_data(data, source="ur5.yaml")
    assert err.value.file == "ur5.yaml" and err.value.field == field


def test_tip_wrench_torque_symbolic_matches_numeric():
    dyn = derived("three")
    F = sp.symbols("m_x m_y m_z f_x f_y f_z")
    expr = dyn.tip_wrench_torque(F)
    q, w = np.array([0.3, -0.7, 1.1]), np.array([0.5, -1.0, 2.0, 0.1, 0.2, -0.3])
    values = {**dict(zip(dyn.q, q, strict=True)), **dict(zip(F, w, strict=True))}
    assert_close(np.array(expr.xreplace(values), dtype=float)[:, 0], dyn.tip_wrench_torque(w, q), 1e-12)
    with pytest.raises(SymdynError, match="6 entries"):
        dyn.tip_wrench_torque([1, 2, 3])


def test_frames_and_jacobian_match_modern_robotics_kinematics():
    """Frame {i} (links 1 .. n-1) and the end-effector frame {n+1} (last link) against FKinSpace,
    and the space Jacobian of MR (JacobianSpace) from symdyn's body Jacobian."""
    Mlist, Glist, Slist = lists_from_file(EXAMPLES / "mr_ur5.yaml")
    robot = symdyn.load_robot(EXAMPLES / "mr_ur5.yaml")
    homes = list(itertools.accumulate(Mlist, np.matmul))
    q = np.random.default_rng(8).uniform(-np.pi, np.pi, 6)
    frames = frame_poses(robot, list(q))
    for i in range(5):
        assert_close(
            np.array(frames[i].matrix(), dtype=float), mr.FKinSpace(homes[i], Slist[:, : i + 1], q[: i + 1])
        )
    T = mr.FKinSpace(homes[6], Slist, q)
    assert_close(np.array(frames[5].matrix(), dtype=float), T)
    Jb = np.array(body_jacobian(robot, list(q)), dtype=float)
    assert_close(mr.Adjoint(T) @ Jb, mr.JacobianSpace(Slist, q))


def test_generated_tip_wrench_torque_matches_modern_robotics(tmp_path):
    """tip_wrench_torque(q, F, p) of the generated NumPy and CasADi code (PoE robots only)."""
    import casadi

    robot = symdyn.load_robot(EXAMPLES / "mr_ur5.yaml")
    Mlist, Glist, Slist = lists_from_file(EXAMPLES / "mr_ur5.yaml")
    files = symdyn.codegen.render(robot, targets=("python", "casadi"))
    for name, content in files.items():
        (tmp_path / name).write_bytes(content.encode() if isinstance(content, str) else content)
    module = _import(tmp_path / "mr_ur5_numpy.py")
    function = casadi.Function.load(str(tmp_path / "mr_ur5_tip_wrench_torque.casadi"))
    rng = np.random.default_rng(9)
    q, F = rng.uniform(-np.pi, np.pi, (4, 6)), rng.normal(size=(4, 6))
    want = np.array([mr.EndEffectorForces(q[k], F[k], Mlist, Glist, Slist) for k in range(4)])
    assert_close(module.tip_wrench_torque(q, F), want, 1e-12)
    assert_close(np.array(function(q[0], F[0], [])).ravel(), want[0], 1e-12)
    assert (
        "tip_wrench_torque"
        not in symdyn.codegen.render(symdyn.load_robot(EXAMPLES / "roger_arm.yaml"), ("c",))[
            "roger_arm_dynamics.h"
        ]
    )


def _import(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem + "_poe_test", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ur5_answers_are_modern_robotics_numbers_and_check_confirms_them():
    """examples/answers/mr_ur5_answers.yaml holds modern_robotics' own numbers (recomputed here)
    at the state it names, and `symdyn check` matches them; a changed digit is caught."""
    answers = EXAMPLES / "answers" / "mr_ur5_answers.yaml"
    data = yaml.safe_load(answers.read_text())
    Mlist, Glist, Slist = lists_from_file(EXAMPLES / "mr_ur5.yaml")
    q, qd, qdd = (np.array(data["at"][k]) for k in ("q", "qd", "qdd"))
    g = [0, 0, -9.81]
    assert_close(q, [0, np.pi / 6, np.pi / 4, np.pi / 3, np.pi / 2, 2 * np.pi / 3], 1e-15)
    assert_close(np.array(data["M"]), mr.MassMatrix(q, Mlist, Glist, Slist), 1e-11)
    assert_close(data["V"], mr.VelQuadraticForces(q, qd, Mlist, Glist, Slist), 1e-11)
    assert_close(data["G"], mr.GravityForces(q, g, Mlist, Glist, Slist), 1e-11)
    assert_close(data["tau"], mr.InverseDynamics(q, qd, qdd, g, np.zeros(6), Mlist, Glist, Slist), 1e-11)
    robot = symdyn.load_robot(EXAMPLES / "mr_ur5.yaml")
    report = check_answers(robot, answers)
    assert report.ok and len(report.results) == 54
    data["tau"][1] = -41.0704
    report = check_answers(robot, data)
    assert [r.label for r in report.differing] == ["tau[2]"]
    with pytest.raises(SymdynError, match="unknown name"):
        check_answers(robot, {**data, "at": {**data["at"], "m9": 1.0}})
    with pytest.raises(SymdynError, match="checked symbolically"):
        check_answers(robot, {**data, "steps": {1: {"omega": [0, 0, "qd1"]}}})


@pytest.mark.parametrize("bad", [np.inf, np.nan, 1e308, -1e200])
def test_robot_from_poe_refuses_numbers_that_are_not_finite_or_beyond_1e150(bad):
    """A NaN or an infinity in M raised ValueError from deep inside; 1e308 is out of range."""
    M = [np.eye(4), np.eye(4)]
    M[0][0, 3] = bad
    S = np.array([[0, 0, 1, 0, 0, 0]]).T
    with pytest.raises(SymdynError, match=r"robot_from_poe: Mlist\[0\] .*(not finite|more than 1e\+150)"):
        robot_from_poe(M, [np.eye(6)], S)
    with pytest.raises(SymdynError, match=r"robot_from_poe: Glist\[0\] .*(not finite|more than 1e\+150)"):
        robot_from_poe([np.eye(4), np.eye(4)], [np.diag([bad, 1, 1, 1, 1, 1])], S)
