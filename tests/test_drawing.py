"""Drawings and animations of robots (symdyn.algorithms.drawing, symdyn.apps.drawing, `symdyn draw`,
`symdyn simulate --animate`).

The frame origins a picture shows are read back from the SVG's data attributes and compared with
the numeric oracle's frames (symdyn.oracle.frames) and with Pinocchio's on URDFs (the Panda, and
Solo-12 on a floating base); a DH robot's parameters read off the picture are the file's rows. The
HTML pages are opened in headless Chromium (one start for the module): no console errors, and the
screenshot shows the robot. Hostile names are escaped everywhere.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import warnings
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path
from urllib.parse import unquote

import numpy as np
import pytest
import sympy as sp
from conftest import IN_CI
from robots import EXAMPLES_DIR, example, raw_example
from timebound import refused, within

import symdyn
from symdyn.algorithms.drawing import scene
from symdyn.apps.drawing import animate, draw
from symdyn.cli import main
from symdyn.errors import SymdynError
from symdyn.oracle.frames import frame_state
from symdyn.regenerate import example_robot_data_folder
from symdyn.spatial.transform import Transform

TOL = 1e-9
SVG = "{http://www.w3.org/2000/svg}"


def _origins(svg: bytes) -> dict[str, tuple[str, np.ndarray]]:
    """frame name -> (kind, origin) read from the SVG's data-frame / data-origin attributes."""
    root = ET.fromstring(svg)
    out = {}
    for g in root.iter(f"{SVG}g"):
        if "data-frame" in g.attrib:
            xyz = np.array([float(x) for x in g.attrib["data-origin"].split()])
            out[g.attrib["data-frame"]] = (g.attrib["data-kind"], xyz)
    return out


