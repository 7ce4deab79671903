"""A robot's frames and base placement as loaded (symdyn.parsers.frame_fields, the URDF loader's
merged links, PoE's end_effector) and the one-line errors of bad frame input."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from robots import EXAMPLES_DIR, example
from test_frame_kinematics import TOL, urdf_dynamics

import symdyn
from symdyn.errors import SymdynError
from symdyn.oracle.frames import frame_state


def test_urdf_keeps_the_frames_of_merged_links():
    _, dyn = urdf_dynamics("panda")
    r = dyn.robot
    assert {"panda_link0", "panda_link8", "panda_hand", "panda_hand_tcp"} <= set(r.frame_names)
    assert r.frame("panda_link0").link == -1
    assert r.frame("panda_hand").link == r.frame_names.index("panda_link7")


BAD = [
    ("frames: [{name: tool, link: l9}]", "field 'frames[0].link': no link named 'l9'"),
    ("frames: [{name: tool, link: l2}, {name: tool, link: l1}]", "duplicate frame name 'tool'"),
    ("frames: [{name: l1, link: l2}]", "frame name 'l1' is the name of link 1"),
    ("frames: [{name: tool, link: l2, xyz: [1, 2]}]", "field 'frames[0].xyz': expected a list of 3"),
    ("frames: [{name: tool, link: l2, rpy: [0, 0, foo(1)]}]", "frames[0].rpy.y"),
    ("frames: [{name: tool, link: l2, xzy: [0, 0, 0]}]", "unknown key 'xzy'"),
    ("frames: [{link: l2}]", "field 'frames[0].name': missing required field"),
    ("base: {xyz: [0, 0, 1], rpy: 3}", "field 'base.rpy'"),
    ("base: [0, 0, 1]", "field 'base'"),
]


@pytest.mark.parametrize("extra,message", BAD)
def test_bad_frames_name_file_field_and_value(extra, message):
    data = yaml.safe_load(
        "name: bad\nlinks:\n  - {name: l1, joint: revolute, a: 1, mass: 1}\n"
        "  - {name: l2, joint: revolute, a: 1, mass: 1}\n" + extra
    )
    with pytest.raises(SymdynError, match="^bad.yaml: ") as err:
        symdyn.robot_from_data(data, "bad.yaml")
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_poe_end_effector_is_a_frame_in_files_and_from_python():
    mr = pytest.importorskip("modern_robotics")
    robot = example("mr_ur5")
    assert robot.frame("end_effector").link == robot.nb - 1
    M01 = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.5], [0, 0, 0, 1]])
    M12 = np.array([[1, 0, 0, 0.3], [0, 1, 0, 0], [0, 0, 1, 0.1], [0, 0, 0, 1]])
    S = np.array([[0, 0, 1, 0, 0, 0]]).T
    built = symdyn.robot_from_poe([M01, M12], [np.diag([0.1, 0.1, 0.1, 1, 1, 1])], S)
    q = [0.7]
    T = mr.FKinSpace(M01 @ M12, S, q)
    np.testing.assert_allclose(frame_state(built, "end_effector", q).pose, T, atol=TOL)
    raw = yaml.safe_load((EXAMPLES_DIR / "mr_ur5.yaml").read_text())
    raw["frames"] = [{"name": "end_effector", "link": "wrist_3_link"}]
    with pytest.raises(SymdynError, match="'end_effector' is PoE's end-effector frame"):
        symdyn.robot_from_data(raw, "ur5.yaml")
