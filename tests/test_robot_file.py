"""The robot description file loader: kinematics, parameters, and one clear error per bad file."""

from __future__ import annotations

import difflib
import hashlib
import importlib
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml
from robots import example, example_context
from timebound import refused

import symdyn.codegen
from symdyn.apps.compilation.compiled import CompiledDynamics
from symdyn.errors import SymdynError, SymdynWarning
from symdyn.parsers import load_robot, robot_from_data
from symdyn.parsers.dh import dh_link
from symdyn.spatial.transform import Transform

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

DATA = Path(__file__).parent / "data"
GOOD = DATA / "good"
BAD = DATA / "bad"


def _load(name: str):
    """Load a good file; any warning is a failure."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_robot(GOOD / name)


# ------------------------------------------------------------------ forward kinematics


def _dh_standard(theta, d, a, alpha):
    """Rz(theta) Tz(d) Tx(a) Rx(alpha), written out by hand."""
    ct, st, ca, sa = sp.cos(theta), sp.sin(theta), sp.cos(alpha), sp.sin(alpha)
    return sp.Matrix(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0, sa, ca, d],
            [0, 0, 0, 1],
        ]
    )


def _dh_modified(alpha, a, theta, d):
    """Rx(alpha) Tx(a) Rz(theta) Tz(d), written out by hand (Craig 3.6)."""
    ct, st, ca, sa = sp.cos(theta), sp.sin(theta), sp.cos(alpha), sp.sin(alpha)
    return sp.Matrix(
        [
            [ct, -st, 0, a],
            [st * ca, ct * ca, -sa, -sa * d],
            [st * sa, ct * sa, ca, ca * d],
            [0, 0, 0, 1],
        ]
    )


def _rows(path: Path) -> list[dict]:
    """The DH rows of a file with its parameter values substituted (numbers, parsed by hand)."""
    doc = yaml.safe_load(path.read_text())
    env = {"pi": sp.pi, **{k: sp.Float(v) for k, v in (doc.get("parameters") or {}).items()}}
    out = []
    for link in doc["links"]:
        row = {}
        for key in ("a", "alpha", "d", "theta"):
            v = link.get(key, 0)
            row[key] = sp.Float(v) if isinstance(v, (int, float)) else sp.S(v).subs(env)
        row["joint"] = link["joint"]
        row["com"] = [sp.S(c).subs(env) for c in link.get("com", [0, 0, 0])]
        e = {k: sp.Float(link["inertia"].get(k, 0)) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
        row["inertia"] = sp.Matrix(
            [
                [e["ixx"], e["ixy"], e["ixz"]],
                [e["ixy"], e["iyy"], e["iyz"]],
                [e["ixz"], e["iyz"], e["izz"]],
            ]
        )
        out.append(row)
    return out


def _num(M) -> np.ndarray:
    return np.array(sp.Matrix(M).evalf(), dtype=float)


@pytest.mark.parametrize("name", ["standard.yaml", "modified.yaml"])
def test_forward_kinematics_match_the_dh_product(name):
    robot = _load(name).resolved()
    rows = _rows(GOOD / name)
    assert robot.convention == name.split(".")[0]
    assert [lk.joint for lk in robot.links] == ["revolute", "prismatic", "revolute"]
    rng = np.random.default_rng(7)
    for _ in range(4):
        q = [float(v) for v in rng.uniform(-2.0, 2.0, size=robot.n)]
        body = Transform.identity()
        dh = sp.eye(4)
        for link, row, qi in zip(robot.links, rows, q, strict=True):
            theta, d = row["theta"], row["d"]
            if row["joint"] == "revolute":
                theta = theta + qi
            else:
                d = d + qi
            if robot.convention == "standard":
                dh = dh * _dh_standard(theta, d, row["a"], row["alpha"])
            else:
                dh = dh * _dh_modified(row["alpha"], row["a"], theta, d)
            body = body @ link.joint_transform(sp.Float(qi))
            frame_i = body @ link.frame
            np.testing.assert_allclose(_num(frame_i.matrix()), _num(dh), atol=1e-12)
            # centre of mass and inertia, given in DH frame i, are the same body in the world
            com_world_file = dh * sp.Matrix([*row["com"], 1])
            np.testing.assert_allclose(_num(body.apply(link.com)), _num(com_world_file[:3, 0]), atol=1e-12)
            R_dh = dh[:3, :3]
            np.testing.assert_allclose(
                _num(body.R * link.inertia * body.R.T),
                _num(R_dh * row["inertia"] * R_dh.T),
                atol=1e-12,
            )


def test_joint_axis_is_z_and_twists_are_exact():
    robot = _load("standard.yaml")
    for link in robot.links:
        assert link.axis == sp.ImmutableMatrix([0, 0, 1])
    # alpha = pi/2 and -pi/2 give exact 0 and +-1 entries
    rot1, rot2 = robot.links[0].frame.R, robot.links[1].frame.R
    assert rot1 == sp.ImmutableMatrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    assert rot2 == sp.ImmutableMatrix([[1, 0, 0], [0, 0, 1], [0, -1, 0]])
    mod = _load("modified.yaml")
    assert all(link.frame.is_identity() for link in mod.links)
    assert mod.links[1].placement.R[0, :] == sp.ImmutableMatrix(
        [[sp.cos(-sp.pi / 3), -sp.sin(-sp.pi / 3), 0]]
    )


def _same(A, B, symbols) -> None:
    """A == B as functions of `symbols`, checked at random points."""
    rng = np.random.default_rng(3)
    for _ in range(3):
        values = rng.uniform(-2, 2, len(symbols))
        point = {s: sp.Float(v) for s, v in zip(symbols, values, strict=True)}
        np.testing.assert_allclose(_num(A.xreplace(point)), _num(B.xreplace(point)), atol=1e-12)


def test_dh_link_symbolic_standard_and_modified():
    q, a, al, d, th = syms = sp.symbols("q a alpha d theta")
    # standard revolute: placement * Rz(q) * frame == Rz(th + q) Tz(d) Tx(a) Rx(al)
    pl, axis, frame = dh_link("standard", "revolute", a, al, d, th)
    assert axis == sp.ImmutableMatrix([0, 0, 1])
    T = pl @ Transform.rz(q) @ frame
    _same(T.matrix(), _dh_standard(th + q, d, a, al), syms)
    # standard prismatic
    pl, axis, frame = dh_link("standard", "prismatic", a, al, d, th)
    T = pl @ Transform.tz(q) @ frame
    _same(T.matrix(), _dh_standard(th, d + q, a, al), syms)
    # modified revolute and prismatic; the body frame is the DH frame
    pl, axis, frame = dh_link("modified", "revolute", a, al, d, th)
    assert frame.is_identity()
    T = pl @ Transform.rz(q)
    _same(T.matrix(), _dh_modified(al, a, th + q, d), syms)
    pl, axis, frame = dh_link("modified", "prismatic", a, al, d, th)
    T = pl @ Transform.tz(q)
    _same(T.matrix(), _dh_modified(al, a, th, d + q), syms)
    # the previous link's frame is prepended
    prev = Transform.tx(sp.Symbol("p")) @ Transform.rx(sp.pi / 2)
    pl2, _, _ = dh_link("standard", "revolute", a, al, d, th, prev)
    assert pl2 == prev @ dh_link("standard", "revolute", a, al, d, th)[0]
    with pytest.raises(TypeError):
        dh_link("standard", "revolute", "__import__('os')", 0, 0, 0)


# ------------------------------------------------------------------ parameters


def test_parameter_order_is_first_appearance():
    robot = _load("order.yaml")
    # links first (as written), then parameters (keys and values), then gravity;
    # valued names (k, m2) are not free; 'unused' was declared free (null)
    assert robot.params == sp.symbols("l1 b m1 J1 fc c unused g")
    assert [str(s) for s, _ in robot.values] == ["m2", "k"]
    assert robot.value_map[sp.Symbol("m2")] == 2 * sp.Symbol("c")


def test_values_are_substituted():
    robot = _load("two_link.yaml")
    g, l1, m1 = sp.symbols("g l1 m1")
    assert robot.params == sp.symbols("l1 m1 b1 l2 m2 Jm")
    assert robot.values == ((g, sp.Float(9.81)),)
    assert robot.gravity == sp.ImmutableMatrix([g, 0, 0])
    resolved = robot.resolved()
    assert resolved.gravity == sp.ImmutableMatrix([sp.Float(9.81), 0, 0])
    assert resolved.params == robot.params
    up = robot.links[0]
    assert up.mass == m1
    assert up.com == sp.ImmutableMatrix([l1 / 2, 0, 0])  # -l1/2 in frame 1 is +l1/2 in the body
    assert up.inertia[2, 2] == m1 * l1**2 / 12
    assert up.friction.viscous == sp.Symbol("b1")
    assert up.friction.coulomb == sp.Float(0.1)
    assert robot.links[1].motor.gear_ratio == 50
    assert robot.links[1].motor.inertia == sp.Symbol("Jm")
    assert robot.links[0].motor.gear_ratio == 1 and robot.links[1].friction.viscous == 0


def test_value_expressions_over_other_parameters():
    robot = _load("chain.yaml")
    vals = robot.value_map
    l1, l2, total, m1, rho = sp.symbols("l1 l2 total m1 rho")
    assert vals[l1] == sp.Float(0.25)
    assert vals[l2] == sp.Float(0.5)
    assert vals[total] == sp.Float(0.75)
    assert vals[m1] == sp.Float(0.25) * rho
    assert [str(s) for s, _ in robot.values] == ["total", "l2", "l1", "m1"]  # file order
    assert robot.params == (rho,)
    r = robot.resolved()
    assert r.links[0].mass == sp.Float(0.25) * rho
    assert r.links[0].frame.p[0] == sp.Float(0.75)


@pytest.mark.parametrize(
    "params, cycle",
    [
        ({"a": "b + 1", "b": "2*a"}, "a -> b -> a"),
        ({"a": "a + 1"}, "a -> a"),
        ({"x": 1, "a": "c", "b": "a*x", "c": "sin(b)"}, "a -> c -> b -> a"),
    ],
)
def test_parameter_cycles_are_refused(params, cycle):
    data = {"name": "cyc", "parameters": params, "links": [{"joint": "revolute", "mass": 1}]}
    with pytest.raises(SymdynError, match="cycle") as info:
        robot_from_data(data, source="cyc.yaml")
    assert cycle in str(info.value)
    assert info.value.file == "cyc.yaml"
    assert info.value.field.startswith("parameters.")


def test_json_input_and_tab_indented_json():
    yaml_robot = _load("two_link.yaml")
    for name in ("two_link.json", "two_link_tabs.json"):
        robot = _load(name)
        assert robot.links == yaml_robot.links
        assert robot.params == yaml_robot.params
        assert robot.values == yaml_robot.values
        assert robot.gravity == yaml_robot.gravity


def test_source_hash_and_defaults(tmp_path):
    path = GOOD / "two_link.yaml"
    robot = _load("two_link.yaml")
    assert robot.source == str(path)
    assert robot.source_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert robot.name == "two_link" and robot.n == 2 and robot.convention == "standard"
    data = {"name": "one", "links": [{"joint": "prismatic", "mass": 1}]}
    r = robot_from_data(data)
    assert r.source is None and r.source_sha256 is None
    assert r.gravity == sp.ImmutableMatrix([0, 0, sp.Float(-9.81)])
    assert r.links[0].name == "link1"
    assert r.links[0].com == sp.zeros(3, 1) and r.links[0].inertia == sp.zeros(3, 3)
    assert r.links[0].placement.is_identity()
    assert r.params == () and r.values == ()
    assert load_robot(str(path)) == load_robot(path)


def test_inertia_is_the_urdf_tensor():
    data = {
        "name": "t",
        "convention": "modified",
        "links": [
            {
                "joint": "revolute",
                "mass": 1,
                "inertia": {"iyz": -0.01, "ixx": 2, "iyy": 3, "izz": 4, "ixy": 0.1, "ixz": 0.2},
            }
        ],
    }
    inertia = robot_from_data(data).links[0].inertia
    f = sp.Float
    assert inertia == sp.ImmutableMatrix([[2, f(0.1), f(0.2)], [f(0.1), 3, f(-0.01)], [f(0.2), f(-0.01), 4]])


# ------------------------------------------------------------------ errors

# file -> (link index, link name, field, words in the message); None = not about a link/field
BAD_FILES = {
    "bad_yaml.yaml": (None, None, None, "line 12"),
    "top_level_list.yaml": (None, None, None, "top level must be a mapping"),
    "empty.yaml": (None, None, None, "empty document"),
    "not_utf8.yaml": (None, None, None, "not UTF-8"),
    "empty_links.yaml": (None, None, "links", "at least one link"),
    "missing_name.yaml": (None, None, "name", "missing required field"),
    "bad_robot_name.yaml": (None, None, "name", "not a valid C identifier"),
    "c_keyword_name.yaml": (None, None, "name", "C keyword"),
    "bad_convention.yaml": (None, None, "convention", "'standard' or 'modified'"),
    "gravity_length.yaml": (None, None, "gravity", "3 numbers"),
    "unknown_top_key.yaml": (None, None, "gravty", "did you mean 'gravity'"),
    "reserved_parameter.yaml": (None, None, "parameters.q1", "reserved for joint symbols"),
    "reserved_parameter_pi.yaml": (None, None, "parameters.pi", "reserved"),
    "parameter_cycle.yaml": (None, None, "parameters.la", "la -> lb -> la"),
    "unknown_link_key.yaml": (2, "elbow", "colour", "unknown key 'colour'"),
    "unknown_inertia_key.yaml": (2, "elbow", "inertia.izx", "unknown key 'izx'"),
    "duplicate_key.yaml": (2, "elbow", "mass", "duplicate key 'mass'"),
    "missing_joint.yaml": (2, "elbow", "joint", "missing required field"),
    "missing_mass.yaml": (2, "elbow", "mass", "missing required field"),
    "bad_joint.yaml": (2, "elbow", "joint", "'rotary'"),
    "com_length.yaml": (2, "elbow", "com", "got 2 entries"),
    "list_for_number.yaml": (2, "elbow", "mass", "not a list"),
    "bool_for_number.yaml": (2, "elbow", "a", "boolean"),
    "negative_mass.yaml": (2, "elbow", "mass", "negative"),
    "negative_mass_param.yaml": (2, "elbow", "mass", "negative"),
    "non_psd_inertia.yaml": (2, "elbow", "inertia", "not positive semi-definite"),
    "negative_friction.yaml": (2, "elbow", "friction.viscous", "negative"),
    "negative_coulomb_minus.yaml": (2, "elbow", "friction.coulomb.minus", "Tc- without its sign"),
    "negative_coulomb_plus.yaml": (2, "elbow", "friction.coulomb.plus", "negative"),
    "coulomb_length.yaml": (2, "elbow", "friction.coulomb", "[c_plus, c_minus]"),
    "coulomb_not_number.yaml": (2, "elbow", "friction.coulomb.minus", "boolean"),
    "negative_motor_inertia.yaml": (2, "elbow", "motor.inertia", "negative"),
    "zero_gear_ratio.yaml": (2, "elbow", "motor.gear_ratio", "zero"),
    "reserved_name_in_expression.yaml": (2, "elbow", "a", "reserved for joint symbols"),
    "python_code.yaml": (2, "elbow", "mass", "call of '__import__"),
    "bad_expression_syntax.yaml": (2, "elbow", "a", "cannot parse"),
    "duplicate_link_name.yaml": (2, "shoulder", "name", "duplicate link name"),
    "bad_link_name.yaml": (2, "elbow joint", "name", "link name"),
    "reversed_limits.yaml": (
        2,
        "elbow",
        "limits",
        "lower limit pi/2 = 1.571 must be below the upper limit -pi/2",
    ),
}


def test_every_bad_file_has_an_expectation():
    assert sorted(p.name for p in BAD.iterdir()) == sorted(BAD_FILES)


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_bad_file_gives_one_clear_error(name):
    link_index, link_name, field, words = BAD_FILES[name]
    path = BAD / name
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SymdynError) as info:
            load_robot(path)
    err = info.value
    msg = str(err)
    assert err.file == str(path) and msg.startswith(f"{path}: ")
    assert (err.link_index, err.link_name, err.field) == (link_index, link_name, field)
    if link_index is not None:
        assert f"link {link_index} ({link_name})" in msg
    if field is not None:
        assert f"field '{field}'" in msg
    assert words in msg
    assert "Traceback" not in msg


@pytest.mark.parametrize(
    "name",
    sorted(n for n in BAD_FILES if (BAD / n).read_bytes().count(b"\n  - name:") == 2),
)
def test_each_bad_file_changes_the_base_file_in_one_place(name):
    """Files built from good/base_arm.yaml differ from it in one hunk: exactly one error.

    negative_mass_param.yaml needs two: the parameter's value and its use as a mass.
    """
    base = (GOOD / "base_arm.yaml").read_text().splitlines()[1:]
    bad = (BAD / name).read_text().splitlines()[1:]
    hunks = [ln for ln in difflib.unified_diff(base, bad, n=0, lineterm="") if ln.startswith("@@")]
    assert len(hunks) == (2 if name == "negative_mass_param.yaml" else 1), hunks


def test_base_file_is_valid():
    robot = _load("base_arm.yaml")
    assert [lk.name for lk in robot.links] == ["shoulder", "elbow"]


def test_python_code_in_a_file_is_not_executed():
    marker = Path("/tmp/symdyn_pwned")  # the path the payload in python_code.yaml touches
    marker.unlink(missing_ok=True)
    with pytest.raises(SymdynError):
        load_robot(BAD / "python_code.yaml")
    assert not marker.exists()


def test_missing_file_and_directory(tmp_path):
    missing = tmp_path / "nope.yaml"
    with pytest.raises(SymdynError, match="no such file") as info:
        load_robot(missing)
    assert info.value.file == str(missing)
    with pytest.raises(SymdynError, match="directory") as info:
        load_robot(tmp_path)
    assert info.value.file == str(tmp_path)


def test_bad_yaml_names_the_line(tmp_path):
    p = tmp_path / "broken.yaml"
    p.write_text("name: arm\nlinks:\n  - joint: revolute\n    mass: [1, 2\n")
    with pytest.raises(SymdynError, match=r"invalid YAML at line \d+") as info:
        load_robot(p)
    assert info.value.file == str(p)


@pytest.mark.parametrize(
    "link, field, words",
    [
        ({"joint": "revolute", "mass": 1, "com": "0, 0, 0"}, "com", "list of 3"),
        ({"joint": "revolute", "mass": 1, "com": [0, 0, "x.y"]}, "com.z", "attribute"),
        ({"joint": "revolute", "mass": 1, "inertia": [1, 2, 3]}, "inertia", "mapping"),
        ({"joint": "revolute", "mass": 1, "inertia": {"ixx": "open('f')"}}, "inertia.ixx", "call"),
        ({"joint": "revolute", "mass": 1, "friction": {"stiction": 1}}, "friction.stiction", "unknown"),
        ({"joint": "revolute", "mass": 1, "motor": {"ratio": 5}}, "motor.ratio", "gear_ratio"),
        ({"joint": "revolute", "mass": 1, "friction": {"coulomb": "-c"}}, "friction.coulomb", None),
        ({"joint": "revolute", "mass": None}, "mass", "null"),
        ({"joint": 1, "mass": 1}, "joint", "'revolute' or 'prismatic'"),
        ({"joint": "revolute", "mass": "m", "theta": "q2"}, "theta", "joint symbols"),
        ({"joint": "revolute", "mass": 1, "limits": 1.5}, "limits", "expected [lower, upper]"),
        ({"joint": "revolute", "mass": 1, "limits": [0, 1, 2]}, "limits", "got 3 entries"),
        ({"joint": "revolute", "mass": 1, "limits": {"lower": 0}}, "limits", "got a mapping"),
        ({"joint": "revolute", "mass": 1, "limits": ["x.y", 1]}, "limits.lower", "attribute"),
        ({"joint": "revolute", "mass": 1, "limits": [0, "qmax"]}, "limits", "without a value (qmax)"),
        ({"joint": "prismatic", "mass": 1, "limits": [0.2, 0.2]}, "limits", "below the upper limit"),
        ({"joint": "revolute", "mass": 1, "limits": ["c", "c/2"]}, "limits", "0.5 must be below"),  # c = 0.5
        ({"joint": "revolute", "mass": 1, "limit": [0, 1]}, "limit", "did you mean 'limits'"),
    ],
)
def test_link_field_errors_through_the_api(link, field, words):
    data = {
        "name": "api",
        "parameters": {"c": 0.5},
        "links": [{"name": "first", "joint": "revolute", "mass": 1}, {"name": "second", **link}],
    }
    with pytest.raises(SymdynError) as info:
        robot_from_data(data, source="api.yaml")
    err = info.value
    assert (err.file, err.link_index, err.link_name, err.field) == ("api.yaml", 2, "second", field)
    if words:
        assert words in str(err)


@pytest.mark.parametrize(
    "data, field",
    [
        ({"name": "a", "links": "x"}, "links"),
        ({"name": "a", "links": [1]}, None),
        ({"name": "a", "links": [{"joint": "revolute", "mass": 1}], "gravity": [0, 0, "pi()"]}, "gravity.z"),
        ({"name": "a", "links": [{"joint": "revolute", "mass": 1}], "parameters": [1]}, "parameters"),
        (
            {"name": "a", "links": [{"joint": "revolute", "mass": 1}], "parameters": {"m": [1]}},
            "parameters.m",
        ),
        (
            {"name": "a", "links": [{"joint": "revolute", "mass": 1}], "parameters": {"2x": 1}},
            "parameters.2x",
        ),
        (
            {"name": "a", "links": [{"joint": "revolute", "mass": 1}], "parameters": {"m": "x."}},
            "parameters.m",
        ),
        ({"name": 5, "links": [{"joint": "revolute", "mass": 1}]}, "name"),
        ({"name": "__arm", "links": [{"joint": "revolute", "mass": 1}]}, "name"),
    ],
)
def test_document_errors_through_the_api(data, field):
    with pytest.raises(SymdynError) as info:
        robot_from_data(data, source="doc.yaml")
    assert info.value.file == "doc.yaml"
    assert info.value.field == field


def test_symbolic_values_are_checked_after_substitution():
    data = {
        "name": "a",
        "parameters": {"m": "2 - k", "k": 3},
        "links": [{"name": "l", "joint": "revolute", "mass": "m"}],
    }
    with pytest.raises(SymdynError, match="negative") as info:
        robot_from_data(data)
    assert (info.value.link_index, info.value.field) == (1, "mass")
    data["parameters"]["k"] = None  # symbolic: cannot be judged, so accepted
    assert robot_from_data(data).params == (sp.Symbol("k"),)


# ------------------------------------------------------------------ joint ranges

RANGED = """\
name: ranged
convention: CONVENTION
parameters:
  qmax: 3*pi/4
