"""MJCF (MuJoCo XML) input, with MuJoCo itself as the oracle (`mujoco` in the test extra).

Each file of tests/data/mjcf exercises one feature of the format (docs/mjcf.md); symdyn's model of
it (symdyn.load_mjcf) is compared with MuJoCo's compiled model of the same file at random states:
tau against mj_inverse's qfrc_inverse (M qdd + bias - passive forces: gravity, Coriolis and the
joint damping, with data.qvel set) and M against mj_fullM (armature on the diagonal). MuJoCo's
frictionloss is a constraint (its force comes out of the constraint solver, bounded by the
frictionloss, not c sign(qd)), so the MuJoCo side runs with its constraints disabled (joint limits
too, which random states violate) and symdyn's Coulomb term is left out. Sites are compared
with MuJoCo's site_xpos/site_xmat.
Example-robot-data URDFs converted to MJCF by MuJoCo itself (meshes stripped, saved with
mj_saveLastXML) are compared with symdyn's URDF loader and Pinocchio on the original URDF.
"""

from __future__ import annotations

import re
import sys
import tempfile
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import hypothesis
import numpy as np
import pytest
import sympy as sp
from hypothesis import strategies as st

import symdyn
from symdyn import SymdynError
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import forward_kinematics, mass_matrix
from tests.robots import assert_close, ev
from tests.timebound import refused, within

mujoco = pytest.importorskip("mujoco", reason="the test extra installs mujoco")

DATA = Path(__file__).resolve().parent / "data" / "mjcf"
FEATURES = (
    "defaults",
    "euler_degrees",
    "orientations",
    "fullinertia",
    "geom_inertia",
    "friction",
    "tree",
    "slide",
    "sites",
    "include/included",
)
TOL = 1e-12


def _mujoco(path: Path):
    """MuJoCo's model of the file without constraints: frictionloss (see the module docstring)
    and joint limits, which random states violate, are MuJoCo's constraints."""
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    return model, mujoco.MjData(model)


