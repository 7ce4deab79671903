"""Whole URDF trees: joint order, parents, placements, merged bodies, massless links, mimic joints.

Expected values never come from the loader itself: the joint order, the parents and the
mimic joints of the hand-made tree are written down by reasoning (tests/data/urdf/tree.urdf
draws the tree); placements and merged inertias are built by hand with NumPy; a tip cuts a
chain whose bodies are merged by hand; and for the example-robot-data robots every property is
recomputed from the raw XML read with ElementTree (depth-first order with siblings by joint
name, each link's nearest movable ancestor, placements as products of origins, masses), with
the joint counts Pinocchio reports for the same files.

The algorithms of this branch still assume a serial chain, so these tests judge the loaded
model (parents, placements, axes, inertias, mimic fields, joint order), not the dynamics of
trees.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from test_urdf import DATA, ERD, as_float, hom, merged, needs_erd, placed, rpy, rx, ry, rz

from symdyn.errors import SymdynError, SymdynWarning
from symdyn.model.robot import Friction, Mimic, Robot
from symdyn.parsers import load
from symdyn.parsers.urdf import load_urdf

TREE = DATA / "tree.urdf"
MOVABLE = ("revolute", "continuous", "prismatic")


def load_tree(path: Path = TREE, **kw) -> Robot:
    """A URDF file; any warning is a failure."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_urdf(path, **kw)


def variant(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    """tree.urdf with each (old, new) text replaced once; each old text must be there."""
    text = TREE.read_text()
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "tree.urdf"
    path.write_text(text)
    return path


def error_of(path: Path, **kw) -> SymdynError:
    with pytest.raises(SymdynError) as info:
        load_urdf(path, **kw)
    assert str(info.value).startswith(str(path))
    return info.value


def close(a, b, atol=1e-15) -> None:
    np.testing.assert_allclose(as_float(a), np.asarray(b, dtype=float).reshape(as_float(a).shape), atol=atol)


# --------------------------------------------------------------------------- the hand-made tree


def test_tree_joint_order_parents_and_mimic():
    robot = load_tree()
    # depth first from the base, siblings in order of joint name (see the drawing in tree.urdf);
    # the file lists z_torso, d_head, b_left, ... , so its own order would be torso, head, ...
    assert [lk.name for lk in robot.links] == [
        "wheel",
        "torso",
        "right_arm",
        "left_arm",
        "left_slider",
        "head",
    ]
    assert robot.parents == (-1, -1, 1, 1, 3, 1)
    assert [lk.parent for lk in robot.links] == [None, -1, None, 1, None, 1]  # None: the previous link
    assert [lk.joint for lk in robot.links] == ["revolute"] * 4 + ["prismatic", "revolute"]
    # c_right mimics b_left, which comes later: q_right = -1 * q_left + 0.1
    assert robot.links[2].mimic == Mimic(3, sp.Integer(-1), sp.Float("0.1"))
    assert [lk.mimic for i, lk in enumerate(robot.links) if i != 2] == [None] * 5
    assert (robot.n, robot.nb, robot.is_chain) == (5, 6, False)
    assert robot.links[5].friction == Friction(sp.Float("0.1"), 0)
    axes = [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1], [1, 0, 0], [0, 1, 0]]
    assert [list(lk.axis) for lk in robot.links] == axes


def test_tree_placements():
    """Each placement: the fixed origins from the parent's link down to the joint, times its origin."""
    robot = load_tree()
    mount = hom(np.eye(3), (0, 0, 0.1))
    want = {
        "wheel": mount @ hom(rx(math.pi / 2), (0.2, 0, 0)),
        "torso": mount @ hom(rz(0.3), (0, 0, 0.4)),
        "right_arm": hom(rx(math.pi / 2), (0, -0.2, 0.3)) @ hom(np.eye(3), (0, 0, 0.05)),
        "left_arm": hom(rx(-math.pi / 2), (0, 0.2, 0.3)),
        "left_slider": hom(rz(0.5), (0.3, 0, 0)) @ hom(ry(0.2), (0.05, 0, 0)),
        "head": hom(np.eye(3), (0, 0, 0.5)),
    }
    for lk in robot.links:
        close(lk.placement.matrix(), want[lk.name])
        assert lk.frame.is_identity()
    # right angles stay exact through the fixed joint a_plate_fix
    assert sp.ImmutableMatrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]]) == robot.links[2].placement.R


