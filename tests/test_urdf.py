"""The URDF loader: geometry, merged and locked links, clear errors, and real robots.

Expected values never come from the loader itself: they come from the same arm
written as a DH robot file, from robots built by hand with NumPy rotations,
from closed forms, from serial chains in which a fixed or locked joint is an
extra joint held at zero (judged by the numeric oracle symdyn.rnea), from
inertias merged by hand with symdyn.model.inertia, from the raw XML read with
ElementTree, and from the manufacturers' published DH tables.

The real robots (Panda, UR5, UR10, a double pendulum) come from the
example-robot-data package (PyPI), which ships URDFs under its install prefix;
those tests skip if it is not installed.
"""

from __future__ import annotations

import hashlib
import math
import warnings
import xml.etree.ElementTree as ET
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from cbuild import build_dynamics, compilers
from robots import assert_close, mat, random_state, rpy, rx, ry, rz, vec
from timebound import refused

import symdyn.codegen
from symdyn import inertia as si
from symdyn.cli.main import main
from symdyn.codegen import c as c_target
from symdyn.dynamics import derive
from symdyn.errors import SymdynError, SymdynWarning
from symdyn.model.robot import Friction, Link, Robot
from symdyn.parsers import robot_from_data
from symdyn.parsers.urdf import load_urdf, urdf_robot_name
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import forward_kinematics, gravity_torque, mass_matrix, rnea
from symdyn.spatial.transform import Transform

DATA = Path(__file__).parent / "data" / "urdf"
G = 9.81


# --------------------------------------------------------------------------- helpers


def rodrigues(axis, q):
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K


def hom(R=None, p=(0, 0, 0)):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = np.eye(3) if R is None else R, p
    return T


def transform(T) -> Transform:
    return Transform(mat(T[:3, :3]), vec([float(x) for x in T[:3, 3]]))


def link(name, T, axis, mass, com, tensor, joint="revolute", friction=(0, 0)) -> Link:
    """A Link built from NumPy data (placement as a 4x4 matrix)."""
    return Link(
        name,
        joint,
        transform(T),
        vec([float(x) for x in axis]),
        sp.Float(float(mass)),
        vec([float(x) for x in com]),
        mat(tensor),
        friction=Friction(sp.Float(friction[0]), sp.Float(friction[1])),
    )


def robot_of(links, name="hand_built") -> Robot:
    return Robot(name, tuple(links), vec([0, 0, -G]))


def load(name: str, **kw) -> Robot:
    """A file of tests/data/urdf; any warning is a failure."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_urdf(DATA / name, **kw)


def compare_rnea(got: Robot, want: Robot, rng, states=4, select=None, pad=None) -> None:
    """rnea(got) equals rnea(want) at random states; `select`/`pad` map got's joints into want's."""
    for _ in range(states):
        q, qd, qdd = random_state(got, rng)
        if pad is None:
            tau_want = rnea(want, q, qd, qdd)
        else:
            full = [np.zeros(want.n) for _ in range(3)]
            for f, x in zip(full, (q, qd, qdd), strict=True):
                f[pad] = x
            tau_want = rnea(want, *full)[pad]
        assert_close(rnea(got, q, qd, qdd), tau_want, what=f"q={q}")


def compare_symbolic(robot: Robot, rng, states=3, dyn=None) -> None:
    """The derivation of a loaded robot agrees with the numeric oracle on the same robot."""
    dyn = dyn or derive(robot, simplify=False)
    for _ in range(states):
        q, qd, qdd = random_state(robot, rng)
        assert_close(dyn.evaluate("tau", q, qd, qdd), rnea(robot, q, qd, qdd), what="tau")
        assert_close(dyn.evaluate("M", q), mass_matrix(robot, q), what="M")
        assert_close(dyn.evaluate("G", q), gravity_torque(robot, q), what="G")


def merged(parts):
    """Mass, centre of mass and inertia about it of (mass, com, tensor about com) in one frame."""
    m = sum(p[0] for p in parts)
    c = sum(p[0] * np.asarray(p[1], dtype=float) for p in parts) / m
    tensor = sum(si.parallel_axis(p[2], p[0], np.asarray(p[1], dtype=float) - c) for p in parts)
    return m, c, tensor


def placed(T, mass, xyz, rpy_angles, tensor):
    """(mass, com, tensor) of an inertial given in a link frame placed at T (4x4) in the body."""
    R = T[:3, :3] @ rpy(*rpy_angles)
    return mass, T[:3, :3] @ np.asarray(xyz, dtype=float) + T[:3, 3], si.rotate(np.asarray(tensor), R)


def as_float(m) -> np.ndarray:
    return np.array(sp.Matrix(m).evalf().tolist(), dtype=float)


@pytest.fixture
def rng():
    return np.random.default_rng(20240605)


# --------------------------------------------------------------------------- the model


def test_robot_fields():
    path = DATA / "two_link.urdf"
    robot = load("two_link.urdf")
    assert robot.name == "two_link"
    assert robot.convention == "urdf"
    assert robot.source == str(path)
    assert robot.source_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert robot.gravity == sp.ImmutableMatrix([0, 0, sp.Float(-9.81)])
    assert [lk.name for lk in robot.links] == ["upper", "lower"]
    assert [lk.joint for lk in robot.links] == ["revolute", "revolute"]  # continuous = revolute
    assert robot.params == () and robot.values == ()
    for lk in robot.links:
        assert lk.frame.is_identity()
        assert lk.axis == sp.ImmutableMatrix([0, 1, 0])


# joint -> (type, the <limit> element or "", the expected limits of its link)
LIMITS = {
    "j1": ("revolute", '<limit effort="5" lower="-1.5" upper="2" velocity="1"/>', (sp.Float("-1.5"), 2)),
    "j2": ("revolute", "", None),  # no <limit>
    "j3": ("revolute", '<limit effort="5" velocity="1"/>', None),  # lower = upper = 0, the defaults
    "j4": ("revolute", '<limit lower="0" upper="0" effort="0" velocity="0"/>', None),
    "j5": ("revolute", '<limit upper="0.5" effort="1" velocity="1"/>', (0, sp.Float("0.5"))),
    "j6": ("prismatic", '<limit lower="0" upper="0.04" effort="20" velocity="0.2"/>', (0, sp.Float("0.04"))),
    "j7": ("continuous", '<limit lower="-1" upper="1" effort="1" velocity="1"/>', None),  # not read
}


def _limits_urdf(joints: dict) -> str:
    """A chain b -> l1 -> l2 ... whose joint i is joints' i-th (type, <limit>) entry."""
    body = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
    links = "".join(f'<link name="l{i}">{body}</link>' for i in range(1, len(joints) + 1))
    chain = "".join(
        f'<joint name="{name}" type="{kind}"><parent link="{"b" if i == 1 else f"l{i - 1}"}"/>'
        f'<child link="l{i}"/><axis xyz="0 0 1"/>{limit}</joint>'
        for i, (name, (kind, limit, *_)) in enumerate(joints.items(), start=1)
    )
    return f'<robot name="ranged"><link name="b"/>{links}{chain}</robot>'


