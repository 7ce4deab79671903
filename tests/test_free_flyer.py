"""The free flyer's rotation against Pinocchio's quaternion and the Robot's nq, nv."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml
from robots import example

from symdyn import load_robot, load_urdf, robot_from_data
from symdyn.errors import SymdynError
from symdyn.model.free_flyer import base_symbols, quaternion_rotation
from symdyn.spatial.transform import Transform

pin = pytest.importorskip("pinocchio")


def test_rotation_is_pinocchios_at_random_unit_quaternions():
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = rng.normal(size=4)
        x /= np.linalg.norm(x)
        R = np.array(quaternion_rotation(*x).evalf(), dtype=float)
        expected = pin.Quaternion(x[3], x[0], x[1], x[2]).toRotationMatrix()
        np.testing.assert_allclose(R, expected, atol=1e-14)


def test_rotation_is_orthonormal_on_the_unit_sphere():
    qb, _, _ = base_symbols()
    R = quaternion_rotation(*qb[3:7])
    unit = {qb[6]: sp.sqrt(1 - qb[3] ** 2 - qb[4] ** 2 - qb[5] ** 2)}
    assert sp.simplify((R.T * R - sp.eye(3)).xreplace(unit)) == sp.zeros(3)


def test_sizes_and_no_fixed_placement():
    puma = example("puma560")
    floating = dataclasses.replace(puma, floating=True)
    assert (puma.nq, puma.nv) == (6, 6)
    assert (floating.nq, floating.nv) == (13, 12)
    with pytest.raises(SymdynError, match="floating base has no fixed placement"):
        dataclasses.replace(puma, floating=True, base=Transform.from_translation([1, 0, 0]))


# --------------------------------------------------------------------------- floating input

DATA = Path(__file__).parent / "data"
ARM = {
    "name": "arm",
    "links": [
        {"joint": "revolute", "a": 0.5, "alpha": 0, "d": 0, "theta": 0, "mass": 1, "com": [-0.2, 0, 0]}
    ],
}


def test_robot_file_base_floating():
    plain = robot_from_data({**ARM, "base": "floating"})
    assert plain.floating and (plain.nq, plain.nv) == (8, 7) and plain.base_body.mass == 0
    assert repr(plain).startswith("Robot arm: 1 joint on a floating base 'base' (NQ 8, NV 7), ")
    body = robot_from_data(
        {
            **ARM,
            "base": {
                "floating": True,
                "mass": "m0",
                "com": [0, 0, 0.1],
                "inertia": {"ixx": 0.1, "iyy": 0.1, "izz": 0.1, "ixy": 0.01},
            },
        }
    )
    assert body.floating and body.base_body.mass == sp.Symbol("m0") and body.params == (sp.Symbol("m0"),)
    assert body.base_body.inertia[0, 1] == body.base_body.inertia[1, 0] == sp.Float(0.01)
    assert body.base_body.com[2] == sp.Float(0.1)
    assert not robot_from_data({**ARM, "base": {"floating": False, "xyz": [1, 0, 0]}}).floating


@pytest.mark.parametrize(
    "base, field, message",
    [
        ({"floating": True, "xyz": [0, 0, 1]}, "base.xyz", "a floating base has no placement in the world"),
        ({"floating": True, "rpy": [0, 0, 1]}, "base.rpy", "a floating base has no placement in the world"),
        ({"floating": "yes"}, "base.floating", "expected true or false, got 'yes'"),
        ({"mass": 2}, "base.mass", "a fixed base is the ground"),
        ("floats", "base", "expected 'floating' or a mapping {xyz, rpy}"),
        ({"floating": True, "mass": -1}, None, "mass"),
    ],
)
def test_robot_file_base_errors(base, field, message):
    with pytest.raises(SymdynError, match=re.escape(message)) as err:
        robot_from_data({**ARM, "base": base})
    text = str(err.value)
    assert "\n" not in text and (field is None or f"field '{field}'" in text), text


def test_parameter_named_like_a_base_coordinate():
    data = {**ARM, "base": "floating", "parameters": {"qw_b": 1}}
    data["links"] = [{**ARM["links"][0], "mass": "qw_b"}]
    with pytest.raises(SymdynError, match="parameter 'qw_b' is the name of a floating base coordinate"):
        robot_from_data(data)


def test_load_robot_floating_on_each_format(tmp_path):
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(ARM))
    assert load_robot(path, floating=True).floating and not load_robot(path).floating
    path.write_text(yaml.safe_dump({**ARM, "base": {"xyz": [0, 0, 1]}}))
    with pytest.raises(SymdynError, match="a floating base has no placement in the world"):
        load_robot(path, floating=True)
    # a URDF whose root joins its base by a floating joint: that joint is the free flyer
    urdf = DATA / "urdf" / "bad_floating.urdf"
    robot = load_urdf(urdf, floating=True)
    assert (
        robot.base_body.name == "body"
        and robot.base_body.mass == 1
        and [lk.name for lk in robot.links] == ["arm"]
    )
    with pytest.raises(SymdynError, match="load it as a floating base with --floating"):
        load_urdf(urdf)
    with pytest.raises(SymdynError, match="give no tip"):
        load_urdf(DATA / "urdf" / "branch.urdf", tip="l2", floating=True)


MJCF_FREE = """<mujoco model="flyer">
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="trunk" pos="0 0 1">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.1 0.05" mass="3"/>
      <body name="leg" pos="0.2 0 0"><joint name="hip" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="0.5"/></body>
    </body>
  </worldbody>
</mujoco>
"""


def test_mjcf_free_joint_is_the_floating_base(tmp_path):
    pytest.importorskip("mujoco")
    path = tmp_path / "flyer.xml"
    path.write_text(MJCF_FREE)
    robot = load_robot(path)
    assert (
        robot.floating and robot.base_body.name == "trunk" and float(robot.base_body.mass) == pytest.approx(3)
    )
    assert [lk.name for lk in robot.links] == ["leg"] and robot.frames[0].name == "trunk"
    path.write_text(MJCF_FREE.replace('<freejoint name="root"/>', ""))
    with pytest.raises(SymdynError, match="no free joint"):
        load_robot(path, floating=True)
