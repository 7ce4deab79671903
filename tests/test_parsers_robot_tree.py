"""Robot files with `parent:` (trees, Khalil's modified DH) and `mimic:` joints.

Expected values come from reasoning (the parents written in tests/data/good/tree.yaml), from
DH frames multiplied out by hand along each link's path to the base (Khalil and Kleinfinger's
Rz(gamma) Tz(b) Rx(alpha) Tx(a) Rz(theta) Tz(d) per row, relative to the parent's frame), and
from the chain the same file gives without `parent:`. The algorithms of this branch still
assume a serial chain, so these tests judge the loaded model, not the dynamics of trees.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml

from symdyn.errors import SymdynError
from symdyn.model.robot import Mimic, Robot
from symdyn.parsers import load_robot, robot_from_data
from symdyn.spatial.transform import Transform

TREE = Path(__file__).parent / "data" / "good" / "tree.yaml"


def load_tree() -> Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_robot(TREE)


def num(M) -> np.ndarray:
    return np.array(sp.Matrix(M).evalf(), dtype=float)


def rot(axis: str, t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4)
    i, j = {"x": (1, 2), "z": (0, 1)}[axis]
    T[i, i], T[i, j], T[j, i], T[j, j] = c, -s, s, c
    return T


def trans(axis: str, v: float) -> np.ndarray:
    T = np.eye(4)
    T["xyz".index(axis), 3] = v
    return T


def khalil(gamma=0.0, b=0.0, alpha=0.0, a=0.0, theta=0.0, d=0.0) -> np.ndarray:
    """Frame j in the frame of its antecedent: Rz(gamma) Tz(b) Rx(alpha) Tx(a) Rz(theta) Tz(d)."""
    return rot("z", gamma) @ trans("z", b) @ rot("x", alpha) @ trans("x", a) @ rot("z", theta) @ trans("z", d)


def world_frames(robot: Robot, q) -> list[np.ndarray]:
    """Each link's frame in the base frame, composed along Robot.parents."""
    out: list[np.ndarray] = []
    for i, (link, qi) in enumerate(zip(robot.links, robot.body_positions(list(q)), strict=True)):
        p = robot.parents[i]
        T = np.eye(4) if p < 0 else out[p]
        out.append(T @ num((link.joint_transform(sp.Float(float(qi))) @ link.frame).matrix()))
    return out


def test_tree_parents_and_mimic():
    robot = load_tree()
    assert [lk.name for lk in robot.links] == [
        "torso",
        "left_arm",
        "left_finger",
        "right_finger",
        "right_arm",
        "head",
        "wheel",
    ]
    assert robot.parents == (-1, 0, 1, 1, 0, 0, -1)
    assert [lk.parent for lk in robot.links] == [None, None, None, 1, 0, 0, -1]  # None: the link before
    k, f0 = sp.symbols("k f0")
    assert robot.links[3].mimic == Mimic(2, k, f0)  # q_right = k q_left + f0
    assert robot.params == (f0,) and robot.value_map == {k: -1}
    assert robot.resolved().links[3].mimic == Mimic(2, -1, f0)
    assert (robot.n, robot.nb, robot.is_chain) == (6, 7, False)


def test_tree_frames_are_khalils_rows_along_each_path():
    robot = load_tree().numeric([0.01])
    rows = {  # (parent, gamma, b, alpha, a, theta offset, d offset, joint)
        "torso": (-1, 0, 0, 0, 0, 0, 0.4, "r"),
        "left_arm": (0, 0, 0, -np.pi / 2, 0.1, 0, 0.2, "r"),
        "left_finger": (1, 0, 0, np.pi / 2, 0.3, 0.2, 0, "p"),
        "right_finger": (1, 0, 0, np.pi / 2, 0.3, -0.2, 0, "p"),
        "right_arm": (0, np.pi, 0.05, -np.pi / 2, 0.1, 0, 0.2, "r"),
        "head": (0, np.pi / 2, 0.5, np.pi / 2, 0, 0, 0, "r"),
        "wheel": (-1, 0.3, 0.1, np.pi / 2, 0.2, 0, 0, "r"),
    }
    rng = np.random.default_rng(11)
    for _ in range(4):
        q = rng.uniform(-2, 2, robot.n)
        qb = [float(x) for x in robot.body_positions(list(q))]
        assert qb[3] == pytest.approx(-qb[2] + 0.01)  # the mimic finger
        want: list[np.ndarray] = []
        for i, (p, gamma, b, alpha, a, theta, d, joint) in enumerate(rows.values()):
            theta, d = (theta + qb[i], d) if joint == "r" else (theta, d + qb[i])
            want.append((np.eye(4) if p < 0 else want[p]) @ khalil(gamma, b, alpha, a, theta, d))
        for got, exp in zip(world_frames(robot, q), want, strict=True):
            np.testing.assert_allclose(got, exp, atol=1e-12)


def test_parent_naming_the_link_before_is_the_chain():
    """`parent:` naming the previous link (or base for the first) changes nothing."""
    doc = yaml.safe_load((TREE.parent / "modified.yaml").read_text())
    chain = robot_from_data(doc)
    doc["links"][0]["parent"] = None
    for prev, link in zip(doc["links"], doc["links"][1:], strict=False):
        link["parent"] = prev["name"]  # the first is named 'base', the name of a link here
    assert robot_from_data(doc) == chain
    doc = yaml.safe_load((TREE.parent / "standard.yaml").read_text())
    chain = robot_from_data(doc)
    doc["links"][1]["parent"] = doc["links"][0]["name"]
    assert robot_from_data(doc) == chain