def test_limits_of_revolute_and_prismatic_joints(tmp_path):
    path = tmp_path / "ranged.urdf"
    path.write_text(_limits_urdf(LIMITS))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = load_urdf(path)
    assert [lk.limits for lk in robot.links] == [want for _, _, want in LIMITS.values()]
    assert robot.joint_ranges() == ((-1.5, 2.0), None, None, None, (0.0, 0.5), (0.0, 0.04), None)
    two_link = load("two_link.urdf")  # shoulder <limit lower="-3" upper="3">, elbow continuous
    assert [lk.limits for lk in two_link.links] == [(-3, 3), None]


@pytest.mark.parametrize(
    ("limit", "field", "fragment"),
    [
        ('<limit lower="-pi" upper="1"/>', "joint(j1).limit.lower", "expected a number, got '-pi'"),
        ('<limit lower="-1" upper="1e999"/>', "joint(j1).limit.upper", "1e999 is not a finite number"),
        (
            '<limit lower="-1" upper="1"/><limit lower="-2" upper="2"/>',
            "joint(j1).limit",
            "more than one <limit>",
        ),
    ],
)
def test_malformed_limits_are_refused(tmp_path, limit, field, fragment):
    path = tmp_path / "bad_limit.urdf"
    path.write_text(_limits_urdf({"j1": ("revolute", limit)}))
    with pytest.raises(SymdynError) as info:
        load_urdf(path)
    err = info.value
    assert (err.file, err.link_index, err.link_name, err.field) == (str(path), 2, "l1", field)
    assert fragment in err.reason and "(line 1)" in err.reason


# -- files that urdfdom and Pinocchio load although they break a rule: read as they read them

ODD_BODY = (
    '<inertial><mass value="1.5"/><origin xyz="0.1 0.2 0.3" rpy="0.1 0.2 0.3"/>'
    '<inertia ixx="0.4" ixy="0.01" ixz="0.02" iyy="0.5" iyz="0.03" izz="0.6"/></inertial>'
)
ODD_LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'

# case -> (text before the file, type and elements of joint j1, fragments of the one warning)
ODD_FILES = {
    "lower above upper": (
        "",
        "revolute",
        '<axis xyz="0 0 1"/>\n<limit lower="1" upper="-1" effort="1" velocity="1"/>',
        (
            "l1): field 'joint(j1).limit': the lower limit 1 is above the upper limit -1",
            "no range",
            "(line 7)",
        ),
    ),
    "lower only": (
        "",
        "prismatic",
        '<axis xyz="0 1 1"/>\n<limit lower="0.5" effort="1" velocity="1"/>',
        ("field 'joint(j1).limit'", "above the upper limit 0 ('upper' is not given: URDF makes it 0)"),
    ),
    "three axes": (
        "",
        "revolute",
        '<axis xyz="1 0 1"/>\n<axis xyz="0 0 1"/>\n<axis xyz="a"/>' + ODD_LIMIT,
        (
            "field 'joint(j1).axis'",
            "3 <axis> elements: the first is read",
            "(line 7, 8) are ignored (line 6)",
        ),
    ),
    "blank lines before the declaration": (
        "\n \t\r\n<?xml version='1.0' encoding='UTF-8'?>\n",
        "revolute",
        '<axis xyz="0 0 1"/>' + ODD_LIMIT,
        ("white space before the XML declaration (line 3) is skipped",),
    ),
}


def _odd_urdf(before: str, kind: str, elements: str) -> str:
    """Two links on joints j1 (`kind`, `elements` from line 6 of the robot) and j2 (revolute about y)."""
    return (
        f'{before}<robot name="odd">\n<link name="b"/>\n<link name="l1">{ODD_BODY}</link>\n'
        f'<link name="l2">{ODD_BODY}</link>\n<joint name="j1" type="{kind}"><parent link="b"/>'
        f'<child link="l1"/><origin xyz="0.1 0 0.2" rpy="0.3 0 0"/>\n{elements}</joint>\n'
        '<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>'
        f'<origin xyz="0.5 0 0"/><axis xyz="0 1 0"/>{ODD_LIMIT}</joint>\n</robot>\n'
    )


@pytest.mark.parametrize("case", ODD_FILES)
def test_files_urdfdom_loads_are_read_as_pinocchio_reads_them_with_a_warning(tmp_path, case, rng):
    """Bullet's lower > upper ("no limit"), a lower limit alone, several <axis> (urdfdom reads the
    first) and blank lines before the XML declaration: Pinocchio loads each; symdyn reads the same
    model (M and tau equal Pinocchio's) and says what it did in one warning naming file and field."""
    pin = pytest.importorskip("pinocchio")
    before, kind, elements, fragments = ODD_FILES[case]
    text = _odd_urdf(before, kind, elements)
    path = tmp_path / "odd.urdf"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_urdf(path)
    (warning,) = [str(w.message) for w in caught]
    assert warning.startswith(f"{path}: ") and "\n" not in warning
    for fragment in fragments:
        assert fragment in warning, warning
    model = pin.buildModelFromXML(text)
    data = model.createData()
    assert [model.names[i] for i in range(1, model.njoints)] == ["j1", "j2"]
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        M = pin.crba(model, data, q)
        assert_close(mass_matrix(robot, q), np.triu(M) + np.triu(M, 1).T, what="M")
        assert_close(rnea(robot, q, qd, qdd), pin.rnea(model, data, q, qd, qdd), what="tau")
    if "limit" in fragments[0]:  # Pinocchio keeps lower > upper as written; symdyn has no range
        assert model.lowerPositionLimit[0] > model.upperPositionLimit[0]
        assert robot.links[0].limits is None and robot.joint_ranges()[0] is None


def test_lines_after_a_declaration_that_white_space_precedes_keep_their_numbers(tmp_path):
    path = tmp_path / "odd.urdf"
    text = _odd_urdf("\n\n<?xml version='1.0'?>\n", "revolute", '<axis xyz="0 0 1"/>' + ODD_LIMIT)
    path.write_text(text.replace("</joint>\n</robot>", "</joint>\n</robt>"))
    with pytest.warns(SymdynWarning, match="line 3"), pytest.raises(SymdynError) as info:
        load_urdf(path)
    assert str(info.value) == f"{path}: invalid XML at line 11, column 3: mismatched tag"


def test_exact_numbers():
    robot = load("rpy_chain.urdf")
    a, b, c = robot.links
    # 1.5707963267948966 and -3.14159265359 are exact multiples of pi/2: entries exactly 0 and +-1
    assert sp.ImmutableMatrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]]) == b.placement.R
    assert all(x.is_Integer or x.is_Float for x in c.placement.R)  # -pi exact, 0.1 a Float
    assert c.placement.R[:, 1] == sp.ImmutableMatrix([-sp.sin(sp.Float("0.1")), sp.cos(sp.Float("0.1")), 0])
    assert b.placement.p == sp.ImmutableMatrix([0, sp.Float("0.25"), 0])
    assert a.mass == sp.Float("1.2") and b.mass == sp.Float("0.8")
    assert b.axis == sp.ImmutableMatrix([0, 0, -1])


