"""Fuzzing the loaders: mutated robot files and URDFs load, or fail with one SymdynError, in time.

The example robot files (examples/*.yaml), a few URDFs of tests/data/urdf and MJCF files of
tests/data/mjcf are mutated: numbers replaced with extreme or garbage values (1e308, nan, 1e400,
thousands of digits), expressions that hang a careless parser (exponent towers, 9**9**9,
pi/2*pi/2), fields deleted, list entries duplicated, odd keys and strings inserted, the text
truncated. Every outcome must
be a Robot or a SymdynError within TIME_BOUND seconds, never another exception or a hang; for the
two-joint Roger's arm the loaded robot is also derived and its NumPy code rendered.

The number of cases per test is SYMDYN_FUZZ_EXAMPLES (default 100: a few hundred cases in all,
under a minute); hypothesis runs derandomized, so every run tries the same cases. A longer hunt:

    SYMDYN_FUZZ_EXAMPLES=5000 python -m pytest -q tests/test_fuzz.py
"""

from __future__ import annotations

import copy
import os
import re
import tempfile
import warnings
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from timebound import within

from symdyn.codegen import render
from symdyn.dynamics import derive
from symdyn.errors import SymdynError
from symdyn.parsers import load_robot, load_urdf

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
URDFS = [ROOT / "tests" / "data" / "urdf" / f"{n}.urdf" for n in ("two_link", "rpy_chain", "tree", "branch")]
MJCFS = [ROOT / "tests" / "data" / "mjcf" / f"{n}.xml" for n in ("defaults", "orientations", "tree", "sites")]
#: Seconds one case may take (loading, and deriving and rendering Roger's arm).
TIME_BOUND = 10
EXAMPLES_PER_TEST = int(os.environ.get("SYMDYN_FUZZ_EXAMPLES", "100"))
#: The robot files mutated by default (the larger ones, with more fields to mutate, too with the flag).
SMALL = ("roger_arm", "roger_arm_values", "roger_eye", "craig_two_link", "spong_two_link", "planar_3r")
NAMES = tuple(sorted(p.stem for p in EXAMPLES.glob("*.yaml"))) if EXAMPLES_PER_TEST > 100 else SMALL

FUZZ = settings(
    max_examples=EXAMPLES_PER_TEST,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=list(HealthCheck),
)

#: Values that have broken parsers: extreme numbers, hanging expressions, code, wrong kinds.
HOSTILE = [
    1e308,
    -1e308,
    5e-324,
    0,
    -1,
    2**70,
    float("nan"),
    float("inf"),
    "1e400",
    "nan",
    "pi/2*pi/2",
    "((((x+1)**64)**64)**64)",
    "(((((x**64)**64)**64)**64)**64)",
    "m*b**e",
    "9**9**9",
    "2**64**2",
    "1/0",
    "0**-1",
    "sqrt(-1)",
    "tan(pi/2)",
    "1" * 40,
    "3." + "3" * 3000,
    "x" * 3000,
    "(" * 200 + "1" + ")" * 200,
    "",
    " ",
    "__import__('os').system('true')",
    "a.b",
    "lambda: 0",
    "q1",
    "sin",
    "pi",
    "é",
    "\x00",
    "<<",
    True,
    None,
    [],
    {},
    [1, 2],
    [1, 2, 3],
    {"ixx": "1e308"},
    {"e": "9**9"},
]
#: Parameters whose names the hostile expressions use (m*b**e, x).
HOSTILE_PARAMETERS = [{"e": "9**9"}, {"x": 3}, {"b": "e**64", "e": 64}, {"a1": 3, "a2": "a1**64"}]
#: Replacements of URDF attribute values.
HOSTILE_ATTRIBUTES = [
    "1e308",
    "-1e308",
    "1e400",
    "nan",
    "inf",
    "5e-324",
    "9" * 3000,
    "0." + "1" * 3000,
    "1e150",
    "-0",
    "",
    "1 2",
    "1 2 3 4",
    "abc",
    "0x10",
    "1,5",
    "&amp;",
]


def _paths(data, prefix=()):
    """Every path (tuple of keys and indices) into nested dicts and lists, the root included."""
    yield prefix
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _paths(v, (*prefix, i))


def _parent(data, path):
    for k in path[:-1]:
        data = data[k]
    return data


