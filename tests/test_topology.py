"""The tree and the coordinates of the model (symdyn.model.topology, symdyn.model.robot).

Expected values are written out by hand from the parent arrays and mimic relations the
robots are built with."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from robots import SOLO_PARENTS, Y_PARENTS, solo_robot, tree_robot, y_robot

from symdyn.errors import SymdynError
from symdyn.model.robot import Motor
from symdyn.model.topology import Mimic, check_parents, children, is_chain, subtree, support

ZERO33 = sp.ImmutableMatrix(sp.zeros(3, 3))


def test_y_tree_relations():
    assert y_robot().parents == Y_PARENTS
    assert children(Y_PARENTS, -1) == [0]
    assert children(Y_PARENTS, 0) == [1, 3]
    assert children(Y_PARENTS, 2) == []
    assert support(Y_PARENTS, 2) == [2, 1, 0]
    assert support(Y_PARENTS, 4) == [4, 3, 0]
    assert subtree(Y_PARENTS, 0) == [0, 1, 2, 3, 4]
    assert subtree(Y_PARENTS, 3) == [3, 4]
    assert not is_chain(Y_PARENTS) and is_chain((-1, 0, 1))
    assert not y_robot().is_chain


def test_solo_legs():
    robot = solo_robot()
    assert robot.parents == (-1, 0, 1, -1, 3, 4, -1, 6, 7, -1, 9, 10)
    assert (robot.n, robot.nb) == (12, 12)
    assert children(SOLO_PARENTS, -1) == [0, 3, 6, 9]
    assert support(SOLO_PARENTS, 11) == [11, 10, 9]
    assert subtree(SOLO_PARENTS, 4) == [4, 5]


def test_parent_none_is_the_previous_link():
    robot = y_robot()
    chain = replace(robot, links=tuple(replace(lk, parent=None) for lk in robot.links))
    assert chain.parents == (-1, 0, 1, 2, 3) and chain.is_chain


@pytest.mark.parametrize(
    "parents,message",
    [((0,), "link 1 has parent 1: a parent must come before its child"), ((-1, 2, 0), "link 2 has parent 3")],
)
def test_parents_must_come_first(parents, message):
    assert message in check_parents(parents)
    robot = y_robot()
    links = tuple(replace(lk, parent=p) for lk, p in zip(robot.links, parents, strict=False))
    with pytest.raises(SymdynError, match=f"^robot 'ytree': {message}"):
        replace(robot, links=links)


def test_mimic_coordinates_selection_and_body_positions():
    """Body 3 follows body 1: q_3 = -2 q_1 + 0.3, so S = [[1, 0], [0, 1], [-2, 0]]."""
    robot = tree_robot(
        "m3", (-1, 0, 1), ("revolute",) * 3, 1, mimic={2: Mimic(0, sp.Integer(-2), sp.Rational(3, 10))}
    )
    assert (robot.n, robot.nb) == (2, 3)
    assert not robot.is_chain
    assert robot.selection() == sp.Matrix([[1, 0], [0, 1], [-2, 0]])
    q1, q2 = sp.symbols("q1 q2")
    assert robot.body_positions([q1, q2]) == [q1, q2, -2 * q1 + sp.Rational(3, 10)]
    assert robot.body_rates([q1, q2]) == [q1, q2, -2 * q1]


@pytest.mark.parametrize(
    "mimic,message",
    [
        ({1: Mimic(1)}, "link 2 (bad2) mimics no other joint"),
        ({1: Mimic(7)}, "link 2 (bad2) mimics no other joint"),
        ({1: Mimic(0), 2: Mimic(1)}, "link 3 (bad3) mimics bad2, which is a mimic joint itself"),
    ],
)
def test_bad_mimic_relations(mimic, message):
    with pytest.raises(SymdynError, match="^" + re.escape(f"robot 'bad': {message}")):
        tree_robot("bad", (-1, 0, 1), ("revolute",) * 3, 1, mimic=mimic)


def _massless(robot, indices, motor: bool = False, inertia: bool = False):
    links = list(robot.links)
    for i in indices:
        keep = links[i].inertia if inertia else ZERO33
        links[i] = replace(links[i], mass=sp.S.Zero, inertia=keep, motor=links[i].motor if motor else Motor())
    return replace(robot, links=tuple(links))


def test_idle_joints_of_a_massless_arm():
    robot = y_robot()
    assert robot.idle_joints() == ()
    assert _massless(robot, (3, 4)).idle_joints() == (3, 4)  # the right arm, prismatic then revolute
    assert _massless(robot, (4,)).idle_joints() == (4,)
    assert _massless(robot, (3,)).idle_joints() == ()  # its child still has mass
    # a rotor on joint 4 keeps M[3, 3] > 0; joint 5 is still idle
    arm = _massless(robot, (3, 4))
    geared = replace(
        arm,
        links=(
            *arm.links[:3],
            replace(arm.links[3], motor=Motor(sp.Float(1e-4), sp.Float(10))),
            arm.links[4],
        ),
    )
    assert geared.idle_joints() == (4,)


def test_idle_joints_with_inertia_but_no_mass():
    """Rotational inertia without mass resists a revolute joint, not a prismatic one."""
    robot = y_robot()  # link 3 (index 2) is prismatic, link 5 (index 4) revolute; both leaves
    assert _massless(robot, (2,), inertia=True).idle_joints() == (2,)
    assert _massless(robot, (4,), inertia=True).idle_joints() == ()


def test_idle_joints_symbolic_mass_is_undecided():
    m = sp.Symbol("m")
    robot = _massless(y_robot(), (3, 4))
    links = (*robot.links[:4], replace(robot.links[4], mass=m))
    symbolic = replace(robot, links=links, params=(m,))
    assert symbolic.idle_joints() == ()  # m may be anything
    valued = replace(symbolic, params=(), values=((m, sp.S.Zero),))
    assert valued.idle_joints() == (3, 4)  # a value in the file decides


def test_idle_mimic_coordinate_needs_every_body_idle():
    """A coordinate that drives a massless finger and a heavy one is not idle."""
    robot = tree_robot(
        "grip", (-1, 0, 0), ("revolute", "prismatic", "prismatic"), 4, mimic={2: Mimic(1, sp.S.NegativeOne)}
    )
    assert _massless(robot, (1,)).idle_joints() == ()
    assert _massless(robot, (1, 2)).idle_joints() == (1, 2)


def test_selection_of_a_chain_is_the_identity():
    robot = y_robot()
    assert robot.selection() == sp.eye(robot.n)
    assert np.array_equal(np.array(robot.body_positions([1, 2, 3, 4, 5])), [1, 2, 3, 4, 5])