def _quiet(load, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(*args, **kwargs)


# --------------------------------------------------------------------------- geometry


@pytest.mark.parametrize(
    "name",
    [
        "puma560",
        "planar_prismatic_modified",
        "mr_ur5",
        "stanford",
        "closed_loops/fourbar",
        "free_floating/free_floating_puma",
    ],
)
def test_every_frame_origin_in_the_svg_is_the_oracle_frame(name):
    path = EXAMPLES_DIR / f"{name}.yaml"
    robot = _quiet(symdyn.load_robot, path)
    rng = np.random.default_rng(3)
    params = rng.uniform(0.5, 1.5, len(robot.params)) if robot.params else None
    q = rng.uniform(-1.2, 1.2, robot.nq)
    joints = q
    base = np.eye(4)
    if robot.floating:  # the base pose from q: position and a unit quaternion
        quat = rng.normal(size=4)
        q[3:7] = quat / np.linalg.norm(quat)
        x, y, z, w = q[3:7]
        base[:3, :3] = sp.matrix2numpy(sp.Quaternion(w, x, y, z).to_rotation_matrix(), dtype=float)
        base[:3, 3] = q[:3]
        joints = q[7:]
    origins = _origins(draw(robot, q, params=params))
    names = [lk.name for lk in robot.links] + [f.name for f in robot.frames]
    assert set(origins) == {"base", *names}
    for f in names:
        want = (base @ frame_state(robot, f, joints, params=params).pose)[:3, 3]
        np.testing.assert_allclose(origins[f][1], want, atol=TOL, rtol=0, err_msg=f)
    assert origins[robot.links[0].name][0] == "link"


def test_an_mjcf_tree_is_drawn_where_the_oracle_puts_its_frames():
    pytest.importorskip("mujoco")
    robot = _quiet(symdyn.load_mjcf, EXAMPLES_DIR.parent / "tests/data/mjcf/tree.xml")
    q = np.random.default_rng(2).uniform(-1, 1, robot.n)
    origins = _origins(draw(robot, q))
    for f in robot.frame_names:
        np.testing.assert_allclose(origins[f][1], frame_state(robot, f, q).pose[:3, 3], atol=TOL, err_msg=f)


def test_the_dh_parameters_on_the_picture_are_the_files_rows():
    """PUMA (standard) and the modified planar arm: a, d, alpha from the file, theta = q + offset."""
    for name in ("puma560", "planar_prismatic_modified"):
        robot, raw = _quiet(example, name), raw_example(name)
        values = {sp.Symbol(k): v for k, v in (raw.get("parameters") or {}).items()}
        q = np.random.default_rng(1).uniform(-1, 1, robot.n)
        rows = scene(robot, q).dh
        assert [r.index for r in rows] == list(range(1, robot.n + 1))
        for row, link, qi in zip(rows, raw["links"], q, strict=True):
            value = lambda k, link=link, values=values: float(sp.sympify(link.get(k, 0)).subs(values))  # noqa: E731
            revolute = link["joint"] == "revolute"
            want = {
                "a": value("a"),
                "alpha": value("alpha"),
                "d": value("d") + (0 if revolute else qi),
                "theta": value("theta") + (qi if revolute else 0),
            }
            for key, v in want.items():
                got = getattr(row, key)
                if key in ("alpha", "theta"):
                    got, v = np.angle(np.exp(1j * got)), np.angle(np.exp(1j * v))
                assert abs(got - v) < 1e-12, (name, row.index, key, got, v)


def _pinocchio():
    pin = pytest.importorskip("pinocchio")
    folder = example_robot_data_folder()
    if folder is None:
        pytest.skip("example-robot-data is not installed")
    return pin, folder


def test_the_panda_urdf_drawn_where_pinocchio_puts_its_frames():
    pin, folder = _pinocchio()
    path = folder / "panda_description/urdf/panda.urdf"
    robot = _quiet(symdyn.load_urdf, path)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    q = np.random.default_rng(5).uniform(-1, 1, robot.n)
    qb = np.array(robot.selection(), dtype=float) @ q
    pin.framesForwardKinematics(model, data, qb)
    origins = _origins(draw(robot, q))
    checked = 0
    for f in model.frames:
        if f.name in origins:
            np.testing.assert_allclose(
                origins[f.name][1], data.oMf[model.getFrameId(f.name)].translation, atol=TOL
            )
            checked += 1
    assert checked >= 10 and "panda_hand" in origins


def test_solo12_floating_drawn_where_pinocchio_puts_its_feet():
    pin, folder = _pinocchio()
    path = folder / "solo_description/robots/solo12.urdf"
    robot = _quiet(symdyn.load_urdf, path, floating=True)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    rng = np.random.default_rng(7)
    q = np.r_[rng.uniform(-1, 1, 3), rng.normal(size=4), rng.uniform(-1, 1, robot.n)]
    q[3:7] /= np.linalg.norm(q[3:7])
    pin.framesForwardKinematics(model, data, q)
    origins = _origins(draw(robot, q))
    for foot in ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT", "base_link"):
        want = data.oMf[model.getFrameId(foot)].translation
        np.testing.assert_allclose(origins[foot][1], want, atol=TOL, err_msg=foot)


def test_a_closed_loop_is_drawn_dashed_and_masses_are_sized():
    robot = _quiet(symdyn.load_robot, EXAMPLES_DIR / "closed_loops/fourbar.yaml")
    s = scene(robot, [0.3, 1.0, 1.5])
    assert [g.kind for g in s.segments].count("loop") == 1
    svg = draw(robot, [0.3, 1.0, 1.5]).decode()
    assert 'stroke-dasharray="6 4"' in svg
    radii = [float(r) for r in re.findall(r'<circle cx="[^"]+" cy="[^"]+" r="([^"]+)" fill="#7f7f7f"', svg)]
    assert len(radii) == 3 and len(set(radii)) == 3  # three different masses, three sizes


def test_contacts_are_drawn_as_frames_of_their_own_style():
    """A robot's contacts (Robot.contacts) are markers of kind contact at their frames' origins: the
    oracle's poses of those frames."""
    from symdyn.model.contacts import Contact

    robot = _quiet(example, "puma560")
    robot = replace(robot, contacts=(Contact("toe", "link2", "point"), Contact("hand", "link6", "6d")))
    q = np.full(6, 0.3)
    origins = _origins(draw(robot, q))
    for name, frame in (("toe", "link2"), ("hand", "link6")):
        assert origins[name][0] == "contact"
        np.testing.assert_allclose(origins[name][1], frame_state(robot, frame, q).pose[:3, 3], atol=TOL)


def test_drawings_are_deterministic_and_every_view_works(tmp_path):
    robot = _quiet(example, "puma560")
    q = np.linspace(-1, 1, 6)
    for view in ("iso", "front", "side", "top"):
        assert draw(robot, q, view=view) == draw(robot, q, view=view)
    png = draw(robot, q, tmp_path / "a.png")
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and png == draw(robot, q, fmt="png")


# --------------------------------------------------------------------------- hostile input

HOSTILE = "</text><script>alert(1)</script>&\"'\x01"


def _hostile_robot():
    """Craig's two-link arm renamed: link, frame and robot names that are markup (a URDF's names
    are any text)."""
    r = _quiet(example, "craig_two_link").numeric({"g": 9.81, "l1": 1, "l2": 0.8, "m1": 1, "m2": 1})
    links = (
        replace(r.links[0], name=HOSTILE),
        replace(r.links[1], name="</script><img src=x onerror=alert(2)>"),
    )
    tip = symdyn.Frame("tip<svg onload=alert(3)>", 1, Transform.from_translation([0.8, 0, 0]))
    return replace(r, name="<b>robot</b>", links=links, frames=(tip,))


def test_hostile_names_are_escaped_in_svg_and_html():
    robot = _hostile_robot()
    svg = draw(robot, [0.2, 0.4])
    root = ET.fromstring(svg)  # well-formed XML, whatever the names hold
    tags = {el.tag for el in root.iter()}
    assert f"{SVG}script" not in tags and not any("img" in t for t in tags)
    assert HOSTILE.replace("\x01", "\ufffd") in _origins(svg)
    html = draw(robot, [0.2, 0.4], fmt="html").decode()
    body = html.split('id="symdyn-data">', 1)[1].split("</script>", 1)[0]
    assert "<" not in body and ">" not in body  # the names cannot close the data element
    assert html.count("<script") == 4  # the error hook, the import map, the data, the page's module
    script = html.split('<script type="module">', 1)[1]  # labels and table cells: textContent only
    html_sinks = r"innerHTML|outerHTML|insertAdjacentHTML|document\.write|createContextualFragment"
    assert not re.search(html_sinks, script)


def test_bad_input_is_refused_in_one_line(tmp_path, capsys):
    robot = _quiet(example, "puma560")
    with within(10):
        for q, what in (([0.1] * 5, "expected (6,)"), ([np.nan] * 6, "not finite"), ("abc", "numbers")):
            with pytest.raises(SymdynError, match=re.escape(what)):
                draw(robot, q)
        with pytest.raises(SymdynError, match="unknown view"):
            draw(robot, None, view="back")
        with pytest.raises(SymdynError, match="quaternion"):
            draw(
                _quiet(symdyn.load_robot, EXAMPLES_DIR / "free_floating/free_floating_puma.yaml"),
                np.zeros(13),
            )
        with pytest.raises(SymdynError, match="suffix"):
            draw(robot, None, tmp_path / "a.jpg")
    puma = str(EXAMPLES_DIR / "planar_3r.yaml")  # 3 joints, loaded without warnings
    refused(capsys, "draw", puma, "--q", "1", "2", "3", "4", "--out", str(tmp_path / "a.svg"))
    refused(capsys, "draw", puma, "--out", str(tmp_path))
    refused(capsys, "draw", puma, "--out", str(tmp_path / "a.pdf"))
    sim = ["simulate", puma, "--duration", "0.1", "--dt", "0.05", "--out", str(tmp_path / "t.csv")]
    refused(capsys, *sim, "--animate", str(tmp_path / "a.mp4"))
    refused(capsys, *sim, "--animate", str(tmp_path / "a.gif"), "--frames", "0")
    refused(capsys, *sim, "--frames", "5")
    assert not (tmp_path / "t.csv").exists() and not (tmp_path / "a.svg").exists()


# --------------------------------------------------------------------------- animations, Chromium


def test_simulate_animates_a_gif_with_the_stated_frame_count(tmp_path, capsys):
    from PIL import Image

    out = tmp_path / "run.gif"
    args = ["simulate", str(EXAMPLES_DIR / "roger_arm_values.yaml"), "--duration", "0.5", "--dt", "0.01"]
    args += ["--tau", "0.1", "--out", str(tmp_path / "t.csv")]
    assert main([*args, "--animate", str(out), "--frames", "7", "--view", "front"]) == 0
    with Image.open(out) as im:
        assert im.n_frames == 7


CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--enable-unsafe-swiftshader",
    "--enable-logging=stderr",
    "--v=0",
    "--virtual-time-budget=4000",
]


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


