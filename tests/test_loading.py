"""symdyn.load_robot and the command line recognise a robot description by its content, whatever the
file's name: a URDF (<robot>), MJCF (<mujoco>), other XML (refused) and robot
files (YAML or JSON). The robot loaded by content is compared with the one its own loader makes."""

from __future__ import annotations

from pathlib import Path

import pytest

import symdyn
from symdyn.cli.main import main
from symdyn.errors import SymdynError
from symdyn.parsers import load_urdf
from symdyn.parsers.robot_file import robot_from_data

ROOT = Path(__file__).resolve().parents[1]
URDF = ROOT / "tests" / "data" / "urdf" / "two_link.urdf"
ROGER = ROOT / "examples" / "roger_arm.yaml"
MJCF = '<mujoco model="arm">\n  <worldbody/>\n</mujoco>\n'
MJCF_ARM = ROOT / "tests" / "data" / "mjcf" / "slide.xml"


def _same(a, b) -> None:
    assert (a.name, a.links, a.gravity, a.convention) == (b.name, b.links, b.gravity, b.convention)


@pytest.mark.parametrize("name", ["model.xml", "arm.yaml", "arm", "arm.URDF"])
def test_a_urdf_under_any_name_is_read_as_a_urdf(tmp_path, name):
    path = tmp_path / name
    path.write_bytes(b"\xef\xbb\xbf" + URDF.read_bytes())  # a byte order mark first
    _same(symdyn.load_robot(path), load_urdf(URDF))
    _same(symdyn.load_robot(path, tip="upper"), load_urdf(URDF, tip="upper"))
    assert symdyn.load_robot(path).source == str(path)


@pytest.mark.parametrize("name", ["roger.urdf", "roger.xml", "roger"])
def test_a_robot_file_under_any_name_is_read_as_a_robot_file(tmp_path, name):
    import yaml

    path = tmp_path / name
    path.write_text(ROGER.read_text())
    _same(symdyn.load_robot(path), robot_from_data(yaml.safe_load(ROGER.read_text())))
    with pytest.raises(SymdynError, match="a base or tip link applies to URDF files only"):
        symdyn.load_robot(path, tip="l2")


def test_load_urdf_of_a_robot_file_points_to_load_robot():
    with pytest.raises(SymdynError) as info:
        load_urdf(ROGER)
    assert str(info.value) == (
        f"{ROGER}: not a URDF: the file does not start with an XML element ('<'); "
        "a robot file (YAML or JSON) is read by symdyn.load_robot"
    )


def test_load_urdf_refuses_mjcf_naming_its_loader(tmp_path):
    path = tmp_path / "model.yaml"
    path.write_text(MJCF)
    with pytest.raises(SymdynError) as info:
        load_urdf(path)
    assert str(info.value) == (
        f"{path}: an MJCF file (top element <mujoco>), not a URDF: read it with symdyn.load_mjcf "
        "(or symdyn.load_robot, which recognises either)"
    )
    with pytest.raises(SymdynError, match="no hinge or slide joint"):
        symdyn.load_robot(path)
    with pytest.raises(SymdynError, match="a base or tip link applies to URDF files only"):
        symdyn.load_robot(path, base="x")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('<?xml version="1.0"?>\n<sdf version="1.6"/>', "an XML file whose top element is <sdf>"),
        ("<robot", "invalid XML at line 1"),
    ],
)
def test_other_xml_is_refused_naming_the_file(tmp_path, text, message):
    path = tmp_path / "model.yaml"
    path.write_text(text)
    for load in (symdyn.load_robot, load_urdf):
        with pytest.raises(SymdynError) as info:
            load(path)
        assert str(info.value).startswith(f"{path}: {message}")


def test_every_command_reads_by_content(tmp_path, capsys):
    urdf = tmp_path / "model.xml"
    urdf.write_bytes(URDF.read_bytes())
    assert main(["derive", str(urdf), "--format", "json"]) == 0
    assert '"robot": "two_link"' in capsys.readouterr().out
    out = tmp_path / "out"
    assert main(["generate", str(urdf), "--target", "python", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["two_link_numpy.py"]
    capsys.readouterr()
    mjcf = tmp_path / "arm.txt"
    mjcf.write_bytes(MJCF_ARM.read_bytes())
    assert main(["derive", str(mjcf), "--format", "json"]) == 0
    assert '"robot": "slide"' in capsys.readouterr().out
    empty = tmp_path / "empty.xml"
    empty.write_text(MJCF)
    assert main(["derive", str(empty)]) == 1
    err = capsys.readouterr().err
    assert err == f"symdyn: error: {empty}: no hinge or slide joint: the model has nothing that moves\n"