def _mujoco_dynamics(model, data, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
    """(qfrc_inverse, M) of MuJoCo at one state."""
    data.qpos[:], data.qvel[:], data.qacc[:] = q, qd, qdd
    mujoco.mj_inverse(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    return data.qfrc_inverse.copy(), M


def _states(n: int, count: int = 3, seed: int = 0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield rng.uniform(-1.5, 1.5, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)


def _without_coulomb(robot, q, qd, qdd) -> np.ndarray:
    """symdyn's tau with the viscous friction but not the Coulomb term."""
    viscous = np.array([float(link.friction.viscous) for link in robot.links])
    return symdyn.rnea(robot, q, qd, qdd, friction=False) + viscous * qd


@pytest.mark.parametrize("name", FEATURES)
def test_rnea_and_mass_matrix_agree_with_mujoco(name):
    path = DATA / f"{name}.xml"
    robot = symdyn.load_mjcf(path)
    model, data = _mujoco(path)
    assert robot.n == model.nv
    for q, qd, qdd in _states(robot.n):
        tau, M = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(_without_coulomb(robot, q, qd, qdd), tau, TOL, f"{name}: tau")
        assert_close(mass_matrix(robot, q), M, TOL, f"{name}: M")


def _agrees_with_mujoco(name: str, tau_of, M_of, seed: int) -> None:
    """tau_of(q, qd, qdd) (with its Coulomb term, taken off here) and M_of(q) against MuJoCo."""
    path = DATA / f"{name}.xml"
    robot = symdyn.load_mjcf(path)
    model, data = _mujoco(path)
    coulomb = np.array([float(link.friction.coulomb) for link in robot.links])
    for q, qd, qdd in _states(robot.n, 2, seed=seed):
        tau, M = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(tau_of(q, qd, qdd) - coulomb * np.sign(qd), tau, TOL, f"{name}: tau")
        assert_close(M_of(q), M, TOL, f"{name}: M")


@pytest.mark.parametrize("name", ["friction", "tree", "slide"])
def test_the_derivation_agrees_with_mujoco(name):
    dyn = symdyn.derive(symdyn.load_mjcf(DATA / f"{name}.xml"))
    _agrees_with_mujoco(name, lambda q, qd, qdd: ev(dyn, "tau", q, qd, qdd), lambda q: ev(dyn, "M", q), 1)


def test_generated_c_agrees_with_mujoco():
    plant = symdyn.compile(symdyn.load_mjcf(DATA / "friction.xml"))
    _agrees_with_mujoco("friction", plant.inverse_dynamics, plant.mass_matrix, 2)


def test_the_mapping_of_joint_fields():
    robot = symdyn.load_mjcf(DATA / "friction.xml")
    assert [link.joint for link in robot.links] == ["revolute", "revolute", "prismatic"]
    assert [link.motor.inertia for link in robot.links] == [sp.Float(0.12), sp.Float(0.04), sp.Float(0.5)]
    assert [link.motor.gear_ratio for link in robot.links] == [1, 1, 1]
    assert [link.friction.viscous for link in robot.links] == [sp.Float(0.8), sp.Float(0.25), 2]
    assert [link.friction.coulomb for link in robot.links] == [sp.Float(0.3), sp.Float(0.1), 0]
    assert robot.gravity == sp.ImmutableMatrix([0, 0, -9.81])
    assert symdyn.load_mjcf(DATA / "tree.xml").gravity == sp.ImmutableMatrix([0, -2, -9.81])
    limited = symdyn.load_mjcf(DATA / "euler_degrees.xml").links[1].limits
    assert limited == (sp.Float(-90 * np.pi / 180), sp.Float(120 * np.pi / 180))  # degrees -> rad


def test_disabled_flags_drop_their_terms(tmp_path):
    path = tmp_path / "flags.xml"
    flags = '<option><flag gravity="disable" damper="disable" constraint="disable"/></option>'
    path.write_text((DATA / "friction.xml").read_text().replace("<worldbody>", flags + "<worldbody>"))
    robot = symdyn.load_mjcf(path)
    assert robot.gravity == sp.ImmutableMatrix([0, 0, 0])
    assert all(link.friction.viscous == 0 and link.friction.coulomb == 0 for link in robot.links)
    assert [link.motor.inertia for link in robot.links] == [sp.Float(0.12), sp.Float(0.04), sp.Float(0.5)]


def test_right_angles_in_degrees_become_exact():
    """euler="90 0 -90" (degrees, compiled to a quaternion of doubles) gives exact 0 and +-1."""
    robot = symdyn.load_mjcf(DATA / "euler_degrees.xml")
    R = robot.links[0].placement.R
    assert all(x in (0, 1, -1) for x in R)
    assert sp.ImmutableMatrix([[0, 0, -1], [1, 0, 0], [0, -1, 0]]) == R  # zyx: Rz(90) Ry(0) Rx(-90)


def test_names_tree_and_merged_bodies():
    robot = symdyn.load_mjcf(DATA / "tree.xml")
    names = [link.name for link in robot.links]
    assert names == ["torso", "left_pitch", "left", "left_hand", "right"]
    assert robot.parents == (-1, 0, 1, 2, 0)
    assert robot.links[0].mass == 5  # the welded head merged into the torso
    assert [f.name for f in robot.frames] == ["head"]
    assert robot.links[1].mass == 0  # the first joint of a body with two joints: massless


def test_sites_agree_with_mujoco():
    path = DATA / "sites.xml"
    robot = symdyn.load_mjcf(path)
    model, data = _mujoco(path)
    for q, _, _ in _states(robot.n):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        poses = forward_kinematics(robot, q)
        for s in range(model.nsite):
            frame = robot.frame(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, s))
            T = np.array(frame.placement.matrix(), dtype=float)
            if frame.link >= 0:
                T = poses[frame.link] @ T
            assert_close(T[:3, 3], data.site_xpos[s], TOL, frame.name)
            assert_close(T[:3, :3].ravel(), data.site_xmat[s], TOL, frame.name)


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("bad_ball", "field 'joint(shoulder).type': body 'l1', joint 'shoulder' is a ball joint"),
        (
            "bad_free",
            "field 'joint(other).type': free joints 'root', 'other': symdyn models one floating base",
        ),
        (
            "bad_include",
            "MuJoCo's compiler refused it: XML Error: Error opening file 'no_such_file.xml'; "
            "Element 'include', line 2",
        ),
        (
            "bad_attribute",
            "MuJoCo's compiler refused it: XML Error: Schema violation: unrecognized attribute: 'axiz'; "
            "Element 'joint', line 4",
        ),
        (
            "bad_number",
            "joint 'j': damping 1e+200 is not a finite number of at most 1e+150 in absolute value",
        ),
    ],
)
def test_bad_files_are_one_line_errors(capsys, name, message):
    path = DATA / f"{name}.xml"
    line = refused(capsys, "derive", path)
    assert line.startswith(f"symdyn: error: {path}: {message}"), line


