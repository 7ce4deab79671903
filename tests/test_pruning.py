"""Significance pruning (symdyn.algorithms.pruning): the stated bounds hold on random states
inside the joint ranges, which come from the robot's limits (robot file, URDF) or +-pi."""

from __future__ import annotations

import copy
import math
import warnings
import xml.etree.ElementTree as ET
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from robots import example, raw_example

from symdyn.algorithms.configuration_space import pair_columns
from symdyn.algorithms.pruning import joint_box, prune, prune_robot, trig_bound
from symdyn.dynamics import derive
from symdyn.errors import SymdynError, SymdynWarning
from symdyn.parsers import load_urdf, robot_from_data

URDF = Path(__file__).parent / "data" / "urdf"
#: the PUMA 560's joint ranges in degrees, as mdl_puma560.m of the Robotics Toolbox for MATLAB
#: (the source of examples/puma560.yaml, same joint conventions) gives them, from Wang and Chen,
#: IEEE Trans. Robotics and Automation 7(4), 1991
PUMA_DEGREES = ((-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266))


@pytest.mark.parametrize("kind", [0, 1])
def test_trig_bound_is_the_maximum_over_the_interval(kind):
    rng = np.random.default_rng(3)
    f = np.cos if kind == 0 else np.sin
    for _ in range(200):
        lo = rng.uniform(-7, 7)
        hi = lo + rng.uniform(0, 4)
        dense = np.abs(f(np.linspace(lo, hi, 20001))).max()
        assert dense <= trig_bound(lo, hi, kind) + 1e-12
        assert trig_bound(lo, hi, kind) <= dense + 1e-6


def _values(cs, name, r, c, q):
    return cs.ring.numeric(cs.poly(name, r, c))(q)


def _entries(n: int) -> list[tuple[str, int, int]]:
    """Every entry (name, row, column) of M (upper triangle), G, B and Csq."""
    entries = [("M", i, j) for i in range(n) for j in range(i, n)] + [("G", k, 0) for k in range(n)]
    entries += [("B", k, c) for k in range(n) for c in range(len(pair_columns(n)))]
    return entries + [("Csq", k, i) for k in range(n) for i in range(n)]


def _assert_within_bounds(dyn, pr, box, seed=5) -> None:
    """On random states drawn inside `box`, every pruned entry differs from the full one by at
    most its stated bound."""
    n = dyn.n
    full, cut = dyn.configuration_space, pr.configuration
    lo, hi = np.array(box, dtype=float).T
    q = np.random.default_rng(seed).uniform(lo, hi, (3000, n))
    for key in _entries(n):
        err = np.abs(_values(full, *key, q) - _values(cut, *key, q)).max()
        assert err <= pr.bounds.get(key, 0.0) * (1 + 1e-9) + 1e-12, (key, err, pr.bounds.get(key))


@pytest.mark.parametrize(("robot", "rel", "limits"), [("puma560", 0.01, None), ("stanford", 0.05, "half")])
def test_error_within_the_stated_bound(robot, rel, limits):
    dyn = derive(example(robot), simplify=False)
    n = dyn.n
    box = None if limits is None else [(-math.pi / 2, math.pi / 2)] * n
    pr = prune(dyn.configuration_space, rel, limits=box)
    assert pr.terms_after < pr.terms_before
    _assert_within_bounds(dyn, pr, box or [(-math.pi, math.pi)] * n)