#: The inertials of tree.urdf as written: link -> (mass, xyz, rpy, tensor) in the link frame.
INERTIALS = {
    "torso": (3, (0, 0, 0.2), (0, 0, 0), np.diag([0.05, 0.04, 0.02])),
    "plate": (0.6, (0, 0, 0.01), (0, 0, 0), np.diag([0.002, 0.002, 0.003])),
    "left_arm": (1.2, (0.15, 0, 0), (0, 0, 0), np.diag([0.001, 0.009, 0.009])),
    "left_tool": (
        0.4,
        (0.02, 0, 0),
        (0.1, 0, 0),
        [[0.0004, 0.00002, 0], [0.00002, 0.0005, 0.00001], [0, 0.00001, 0.0006]],
    ),
    "left_slider": (0.2, (0.01, 0, 0.02), (0, 0, 0), np.diag([0.0001, 0.0002, 0.0002])),
    "head": (0.8, (0, 0, 0.1), (0, 0, 0), np.diag([0.003, 0.003, 0.002])),
    "wheel": (0.5, (0, 0, 0), (0, 0, 0), np.diag([0.001, 0.001, 0.002])),
}
#: Joint origins of tree.urdf (child frame in parent frame, joints at 0).
PLATE_IN_TORSO = hom(rx(math.pi / 2), (0, -0.2, 0.3))
LEFT_IN_TORSO = hom(rx(-math.pi / 2), (0, 0.2, 0.3))
TOOL_IN_LEFT = hom(rz(0.5), (0.3, 0, 0))
SLIDER_IN_TOOL = hom(ry(0.2), (0.05, 0, 0))


def part(T: np.ndarray, name: str):
    """(mass, com, tensor about the com) of link `name`'s inertial, its frame placed at T in the body."""
    return placed(T, *INERTIALS[name])


def test_tree_bodies_merge_fixed_subtrees_and_links_without_inertial_are_massless():
    robot = {lk.name: lk for lk in load_tree().links}
    want = {
        # the plate hangs from the torso by a fixed joint: merged into it
        "torso": merged([part(np.eye(4), "torso"), part(PLATE_IN_TORSO, "plate")]),
        # the tool is fixed to the left arm; the slider below it moves on its own
        "left_arm": merged([part(np.eye(4), "left_arm"), part(TOOL_IN_LEFT, "left_tool")]),
        # the camera (no <inertial>) adds nothing to the head
        **{name: part(np.eye(4), name) for name in ("wheel", "left_slider", "head")},
    }
    for name, (m, c, J) in want.items():
        assert float(robot[name].mass) == pytest.approx(m, rel=1e-15), name
        close(robot[name].com, c)
        close(robot[name].inertia, J)
    right = robot["right_arm"]  # no <inertial>: zero mass and inertia, exactly, and no warning
    assert right.mass == 0 and right.com == sp.zeros(3, 1) and right.inertia == sp.zeros(3, 3)
    # the pedestal (5 kg) is fixed to the base: ground, not part of the robot
    assert sum(float(lk.mass) for lk in robot.values()) == pytest.approx(0.5 + 3.6 + 1.6 + 0.2 + 0.8)


def test_a_tip_cuts_one_chain_out_of_the_tree():
    """With tip=head the chain is torso, head; the arms are locked at zero (right arm at its
    offset) and merged into the torso; the wheel hangs from the ground and is left out."""
    tree = {lk.name: lk for lk in load_tree().links}
    chain = load_tree(tip="head")
    assert [lk.name for lk in chain.links] == ["torso", "head"]
    assert chain.parents == (-1, 0) and chain.is_chain
    for lk in chain.links:
        assert lk.placement == tree[lk.name].placement and lk.axis == tree[lk.name].axis
    T_tool = LEFT_IN_TORSO @ TOOL_IN_LEFT
    m, c, J = merged(
        [
            part(np.eye(4), "torso"),
            part(PLATE_IN_TORSO, "plate"),
            part(LEFT_IN_TORSO, "left_arm"),
            part(T_tool, "left_tool"),
            part(T_tool @ SLIDER_IN_TOOL, "left_slider"),
        ]
    )
    assert float(chain.links[0].mass) == pytest.approx(m, rel=1e-15)
    close(chain.links[0].com, c)
    close(chain.links[0].inertia, J)
    # the same chain from the command-line loader, which picks URDF by the suffix
    assert load(TREE, tip="head") == chain