def test_ignored_forces_are_warned_about(tmp_path):
    path = tmp_path / "gravcomp.xml"
    path.write_text(
        '<mujoco><worldbody><body name="b" gravcomp="1"><joint name="j"/>'
        '<geom size="0.1" pos="0.1 0 0"/></body></worldbody></mujoco>'
    )
    with pytest.warns(symdyn.SymdynWarning, match="the gravity compensation of body 'b' is ignored"):
        symdyn.load_mjcf(path)


def test_mujocos_own_warnings_become_symdyn_warnings_once_the_model_passes(tmp_path, capfd, monkeypatch):
    """MuJoCo prints its warnings itself (to the process's stderr): they become SymdynWarnings,
    said once symdyn's checks of the model pass. A negative armature makes MuJoCo warn of a
    singular M while compiling: the file is refused in its one line, the warning held back. (A
    warning of a model that passes: one of the compiling child's answers, given one.)"""
    from symdyn.parsers import mjcf_compile

    path = tmp_path / "negative.xml"
    path.write_text((DATA / "bad_number.xml").read_text().replace('damping="1e200"', 'armature="-5"'))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(
            SymdynError, match=r"field 'joint\(j\).armature': must not be negative \(got -5\)"
        ):
            symdyn.load_mjcf(path)
    assert capfd.readouterr() == ("", "")
    request = mjcf_compile._SERVER.request

    def warned(*args):
        answer, mjb = request(*args)
        return {**answer, "warnings": ["Inertia matrix is too close\nto singular"]}, mjb

    monkeypatch.setattr(mjcf_compile._SERVER, "request", warned)
    with pytest.warns(
        symdyn.SymdynWarning, match=r"tree.xml: MuJoCo: Inertia matrix is too close; to singular$"
    ):
        assert symdyn.load_mjcf(DATA / "tree.xml").n


