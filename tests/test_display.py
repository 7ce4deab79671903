"""How robots and dynamics print: the link table (symdyn.model.table), the one-line repr of a
Dynamics and its LaTeX for notebooks (Dynamics._repr_latex_, Dynamics.latex)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import sympy as sp

import symdyn
from symdyn.errors import SymdynError
from symdyn.spatial.transform import rpy_matrix
from tests.robots import example, roger_arm_lecture

URDF_DIR = Path(__file__).parent / "data" / "urdf"


def _rows(robot) -> list[list[str]]:
    """The table's link rows split into cells (header line, column titles and rule dropped)."""
    lines = repr(robot).splitlines()
    assert [c.strip() for c in lines[1].split(" | ")][:4] == ["#", "link", "joint", "parent"]
    assert set(lines[2]) <= {"-", "+"}
    return [[c.strip() for c in line.split(" | ")] for line in lines[3:]]


def test_chain_table_has_one_row_per_link():
    robot = example("puma560")
    rows = _rows(robot)
    assert len(rows) == robot.nb == 6
    assert [r[0] for r in rows] == [str(i) for i in range(1, 7)]
    assert [r[1] for r in rows] == [f"link{i}" for i in range(1, 7)]
    assert [r[2] for r in rows] == ["R"] * 6
    assert [r[3] for r in rows] == ["base", "link1", "link2", "link3", "link4", "link5"]
    masses = [float(link.mass) for link in robot.links]
    assert [float(r[6]) for r in rows] == pytest.approx(masses, rel=5e-4)
    assert str(robot) == repr(robot)
    header = repr(robot).splitlines()[0]
    assert header.startswith("Robot puma560: 6 joints, 0 free parameters") and "puma560.yaml" in header
    # the base-to-link-3 placement of the Puma: a2 = 0.4318 along x, d3 = 0.15 along z (Craig, table 3.4)
    assert rows[2][4] == "xyz (0.4318, 0, 0.15)"


def test_free_parameters_are_listed_in_the_header_and_per_link():
    robot = example("roger_arm")
    header, *_ = repr(robot).splitlines()
    assert "5 free parameters (g, l1, m1, l2, m2)" in header and "gravity (g, 0, 0)" in header
    rows = _rows(robot)
    assert [r[6] for r in rows] == ["m1", "m2"]
    assert [set(r[7].split(", ")) for r in rows] == [{"l1", "m1"}, {"l1", "l2", "m2"}]


TREE = {
    "name": "gripper",
    "convention": "modified",
    "links": [
        {"name": "palm", "joint": "revolute", "d": 0.1, "mass": 2},
        {"name": "left", "joint": "prismatic", "alpha": "pi/2", "mass": 0.25},
        {
            "name": "right",
            "parent": "palm",
            "joint": "prismatic",
            "alpha": "-pi/2",
            "mass": 0.5,
            "mimic": {"joint": "left", "multiplier": -1, "offset": 0.5},
        },
    ],
}


def test_tree_with_a_mimic_joint():
    robot = symdyn.robot_from_data(TREE, source="gripper.yaml")
    rows = _rows(robot)
    assert [r[1] for r in rows] == ["palm", "left", "right"]
    assert [r[2] for r in rows] == ["R", "P", "P mimic of left (-1, 0.5)"]
    assert [r[3] for r in rows] == ["base", "palm", "palm"]
    assert [float(r[6]) for r in rows] == [2, 0.25, 0.5]
    assert repr(robot).splitlines()[0].startswith("Robot gripper: 2 joints (3 bodies),")


def test_urdf_tree_table():
    robot = symdyn.load_urdf(URDF_DIR / "tree.urdf")
    rows = _rows(robot)
    names = [link.name for link in robot.links]
    assert [r[1] for r in rows] == names
    assert [r[3] for r in rows] == ["base" if p < 0 else names[p] for p in robot.parents]
    assert rows[names.index("right_arm")][2].startswith("R mimic of left_arm (-1, 0.1)")
    assert rows[names.index("left_slider")][2] == "P"
    assert [float(r[6]) for r in rows] == pytest.approx([float(link.mass) for link in robot.links], rel=5e-4)


def test_equality_and_hash_are_the_dataclass_ones():
    a, b = example("roger_arm"), example("roger_arm")
    assert a == b and hash(a) == hash(b)
    assert a != symdyn.robot_from_data(TREE)