links:
  - {name: a, joint: revolute, mass: 1, inertia: {ixx: 1, iyy: 1, izz: 1}, limits: [-pi/2, pi/2]}
  - {name: b, joint: prismatic, mass: 1, limits: [0, 0.25]}
  - {name: c, joint: revolute, mass: 1, limits: [-qmax, qmax]}
  - {name: d, joint: revolute, mass: 1, limits: null}
  - {name: e, joint: revolute, mass: 1}
"""


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_limits_are_kept_as_written_and_resolve_to_numbers(tmp_path, convention):
    path = tmp_path / "ranged.yaml"
    path.write_text(RANGED.replace("CONVENTION", convention))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = load_robot(path)
    qmax = sp.Symbol("qmax")
    assert [lk.limits for lk in robot.links] == [
        (-sp.pi / 2, sp.pi / 2),
        (0, sp.Float("0.25")),
        (-qmax, qmax),
        None,
        None,
    ]
    assert robot.params == ()  # qmax has a value
    assert robot.resolved().links[2].limits == (-3 * sp.pi / 4, 3 * sp.pi / 4)
    assert robot.joint_ranges() == (
        (-math.pi / 2, math.pi / 2),
        (0.0, 0.25),
        (-3 * math.pi / 4, 3 * math.pi / 4),
        None,
        None,
    )
    as_json = tmp_path / "ranged.json"
    as_json.write_text(json.dumps(yaml.safe_load(path.read_text())))
    assert load_robot(as_json).links == robot.links
    table = repr(robot).splitlines()
    assert table[1].split(" | ")[-1].strip() == "limits"
    assert [row.split(" | ")[-1].strip() for row in table[3:]] == [
        "[-1.571, 1.571]",  # numbers with 4 significant digits, as every number in the table
        "[0, 0.25]",
        "[-qmax, qmax]",
        "-",
        "-",
    ]


def test_a_robot_without_limits_prints_no_limits_column():
    robot = _load("base_arm.yaml")
    assert all(lk.limits is None for lk in robot.links)
    assert "limits" not in repr(robot)


def test_limits_with_a_free_parameter_are_refused_naming_it():
    data = {"name": "a", "links": [{"name": "l", "joint": "revolute", "mass": 1, "limits": [0, "qmax"]}]}
    with pytest.raises(SymdynError, match=r"names parameters without a value \(qmax\)") as info:
        robot_from_data(data, source="a.yaml")
    assert (info.value.file, info.value.link_index, info.value.field) == ("a.yaml", 1, "limits")
    data["parameters"] = {"qmax": "2*pi/3"}
    ((lo, hi),) = robot_from_data(data).joint_ranges()
    assert lo == 0 and hi == pytest.approx(2 * math.pi / 3, rel=1e-15)


# ------------------------------------------------------------------ warnings


def test_triangle_inequality_warns_with_the_location():
    path = GOOD / "warn_triangle.yaml"
    with pytest.warns(SymdynWarning, match="triangle") as record:
        robot = load_robot(path)
    assert robot.n == 1
    assert any(f"{path}: link 1 (plate)" in str(w.message) for w in record)


def test_zero_mass_with_inertia_warns_with_the_location():
    path = GOOD / "warn_zero_mass.yaml"
    with pytest.warns(SymdynWarning, match="mass is zero") as record:
        robot = load_robot(path)
    assert robot.links[0].mass == 0
    assert any(f"{path}: link 1 (base)" in str(w.message) for w in record)


# ------------------------------------------------------------------ decimal angles

PUMA = Path(__file__).resolve().parents[1] / "examples" / "puma560.yaml"
#: The PUMA 560's exact angles as a Python or MATLAB user writes them.
DECIMAL = {"pi/2": math.pi / 2, "-pi/2": -math.pi / 2, 0: 0.0}


def _loaded(path):
    """The robot of a file and the messages of every warning it gave, with the path left out."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(path)
    return robot, [str(w.message).replace(str(path), "FILE") for w in caught]