def _robot(data: dict, source: str):
    """A robot from data based on an example file (its published-data warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        return robot_from_data(data, source=source)


@cache
def puma_with_limits():
    """examples/puma560.yaml with `limits` in degrees (PUMA_DEGREES) written as expressions."""
    data = copy.deepcopy(raw_example("puma560"))
    for link, (lo, hi) in zip(data["links"], PUMA_DEGREES, strict=True):
        link["limits"] = [f"{lo}*pi/180", f"{hi}*pi/180"]
    return _robot(data, "puma560_limits.yaml")


def test_the_box_is_the_robot_file_limits():
    box, text = joint_box(puma_with_limits())
    want = [math.radians(x) for pair in PUMA_DEGREES for x in pair]
    assert [x for pair in box for x in pair] == pytest.approx(want, rel=1e-15)
    assert text == "joint ranges: robot file limits for q1..q6"
    box, text = joint_box(example("puma560"))  # no limits: +-pi
    assert box == [(-math.pi, math.pi)] * 6
    assert text == "joint ranges: +-pi for q1..q6 (no limits)"


def test_a_prismatic_joint_without_limits_keeps_plus_minus_pi_metres():
    """Stanford arm: joint 3 slides; without limits its range is +-pi, read as metres."""
    data = copy.deepcopy(raw_example("stanford"))
    assert [link["joint"] for link in data["links"]][2] == "prismatic"
    box, text = joint_box(example("stanford"))
    assert box == [(-math.pi, math.pi)] * 6
    assert (
        text == "joint ranges: +-pi for q1, q2, q4..q6 (no limits); +-3.142 m for q3 (prismatic, no limits)"
    )
    data["links"][2]["limits"] = [0.1, 0.6]
    data["links"][4]["limits"] = ["-pi/2", "pi/2"]
    box, text = joint_box(_robot(data, "stanford_limits.yaml"))
    assert box[2] == (0.1, 0.6) and box[4] == (-math.pi / 2, math.pi / 2)
    assert text == "joint ranges: robot file limits for q3, q5; +-pi for q1, q2, q4, q6 (no limits)"


def test_a_mimic_joint_takes_its_masters_range():
    disc = {"ixx": 0.01, "iyy": 0.01, "izz": 0.02}
    data = {
        "name": "gripper",
        "convention": "modified",
        "links": [
            {"name": "palm", "joint": "revolute", "mass": 1, "inertia": disc},
            {"name": "left", "joint": "prismatic", "mass": 0.1, "limits": [0, 0.04]},
            {"name": "right", "joint": "prismatic", "mass": 0.1, "parent": "palm", "limits": [-0.04, 0],
             "mimic": {"joint": "left", "multiplier": -1}},
        ],
    }  # fmt: skip
    robot = robot_from_data(data, source="gripper.yaml")
    assert robot.links[2].limits == (-0.04, 0)  # carried, as written
    assert robot.joint_ranges() == (None, (0.0, 0.04))  # one range per coordinate: the master's
    assert joint_box(robot)[1] == "joint ranges: robot file limits for q2; +-pi for q1 (no limits)"


@pytest.mark.parametrize(
    ("make", "rel"),
    [(puma_with_limits, 0.01), (lambda: _robot(_stanford_ranged(), "stanford_ranged.yaml"), 0.05)],
    ids=["puma560_published_ranges", "stanford_prismatic_range"],
)
def test_error_within_the_stated_bound_inside_the_robots_limits(make, rel):
    robot = make()
    dyn = derive(robot, simplify=False)
    pr = prune_robot(dyn.configuration_space, robot, rel)
    box, text = joint_box(robot)
    assert pr.limits == box and pr.ranges == text
    assert pr.terms_after < pr.terms_before
    _assert_within_bounds(dyn, pr, box, seed=11)


def _stanford_ranged() -> dict:
    """The Stanford arm with a narrow range for every joint, the prismatic one 0.2 .. 0.5 m."""
    data = copy.deepcopy(raw_example("stanford"))
    for k, link in enumerate(data["links"]):
        link["limits"] = [0.2, 0.5] if k == 2 else [-1, 0.5]
    return data


@pytest.mark.parametrize("robot", ["puma560", "stanford"])
def test_narrower_ranges_keep_more_only_where_the_entry_got_smaller(robot):
    """A narrower box never raises a term's bound (interval arithmetic on a sub-box), so a term
    dropped over +-pi can be kept over the narrower box only when the entry's largest value there
    is smaller (the threshold is relative to it): for every entry whose largest value did not
    shrink, the narrower box keeps a subset of the terms."""
    dyn = derive(example(robot), simplify=False)
    n, rel = dyn.n, 0.01
    wide = prune(dyn.configuration_space, rel)
    for box in ([(-math.pi / 2, math.pi / 2)] * n, [(-0.3, 1.2)] * n):
        narrow = prune(dyn.configuration_space, rel, limits=box)
        for key in _entries(n):
            kept_narrow = set(narrow.configuration.poly(*key))
            kept_wide = set(wide.configuration.poly(*key))
            if narrow.largest.get(key, 0.0) >= wide.largest.get(key, 0.0):
                assert kept_narrow <= kept_wide, key


def test_pruning_a_urdf_robot_uses_its_limits():
    """tests/data/urdf/two_link.urdf: a revolute shoulder with <limit> and a continuous elbow."""
    joints = {j.get("name"): j for j in ET.parse(URDF / "two_link.urdf").getroot().iter("joint")}
    limit = joints["shoulder"].find("limit")
    robot = load_urdf(URDF / "two_link.urdf")
    box, text = joint_box(robot)
    assert box == [(float(limit.get("lower")), float(limit.get("upper"))), (-math.pi, math.pi)]
    assert joints["elbow"].get("type") == "continuous"
    assert text == "joint ranges: URDF limits for q1; +-pi for q2 (no limits)"
    dyn = derive(robot, simplify=False)
    pr = prune_robot(dyn.configuration_space, robot, 0.2)
    _assert_within_bounds(dyn, pr, box)


def test_prune_needs_numbers_and_a_threshold():
    dyn = derive(example("roger_arm"), simplify=False)
    with pytest.raises(SymdynError, match="free parameters"):
        prune(dyn.configuration_space, 0.01)
    with pytest.raises(SymdynError, match="between 0 and 1"):
        prune(derive(example("planar_3r")).configuration_space, 2.0)


def test_generated_code_from_the_pruned_model_states_and_keeps_its_bound():
    from symdyn import rnea
    from symdyn.codegen import context
    from symdyn.codegen.render import header_lines

    robot = example("puma560")
    ctx = context(robot, prune=0.01)
    assert any("Pruned model (--prune 0.01)" in line for line in header_lines(ctx))
    assert any("Joint ranges: +-pi for q1..q6 (no limits)." in line for line in header_lines(ctx))
    pr = prune(derive(robot, simplify=False).configuration_space, 0.01)
    rng = np.random.default_rng(8)
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 6)
        M, G = ctx.dynamics.evaluate("M", q), ctx.dynamics.evaluate("G", q)
        M_true, G_true = rnea.mass_matrix(ctx.robot, q), rnea.gravity_torque(ctx.robot, q)
        for i in range(6):
            assert abs(G[i] - G_true[i]) <= pr.bounds.get(("G", i, 0), 0.0) + 1e-9
            for j in range(i, 6):
                assert abs(M[i, j] - M_true[i, j]) <= pr.bounds.get(("M", i, j), 0.0) + 1e-9


def test_generated_headers_name_the_joint_ranges():
    from symdyn.codegen import context
    from symdyn.codegen.render import header_lines

    data = copy.deepcopy(raw_example("planar_3r"))
    data["links"][2]["limits"] = ["-pi/3", "pi/3"]
    lines = header_lines(context(_robot(data, "planar_3r_limits.yaml"), prune=0.05))
    assert any(
        ln.strip(" *") == "Joint ranges: robot file limits for q3; +-pi for q1, q2 (no limits)."
        for ln in lines
    )