SNAP_BODY = (
    '<robot name="s"><link name="b"/><link name="l"><inertial><mass value="1"/>'
    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
    '<joint name="j" type="revolute"><parent link="b"/><child link="l"/>'
    '<origin rpy="{} 0 0"/></joint></robot>'
)


def test_angle_snapping_tolerance(tmp_path):
    """(text, k of the exact multiple k pi/2 it becomes or None, whether it warns)."""
    for text, k, warns in (
        ("1.57079632679", 1, False),  # 4.9e-12 from pi/2
        ("1.5707963", None, True),  # 2.7e-8: kept, with a warning
        ("-1.5707963267948966", -1, False),
        ("1.5707963267948966e0", 1, False),
        ("1", None, False),
        ("0.0000000001", 0, False),  # 1e-10 from 0
    ):
        f = tmp_path / "s.urdf"
        f.write_text(SNAP_BODY.format(text))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            R = load_urdf(f).links[0].placement.R
        assert len(caught) == warns, text
        angle = float(text) if k is None else k * math.pi / 2
        assert (R[1, 1] == sp.cos(k * sp.pi / 2)) if k is not None else R[1, 1].is_Float, text
        assert np.allclose(np.array(R, dtype=float), rx(angle), rtol=0, atol=1e-15), text
        assert all(x.is_Integer or x.is_Float for x in R), R  # numbers, not cos(1)


def test_rpy_angles_snap_on_both_sides_of_1e9(tmp_path):
    f = tmp_path / "s.urdf"
    for offset, exact in ((0.99e-9, True), (-0.99e-9, True), (1.01e-9, False), (-1.01e-9, False)):
        text = repr(-math.pi + offset)
        f.write_text(SNAP_BODY.format(text))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            R = load_urdf(f).links[0].placement.R
        assert len(caught) == (0 if exact else 1), text
        want = sp.ImmutableMatrix([[1, 0, 0], [0, -1, 0], [0, 0, -1]])  # Rx(-pi)
        assert (want == R) is exact, text
        angle = -math.pi if exact else float(text)
        assert np.allclose(np.array(R, dtype=float), rx(angle), rtol=0, atol=1e-15), text