def test_repr_of_a_101_joint_robot_is_fast_and_has_101_rows():
    data = {
        "name": "snake",
        "links": [{"name": f"s{i}", "joint": "revolute", "a": "l", "mass": "m"} for i in range(101)],
    }
    robot = symdyn.robot_from_data(data)
    start = time.perf_counter()
    text = repr(robot)
    assert time.perf_counter() - start < 10  # about 0.1 s; generous, not a benchmark
    assert len(_rows(robot)) == 101 and text.splitlines()[0].startswith("Robot snake: 101 joints")


@pytest.fixture(scope="module")
def roger():
    return symdyn.derive(example("roger_arm"))


def test_dynamics_repr_is_one_line(roger):
    assert repr(roger) == (
        "<Dynamics of roger_arm: 2 joints, newton-euler, 5 free parameters (g, l1, m1, l2, m2)>"
    )
    dyn = symdyn.derive(symdyn.robot_from_data(TREE), method="lagrange")
    assert repr(dyn) == "<Dynamics of gripper: 2 joints (3 bodies), lagrange, 0 free parameters>"
    assert roger.table() == repr(roger.robot)


def _balanced(tex: str) -> bool:
    depth = 0
    for i, ch in enumerate(tex):
        if ch in "{}" and (i == 0 or tex[i - 1] != "\\"):
            depth += 1 if ch == "{" else -1
            if depth < 0:
                return False
    return depth == 0 and tex.count("\\begin{") == tex.count("\\end{")


def test_repr_latex_is_display_math(roger):
    tex = roger._repr_latex_()
    assert tex.startswith("$$") and tex.endswith("$$") and _balanced(tex)
    assert "\\text{roger\\_arm}" in tex and "\\tau = M(q)" in tex
    assert all(f"{k} = \\left[" in tex for k in "MVG")  # closed forms for a 2-joint robot


def test_repr_latex_of_a_big_robot_shows_only_the_structure():
    dyn = symdyn.derive(example("puma560"))
    tex = dyn._repr_latex_()
    assert _balanced(tex) and "M = \\left[" not in tex and "\\mathbb{R}^{6 \\times 6}" in tex


def test_latex_of_m_uses_the_textbook_symbols(roger):
    q1, q2, qd1, qd2, qdd1, qdd2 = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2")
    # the closed form is the lecture's M (slide 18), so the LaTeX shows that matrix
    M_lecture, _, _ = roger_arm_lecture()
    assert sp.simplify(roger.M - M_lecture) == sp.zeros(2, 2)
    renamed = {
        q1: sp.Symbol("q_{1}"),
        q2: sp.Symbol("q_{2}"),
        qd1: sp.Symbol("\\dot{q}_{1}"),
        qd2: sp.Symbol("\\dot{q}_{2}"),
        qdd1: sp.Symbol("\\ddot{q}_{1}"),
        qdd2: sp.Symbol("\\ddot{q}_{2}"),
    }
    assert roger.latex("M") == sp.latex(roger.M.xreplace(renamed))
    assert "\\dot{q}_{1}" in roger.latex("V") and "\\ddot{q}_{2}" in roger.latex("tau")
    assert "qd" not in roger.latex("tau")


def test_latex_of_an_unknown_quantity_is_an_error(roger):
    with pytest.raises(SymdynError, match="unknown quantity 'K'"):
        roger.latex("K")


def test_symbolic_turns_print_as_written():
    data = {
        "name": "turns",
        "links": [
            {"name": "a", "joint": "revolute", "theta": "th", "mass": 1},
            {"name": "b", "joint": "prismatic", "alpha": "al", "a": "0.123456", "mass": 1},
            {"name": "c", "joint": "revolute", "mass": 1},
        ],
    }
    robot = symdyn.robot_from_data(data)
    th, al = sp.symbols("th al")
    # standard DH: Rz(theta) of link a places a; Tx(a) Rx(alpha) of link b, at its far end, place c
    assert rpy_matrix(0, 0, th) == robot.links[0].placement.R
    assert rpy_matrix(al, 0, 0) == robot.links[2].placement.R
    rows = _rows(robot)
    assert [r[4] for r in rows] == ["rpy (0, 0, th)", "-", "xyz (0.1235, 0, 0) rpy (al, 0, 0)"]
    assert [r[7] for r in rows] == ["th", "-", "al"]