def test_puma560_with_decimal_angles_is_the_pi_over_2_robot(tmp_path):
    """Every alpha and theta written as a double: the same links, op counts and dynamics as pi/2."""
    data = yaml.safe_load(PUMA.read_text())
    for link in data["links"]:
        for key in ("alpha", "theta"):
            link[key] = DECIMAL[link[key]]
    path = tmp_path / "puma560_decimal.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    text = path.read_text()
    assert text.count("alpha: 1.5707963267948966") == 2 and text.count("alpha: -1.5707963267948966") == 2
    assert text.count("theta: 0.0") == 6 and "pi" not in text

    exact, exact_warnings = _loaded(PUMA)
    decimal, decimal_warnings = _loaded(path)
    assert decimal_warnings == exact_warnings  # the file's inertia warnings only, no angle warning
    assert decimal.links == exact.links

    assert exact == example("puma560")  # whose context the session caches (robots.example_context)
    ops = {f.name: f.ops for f in example_context("puma560").functions}
    assert ops["inverse_dynamics"].total == 434  # the count in generated/puma560/puma560_dynamics.h
    decimal_functions = symdyn.codegen.context(decimal).functions
    assert {f.name: f.ops for f in decimal_functions} == ops
    assert {"inverse_dynamics", "mass_matrix", "forward_dynamics", "regressor", "linearize"} <= set(ops)

    # the decimal robot's generated functions against the oracle on the pi/2 robot
    plant = CompiledDynamics(decimal)
    rng = np.random.default_rng(560)
    q, qd, qdd, tau = rng.uniform(-2.0, 2.0, (4, 16, 6))
    scale = {"atol": 1e-9, "rtol": 1e-9}
    np.testing.assert_allclose(plant.inverse_dynamics(q, qd, qdd), rn.rnea(exact, q, qd, qdd), **scale)
    np.testing.assert_allclose(plant.mass_matrix(q), rn.mass_matrix(exact, q), **scale)
    np.testing.assert_allclose(plant.coriolis(q, qd), rn.bias_torque(exact, q, qd), **scale)
    np.testing.assert_allclose(plant.gravity(q), rn.gravity_torque(exact, q), **scale)
    np.testing.assert_allclose(plant.friction(qd), rn.friction_torque(exact, qd), **scale)
    np.testing.assert_allclose(
        plant.forward_dynamics(q, qd, tau), rn.forward_dynamics(exact, q, qd, tau), **scale
    )
    C = plant.module.coriolis_matrix(q, qd, None)  # C qd = V
    np.testing.assert_allclose(np.einsum("nij,nj->ni", C, qd), rn.bias_torque(exact, q, qd), **scale)