def test_a_nan_is_refused_before_mujoco_reads_it(tmp_path, capfd):
    path = tmp_path / "nan.xml"
    path.write_text((DATA / "bad_number.xml").read_text().replace("1e200", "nan"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning of MuJoCo's: it never saw the file
        with pytest.raises(SymdynError, match=r"field 'joint\(j\).damping': line 4: 'nan' is not a finite"):
            symdyn.load_mjcf(path)
    assert capfd.readouterr() == ("", "")


def test_a_missing_mujoco_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "mujoco", None)  # `import mujoco` raises ImportError
    with pytest.raises(SymdynError, match=r"needs the Python package 'mujoco'.*pip install 'symdyn\[mjcf\]'"):
        symdyn.load_mjcf(DATA / "slide.xml")


# ------------------------------------------------------------ example-robot-data through MuJoCo

ROBOTS = example_robot_data_folder()
CONVERTED = (
    "panda_description/urdf/panda.urdf",
    "ur_description/urdf/ur5_robot.urdf",
    "solo_description/robots/solo12.urdf",
)
#: mj_saveLastXML writes 6 significant digits: positions, quaternions, masses and inertias rounded
#: at 5e-6 relative, which the dynamics show as relative errors of a few 1e-6
SAVED_TOL = 2e-5


def _stripped(urdf: Path, folder: Path) -> Path:
    """The URDF without <visual>, <collision> (meshes) and <mimic> (MuJoCo ignores mimic joints)."""
    root = ET.parse(urdf).getroot()
    for parent in root.iter():
        for child in list(parent):
            if child.tag in ("visual", "collision", "mimic"):
                parent.remove(child)
    out = folder / urdf.name
    out.write_text(ET.tostring(root, encoding="unicode"))
    return out


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
@pytest.mark.parametrize("rel", CONVERTED)
def test_urdfs_converted_by_mujoco(tmp_path, rel):
    urdf = _stripped(ROBOTS / rel, tmp_path)
    model = mujoco.MjModel.from_xml_string(urdf.read_text())
    saved = tmp_path / "saved.xml"
    mujoco.mj_saveLastXML(str(saved), model)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", symdyn.SymdynWarning)  # the published data's own oddities
        robot = symdyn.load_mjcf(saved)
        original = symdyn.load_urdf(urdf)
    names = [link.name for link in original.links]
    assert sorted(link.name for link in robot.links) == sorted(names)
    order = [[link.name for link in robot.links].index(n) for n in names]  # MJCF index of each URDF link
    saved_model, saved_data = _mujoco(saved)
    pin = pytest.importorskip("pinocchio")
    pmodel = pin.buildModelFromUrdf(str(urdf))
    pdata = pmodel.createData()
    pin_order = [pmodel.getJointId(n) - 1 for n in _joints_by_child(urdf, names)]
    for q, qd, qdd in _states(robot.n):
        qm, qdm, qddm = (np.empty_like(x) for x in (q, qd, qdd))
        qm[order], qdm[order], qddm[order] = q, qd, qdd
        # the MJCF reader against MuJoCo on the same saved file: to double precision
        tau, M = _mujoco_dynamics(saved_model, saved_data, qm, qdm, qddm)
        tau_mjcf = _without_coulomb(robot, qm, qdm, qddm)
        M_mjcf = mass_matrix(robot, qm)
        assert_close(tau_mjcf, tau, TOL, f"{rel}: tau against MuJoCo")
        assert_close(M_mjcf, M, TOL, f"{rel}: M against MuJoCo")
        # the saved MJCF against the original URDF (symdyn and Pinocchio): to the saved digits
        want = symdyn.rnea(original, q, qd, qdd, friction=False)
        assert_close(symdyn.rnea(robot, qm, qdm, qddm, friction=False)[order], want, SAVED_TOL, rel)
        assert_close(M_mjcf[np.ix_(order, order)], mass_matrix(original, q), SAVED_TOL, rel)
        qp, vp, ap = (np.empty_like(x) for x in (q, qd, qdd))
        qp[pin_order], vp[pin_order], ap[pin_order] = q, qd, qdd
        tau_pin = pin.rnea(pmodel, pdata, qp, vp, ap)[pin_order]
        assert_close(want, tau_pin, 1e-9, f"{rel}: symdyn's URDF against Pinocchio")


def _joints_by_child(urdf: Path, links: list[str]) -> list[str]:
    """The URDF joint whose child is each of `links`."""
    by_child = {j.find("child").get("link"): j.get("name") for j in ET.parse(urdf).getroot().findall("joint")}
    return [by_child[name] for name in links]


#: MuJoCo's compiler allocates what a file asks: four nested <replicate count="100"> make 10^8
#: geoms (10^8 bodies symdyn counts before compiling: symdyn.parsers.mjcf_compile._count_tags), time
#: or memory running out first, as the machine goes; a 10^5 x 10^5 hfield and a 2000^3 flexcomp
#: grid ask for tens of GiB at once
_BOMBS = {
    "replicate": "<worldbody>"
    + "".join(f'<replicate count="100" offset="{d}">' for d in ("0.1 0 0", "0 0.1 0", "0 0 0.1", "0.1 0.1 0"))
    + '<geom size="0.1"/>'
    + "</replicate>" * 4
    + "</worldbody>",
    "hfield": '<asset><hfield name="h" nrow="100000" ncol="100000" size="1 1 1 1"/></asset>'
    '<worldbody><geom type="hfield" hfield="h"/><body><joint/><geom size="0.1"/></body></worldbody>',
    "flexcomp": '<worldbody><flexcomp name="f" type="grid" count="2000 2000 2000" spacing="0.1 0.1 0.1" '
    'dim="3"><edge equality="false"/></flexcomp><body><joint/><geom size="0.1"/></body></worldbody>',
}


@pytest.mark.parametrize(
    ("bomb", "limit"),
    [
        ("replicate", "more than (3 s|1 GiB of memory)"),
        ("hfield", "more than 1 GiB of memory"),
        ("flexcomp", "more than 1 GiB"),
    ],
)
def test_the_compiler_is_bounded(capsys, tmp_path, monkeypatch, bomb, limit):
    """The compiler runs in a contained child (symdyn.parsers.contained) of at most MEMORY bytes
    and TIMEOUT s: here lowered to 1 GiB and 3 s so that the test takes seconds."""
    from symdyn.parsers import mjcf_compile

    monkeypatch.setattr(mjcf_compile, "TIMEOUT", 3)
    monkeypatch.setattr(mjcf_compile, "MEMORY", 2**30)
    path = tmp_path / f"{bomb}.xml"
    path.write_text(f"<mujoco>{_BOMBS[bomb]}</mujoco>")
    line = refused(capsys, "derive", path, seconds=20)
    assert re.fullmatch(f"symdyn: error: {re.escape(str(path))}: MuJoCo's compiler needed {limit}.*", line), (
        line
    )
    assert symdyn.load_mjcf(DATA / "tree.xml").name  # and the next file compiles as before


# ------------------------------------------------------------ numbers MuJoCo would take or lose

TWO = """<mujoco model="two">
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="a">
      <joint name="j1" axis="0 1 0" damping="0.2" armature="0.1"/>
      <geom size="0.05" pos="0.2 0 0" mass="1"/>
      <body name="b" pos="0.4 0 0">
        <joint name="j2" axis="0 1 0"/>
        <geom size="0.05" pos="0.2 0.1 0" mass="0.5"/>
      </body>
    </body>
  </worldbody>
  TENDON
</mujoco>
"""


def _two(tmp_path: Path, name: str, tendon: str = "", **replace: str) -> Path:
    """The two-hinge arm TWO with `tendon` (a <tendon> element) and the text replacements `replace`."""
    text = TWO.replace("TENDON", tendon)
    for old, new in replace.items():
        assert old.replace("_", " ") in text
        text = text.replace(old.replace("_", " "), new)
    path = tmp_path / f"{name}.xml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("field", ["armature", "damping", "frictionloss"])
def test_negative_joint_coefficients_are_refused_as_in_a_urdf(capsys, tmp_path, field):
    """MuJoCo accepts armature="-1" (its M loses 1 on the diagonal); the URDF loader's message."""
    # (heavy links: with M[0, 0] - 1 < 0 MuJoCo would warn of a singular M first)
    text = TWO.replace("TENDON", "").replace(' armature="0.1"', "").replace('mass="1"', 'mass="100"')
    path = tmp_path / f"{field}.xml"
    path.write_text(text.replace('damping="0.2"', f'{field}="-1"'))
    assert getattr(mujoco.MjModel.from_xml_path(str(path)), f"dof_{field}")[0] == -1  # MuJoCo takes it
    line = refused(capsys, "derive", path)
    # the words of the URDF loader's <dynamics damping="-1"> (tests/test_urdf.py)
    assert line == f"symdyn: error: {path}: field 'joint(j1).{field}': must not be negative (got -1)"


def test_a_negative_tendon_coefficient_is_refused(capsys, tmp_path):
    tendon = '<tendon><fixed name="t" damping="-3"><joint joint="j1" coef="1"/></fixed></tendon>'
    line = refused(capsys, "derive", _two(tmp_path, "t", tendon))
    assert line.endswith("field 'tendon(t).damping': must not be negative (got -3)"), line


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # MuJoCo compiles the nan to 0 (with a warning): the compiled model is a valid one
        ('pos="0.2 0.1 0"', 'pos="nan 0.1 0"', "field 'geom.pos': line 9: 'nan' is not a finite number"),
        ('pos="0.2 0.1 0"', 'pos="0.2 -inf 0"', "field 'geom.pos': line 9: '-inf' is not a finite number"),
        # the squared norm overflows: MuJoCo's axis compiles to (0, 0, 0)
        (
            'axis="0 1 0" damping',
            'axis="1e200 1e200 0" damping',
            "field 'joint(j1).axis': line 5: the direction 1e200 1e200 0 has a squared norm that overflows",
        ),
        (
            '<geom size="0.05" pos="0.2 0 0"',
            '<site name="s" zaxis="1e300 0 0"/><geom size="0.05" pos="0.2 0 0"',
            "field 'site(s).zaxis': line 6: the direction 1e300 0 0 has a squared norm that overflows",
        ),
    ],
)
def test_numbers_mujoco_loses_are_refused(capsys, tmp_path, old, new, message):
    path = _two(tmp_path, "lost")
    path.write_text(path.read_text().replace(old, new))
    line = refused(capsys, "derive", path)
    assert line.startswith(f"symdyn: error: {path}: {message}"), line


