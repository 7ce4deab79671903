"""Contacts in the model (symdyn.model.contacts): the robot files' `contacts:` in every convention,
the loaders' contacts= and `--contacts FRAME[:point|6d]`, and the one-line refusals of bad,
duplicate and hostile contacts (unknown frame or type, names that are no identifiers, text that
is no list)."""

from __future__ import annotations

import warnings

import pytest
import yaml
from robots import EXAMPLES_DIR
from timebound import refused, within

import symdyn
from symdyn.cli.main import main
from symdyn.errors import SymdynError, SymdynWarning
from symdyn.model.contacts import Contact, contact_rows, parse_contact_option

TWO = """name: two
links:
  - {name: l1, joint: revolute, a: 0.3, mass: 1, com: [-0.1, 0, 0],
     inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01}}
  - {name: l2, joint: revolute, a: 0.2, mass: 1, com: [-0.1, 0, 0],
     inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01}}
frames:
  - {name: tip, link: l2, xyz: [0.05, 0, 0]}
"""


def _data(extra: str = "") -> dict:
    return yaml.safe_load(TWO + extra)


def test_a_robot_files_contacts_in_declaration_order():
    r = symdyn.robot_from_data(_data("contacts:\n  - {name: hand, frame: tip, type: 6d}\n  - {frame: l1}\n"))
    assert r.contacts == (Contact("hand", "tip", "6d"), Contact("l1", "l1", "point"))
    assert contact_rows(r.contacts) == 9 and [c.rows for c in r.contacts] == [6, 3]
    assert symdyn.robot_from_data(_data()).contacts == ()


def test_every_convention_reads_contacts(tmp_path):
    for name in ("puma560", "mr_ur5"):  # standard DH and product of exponentials
        text = (EXAMPLES_DIR / f"{name}.yaml").read_text()
        path = tmp_path / f"{name}.yaml"
        frame = "end_effector" if name == "mr_ur5" else "link6"
        path.write_text(text + f"\ncontacts: [{{name: tool, frame: {frame}, type: 6d}}]\n")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SymdynWarning)  # the published PUMA data's inertias
            r = symdyn.load_robot(path)
        assert r.contacts == (Contact("tool", frame, "6d"),)
    data = yaml.safe_load((EXAMPLES_DIR / "planar_prismatic_modified.yaml").read_text())
    first = data["links"][0]["name"]
    data["contacts"] = [{"frame": first}]
    assert symdyn.robot_from_data(data).contacts == (Contact(first, first, "point"),)


BAD = [
    ("contacts: [{name: c, frame: l9}]", "contacts[0].frame: contact 'c' is at 'l9', which is no frame"),
    ("contacts: [{frame: l1}, {frame: l1}]", "contacts[1].name: duplicate contact name 'l1'"),
    (
        "contacts: [{frame: l1, type: 3d}]",
        "contacts[0].type: contact 'l1' has type '3d', expected point or 6d",
    ),
    ("contacts: [{frame: l1, kind: 6d}]", "contacts[0]: unknown field 'kind'"),
    ("contacts: [{name: c}]", "contacts[0]: missing required field 'frame'"),
    ("contacts: [{frame: [l1]}]", "contacts[0].frame: expected a frame's name"),
    ("contacts: [{name: 1st, frame: l1}]", "'1st' is not a contact name"),
    ('contacts: [{name: "a\\nb", frame: l1}]', "is not a contact name"),
    ("contacts: [{name: a.b, frame: l1}]", "'a.b' is not a contact name"),
    (f"contacts: [{{name: {'x' * 300}, frame: l1}}]", "is not a contact name"),
    ("contacts: [{name: [x], frame: l1}]", "is not a contact name"),
    ("contacts: [{frame: l1, type: [6d]}]", "expected point or 6d"),
    ("contacts: l1", "contacts: expected a list of contacts"),
    ("contacts: {frame: l1}", "contacts: expected a list of contacts"),
    ("contacts: [3]", "contacts[0]: expected a contact"),
    ("contacts: [null]", "contacts[0]: expected a contact"),
]