def _one_link(**row) -> dict:
    link = {"name": "upper", "joint": "revolute", "a": 0.4318, "alpha": 0, "d": 0, "theta": 0, "mass": 1}
    link.update(row)
    return {"name": "arm", "links": [{"name": "base", "joint": "revolute", "mass": 1}, link]}


@pytest.mark.parametrize(
    "field, row, multiple",
    [
        ("alpha", {"alpha": 1.5708}, "pi/2"),
        ("alpha", {"alpha": "-1.5708"}, "-pi/2"),
        ("theta", {"theta": 3.1416}, "pi"),
        ("theta", {"joint": "prismatic", "theta": -4.7124}, "-3*pi/2"),
    ],
)
def test_a_printed_right_angle_warns_once_and_is_kept(tmp_path, field, row, multiple):
    path = tmp_path / "printed.yaml"
    path.write_text(yaml.safe_dump(_one_link(**row)))
    with pytest.warns(SymdynWarning) as record:
        robot = load_robot(path)
    (message,) = [str(w.message) for w in record]
    assert message.startswith(f"{path}: link 2 (upper): field '{field}': ")
    assert f"write {multiple} if {multiple} is meant" in message
    written = sp.Float(float(row[field]))
    link = robot.links[1]
    if field == "alpha":  # standard DH: frame = Tx(a) Rx(alpha)
        assert link.frame.R == Transform.rx(written).R
        assert link.frame.R[1, 1] == sp.cos(written) != 0
    else:  # placement = Rz(theta) Tz(d) after the previous frame
        assert link.placement.R == (robot.links[0].frame @ Transform.rz(written)).R