TWO = {
    "name": "two",
    "convention": "modified",
    "links": [
        {"name": "a", "joint": "revolute", "mass": 1},
        {"name": "b", "joint": "revolute", "mass": 1},
        {"name": "c", "joint": "revolute", "mass": 1},
    ],
}


def with_fields(fields: dict[int, dict], convention: str = "modified") -> dict:
    doc = {**TWO, "convention": convention, "links": [dict(lk) for lk in TWO["links"]]}
    for i, extra in fields.items():
        doc["links"][i].update(extra)
    return doc


def test_a_mimic_may_point_ahead():
    robot = robot_from_data(
        with_fields({1: {"parent": "base", "mimic": {"joint": "c", "offset": "pi/4"}}, 2: {"parent": "a"}})
    )
    assert robot.links[1].mimic == Mimic(2, 1, sp.pi / 4)
    assert robot.parents == (-1, -1, 0) and robot.n == 2


def test_a_mimic_of_a_mimic_is_refused_with_the_composed_relation():
    data = with_fields(
        {
            0: {"mimic": {"joint": "b", "multiplier": 2, "offset": 0.5}},
            1: {"parent": "base", "mimic": {"joint": "c", "offset": "pi/4"}},
            2: {"parent": "a"},
        }
    )
    # q_a = 2 q_b + 0.5 and q_b = q_c + pi/4, so q_a = 2 q_c + pi/2 + 0.5
    with pytest.raises(SymdynError) as err:
        robot_from_data(data)
    message = str(err.value)
    assert "link 1 (a): field 'mimic.joint': link 'b' is a mimic joint itself: follow 'c' directly" in message
    relation = message.split("mimic: {joint: c, multiplier: ")[1].rstrip("}")
    k, o = relation.split(", offset: ")
    assert sp.sympify(k) == 2 and abs(float(sp.sympify(o)) - (float(sp.pi) / 2 + 0.5)) < 1e-12


def test_parent_base_is_a_link_named_base_if_there_is_one():
    assert robot_from_data(with_fields({2: {"parent": "base"}})).parents == (-1, 0, -1)
    named = robot_from_data(with_fields({0: {"name": "base"}, 2: {"parent": "base"}}))
    assert named.parents == (-1, 0, 0)
    assert robot_from_data(with_fields({0: {"name": "base"}, 2: {"parent": None}})).parents == (-1, 0, -1)


ERRORS = [
    (
        {1: {"parent": "c"}},
        "modified",
        2,
        "parent",
        "parent 'c' is listed after this link (as link 3): list every",
    ),
    ({1: {"parent": "b"}}, "modified", 2, "parent", "a link cannot be its own parent"),
    (
        {1: {"parent": "bb"}},
        "modified",
        2,
        "parent",
        "parent 'bb' is not a link of the robot (did you mean 'b'?)",
    ),
    ({1: {"parent": 3}}, "modified", 2, "parent", "parent must be the name of a link listed before this one"),
    (
        {2: {"parent": "a"}},
        "standard",
        3,
        "parent",
        "with convention: standard a link hangs from the link before it",
    ),
    ({1: {"parent": None}}, "standard", 2, "parent", "(link 'a'): standard DH puts frame i at the far end"),
    (
        {1: {"gamma": 0.1}},
        "standard",
        2,
        "gamma",
        "gamma (Khalil's tree parameter) needs convention: modified",
    ),
    (
        {1: {"mimic": {"joint": "x"}}},
        "modified",
        2,
        "mimic.joint",
        "link 'x' does not exist; mimic.joint names",
    ),
    ({1: {"mimic": {"joint": "b"}}}, "modified", 2, "mimic.joint", "in a cycle: b -> b"),
    (
        {0: {"mimic": {"joint": "b"}}, 1: {"mimic": {"joint": "a"}}},
        "modified",
        2,
        "mimic.joint",
        "in a cycle: a -> b -> a",
    ),
    ({1: {"mimic": {"multiplier": 2}}}, "modified", 2, "mimic.joint", "missing required field"),
    ({1: {"mimic": {"joint": 1}}}, "modified", 2, "mimic.joint", "expected the name of a link, got int 1"),
    ({1: {"mimic": {"joint": "a", "gain": 1}}}, "modified", 2, "mimic.gain", "unknown key 'gain'"),
    ({1: {"mimic": "a"}}, "modified", 2, "mimic", "expected a mapping with keys joint, multiplier, offset"),
]


@pytest.mark.parametrize(("fields", "convention", "index", "field", "fragment"), ERRORS)
def test_errors_name_file_link_and_field(fields, convention, index, field, fragment):
    with pytest.raises(SymdynError) as info:
        robot_from_data(with_fields(fields, convention), source="tree.yaml")
    err = info.value
    assert (err.file, err.link_index, err.field) == ("tree.yaml", index, field)
    assert fragment in str(err)


def test_dh_rows_without_gamma_and_b_are_unchanged():
    """gamma = b = 0 leaves the placement the plain modified row (no extra factors)."""
    robot = robot_from_data(with_fields({1: {"gamma": 0, "b": 0, "alpha": "pi/2", "a": 0.3}}))
    plain = robot_from_data(with_fields({1: {"alpha": "pi/2", "a": 0.3}}))
    assert robot == plain
    assert robot.links[1].placement == Transform.rx(sp.pi / 2) @ Transform.tx(sp.Float("0.3"))