@pytest.fixture(scope="module")
def browser_run(tmp_path_factory):
    """One Chromium start: a page holding the drawing (HTML of a robot with hostile names) and
    the animation of a simulation (opened at its last step) in two frames side by side; its
    console and screenshot."""
    exe = _chromium()
    if exe is None:
        if IN_CI:
            pytest.fail("chromium is missing (CI installs it: .ci/run)")
        pytest.skip("chromium is not installed")
    folder = tmp_path_factory.mktemp("browser")
    draw(_hostile_robot(), [0.2, 0.4], folder / "draw.html")
    robot = _quiet(example, "puma560")
    t = np.linspace(0, 1, 41)
    animate(robot, t, np.outer(np.sin(2 * t), np.ones(6)), folder / "anim.html", frames=20)
    (folder / "both.html").write_text(
        '<!DOCTYPE html><html><body style="margin:0;background:#fff;overflow:hidden">'
        '<iframe src="draw.html" style="position:absolute;left:0;top:0;border:0;width:980px;height:800px">'
        '</iframe><iframe src="anim.html#step=19" style="position:absolute;left:980px;top:0;border:0;'
        'width:980px;height:800px"></iframe></body></html>'
    )
    shot = folder / "shot.png"
    cmd = [exe, *CHROMIUM_FLAGS, f"--user-data-dir={folder / 'profile'}", "--window-size=1960,800"]
    run = subprocess.run(
        [*cmd, f"--screenshot={shot}", (folder / "both.html").as_uri()],
        capture_output=True,
        text=True,
        timeout=60,
    )
    return run, shot