@pytest.mark.parametrize(
    "offset, exact",
    [(0.99e-9, True), (-0.99e-9, True), (1.01e-9, False), (-1.01e-9, False)],
)
def test_dh_angles_snap_within_1e9_and_not_beyond(offset, exact):
    alpha = -math.pi / 2 + offset
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = robot_from_data(_one_link(alpha=alpha), "edge")
    assert len(caught) == (0 if exact else 1)
    rotation = robot.links[1].frame.R
    assert rotation == Transform.rx(-sp.pi / 2 if exact else sp.Float(alpha)).R
    assert (rotation[1, 1] == 0) is exact


def test_negative_multiples_and_multiples_beyond_two_pi_are_exact():
    data = _one_link(alpha=-3 * math.pi / 2, theta=5 * math.pi / 2)
    data["links"][0].update(alpha=-4 * math.pi, theta=-13 * math.pi / 2)
    robot = _load_data(data)
    base, upper = robot.links
    assert base.frame.R == Transform.rx(-4 * sp.pi).R == sp.eye(3)
    assert base.placement.R == Transform.rz(-13 * sp.pi / 2).R
    assert upper.frame.R == Transform.rx(-3 * sp.pi / 2).R
    assert upper.placement.R == (base.frame @ Transform.rz(5 * sp.pi / 2)).R
    assert all(x.is_Integer for T in (base.frame, upper.frame, upper.placement) for x in T.R)