def test_a_tip_and_mimic_joints(tmp_path):
    # the right arm (locked, off the chain) would have to follow the chain joint b_left
    err = error_of(TREE, tip="left_slider")
    assert (err.link_name, err.field) == ("right_arm", "joint(c_right).mimic.joint")
    assert (
        "follows the chain joint 'b_left', so it cannot be locked: load the whole tree (no tip)" in err.reason
    )
    # a chain joint whose master is off the chain: not loaded
    err = error_of(TREE, tip="right_arm")
    assert (err.link_index, err.link_name, err.field) == (10, "right_arm", "joint(c_right).mimic.joint")
    assert err.reason.startswith(
        "follows joint 'b_left', which is not loaded: it is not on the chain from 'base' to 'right_arm' "
        "(cut away by --base or --tip"
    )
    # a mimic on the chain with its master on the chain is a mimic link of the chain
    path = variant(
        tmp_path, ('<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/><mimic joint="z_torso" multiplier="3"/>')
    )
    chain = load_tree(path, tip="head")
    assert chain.links[1].mimic == Mimic(0, 3, 0) and (chain.n, chain.nb) == (1, 2)


# --------------------------------------------------------------------------- mimic joints


def test_a_mimic_of_a_mimic_is_refused_with_the_composed_relation(tmp_path):
    """head follows right_arm, which follows left_arm: q_h = 2 (-q_l + 0.1) + 0.3 = -2 q_l + 0.5."""
    path = variant(
        tmp_path,
        ('<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/><mimic joint="c_right" multiplier="2" offset="0.3"/>'),
    )
    with pytest.raises(SymdynError) as err:
        load_tree(path)
    message = str(err.value)
    assert "mimics joint 'c_right', which is a mimic joint itself: follow 'b_left' directly" in message
    k = message.split('multiplier="')[1].split('"')[0]
    o = message.split('offset="')[1].split('"')[0]
    assert float(k) == -2 and float(o) == pytest.approx(0.5, rel=1e-15)


MIMIC_ERRORS = [
    # (edit of tree.urdf, base, joint named in the field, its child link, message start)
    (
        ('<mimic joint="b_left" multiplier', '<mimic joint="b_lef" multiplier'),
        None,
        "c_right",
        "right_arm",
        "mimics joint 'b_lef', which does not exist (did you mean 'b_left'?)",
    ),
    (
        ('<mimic joint="b_left" multiplier', '<mimic joint="a_plate_fix" multiplier'),
        None,
        "c_right",
        "right_arm",
        "mimics joint 'a_plate_fix', which is a fixed joint: only a revolute, continuous or prismatic",
    ),
    (
        ('<mimic joint="b_left" multiplier', '<mimic joint="c_right" multiplier'),
        None,
        "c_right",
        "right_arm",
        "mimic joints follow each other in a cycle: c_right -> c_right",
    ),
    (
        (
            '<origin xyz="0 0.2 0.3" rpy="-1.5707963267948966 0 0"/>',
            '<origin xyz="0 0.2 0.3" rpy="-1.5707963267948966 0 0"/><mimic joint="c_right"/>',
        ),
        None,
        "b_left",
        "left_arm",
        "mimic joints follow each other in a cycle: c_right -> b_left -> c_right",
    ),
    (
        ('<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/><mimic joint="a_wheel"/>'),
        "torso",
        "d_head",
        "head",
        "follows joint 'a_wheel', which is not loaded: it is not below the base 'torso' (cut away by --base",
    ),
    (
        ('<axis xyz="1 0 0"/>', '<axis xyz="1 0 0"/><mimic joint="c_right"/>'),
        "left_arm",
        "left_slide",
        "left_slider",
        "mimics joint 'c_right', which is a mimic joint itself: follow 'b_left' directly, with "
        '<mimic joint="b_left" multiplier="-1" offset="0.1"/>',
    ),
]


@pytest.mark.parametrize(("edit", "base", "joint", "link", "start"), MIMIC_ERRORS)
def test_mimic_errors_name_file_link_joint_and_line(tmp_path, edit, base, joint, link, start):
    path = variant(tmp_path, edit)
    err = error_of(path, base=base)
    assert (err.link_name, err.field) == (link, f"joint({joint}).mimic.joint")
    assert err.reason.startswith(start)
    lines = path.read_text().splitlines()
    at = next(k for k, text in enumerate(lines, 1) if f'<joint name="{joint}"' in text)
    mimic_line = next(k for k, text in enumerate(lines, 1) if k >= at and "<mimic" in text)
    assert err.reason.endswith(f"(line {mimic_line})")