def test_printed_right_angles_in_rpy_warn_naming_file_link_field_and_line(tmp_path):
    """1.5708 in a joint origin and -3.1416 in an inertial origin: kept as written, one warning each."""
    f = tmp_path / "printed.urdf"
    f.write_text(
        (DATA / "two_link.urdf")
        .read_text()
        .replace('<origin xyz="0 0 1.0" rpy="0 0 0"/>', '<origin xyz="0 0 1.0" rpy="0 1.5708 0"/>')
        .replace('<origin xyz="0.25 0 0"/>', '<origin xyz="0.25 0 0" rpy="0 0 -3.1416"/>')
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_urdf(f)
    messages = [str(w.message) for w in caught]
    assert all(issubclass(w.category, SymdynWarning) for w in caught) and len(messages) == 2
    lower, upper = messages  # links are read before joints
    assert upper.startswith(f"{f}: link 2 (upper): field 'joint(shoulder).origin.rpy': pitch 1.5708 rad")
    assert "write 1.5707963267948966 if pi/2 is meant (line 26)" in upper
    assert lower.startswith(f"{f}: link 3 (lower): field 'inertial.origin.rpy': yaw -3.1416 rad")
    assert "write -3.141592653589793 if -pi is meant (line 18)" in lower
    R = robot.links[0].placement.R
    assert R[0, 0] == sp.cos(sp.Float("1.5708")) != 0  # not snapped: Ry(1.5708) as written
    assert np.allclose(np.array(R, dtype=float), ry(1.5708), atol=1e-15)


def test_rpy_multiples_beyond_two_pi_and_negative_are_exact(tmp_path):
    f = tmp_path / "s.urdf"
    for k in (-7, -4, 5, 9):
        text = repr(k * math.pi / 2)
        f.write_text(SNAP_BODY.format(text))
        R = load(f).links[0].placement.R
        assert all(x.is_Integer for x in R), (k, R)
        assert np.array_equal(np.array(R, dtype=float), np.round(rx(k * math.pi / 2))), k


def test_robot_name_as_c_identifier():
    assert urdf_robot_name("panda") == "panda"
    assert urdf_robot_name("2dof_planar") == "robot_2dof_planar"
    assert urdf_robot_name("rpy chain") == "rpy_chain"
    assert urdf_robot_name("my-robot/v1.2") == "my_robot_v1_2"
    assert urdf_robot_name("_Arm") == "robot_Arm"
    assert urdf_robot_name("__x") == "robot__x"
    assert urdf_robot_name("int") == "int_robot"
    assert urdf_robot_name("") == "robot"
    assert urdf_robot_name("Größe") == "Gr__e"
    assert load("rpy_chain.urdf").name == "rpy_chain"


# --------------------------------------------------------------------------- geometry


def test_two_link_matches_dh_robot_file(rng):
    """The vertical two-link arm equals the same arm as a standard-DH robot file.

    DH base axes in URDF base axes: x_d = x_u, y_d = -z_u, z_d = y_u (the joint axis), so
    gravity (0, 0, -g) becomes (0, g, 0); DH frame i sits at the distal end of link i, so a
    centre of mass at x along the link becomes x - a, and the moments (ixx, iyy, izz) of the
    URDF become (ixx, izz, iyy).
    """
    dh = robot_from_data(
        {
            "name": "two_link_dh",
            "gravity": [0, G, 0],
            "links": [
                {
                    "name": "upper",
                    "joint": "revolute",
                    "a": 0.5,
                    "mass": 2.0,
                    "com": [0.3 - 0.5, 0, 0],
                    "inertia": {"ixx": 0.01, "iyy": 0.04, "izz": 0.05},
                },
                {
                    "name": "lower",
                    "joint": "revolute",
                    "a": 0.4,
                    "mass": 1.5,
                    "com": [0.25 - 0.4, 0, 0],
                    "inertia": {"ixx": 0.02, "iyy": 0.015, "izz": 0.03},
                },
            ],
        }
    )
    robot = load("two_link.urdf")
    compare_rnea(robot, dh, rng, states=6)
    dyn = derive(robot, simplify=False)
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        assert_close(dyn.evaluate("tau", q, qd, qdd), rnea(dh, q, qd, qdd))
    # at q = 0 both links lie along +x; gravity pulls them round +y (x -> -z is a positive
    # turn about y), so holding them takes negative efforts: G = -g * (moments of the masses)
    g1 = G * (2.0 * 0.3 + 1.5 * (0.5 + 0.25))
    assert_close(dyn.evaluate("G", [0, 0]), [-g1, -G * 1.5 * 0.25])


def test_rpy_origins_and_inertial_frames(rng):
    """General rpy origins and rotated inertial frames against a robot built with NumPy."""
    robot = load("rpy_chain.urdf")
    T1 = hom(rpy(0.3, -0.5, 1.2), (0.1, -0.2, 0.3))
    T2 = hom(rpy(math.pi / 2, 0, 0), (0, 0.25, 0))
    T3 = hom(rpy(0, -math.pi, 0.1), (0.3, 0, 0.05))
    Ia = np.array([[0.03, 0.001, -0.002], [0.001, 0.02, 0.0015], [-0.002, 0.0015, 0.025]])
    Ib = np.array([[0.004, 0.0005, 0], [0.0005, 0.006, 0], [0, 0, 0.005]])
    Ic = np.array([[0.002, 0, 0.0001], [0, 0.003, 0], [0.0001, 0, 0.0025]])
    Ra, Rb, Rc = rpy(0.2, 0.4, -0.6), rz(math.pi / 4), rx(1.0)
    want = robot_of(
        [
            link("a", T1, (0, 0, 1), 1.2, (0.05, 0.02, -0.1), Ra @ Ia @ Ra.T),
            link("b", T2, (0, 0, -1), 0.8, (0.1, 0, 0), Rb @ Ib @ Rb.T),
            link("c", T3, (1, 0, 0), 0.5, (0.05, 0.01, 0), Rc @ Ic @ Rc.T),
        ]
    )
    for got, exp in zip(robot.links, want.links, strict=True):
        np.testing.assert_allclose(
            as_float(got.placement.matrix()), as_float(exp.placement.matrix()), atol=1e-11
        )
        np.testing.assert_allclose(as_float(got.inertia), as_float(exp.inertia), atol=1e-15)
    compare_rnea(robot, want, rng, states=6)
    compare_symbolic(robot, rng)


def test_non_coordinate_axes_and_prismatic(rng):
    """Axes 1 2 2, 0 3 4 (prismatic) and -0.6 0 0.8 against the same robot with z axes only.

    Each body frame is turned by a rotation S_i whose third column is the axis: placement
    S_{i-1}^T T_i S_i, com S_i^T c, inertia S_i^T I S_i, axis z. The joint motion is the same.
    """
    robot = load("axes.urdf")
    axes = [np.array([1, 2, 2]) / 3, np.array([0, 3, 4]) / 5, np.array([-0.6, 0, 0.8])]
    assert robot.links[0].axis == sp.ImmutableMatrix(
        [sp.Rational(1, 3), sp.Rational(2, 3), sp.Rational(2, 3)]
    )
    assert robot.links[1].axis == sp.ImmutableMatrix([0, sp.Rational(3, 5), sp.Rational(4, 5)])
    assert [lk.joint for lk in robot.links] == ["revolute", "prismatic", "revolute"]
    assert robot.links[1].friction == Friction(sp.Float("0.7"), sp.Float("0.2"))  # damping, friction
    assert robot.links[2].friction == Friction(sp.Float("0.05"), 0)

    def turn(a):
        x = np.cross(a, [1.0, 0, 0]) if abs(a[0]) < 0.9 else np.cross(a, [0, 1.0, 0])
        x /= np.linalg.norm(x)
        return np.column_stack([x, np.cross(a, x), a])

    S = [turn(a) for a in axes]
    Ts = [hom(np.eye(3), (0, 0, 0.2)), hom(ry(0.4), (0.3, 0, 0)), hom(np.eye(3), (0, 0, 0.15))]
    data = [
        (1.0, (0.1, 0.05, 0.02), np.eye(3), [[0.02, 0.001, 0], [0.001, 0.015, 0.002], [0, 0.002, 0.01]]),
        (0.6, (0, 0.02, 0.1), rx(0.3), np.diag([0.003, 0.004, 0.002])),
        (0.4, (0.02, 0, 0.05), np.eye(3), np.diag([0.001, 0.001, 0.0005])),
    ]
    friction = [(0, 0), (0.7, 0.2), (0.05, 0)]
    links, prev = [], np.eye(3)
    for i, (m, c, Ri, I) in enumerate(data):
        T = hom(prev.T) @ Ts[i] @ hom(S[i])
        Ib = S[i].T @ (Ri @ np.asarray(I) @ Ri.T) @ S[i]
        joint = "prismatic" if i == 1 else "revolute"
        links.append(link(f"z{i}", T, (0, 0, 1), m, S[i].T @ np.asarray(c), Ib, joint, friction[i]))
        prev = S[i]
    compare_rnea(robot, robot_of(links), rng, states=6)
    compare_symbolic(robot, rng)


def test_prismatic_cartesian_closed_form(rng):
    robot = load("cartesian.urdf")
    dyn = derive(robot, simplify=False)
    for _ in range(4):
        q, qd, qdd = random_state(robot, rng)
        want = [
            (3 + 2) * (qdd[0] + G) + 3.5 * qd[0] + 1.25 * np.sign(qd[0]),
            2 * qdd[1] + 0.5 * qd[1],
        ]
        assert_close(rnea(robot, q, qd, qdd), want)
        assert_close(dyn.evaluate("tau", q, qd, qdd), want)
    assert sp.simplify(dyn.M - sp.Matrix([[5, 0], [0, 2]])) == sp.zeros(2, 2)


def test_fixed_joints_merged(rng):
    """l1 + bracket merged by hand with symdyn.model.inertia; the ground mount and the tool frame vanish."""
    robot = load("fixed_offset.urdf")
    assert [lk.name for lk in robot.links] == ["l1", "l2"]
    I1 = np.array([[0.01, 0.001, 0], [0.001, 0.02, 0], [0, 0, 0.02]])
    Ibr = np.array([[0.004, 0.0002, 0], [0.0002, 0.003, 0.0001], [0, 0.0001, 0.005]])
    I2 = np.diag([0.001, 0.006, 0.006])
    T_bracket = hom(rz(0.5), (0.3, 0.05, 0))
    m1, c1, J1 = merged(
        [
            placed(np.eye(4), 2, (0.1, 0, 0), (0, 0, 0), I1),
            placed(T_bracket, 1, (0.05, 0.02, 0.01), (0.1, 0.2, 0.3), Ibr),
        ]
    )
    placement1 = hom(rz(0.3), (0, 0, 0.1)) @ hom(np.eye(3), (0, 0, 0.2))
    placement2 = T_bracket @ hom(rx(math.pi / 2), (0.1, 0, 0))
    want = robot_of(
        [
            link("l1", placement1, (0, 0, 1), m1, c1, J1),
            link("l2", placement2, (0, 0, 1), 0.7, (0.2, 0, 0.01), I2),
        ]
    )
    assert float(robot.links[0].mass) == pytest.approx(3.0, abs=1e-15)
    np.testing.assert_allclose(as_float(robot.links[0].com), c1[:, None], atol=1e-15)
    np.testing.assert_allclose(as_float(robot.links[0].inertia), J1, atol=1e-15)
    np.testing.assert_allclose(as_float(robot.links[1].placement.matrix()), placement2, atol=1e-15)
    compare_rnea(robot, want, rng)

    # the same arm with the bracket as its own body on an extra joint held at zero (the oracle merges)
    serial = robot_of(
        [
            link("l1", placement1, (0, 0, 1), 2, (0.1, 0, 0), I1),
            link(
                "bracket",
                T_bracket,
                (0, 0, 1),
                1,
                (0.05, 0.02, 0.01),
                rpy(0.1, 0.2, 0.3) @ Ibr @ rpy(0.1, 0.2, 0.3).T,
            ),
            link("l2", hom(rx(math.pi / 2), (0.1, 0, 0)), (0, 0, 1), 0.7, (0.2, 0, 0.01), I2),
        ]
    )
    compare_rnea(robot, serial, rng, pad=[0, 2])
    compare_symbolic(robot, rng)


def test_branches_locked(rng):
    """Branches locked at zero (the mimic wrist at 2 * 0 + 0.4 rad) and merged into l1 and l2."""
    robot = load("branch.urdf", tip="l2")
    assert [lk.name for lk in robot.links] == ["l1", "l2"]
    T_slide = hom(ry(0.3), (0.1, 0.05, 0))  # the slide at 0
    T_wrist = T_slide @ hom(np.eye(3), (0, 0.1, 0)) @ hom(rx(0.4))  # locked at the mimic offset
    m1, c1, J1 = merged(
        [
            placed(np.eye(4), 2, (0.15, 0, 0), (0, 0, 0), np.diag([0.01, 0.03, 0.03])),
            placed(T_slide, 0.5, (0, 0.02, 0.01), (0, 0, 0), np.diag([0.001, 0.002, 0.0015])),
            placed(
                T_wrist,
                0.3,
                (0, 0.05, 0.02),
                (0, 0, 0.2),
                [[0.0008, 0.0001, 0], [0.0001, 0.0005, 0], [0, 0, 0.0009]],
            ),
        ]
    )
    T_finger = hom(rz(0.6), (0.2, 0, 0))
    If = np.diag([0.0001, 0.0003, 0.0003])
    m2, c2, J2 = merged(
        [
            placed(np.eye(4), 1, (0.1, 0, 0), (0, 0, 0), np.diag([0.002, 0.008, 0.008])),
            placed(T_finger, 0.2, (0.04, 0, 0), (0, 0, 0), If),
        ]
    )
    for got, (m, c, J) in zip(robot.links, ((m1, c1, J1), (m2, c2, J2)), strict=True):
        assert float(got.mass) == pytest.approx(m, rel=1e-15)
        np.testing.assert_allclose(as_float(got.com), c[:, None], atol=1e-15)
        np.testing.assert_allclose(as_float(got.inertia), J, atol=1e-15)
    want = robot_of(
        [
            link("l1", hom(np.eye(3), (0, 0, 0.3)), (0, 0, 1), m1, c1, J1),
            link("l2", hom(rx(math.pi / 2), (0.3, 0, 0)), (0, 0, 1), m2, c2, J2),
        ]
    )
    compare_rnea(robot, want, rng)
    # the finger as an extra joint held at zero
    serial = robot_of(
        [
            want.links[0],
            link(
                "l2",
                hom(rx(math.pi / 2), (0.3, 0, 0)),
                (0, 0, 1),
                1,
                (0.1, 0, 0),
                np.diag([0.002, 0.008, 0.008]),
            ),
            link("finger", T_finger, (0, 0, 1), 0.2, (0.04, 0, 0), If),
        ]
    )
    compare_rnea(robot, serial, rng, pad=[0, 1])
    compare_symbolic(robot, rng)


def test_base_and_tip():
    # a base below the root: the links above it are ground
    robot = load("two_link.urdf", base="upper")
    assert [lk.name for lk in robot.links] == ["lower"]
    assert robot.links[0].placement.p == sp.ImmutableMatrix([sp.Float("0.5"), 0, 0])
    # a tip inside the chain locks what lies below it
    robot = load("two_link.urdf", tip="upper")
    assert [lk.name for lk in robot.links] == ["upper"]
    assert float(robot.links[0].mass) == pytest.approx(3.5)
    # the default tip is the only leaf, the massless tool frame fixed to l2: the same as tip l2
    assert load("fixed_offset.urdf", tip="l2") == load("fixed_offset.urdf")
    # a base with fixed links: the chain starts at the first movable joint
    assert load("fixed_offset.urdf", base="mount").links[0].placement.p == sp.ImmutableMatrix(
        [0, 0, sp.Float("0.2")]
    )


@pytest.mark.parametrize(
    ("kw", "fragment"),
    [
        ({"tip": "fingr"}, "tip link 'fingr' is not a link of the robot (did you mean 'finger'?)"),
        ({"base": "l2", "tip": "l1"}, "the tip link 'l1' is not below the base link 'l2'"),
        ({"tip": "base"}, "the tip link 'base' is the base link"),
        ({"base": "finger"}, "the base link 'finger' has no links below it"),
        ({"tip": 3}, "tip must be a link name"),
    ],
)
def test_base_and_tip_errors(kw, fragment):
    with pytest.raises(SymdynError) as info:
        load_urdf(DATA / "branch.urdf", **kw)
    assert fragment in str(info.value)
    assert str(info.value).startswith(str(DATA / "branch.urdf"))


def test_no_movable_joint(tmp_path):
    with pytest.raises(SymdynError, match="no movable joint between the base 'base' and the tip 'mount'"):
        load_urdf(DATA / "fixed_offset.urdf", tip="mount")


def test_mimic_following_the_chain():
    with pytest.raises(SymdynError) as info:
        load_urdf(DATA / "branch.urdf", tip="slider")
    err = info.value
    assert (err.link_index, err.link_name, err.field) == (5, "wrist", "joint(wrist_joint).mimic.joint")
    assert "follows the chain joint 'slide'" in err.reason


def test_plausibility_only_for_links_that_move(tmp_path):
    text = (DATA / "fixed_offset.urdf").read_text()
    # an impossible tensor on the ground mount does not matter
    bad_mount = text.replace(
        '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1"', '<inertia ixx="0.1" ixy="5" ixz="0" iyy="0.1"'
    )
    assert bad_mount != text
    (tmp_path / "mount.urdf").write_text(bad_mount)
    load_urdf(tmp_path / "mount.urdf")
    # a tensor breaking the triangle inequality on a merged link warns, naming it
    odd = text.replace(
        'ixx="0.004" ixy="0.0002" ixz="0" iyy="0.003"', 'ixx="0.001" ixy="0" ixz="0" iyy="0.001"'
    )
    assert odd != text
    (tmp_path / "odd.urdf").write_text(odd)
    with pytest.warns(SymdynWarning, match=r"link 4 \(bracket\): field 'inertia'"):
        load_urdf(tmp_path / "odd.urdf")


def _massless_warnings(path: Path, **kw) -> list[str]:
    """The messages of the massless-link warnings that loading `path` gives (the others pass)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_urdf(path, **kw)
    assert robot.n >= 1
    return [str(w.message) for w in caught if "has no <inertial>" in str(w.message)]


def test_massless_link_in_the_middle_of_a_chain_warns(tmp_path):
    """l2 has no <inertial> yet carries j3 0.3 m from its joint: a forgotten <inertial>."""
    text = (DATA / "bad_missing_inertial.urdf").read_text()
    leaf = tmp_path / "leaf.xml"  # l2 is the last link: massless, but nothing hangs from it
    leaf.write_text(text)
    assert _massless_warnings(leaf) == []
    chain = tmp_path / "chain.xml"
    l3 = (
        '<link name="l3"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
    )
    j3 = (
        '<joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>'
        '<origin xyz="0.3 0 0"/><axis xyz="0 0 1"/></joint>'
    )
    chain.write_text(text.replace("</robot>", l3 + j3 + "</robot>"))
    (message,) = _massless_warnings(chain)
    assert message.startswith(
        f"{chain}: link 3 (l2): has no <inertial>, so it is massless, yet it carries joint 'j3'"
    )
    assert message.endswith("it is almost always a forgotten <inertial>")
    # the chain from the base to l2 does not carry j3: no warning
    assert _massless_warnings(chain, tip="l2") == []
    # the same links with j3 at l2's origin (a universal joint built from two revolute ones): no warning
    at_origin = tmp_path / "universal.urdf"
    at_origin.write_text(
        chain.read_text().replace(
            '<origin xyz="0.3 0 0"/><axis xyz="0 0 1"/></joint></robot>',
            '<axis xyz="1 0 0"/></joint></robot>',
        )
    )
    assert at_origin.read_text() != chain.read_text()
    assert _massless_warnings(at_origin) == []
    # a massless frame fixed to a link with mass carries the next joint: no warning either
    framed = tmp_path / "framed.urdf"
    frame = (
        '<link name="tool"/><joint name="mount" type="fixed"><parent link="l1"/><child link="tool"/>'
        '<origin xyz="0.3 0 0"/></joint>'
    )
    framed.write_text(
        text.replace("</robot>", frame + "</robot>").replace(
            '<parent link="l1"/><child link="l2"/><origin xyz="0.3 0 0"/>',
            '<parent link="tool"/><child link="l2"/>',
        )
    )
    assert _massless_warnings(framed) == []


# --------------------------------------------------------------------------- errors

BAD = [
    (
        "bad_joint_type.urdf",
        2,
        "l1",
        "joint(j1).type",
        "unknown joint type 'revolut' (did you mean 'revolute'?)",
    ),
    ("bad_dangling_parent.urdf", 3, "l2", "joint(j2).parent.link", "parent link 'link1' does not exist"),
    ("bad_cycle.urdf", 3, "b", "joint(ab).child", "the joints form a cycle: a -> b -> c -> a"),
    ("bad_two_parents.urdf", 3, "b", "joint(j3).child", "link 'b' is the child of two joints, 'j2'"),
    ("bad_two_roots.urdf", None, None, None, "2 separate trees, with roots base, loose"),
    (
        "bad_floating.urdf",
        2,
        "body",
        "joint(free).type",
        "is a floating joint: symdyn handles revolute, continuous, prismatic and fixed joints only; "
        "load it as a floating base with --floating (floating=True), or the robot below it on a fixed "
        "base with --base body",
    ),
    ("bad_planar.urdf", 3, "puck", "joint(slide).type", "is a planar joint"),
    ("bad_number.urdf", 2, "l1", "inertial.mass.value", "expected a number, got '1,5'"),
    ("bad_origin.urdf", 2, "l1", "joint(j1).origin.xyz", "expected 3 numbers 'x y z', got '0 0'"),
    ("bad_zero_axis.urdf", 2, "l1", "joint(j1).axis.xyz", "the joint axis is zero"),
    ("bad_negative_mass.urdf", 2, "l1", "mass", "mass -1 is negative"),
    ("bad_inertia.urdf", 2, "l1", "inertia", "not positive semi-definite"),
    ("bad_missing_inertia_entry.urdf", 2, "l1", "inertial.inertia.iyz", "needs the attribute 'iyz'"),
    ("bad_duplicate_link.urdf", 3, "l1", "name", "duplicate link name 'l1' (also link 2"),
    ("bad_xml.urdf", None, None, None, "invalid XML at line 5, column 3: mismatched tag"),
    ("bad_entity_expansion.urdf", None, None, None, "line 2: document type declarations (<!DOCTYPE>)"),
    ("bad_external_entity.urdf", None, None, None, "line 2: document type declarations (<!DOCTYPE>)"),
    # a xacro file (a <xacro:property>) is expanded first; what remains is a lone base link
    ("bad_xacro.urdf", None, None, None, "the base link 'base' has no links below it"),
    ("bad_root.urdf", None, None, None, "an XML file whose top element is <sdf>: symdyn reads URDF"),
]


@pytest.mark.parametrize(("name", "index", "link_name", "field", "fragment"), BAD, ids=[b[0] for b in BAD])
def test_errors_name_file_link_and_field(name, index, link_name, field, fragment):
    path = DATA / name
    with pytest.raises(SymdynError) as info:
        load_urdf(path)
    err = info.value
    assert (err.file, err.link_index, err.link_name, err.field) == (str(path), index, link_name, field)
    assert fragment in err.reason
    where = f"{path}: link {index} ({link_name}): field '{field}': " if index else f"{path}: "
    assert str(err).startswith(where)


def test_file_errors(tmp_path):
    with pytest.raises(SymdynError, match="no such file"):
        load_urdf(tmp_path / "none.urdf")
    with pytest.raises(SymdynError, match="is a directory"):
        load_urdf(tmp_path)
    (tmp_path / "empty.urdf").write_text("")
    with pytest.raises(SymdynError, match="not a URDF: the file does not start with an XML element"):
        load_urdf(tmp_path / "empty.urdf")
    (tmp_path / "doc.urdf").write_text("<?xml version='1.0'?>\n<!-- a comment -->\n<robot")
    with pytest.raises(SymdynError, match="invalid XML at line 3"):
        load_urdf(tmp_path / "doc.urdf")
    (tmp_path / "nolinks.urdf").write_text('<robot name="x"/>')
    with pytest.raises(SymdynError, match="the robot has no <link>"):
        load_urdf(tmp_path / "nolinks.urdf")


def test_hostile_xml_is_refused(tmp_path):
    """A billion laughs and an external DTD are refused at the <!DOCTYPE>, before any expansion."""
    lol = ['<!ENTITY l0 "lol">'] + [f'<!ENTITY l{i} "{f"&l{i - 1};" * 10}">' for i in range(1, 10)]
    (tmp_path / "lol.urdf").write_text(f"<!DOCTYPE robot [{''.join(lol)}]><robot name='&l9;'/>")
    with pytest.raises(SymdynError, match="document type declarations"):
        load_urdf(tmp_path / "lol.urdf")
    secret = tmp_path / "secret.dtd"
    secret.write_text('<!ENTITY name "stolen">')
    doc = (DATA / "two_link.urdf").read_text()
    doc = doc.replace('<?xml version="1.0"?>', f'<!DOCTYPE robot SYSTEM "{secret.as_uri()}">')
    (tmp_path / "dtd.urdf").write_text(doc.replace('name="two_link"', 'name="&name;"'))
    with pytest.raises(SymdynError, match="document type declarations"):
        load_urdf(tmp_path / "dtd.urdf")
    # an entity never declared is an XML error, not an empty string
    doc = (DATA / "two_link.urdf").read_text().replace('name="two_link"', 'name="&name;"')
    (tmp_path / "ref.urdf").write_text(doc)
    with pytest.raises(SymdynError, match="invalid XML at line 4, column [0-9]+: undefined entity"):
        load_urdf(tmp_path / "ref.urdf")


# --------------------------------------------------------------------------- code and the command line


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_generated_c_of_a_urdf_robot(tmp_path, rng):
    robot = load("branch.urdf", tip="l2")
    files = symdyn.codegen.render(robot, targets=("c",))
    assert set(files) == {"branch_dynamics.h", "branch_dynamics.c", "CMakeLists.txt"}
    assert "branch.urdf (sha256 " + robot.source_sha256 in files["branch_dynamics.c"]
    lib = build_dynamics(files, tmp_path, "branch")
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        assert_close(lib.inverse_dynamics(q, qd, qdd), rnea(robot, q, qd, qdd))
        assert_close(lib.mass_matrix(q), mass_matrix(robot, q))


def test_cli_derive_and_generate(tmp_path, capsys):
    assert main(["derive", str(DATA / "two_link.urdf"), "--format", "json"]) == 0
    out = capsys.readouterr().out
    assert '"robot": "two_link"' in out and '"joints": 2' in out
    assert (
        main(["derive", str(DATA / "branch.urdf"), "--tip", "l2", "--base", "base", "--simplify", "no"]) == 0
    )
    assert capsys.readouterr().out.startswith("# branch: 2 joints")
    out_dir = tmp_path / "out"
    assert main(["generate", str(DATA / "rpy_chain.urdf"), "--target", "c", "--out", str(out_dir)]) == 0
    assert sorted(p.name for p in out_dir.iterdir()) == [
        "CMakeLists.txt",
        "rpy_chain_dynamics.c",
        "rpy_chain_dynamics.h",
    ]


def test_cli_errors(tmp_path, capsys):
    assert main(["derive", str(DATA / "bad_cycle.urdf")]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"symdyn: error: {DATA / 'bad_cycle.urdf'}: link 3 (b): field 'joint(ab).child': ")
    assert "Traceback" not in err
    assert main(["derive", str(DATA / "bad_floating.urdf")]) == 1
    assert (
        "load it as a floating base with --floating (floating=True), or the robot below it on a fixed "
        "base with --base body" in capsys.readouterr().err
    )
    out_dir = tmp_path / "out"
    assert main(["generate", str(DATA / "branch.urdf"), "--tip", "nope", "--out", str(out_dir)]) == 1
    assert "tip link 'nope' is not a link of the robot" in capsys.readouterr().err
    assert not out_dir.exists() or not any(out_dir.iterdir())


# --------------------------------------------------------------------------- real robots


ERD = example_robot_data_folder()
needs_erd = pytest.mark.skipif(ERD is None, reason="example-robot-data is not installed")

#: name -> (file under the package's robots/ folder, load_urdf keywords, links merged into the last)
REAL = {
    "panda": (
        "panda_description/urdf/panda.urdf",
        {"tip": "panda_hand"},
        ["panda_link8", "panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger"],
    ),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", {}, ["ee_link", "tool0"]),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", {}, ["ee_link", "tool0"]),
    "double_pendulum": ("double_pendulum_description/urdf/double_pendulum.urdf", {}, []),
}
GROUND = {
    "panda": ["panda_link0"],
    "ur5": ["world", "base_link", "base"],
    "ur10": ["world", "base_link", "base"],
}
GROUND["double_pendulum"] = ["base_link"]


@cache
def real(name: str) -> Robot:
    file, kw, _ = REAL[name]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_urdf(ERD / file, **kw)


@cache
def real_context(name: str):
    """Derivation and function specs (symdyn.codegen.context), once per session."""
    return symdyn.codegen.context(real(name))


def xml_masses(name: str) -> dict[str, float]:
    root = ET.parse(ERD / REAL[name][0]).getroot()
    out = {}
    for el in root.findall("link"):
        m = el.find("inertial/mass")
        out[el.get("name")] = 0.0 if m is None else float(m.get("value"))
    return out


@needs_erd
@pytest.mark.parametrize("name", list(REAL))
def test_real_robot_masses(name):
    robot = real(name)
    masses = xml_masses(name)
    merged_last = REAL[name][2]
    moving = [n for n in masses if n not in GROUND[name]]
    assert sum(float(lk.mass) for lk in robot.links) == pytest.approx(
        sum(masses[n] for n in moving), rel=1e-14
    )
    for lk in robot.links[:-1]:
        assert float(lk.mass) == masses[lk.name]
    last = robot.links[-1]
    assert float(last.mass) == pytest.approx(
        masses[last.name] + sum(masses[n] for n in merged_last), rel=1e-14
    )
    assert robot.convention == "urdf" and robot.source == str(ERD / REAL[name][0])


@needs_erd
def test_real_robot_names_and_sizes():
    assert [(real(n).name, real(n).n) for n in REAL] == [
        ("panda", 7),
        ("ur5", 6),
        ("ur10", 6),
        ("robot_2dof_planar", 2),  # "2dof_planar" made a C identifier
    ]
    assert [lk.name for lk in real("panda").links] == [f"panda_link{i}" for i in range(1, 8)]


@needs_erd
@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_real_robot_limits_are_the_xml_limits(name):
    """Each link's limits are the <limit lower upper> of the joint whose child it is, read here
    with ElementTree (the Panda's finger joints are locked by its tip: not loaded)."""
    root = ET.parse(ERD / REAL[name][0]).getroot()
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    robot = real(name)
    assert robot.links
    for lk in robot.links:
        joint = by_child[lk.name]
        assert joint.get("type") == "revolute"
        limit = joint.find("limit")
        assert lk.limits is not None
        assert tuple(float(x) for x in lk.limits) == (float(limit.get("lower")), float(limit.get("upper")))


@needs_erd
def test_panda_fingers_locked_into_link7():
    """link7 + flange + hand (turned -pi/4) + both fingers (closed) merged by hand."""
    root = ET.parse(ERD / REAL["panda"][0]).getroot()

    def inertial(name, T):
        el = root.find(f"link[@name='{name}']/inertial")
        o = el.find("origin")
        xyz = [float(x) for x in o.get("xyz").split()]
        r = [float(x) for x in o.get("rpy").split()]
        i = {k: float(v) for k, v in el.find("inertia").attrib.items()}
        I = [[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]]
        return placed(T, float(el.find("mass").get("value")), xyz, r, I)

    T_hand = hom(np.eye(3), (0, 0, 0.107)) @ hom(rz(-math.pi / 4))
    T_finger = T_hand @ hom(np.eye(3), (0, 0, 0.0584))
    m, c, J = merged(
        [
            inertial("panda_link7", np.eye(4)),
            inertial("panda_hand", T_hand),
            inertial("panda_leftfinger", T_finger),
            inertial("panda_rightfinger", T_finger),
        ]
    )
    link7 = real("panda").links[-1]
    assert float(link7.mass) == pytest.approx(0.735522 + 0.73 + 2 * 0.015, rel=1e-15)
    assert float(link7.mass) == pytest.approx(m, rel=1e-15)
    np.testing.assert_allclose(as_float(link7.com), c[:, None], atol=1e-15)
    np.testing.assert_allclose(as_float(link7.inertia), J, atol=1e-15)


@needs_erd
def test_panda_tips():
    path = ERD / REAL["panda"][0]
    with pytest.raises(SymdynError, match="follows the chain joint 'panda_finger_joint1'"):
        load_urdf(path, tip="panda_leftfinger")
    tcp = load_urdf(path, tip="panda_hand_tcp")  # a fixed frame below the hand: the same robot
    for a, b in zip(tcp.links, real("panda").links, strict=True):
        assert a.placement == b.placement and a.axis == b.axis
        np.testing.assert_allclose(as_float(a.inertia), as_float(b.inertia), rtol=0, atol=1e-15)
        np.testing.assert_allclose(as_float(a.com), as_float(b.com), rtol=0, atol=1e-15)
        assert float(a.mass) == pytest.approx(float(b.mass), rel=1e-15)


@needs_erd
def test_panda_frames_are_the_franka_dh_frames():
    """Franka's published modified-DH table gives the URDF's link frames exactly."""
    d = [0.333, 0, 0.316, 0, 0.384, 0, 0]
    a = [0, 0, 0, 0.0825, -0.0825, 0, 0.088]
    alpha = [0, -math.pi / 2, math.pi / 2, math.pi / 2, -math.pi / 2, math.pi / 2, math.pi / 2]
    robot = real("panda")
    for q in np.random.default_rng(7).uniform(-2.5, 2.5, (5, 7)):
        T = np.eye(4)
        for i, F in enumerate(forward_kinematics(robot, q)):
            T = T @ hom(rx(alpha[i]), (a[i], 0, 0)) @ hom(rz(q[i]), (0, 0, d[i]))
            np.testing.assert_allclose(F, T, atol=1e-12)


@needs_erd
@pytest.mark.parametrize(
    ("name", "d", "a"),
    [
        ("ur5", [0.089159, 0, 0, 0.10915, 0.09465, 0.0823], [0, -0.425, -0.39225, 0, 0, 0]),
        ("ur10", [0.1273, 0, 0, 0.163941, 0.1157, 0.0922], [0, -0.612, -0.5723, 0, 0, 0]),
    ],
)
def test_ur_flange_matches_published_dh(name, d, a):
    """The flange (tool0's origin) in the controller's 'base' frame (base_link turned by pi) is UR's DH."""
    alpha = [math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0]
    robot = real(name)
    for q in np.random.default_rng(8).uniform(-3, 3, (5, 6)):
        T = np.eye(4)
        for i in range(6):
            T = T @ hom(rz(q[i]), (0, 0, d[i])) @ hom(rx(alpha[i]), (a[i], 0, 0))
        flange = hom(rz(math.pi)) @ forward_kinematics(robot, q)[-1] @ np.array([0, d[5], 0, 1])
        np.testing.assert_allclose(flange[:3], T[:3, 3], atol=1e-10)


@needs_erd
@pytest.mark.parametrize("name", list(REAL))
def test_real_robot_derivation_matches_rnea(name, rng):
    compare_symbolic(real(name), rng, dyn=real_context(name).dynamics)


@needs_erd
@pytest.mark.skipif(not compilers(), reason="no C compiler")
@pytest.mark.parametrize("name", list(REAL))
def test_real_robot_generated_c_matches_rnea(name, tmp_path, rng):
    robot, ctx = real(name), real_context(name)
    files = c_target.render(ctx)
    assert set(files) == {f"{robot.name}_dynamics.h", f"{robot.name}_dynamics.c", "CMakeLists.txt"}
    assert f"void {robot.name}_inverse_dynamics(" in files[f"{robot.name}_dynamics.h"]
    lib = build_dynamics(files, tmp_path, robot.name)
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        assert_close(lib.inverse_dynamics(q, qd, qdd), rnea(robot, q, qd, qdd))
        assert_close(lib.mass_matrix(q), mass_matrix(robot, q))
        assert_close(lib.gravity(q), gravity_torque(robot, q))


# -- hostile numbers (issue 21): read as doubles, finite, at most 1e150


def _two_link_with(tmp_path, old: str, new: str) -> Path:
    path = tmp_path / "numbers.urdf"
    text = (DATA / "two_link.urdf").read_text()
    assert old in text
    path.write_text(text.replace(old, new))
    return path


def test_a_number_with_thousands_of_digits_is_read_as_its_double(tmp_path):
    """Kept at the text's precision, 3,000 digits made `--target latex` run for minutes."""
    digits = "2." + "3" * 3000
    robot = load_urdf(_two_link_with(tmp_path, 'value="2.0"', f'value="{digits}"'))
    mass = robot.links[0].mass
    assert mass.is_Float and mass._prec == 53 and float(mass) == float(digits) == 7 / 3


@pytest.mark.parametrize("value", ["1e308", "-1e151", "1e400", "-" + "9" * 400])
def test_numbers_beyond_1e150_or_not_finite_are_refused_in_one_line(tmp_path, capsys, value):
    path = _two_link_with(tmp_path, 'izz="0.04"', f'izz="{value}"')
    line = refused(capsys, "generate", path, "--target", "latex", "--out", tmp_path / "out", seconds=10)
    assert f"{path}: link 2 (upper): field 'inertial.inertia.izz': " in line
    assert "is too large (more than 1e+150 in absolute value)" in line or "is not a finite number" in line
    assert not (tmp_path / "out").exists()