@pytest.mark.parametrize("extra,message", BAD)
def test_bad_contacts_are_refused_in_one_line(extra, message, tmp_path):
    path = tmp_path / "two.yaml"
    path.write_text(TWO + extra + "\n")
    with within(5), pytest.raises(SymdynError) as e:
        symdyn.load_robot(path)
    text = str(e.value)
    assert message in text and str(path) in text and "\n" not in text, text


def test_contacts_beside_closed_loops_are_refused():
    loop = "loops: [{name: c1, link: l2, point: [0.2, 0, 0], to: base, to_point: [0.5, 0, 0]}]\n"
    with pytest.raises(SymdynError, match="contacts .* closed loops are not handled"):
        symdyn.robot_from_data(_data(loop + "contacts: [{frame: tip}]\n"))


def test_the_loaders_contacts_keyword_replaces_the_files(tmp_path):
    path = tmp_path / "two.yaml"
    path.write_text(TWO + "contacts: [{frame: l1}]\n")
    r = symdyn.load_robot(path, contacts=["tip:6d", {"name": "c2", "frame": "l2"}, Contact("c3", "l1")])
    assert [(c.name, c.frame, c.kind) for c in r.contacts] == [
        ("tip", "tip", "6d"),
        ("c2", "l2", "point"),
        ("c3", "l1", "point"),
    ]
    assert symdyn.load_robot(path, contacts=[]).contacts == ()
    for bad, message in (("nope", "'nope', which is no frame"), ("tip:7d", "unknown contact type '7d'")):
        with pytest.raises(SymdynError, match=message):
            symdyn.load_robot(path, contacts=[bad])
    with pytest.raises(SymdynError, match="expected a list of contacts"):
        symdyn.load_robot(path, contacts="tip")


def test_the_option_names_a_contact_after_its_frame():
    assert parse_contact_option("FL_FOOT") == Contact("FL_FOOT", "FL_FOOT", "point")
    assert parse_contact_option("sole:6d") == Contact("sole", "sole", "6d")
    assert parse_contact_option("a:b:point") == Contact("a_b", "a:b", "point")  # an identifier of the frame
    assert parse_contact_option("left-foot.1") == Contact("left_foot_1", "left-foot.1", "point")
    for bad in (":6d", "x:", "x:planar"):
        with pytest.raises(SymdynError, match="--contacts"):
            parse_contact_option(bad)


def test_the_command_line_refuses_bad_contacts_in_one_line(capsys, tmp_path):
    path = tmp_path / "two.yaml"
    path.write_text(TWO)
    assert "unknown contact type 'x'" in refused(capsys, "derive", path, "--contacts", "tip:x")
    line = refused(capsys, "generate", path, "--out", tmp_path / "o", "--contacts", "tip", "tip")
    assert "duplicate contact name 'tip'" in line
    line = refused(capsys, "derive", path, "--contacts", "\x1b[2Jfoot\nx")
    assert "which is no frame" in line and "\x1b" not in line
    assert not (tmp_path / "o").exists()


def test_generate_writes_the_contact_functions(tmp_path, capsys):
    path = tmp_path / "two.yaml"
    path.write_text(TWO)
    out = tmp_path / "out"
    args = ["generate", str(path), "--out", str(out), "--contacts", "tip:6d", "l1", "--functions", "contacts"]
    assert main([*args, "--target", "c", "--target", "latex"]) == 0
    header = (out / "two_dynamics.h").read_text()
    assert "#define two_NCONTACT 2" in header and "#define two_NLAMBDA 9" in header
    assert "void two_contact_forward_dynamics(" in header and "void two_impulse_dynamics(" in header
    tex = (out / "two_dynamics.tex").read_text()
    assert "\\section*{Contacts}" in tex and "contact\\_jacobian" in tex and "contact\\_drift" in tex