def test_lengths_and_masses_are_never_rounded():
    """A length or mass equal to pi/2 as a double, or printed like 1.5708, stays as written."""
    data = _one_link(a=math.pi / 2, d=1.5708, mass=1.5707963267948966)
    data["links"][0].update(a=0.4318, d=3.141592653589793, mass=3.1416)
    robot = _load_data(data)
    base, upper = robot.links
    assert upper.frame.p[0] == sp.Float(math.pi / 2) and upper.frame.p[0].is_Float
    assert upper.placement.p[2] == sp.Float(1.5708)
    assert upper.mass == sp.Float(1.5707963267948966) and base.mass == sp.Float(3.1416)
    assert base.frame.p[0] == sp.Float(0.4318)
    assert base.placement.p[2] == sp.Float(3.141592653589793)


def _load_data(data):
    """robot_from_data; any warning is a failure."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return robot_from_data(data, "data")


def test_direction_dependent_coulomb_friction_is_read_as_written():
    """coulomb: [c_plus, c_minus] keeps both magnitudes, expressions included; one number stays
    symmetric (no second magnitude); the order of first appearance covers the list's names."""
    data = yaml.safe_load((GOOD / "asymmetric_friction.yaml").read_text())
    robot = _load("asymmetric_friction.yaml")
    f1, f2, f3 = (link.friction for link in robot.links)
    want = data["links"][0]["friction"]
    assert (f1.viscous, f1.coulomb, f1.coulomb_minus) == (
        sp.Float(want["viscous"]),
        sp.Float(want["coulomb"][0]),
        sp.Float(want["coulomb"][1]),
    )
    assert f1.asymmetric and f3.asymmetric and not f2.asymmetric
    assert (f2.coulomb, f2.coulomb_minus) == (sp.Float(0.3), None)
    assert (f3.viscous, f3.coulomb, f3.coulomb_minus) == sp.symbols("b3 cp3 cm3")
    assert robot.params == sp.symbols("m3 b3 cp3 cm3")