def test_files_that_were_refused_before_trees():
    """A link without <inertial> is massless; a mimic joint on a chain is a mimic link."""
    robot = load_tree(DATA / "bad_missing_inertial.urdf")
    assert [lk.name for lk in robot.links] == ["l1", "l2"] and robot.is_chain
    assert robot.links[1].mass == 0 and robot.links[1].inertia == sp.zeros(3, 3)
    robot = load_tree(DATA / "bad_mimic.urdf")
    assert robot.parents == (-1, 0) and robot.links[1].mimic == Mimic(0, -1, 0)
    assert (robot.n, robot.nb, robot.is_chain) == (1, 2, False)
    # below the floating joint the robot has a fixed base
    assert [lk.name for lk in load_tree(DATA / "bad_floating.urdf", base="body").links] == ["arm"]


def test_tree_errors(tmp_path):
    err = error_of(DATA / "bad_planar.urdf")
    assert (err.link_name, err.field) == ("puck", "joint(slide).type")
    assert "'slide' below the base 'base' is a planar joint" in err.reason
    assert "choose a base below it (--base), or a tip (--tip) whose chain does not carry it" in err.reason
    path = variant(tmp_path, ('name="a_wheel" type="continuous"', 'name="a_wheel" type="planar"'))
    assert "planar bases are out of scope: load the robot below it with --base wheel" in error_of(path).reason
    assert "the base link 'camera' has no links below it" in str(error_of(TREE, base="camera"))
    assert "no movable joint below the base link 'head'" in str(error_of(TREE, base="head"))


# --------------------------------------------------------------------------- real robots


@dataclass(frozen=True)
class XmlJoint:
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray  # 4x4, the child link frame in the parent link frame
    mimic: tuple[str, float, float] | None