def test_what_mujoco_makes_of_the_lost_numbers(tmp_path):
    """Why the XML is read: MuJoCo turns a nan into 0 and an overflowing axis into zero."""
    path = _two(tmp_path, "nan")
    path.write_text(path.read_text().replace('pos="0.2 0.1 0"', 'pos="nan 0.1 0"'))
    model = mujoco.MjModel.from_xml_path(str(path))
    assert np.isfinite(model.body_ipos).all() and model.body_ipos[2, 1] != 0.1
    path.write_text(TWO.replace("TENDON", "").replace('axis="0 1 0" damping', 'axis="1e200 1e200 0" damping'))
    assert mujoco.MjModel.from_xml_path(str(path)).jnt_axis[0].tolist() == [0, 0, 0]


def test_a_nan_in_an_included_file_is_refused(capsys, tmp_path):
    (tmp_path / "arm.xml").write_text(
        '<mujoco><body name="b"><joint name="j"/><geom size="0.1" pos="0.1 nan 0"/></body></mujoco>'
    )
    (tmp_path / "top.xml").write_text('<mujoco><worldbody><include file="arm.xml"/></worldbody></mujoco>')
    line = refused(capsys, "derive", tmp_path / "top.xml")
    assert line.startswith(f"symdyn: error: {tmp_path / 'arm.xml'}: field 'geom.pos': line 1: 'nan'"), line