def _mutate(data, draw):
    """Apply one drawn mutation to `data` (nested dicts and lists) in place; may return new data."""
    paths = [p for p in _paths(data) if p]
    if not paths:
        return data
    path = paths[draw(st.integers(0, len(paths) - 1))]
    parent, key = _parent(data, path), path[-1]
    kind = draw(
        st.sampled_from(["replace", "replace", "replace", "delete", "duplicate", "odd key", "parameters"])
    )
    if kind == "replace":
        parent[key] = copy.deepcopy(draw(st.sampled_from(HOSTILE)))
    elif kind == "delete":
        del parent[key]
    elif kind == "duplicate" and isinstance(parent, list):
        parent.insert(key, parent[key])
    elif kind == "odd key" and isinstance(parent, dict):
        key = draw(st.sampled_from(["links", "name", "mass", "unknown", "<<", "__class__", 1]))
        parent[key] = copy.deepcopy(draw(st.sampled_from(HOSTILE)))
    elif isinstance(data, dict):
        data["parameters"] = copy.deepcopy(draw(st.sampled_from(HOSTILE_PARAMETERS)))
    return data


def _outcome(load, path: Path):
    """The Robot that `load` makes of `path`, or None for a SymdynError; anything else fails the test."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return load(path)
        except SymdynError as exc:
            message = str(exc)
            assert message and "\n" not in message.strip(), message
            return None


def _text(data, draw) -> str:
    try:
        text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    except yaml.YAMLError:
        text = repr(data)
    if draw(st.integers(0, 9)) == 0:
        text = text[: draw(st.integers(0, len(text)))]
    return text


@FUZZ
@given(st.data())
def test_mutated_robot_files_load_or_fail_cleanly(data):
    name = data.draw(st.sampled_from(NAMES))
    doc = yaml.safe_load((EXAMPLES / f"{name}.yaml").read_text())
    for _ in range(data.draw(st.integers(1, 3))):
        doc = _mutate(doc, data.draw)
    text = _text(doc, data.draw)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{name}.yaml"
        path.write_text(text)
        with within(TIME_BOUND):
            _outcome(load_robot, path)


@FUZZ
@given(st.data())
def test_mutated_roger_arms_derive_and_render_or_fail_cleanly(data):
    """Roger's arm, symbolic and with values: what loads is derived and rendered as NumPy in time."""
    name = data.draw(st.sampled_from(["roger_arm", "roger_arm_values"]))
    doc = yaml.safe_load((EXAMPLES / f"{name}.yaml").read_text())
    doc = _mutate(doc, data.draw)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{name}.yaml"
        path.write_text(_text(doc, data.draw))
        with within(TIME_BOUND):
            robot = _outcome(load_robot, path)
            if robot is not None:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        derive(robot)
                        files = render(robot, ("python",), functions=("dynamics",))
                        assert files
                    except SymdynError as exc:
                        assert "\n" not in str(exc).strip(), str(exc)


_ATTRIBUTE = re.compile(r'="([^"]*)"')


def _mutated_xml(data, text: str) -> str:
    """The XML text with 1 to 3 mutations: a hostile attribute value, a line deleted or
    duplicated, the text cut short."""
    for _ in range(data.draw(st.integers(1, 3))):
        kind = data.draw(
            st.sampled_from(["attribute", "attribute", "delete line", "duplicate line", "truncate"])
        )
        lines = text.splitlines(keepends=True)
        spans = [m.span(1) for m in _ATTRIBUTE.finditer(text)]
        if not lines or (kind == "attribute" and not spans):
            break
        if kind == "attribute":
            a, b = spans[data.draw(st.integers(0, len(spans) - 1))]
            text = text[:a] + data.draw(st.sampled_from(HOSTILE_ATTRIBUTES)) + text[b:]
        elif kind == "delete line":
            del lines[data.draw(st.integers(0, len(lines) - 1))]
            text = "".join(lines)
        elif kind == "duplicate line":
            i = data.draw(st.integers(0, len(lines) - 1))
            text = "".join([*lines[: i + 1], lines[i], *lines[i + 1 :]])
        else:
            text = text[: data.draw(st.integers(0, len(text)))]
    return text


@pytest.mark.parametrize("kind", ["urdf", "mjcf"])
@FUZZ
@given(data=st.data())
def test_mutated_xml_files_load_or_fail_cleanly(kind, data):
    """URDFs (load_urdf) and MJCF files (load_robot; compiled by MuJoCo, in the test extra)."""
    if kind == "mjcf":
        pytest.importorskip("mujoco", reason="the test extra installs mujoco")
    source = data.draw(st.sampled_from(URDFS if kind == "urdf" else MJCFS))
    text = _mutated_xml(data, source.read_text())
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / source.name
        path.write_text(text)
        with within(TIME_BOUND):
            _outcome(load_urdf if kind == "urdf" else load_robot, path)


@pytest.mark.parametrize("name", NAMES)
def test_the_unmutated_files_load(name):
    """The mutations start from files that load (else every case would be an error)."""
    assert _outcome(load_robot, EXAMPLES / f"{name}.yaml") is not None