def xml_tree(path: Path) -> tuple[list[str], dict[str, XmlJoint], dict[str, float]]:
    """(link names, joints by name, mass per link) read with ElementTree."""
    root = ET.parse(path).getroot()
    links = [el.get("name") for el in root.findall("link")]
    masses = {}
    for el in root.findall("link"):
        m = el.find("inertial/mass")
        masses[el.get("name")] = 0.0 if m is None else float(m.get("value"))
    joints = {}
    for el in root.findall("joint"):
        o = el.find("origin")
        xyz = [float(x) for x in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()]
        angles = [float(x) for x in (o.get("rpy", "0 0 0") if o is not None else "0 0 0").split()]
        m = el.find("mimic")
        mimic = (
            None if m is None else (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
        )
        joints[el.get("name")] = XmlJoint(
            el.get("name"),
            el.get("type"),
            el.find("parent").get("link"),
            el.find("child").get("link"),
            hom(rpy(*angles), xyz),
            mimic,
        )
    return links, joints, masses


def check_against_xml(robot: Robot, path: Path) -> None:
    """The loaded tree against the raw XML: order, parents, placements, masses and mimic joints."""
    links, joints, masses = xml_tree(path)
    by_child = {j.child: j for j in joints.values()}
    root = next(name for name in links if name not in by_child)

    def depth_first(link: str, key) -> list[XmlJoint]:
        out = []
        for j in sorted((j for j in joints.values() if j.parent == link), key=key):
            out += [j, *depth_first(j.child, key)]
        return out

    order = [j for j in depth_first(root, lambda j: j.name) if j.type in MOVABLE]
    assert [lk.name for lk in robot.links] == [j.child for j in order]
    index = {j.child: i for i, j in enumerate(order)}
    body = {}  # link -> the moving link it is rigidly part of (None: the ground)
    for name in [root] + [j.child for j in depth_first(root, lambda j: j.name)]:
        j = by_child.get(name)
        body[name] = None if j is None else (name if j.type in MOVABLE else body[j.parent])
    for i, lk in enumerate(robot.links):
        j = by_child[lk.name]
        # the parent: the nearest movable joint above, through fixed joints only
        T, up = j.origin, j.parent
        while by_child.get(up) is not None and by_child[up].type not in MOVABLE:
            T, up = by_child[up].origin @ T, by_child[up].parent
        assert robot.parents[i] == index.get(up, -1), lk.name
        assert robot.parents[i] < i
        # snapped right angles (within 1e-9 rad) move the placements by about 1e-9 m
        np.testing.assert_allclose(as_float(lk.placement.matrix()), T, atol=1e-8, err_msg=lk.name)
        assert float(lk.mass) == pytest.approx(
            sum(masses[n] for n in links if body.get(n) == lk.name), rel=1e-13
        )
        if j.mimic is None:
            assert lk.mimic is None
        else:
            master, k, o = j.mimic
            assert lk.mimic.joint == index[joints[master].child]
            assert (float(lk.mimic.multiplier), float(lk.mimic.offset)) == (k, o)
    # depth first: every subtree is one contiguous run of links
    for i in range(len(robot.links)):
        inside = [k for k in range(len(robot.links)) if _carries(robot.parents, i, k)]
        assert inside == list(range(i, i + len(inside)))


def _carries(parents, i: int, k: int) -> bool:
    while k >= 0:
        if k == i:
            return True
        k = parents[k]
    return False


#: Joints per robot as Pinocchio 4.1 reports them (example-robot-data 6.0.0):
#: nv of pinocchio.buildModelFromUrdf(path), which counts a mimic joint as a joint of its own
#: (symdyn's nb), and nv with mimic=True, the independent coordinates (symdyn's n); None where
#: Pinocchio refuses mimic=True (Talos' mimic joints follow joints that come later).
PINOCCHIO_NV = {
    "solo12": ("solo_description/robots/solo12.urdf", 12, 12),
    "baxter": ("baxter_description/urdf/baxter.urdf", 19, 17),
    "talos_reduced": ("talos_data/robots/talos_reduced.urdf", 32, 32),
    "talos_full_v2": ("talos_data/robots/talos_full_v2.urdf", 44, None),
    "panda": ("panda_description/urdf/panda.urdf", 9, 8),
    "human": ("human_description/robots/human.urdf", 36, 36),
    "romeo_laas_small": ("romeo_description/urdf/romeo_laas_small.urdf", 33, 33),
}


def erd_robot(name: str, tmp_path: Path | None) -> tuple[Robot, Path]:
    """A robot of PINOCCHIO_NV and its file; only the warnings its published data earns
    (printed right angles, tensors breaking the triangle inequality) are allowed."""
    path = ERD / PINOCCHIO_NV[name][0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if name == "romeo_laas_small":
            # two hip tensors are impossible (a negative principal moment): refused as they are,
            # then loaded with their products of inertia set to zero (Pinocchio takes them as given)
            with pytest.raises(SymdynError, match=r"link 61 \(LHipPitch_link\): field 'inertia': .* not pos"):
                load_urdf(path)
            root = ET.parse(path).getroot()
            for el in root.findall("link"):
                if el.get("name") in ("LHipPitch_link", "RHipPitch_link"):
                    for key in ("ixy", "ixz", "iyz"):
                        el.find("inertial/inertia").set(key, "0")
            path = tmp_path / "romeo_laas_small.urdf"
            ET.ElementTree(root).write(path)
        robot = load_urdf(path)
    for w in caught:
        assert issubclass(w.category, SymdynWarning), w
        assert "origin.rpy" in str(w.message) or "break the triangle inequality" in str(w.message), w
    return robot, path


@needs_erd
@pytest.mark.parametrize("name", list(PINOCCHIO_NV))
def test_real_trees_against_their_xml_and_pinocchio_counts(name, tmp_path):
    robot, path = erd_robot(name, tmp_path)
    _, nv, nv_mimic = PINOCCHIO_NV[name]
    assert robot.nb == nv
    if nv_mimic is not None:
        assert robot.n == nv_mimic
    check_against_xml(robot, path)


@needs_erd
def test_joint_order_is_by_name_not_by_file():
    """Baxter lists its joints otherwise: the order by name is Pinocchio's, not the file's."""
    robot, path = erd_robot("baxter", None)
    _, joints, _ = xml_tree(path)
    by_child = {j.child: j for j in joints.values()}
    names = [by_child[lk.name].name for lk in robot.links]
    in_file = [name for name in joints if joints[name].type in MOVABLE]
    assert sorted(names) == sorted(in_file) and names != in_file
    assert names[:3] == ["head_pan", "left_s0", "left_s1"]


@needs_erd
def test_panda_whole_tree_fingers():
    """The Panda's second finger mimics the first: 9 bodies, 8 coordinates."""
    robot, _ = erd_robot("panda", None)
    names = [lk.name for lk in robot.links]
    assert names == [f"panda_link{i}" for i in range(1, 8)] + ["panda_leftfinger", "panda_rightfinger"]
    assert robot.parents == (-1, 0, 1, 2, 3, 4, 5, 6, 6)
    assert robot.links[8].mimic == Mimic(7, 1, 0)
    assert [lk.joint for lk in robot.links[7:]] == ["prismatic", "prismatic"]
    assert list(robot.links[7].axis) == [0, 1, 0] and list(robot.links[8].axis) == [0, -1, 0]