def test_names_are_not_numbers(tmp_path):
    """A body named 'nan' or 'inf' is a name, not a number."""
    path = _two(tmp_path, "names")
    path.write_text(path.read_text().replace('name="a"', 'name="nan"').replace('name="b"', 'name="inf"'))
    assert [link.name for link in symdyn.load_mjcf(path).links] == ["nan", "inf"]


# ------------------------------------------------------------ tendons and fluid forces


def _mujoco_passive_free(path: Path, flags: str):
    """MuJoCo's model with its constraints and the passive forces `flags` disabled."""
    model, data = _mujoco(path)
    for flag in flags.split():
        model.opt.disableflags |= int(getattr(mujoco.mjtDisableBit, f"mjDSBL_{flag}"))
    return model, data


def test_a_fixed_tendon_over_one_joint_is_folded_into_it(tmp_path):
    """armature a, damping d and frictionloss f on L = c q2: a c^2, d c^2, f |c| on joint 2."""
    tendon = (
        '<tendon><fixed name="t" armature="0.5" damping="3" frictionloss="0.4">'
        '<joint joint="j2" coef="-2"/></fixed></tendon>'
    )
    path = _two(tmp_path, "one", tendon)
    robot = symdyn.load_mjcf(path)
    assert robot.links[1].motor.inertia == 2  # 0.5 * (-2)**2
    assert robot.links[1].friction.viscous == 12  # 3 * (-2)**2
    assert robot.links[1].friction.coulomb == sp.Float(0.8)  # 0.4 * |-2|
    model, data = _mujoco(path)
    for q, qd, qdd in _states(robot.n):
        tau, M = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(_without_coulomb(robot, q, qd, qdd), tau, TOL, "tau")
        assert_close(mass_matrix(robot, q), M, TOL, "M")


# (fixed tendons over several joints and springs are modelled: tests/test_tendons.py)


def test_spatial_tendons_and_fluid_forces_are_warned_about(tmp_path):
    tendon = (
        '<tendon><spatial name="cable" damping="2"><site site="s1"/><site site="s2"/></spatial>'
        '<spatial name="limit"><site site="s1"/><site site="s2"/></spatial></tendon>'
    )
    path = _two(
        tmp_path,
        "spatial",
        tendon,
        **{'<option_gravity="0 0 -9.81"/>': '<option density="1.2" viscosity="0.01"/>'},
    )
    text = path.read_text().replace(
        '<geom size="0.05" pos="0.2 0 0"', '<site name="s1"/><geom size="0.05" pos="0.2 0 0"'
    )
    path.write_text(
        text.replace(
            '<geom size="0.05" pos="0.2 0.1 0"',
            '<site name="s2" pos="0.1 0 0"/><geom size="0.05" pos="0.2 0.1 0"',
        )
    )
    with pytest.warns(symdyn.SymdynWarning) as said:
        symdyn.load_mjcf(path)
    assert [str(w.message).removeprefix(f"{path}: ") for w in said] == [
        "the damping of spatial tendon 'cable' is ignored: symdyn does not model it",
        "the fluid force model of <option density=1.2 viscosity=0.01> is ignored: symdyn does not model it",
    ]