def test_a_negative_coulomb_magnitude_from_a_parameter_value_is_refused():
    data = yaml.safe_load((GOOD / "asymmetric_friction.yaml").read_text())
    data["parameters"] = {"cm3": "-2*cp3", "cp3": 0.1}
    with pytest.raises(SymdynError) as info:
        robot_from_data(data, "arm.yaml")
    err = info.value
    assert (err.link_index, err.link_name, err.field) == (3, "wrist", "friction.coulomb.minus")
    assert "must not be negative (got -0.2)" in str(err) and "\n" not in str(err)


# -- hostile input: powers completed by parameter values, constant angles (issue 21)


@pytest.mark.parametrize(
    "parameters, mass, message",
    [
        ({}, "((((x+1)**64)**64)**64)", r"field 'mass': exponent 262144 of '\(x \+ 1\)\*\*262144'"),
        ({"x": 3}, "(((((x**64)**64)**64)**64)**64)", "field 'mass': exponent 1073741824"),
        ({"e": "9**9"}, "m*b**e", r"field 'mass': exponent 387420489 in 'b\*\*e' is larger than 64"),
        (
            {"a1": 3, "a2": "a1**64", "a3": "a2**64"},
            "a3",
            r"field 'parameters.a3': number 'a2\*\*64' is too large",
        ),
        ({"a1": "y**8", "a2": "a1**8", "a3": "a2**8"}, "a3", r"field 'parameters.a3': exponent 512"),
    ],
)
def test_powers_merged_or_completed_by_values_are_refused_quickly(
    tmp_path, capsys, parameters, mass, message
):
    """The command exits 1 with one line within 10 s (before: it hung in SymPy)."""
    data = _one_link(mass=mass)
    data["parameters"] = parameters
    path = tmp_path / "tower.yaml"
    path.write_text(yaml.safe_dump(data))
    line = refused(capsys, "derive", path)
    assert re.search(message, line), line


def test_an_angle_that_a_parameter_makes_constant_is_evaluated_to_a_double():
    """alpha: x with x: pi*pi/4 is used as the double nearest to pi**2/4, like alpha: pi/2*pi/2."""
    data = _one_link(alpha="x")
    data["parameters"] = {"x": "pi*pi/4"}
    via_parameter = robot_from_data(data, "data")
    written = robot_from_data(_one_link(alpha=2.4674011002723395), "data")
    assert via_parameter.links[1].frame.R == written.links[1].frame.R
    assert not via_parameter.resolved().links[1].frame.R.has(sp.pi)