def test_the_html_pages_open_in_chromium_without_console_errors(browser_run):
    run, _ = browser_run
    console = [line for line in run.stderr.splitlines() if ":CONSOLE" in line]
    drawn = [line for line in console if "symdyn: drawn" in line]
    assert len(drawn) == 2, run.stderr[-3000:]
    noise = ("GL Driver Message", "GPU stall")
    ours = ('"symdyn: drawn ', '"symdyn: labels ')  # the pages' own lines
    errors = [line for line in console if not any(n in line for n in (*ours, *noise))]
    assert not errors, errors


def _shown(run) -> list[dict]:
    """What each page printed it shows as text (page.js, "symdyn: labels"), read from its DOM."""
    found = re.findall(r"symdyn: labels (\S+?)\"", run.stderr)
    return [json.loads(unquote(text)) for text in found]


_DH_TEXT = re.compile(r"([adαθ])(\d+) = (-?[0-9.e+-]+)(°?)")


def _check_dh_labels(page: dict, s) -> None:
    """The page's DH labels and table hold the scene's rows (read back from the frames, checked
    against the file by test_the_dh_parameters_on_the_picture_are_the_files_rows), to the
    figures' 4 digits and 0.1 degree."""
    rows = {r.index: r for r in s.dh}
    dh = [text for kind, _, text in page["labels"] if kind == "label dh"]
    assert len(dh) >= len(rows), dh
    for text in dh:
        match = _DH_TEXT.fullmatch(text)
        assert match, text
        name, i, value, deg = match.groups()
        row = rows[int(i) + (name in "aα" and s.dh[0].convention == "modified")]
        want = {"a": row.a, "d": row.d, "α": row.alpha, "θ": row.theta}[name]
        if deg:
            diff = np.angle(np.exp(1j * (np.radians(float(value)) - want)))
            assert abs(diff) <= np.radians(0.051), (text, want)
        else:
            assert abs(float(value) - want) <= 5e-4 * abs(want), (text, want)
    table = page["table"]
    assert [r[0] for r in table[1:]] == [str(i) for i in rows]
    for cells, row in zip(table[1:], s.dh, strict=True):
        np.testing.assert_allclose([float(c) for c in cells[1:3]], [row.a, row.d], rtol=5e-4, atol=1e-12)