# ------------------------------------------------------------ a site named like a body


def test_a_site_named_like_a_body_is_kept_as_site_name(tmp_path):
    """MuJoCo keeps body and site names apart (stretch_3, fruitfly): the body keeps its name (a
    link 'b', a welded body's frame 'w'), the site's frame is 'site:NAME'; poses from MuJoCo."""
    path = _two(tmp_path, "clash")
    text = path.read_text().replace(
        '<geom size="0.05" pos="0.2 0.1 0" mass="0.5"/>',
        '<geom size="0.05" pos="0.2 0.1 0" mass="0.5"/><site name="b" pos="0.3 0.1 0" euler="0.3 0 0.2"/>'
        '<body name="w" pos="0.1 0 0.2"><geom size="0.05" mass="0.1"/><site name="w" pos="0 0.1 0"/></body>',
    )
    path.write_text(text)
    robot = symdyn.load_mjcf(path)
    assert [link.name for link in robot.links] == ["a", "b"]
    assert [f.name for f in robot.frames] == ["w", "site:b", "site:w"]
    model, data = _mujoco(path)
    for q, _, _ in _states(robot.n):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        poses = forward_kinematics(robot, q)
        for s, name in enumerate(["site:b", "site:w"]):
            frame = robot.frame(name)
            T = poses[frame.link] @ np.array(frame.placement.matrix(), dtype=float)
            assert_close(T[:3, 3], data.site_xpos[s], TOL, name)
            assert_close(T[:3, :3].ravel(), data.site_xmat[s], TOL, name)


# ------------------------------------------------------------ fuzzing the attributes against MuJoCo

#: (the attribute as written in TWO, with a site) -> mutated; values that broke readers before
FUZZ_TEXT = TWO.replace("TENDON", "").replace(
    '<geom size="0.05" pos="0.2 0.1 0" mass="0.5"/>',
    '<geom size="0.05" pos="0.2 0.1 0" mass="0.5"/><site name="s" pos="0.3 0.1 0" euler="0.3 0 0.2"/>',
)
FUZZ_ATTRIBUTES = [m.start() for m in re.finditer(r'"[-0-9. ]+"', FUZZ_TEXT)]
FUZZ_HOSTILE = ["nan", "inf", "-inf", "-1", "1e300", "1e400", "1e-300", "0", "abc", "", "1e149"]
FUZZ_VALUES = FUZZ_HOSTILE + ["2.5", "-0.3", "0.7", "3", "-2", "1e-3", "100", "0.05"]  # and plain ones


@hypothesis.settings(
    max_examples=40,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=list(hypothesis.HealthCheck),
)
@hypothesis.given(
    st.lists(
        st.tuples(st.sampled_from(FUZZ_ATTRIBUTES), st.integers(0, 2), st.sampled_from(FUZZ_VALUES)),
        min_size=1,
        max_size=3,
    )
)
def test_fuzzed_attributes_load_as_mujoco_reads_them_or_are_refused(mutations):
    """Numbers of the attributes of a small MJCF replaced by extreme and garbage values: symdyn
    loads it or refuses it in one line; where it loads, M and tau agree with MuJoCo's."""
    text = FUZZ_TEXT
    for start, token, value in sorted(mutations, reverse=True):
        end = text.index('"', start + 1)
        words = text[start + 1 : end].split()
        words[min(token, len(words) - 1)] = value
        text = text[: start + 1] + " ".join(words) + text[end:]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.xml"
        path.write_text(text)
        with within(10), warnings.catch_warnings():
            warnings.simplefilter("ignore", symdyn.SymdynWarning)
            try:
                robot = symdyn.load_mjcf(path)
            except SymdynError as exc:
                assert "\n" not in str(exc)
                return
        model, data = _mujoco(path)
    assert robot.n == model.nv
    for q, qd, qdd in _states(robot.n, 1, seed=len(text)):
        tau, M = _mujoco_dynamics(model, data, q, qd, qdd)
        assert_close(_without_coulomb(robot, q, qd, qdd), tau, 1e-9, f"tau of\n{text}")
        assert_close(mass_matrix(robot, q), M, 1e-9, f"M of\n{text}")
