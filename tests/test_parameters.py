"""The standard dynamic parameters (symdyn.standard_parameters): layout, hand-computed values, Pinocchio.

Expected values come from the parallel-axis theorem worked by hand on exact numbers, from the
link fields the test builds itself, and from Pinocchio's `Inertia.toDynamicParameters` (a peer
library sharing no code with symdyn) for hand-built inertias and for the bodies of URDF files.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from robots import EXAMPLE_NAMES, example, mat, random_inertia, rotation, tree_robot, vec

import symdyn
from symdyn.model.parameters import numeric_parameters, standard_parameters
from symdyn.model.robot import Friction, Link, Mimic, Motor, Robot
from symdyn.spatial.transform import Transform

URDF_DIR = Path(__file__).resolve().parent / "data" / "urdf"
URDFS = ("axes", "branch", "cartesian", "fixed_offset", "rpy_chain", "tree", "two_link")
PER_BODY = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz", "Ia", "fv", "fc")

R = sp.Rational


def hand_link(**extra) -> Link:
    """m = 2, c = (1/10, -1/5, 3/10), I_c = [[1, 1/10, 1/5], [1/10, 2, 3/10], [1/5, 3/10, 3]] (exact),
    a rotor of inertia 1/100 behind a 9:1 gear, viscous 1/2 and Coulomb 1/4 friction."""
    fields = dict(
        name="hand",
        joint="revolute",
        placement=Transform.identity(),
        axis=vec([0, 0, 1]),
        mass=sp.Integer(2),
        com=vec([R(1, 10), R(-1, 5), R(3, 10)]),
        inertia=sp.ImmutableMatrix([[1, R(1, 10), R(1, 5)], [R(1, 10), 2, R(3, 10)], [R(1, 5), R(3, 10), 3]]),
        friction=Friction(R(1, 2), R(1, 4)),
        motor=Motor(R(1, 100), sp.Integer(9)),
    )
    fields.update(extra)
    return Link(**fields)


def test_the_hand_built_link_by_hand():
    """Parallel-axis theorem, I_O = I_c + m (c^T c 1 - c c^T), worked by hand: c^T c = 7/50,
    Ixx = 1 + 2 (7/50 - 1/100) = 63/50, Iyy = 2 + 2 (7/50 - 1/25) = 11/5, Izz = 3 + 2 (7/50 - 9/100)
    = 31/10, Ixy = 1/10 - 2 (1/10)(-1/5) = 7/50, Ixz = 1/5 - 2 (1/10)(3/10) = 7/50, Iyz = 3/10 -
    2 (-1/5)(3/10) = 21/50; Ia = 9^2 / 100."""
    robot = Robot("hand", (hand_link(),), vec([0, 0, -9.81]))
    names, values = standard_parameters(robot)
    assert names == tuple(f"{p}1" for p in PER_BODY)
    by_hand = [2, R(1, 5), R(-2, 5), R(3, 5), R(63, 50), R(7, 50), R(11, 5), R(7, 50), R(21, 50), R(31, 10)]
    assert list(values) == [*by_hand, R(81, 100), R(1, 2), R(1, 4)]


def test_names_and_order_per_body_of_a_tree_with_a_mimic_joint():
    """13 per body (nb, mimic bodies included), link 1 first, 1-based names."""
    parents = (-1, 0, 0, 2)
    robot = tree_robot("t", parents, ("revolute",) * 4, seed=3, mimic={3: Mimic(1, sp.Float(2), sp.Float(0))})
    assert (robot.n, robot.nb) == (3, 4)
    names, values = standard_parameters(robot)
    assert names == tuple(f"{p}{i}" for i in range(1, 5) for p in PER_BODY)
    assert len(values) == 13 * 4
    for i, link in enumerate(robot.links):  # the mass, first moment and joint parameters of each body
        block = values[13 * i : 13 * (i + 1)]
        assert block[0] == link.mass
        assert list(block[1:4]) == [link.mass * x for x in link.com]
        assert list(block[10:]) == [
            link.motor.reflected_inertia,
            link.friction.viscous,
            link.friction.coulomb,
        ]


def test_free_parameters_stay_symbols_and_valued_ones_are_substituted():
    eye = example("roger_eye")  # a point mass m at the origin of frame 1 (slide 17)
    names, values = standard_parameters(eye)
    m = sp.Symbol("m")
    assert values[names.index("m1")] == m
    assert set().union(*(sp.sympify(v).free_symbols for v in values)) <= set(eye.params)
    valued = example("planar_prismatic_modified")  # 15 named parameters, all with values
    assert valued.values and not valued.params
    assert all(not sp.sympify(v).free_symbols for v in standard_parameters(valued)[1])


def test_symdyn_exports_standard_parameters():
    assert "standard_parameters" in symdyn.__all__
    assert symdyn.standard_parameters is standard_parameters


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_numeric_parameters_substitute_the_free_parameters(name):
    robot = example(name)
    values = {p: 0.5 + k for k, p in enumerate(robot.params)}
    pi = numeric_parameters(robot, values or None)
    exact = [
        sp.sympify(v).xreplace({p: sp.Float(x) for p, x in values.items()})
        for v in standard_parameters(robot)[1]
    ]
    np.testing.assert_allclose(pi, np.array(exact, dtype=float), rtol=1e-14, atol=0)
    assert pi.shape == (13 * robot.nb,)


# --- Pinocchio, a peer library ---------------------------------------------------------------------


def pinocchio_order(path: Path, robot, model) -> list[int]:
    """Pinocchio's joint id of each symdyn body (symdyn names a joint's link after its child link)."""
    root = ET.parse(path).getroot()
    joint_of = {j.find("child").get("link"): j.get("name") for j in root.findall("joint")}
    return [model.getJointId(joint_of[link.name]) for link in robot.links]


def test_hand_built_inertias_against_pinocchio():
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(2015)
    links = [hand_link()]
    for k in range(5):
        mass = float(rng.uniform(0.2, 3.0))
        R0 = rotation(rng)
        links.append(
            hand_link(
                name=f"random{k}",
                mass=sp.Float(mass),
                com=mat(rng.uniform(-0.5, 0.5, (3, 1))),
                inertia=mat(R0 @ random_inertia(rng, mass) @ R0.T),
            )
        )
    robot = Robot("hands", tuple(links), vec([0, 0, -9.81]))
    ours = numeric_parameters(robot).reshape(-1, 13)
    for link, row in zip(robot.links, ours, strict=True):
        I_c = np.array(link.inertia.tolist(), dtype=float)
        lever = np.array(link.com, dtype=float).ravel()
        theirs = pin.Inertia(float(link.mass), lever, I_c).toDynamicParameters()
        np.testing.assert_allclose(row[:10], theirs, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("name", URDFS)
def test_urdf_bodies_against_pinocchio(name):
    """The same URDF file through symdyn.load_urdf and pinocchio.buildModelFromUrdf: the body frames
    are the joints' child-link frames in both, so the 10 inertial parameters agree per body
    (bodies matched by the joint's name: symdyn names a link after the joint's child link)."""
    pin = pytest.importorskip("pinocchio")
    path = URDF_DIR / f"{name}.urdf"
    robot = symdyn.load_urdf(path)
    model = pin.buildModelFromUrdf(str(path))
    order = pinocchio_order(path, robot, model)
    ours = numeric_parameters(robot).reshape(-1, 13)[:, :10]
    theirs = np.array([model.inertias[j].toDynamicParameters() for j in order])
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-14)