def test_the_labels_are_in_the_pages_with_the_scenes_text(browser_run):
    """The axis labels (x_i, z_i), the named frames' names and the DH parameters are elements of
    each page, their text read back from the DOM (the animation's at its last step: the labels
    follow the motion); hostile names are text, no element."""
    run, _ = browser_run
    pages = _shown(run)
    assert len(pages) == 2, run.stderr[-3000:]
    drawing = next(p for p in pages if any(f == HOSTILE for _, f, _ in p["labels"]))
    anim = next(p for p in pages if p is not drawing)
    last = np.full(6, np.sin(2.0))  # the animation's q at t = 1
    for page, robot, q in ((drawing, _hostile_robot(), [0.2, 0.4]), (anim, _quiet(example, "puma560"), last)):
        s = scene(robot, q)
        axes = [f for f in s.frames if f.kind in ("link", "base")]
        want = [("label axis", f.name, a + f.label) for f in axes for a in "xz"]
        want += [(f"label {f.kind}", f.name, f.label) for f in s.frames if f.kind in ("frame", "contact")]
        got = [tuple(x) for x in page["labels"] if x[0] != "label dh"]
        assert sorted(got) == sorted(want)
        assert page["foreign"] == 0 and page["scripts"] == 4
        _check_dh_labels(page, s)
    assert "tip<svg onload=alert(3)>" in [text for _, _, text in drawing["labels"]]


def test_the_screenshot_shows_both_robots(browser_run):
    from PIL import Image

    _, shot = browser_run
    with Image.open(shot) as im:
        rgb = np.asarray(im.convert("RGB")).astype(int)
    for left in (0, 980):  # each frame's drawing area (below the heading, above the controls)
        area = rgb[60:760, left + 10 : left + 950]
        ink = (area.sum(axis=-1) < 720).sum()
        red = ((area[..., 0] > 150) & (area[..., 1] < 90) & (area[..., 2] < 90)).sum()
        blue = ((area[..., 2] > 130) & (area[..., 0] < 90)).sum()
        assert ink > 2000 and red > 30 and blue > 30, (left, ink, red, blue)


def test_the_animation_page_holds_the_frames_and_the_tool_path(tmp_path):
    robot = _quiet(example, "puma560")
    t = np.linspace(0, 1, 11)
    q = np.outer(t, np.ones(6))
    page = animate(robot, t, q, tmp_path / "a.html", frames=4).decode()
    data = page.split('id="symdyn-data">', 1)[1].split("</script>", 1)[0]
    d = json.loads(data)
    assert len(d["steps"]) == 4 and d["times"] == [0.0, 0.3, 0.7, 1.0]
    want = [frame_state(robot, "link6", x).pose[:3, 3] for x in q]
    np.testing.assert_allclose(d["trace"], want, atol=1e-9)
    assert Path(tmp_path / "a.html").read_bytes() == page.encode()
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//)""", page)  # nothing from the network
    assert '"three":"data:text/javascript;base64,' in page.replace(" ", "")
    for step, k in zip(d["steps"], (0, 3, 7, 10), strict=True):  # the DH labels follow the motion
        thetas = [float(sub.split(" = ")[1][:-1]) for text, sub, *_ in step["dh"] if text == "θ"]
        rows = scene(robot, q[k]).dh
        want = [np.degrees(r.theta) for r in rows if abs(r.theta) > 1e-9]
        np.testing.assert_allclose(thetas, want, atol=0.051)
        assert [c[0][0] for c in step["table"][1:]] == [str(r.index) for r in rows]


# --------------------------------------------------------------------------- the documentation's pictures


def test_the_committed_pictures_are_what_symdyn_draw_writes(tmp_path, monkeypatch):
    """docs/images/robots/*.svg drawn again by docs/pictures.py (`symdyn draw`) are the same bytes."""
    if example_robot_data_folder() is None:
        pytest.skip("Solo-12's picture needs example-robot-data")
    root = EXAMPLES_DIR.parent
    monkeypatch.chdir(root)
    monkeypatch.syspath_prepend(str(root / "docs"))
    import pictures

    written = pictures.write(tmp_path)
    committed = sorted(p.name for p in (root / pictures.OUT).glob("*.svg"))
    assert sorted(p.name for p in written) == committed
    for path in written:
        assert path.read_bytes() == (root / pictures.OUT / path.name).read_bytes(), (
            f"{path.name} differs: run python docs/pictures.py"
        )
