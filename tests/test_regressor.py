"""The symbolic regressor (symdyn.algorithms.regressor, `Dynamics.regressor`), judged by independent routes.

At random states the compact Y of the derivation (over its intermediates) must equal the oracle's
numeric regressor symdyn.oracle.regressor entry by entry and give Y pi = tau of the numeric RNEA
symdyn.rnea (friction and rotor inertia included) with pi the standard parameters, to 1e-10
relative: every example robot (standard and modified DH, prismatic joints, free parameters),
random DH and general robots, URDF files, trees and mimic joints. On the two-link arm of the
lecture the closed form Y pi equals the Lagrange route's tau symbolically.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from robots import (
    ASYMMETRIC_PARAMS,
    EXAMPLE_NAMES,
    assert_close,
    asymmetric_friction,
    build_robot,
    derived,
    derived_robot,
    example,
    friction_states,
    random_params,
    random_state,
    robot_specs,
    tree_robot,
    y_robot,
)

import symdyn
from symdyn.model.parameters import numeric_parameters, standard_parameters
from symdyn.model.robot import Mimic
from symdyn.oracle.regressor import regressor as oracle_regressor

URDF_DIR = Path(__file__).resolve().parent / "data" / "urdf"
URDFS = ("axes", "branch", "cartesian", "fixed_offset", "rpy_chain", "tree", "two_link")
RTOL = 1e-10


def compact_function(dyn):
    """Y(q, qd, qdd, p) as NumPy over the compact form (the program's intermediates)."""
    Y = dyn.regressor_compact()
    steps = dyn.program.needed(list(Y))
    args = [list(dyn.q), list(dyn.qd), list(dyn.qdd), list(dyn.params)]
    return sp.lambdify(args, Y, modules="numpy", cse=lambda exprs: (steps, exprs))


def check(dyn, seed: int, states: int = 3) -> None:
    robot = dyn.robot
    f = compact_function(dyn)
    rng = np.random.default_rng(seed)
    params = random_params(robot, rng) if robot.params else None
    pi = numeric_parameters(robot, params)
    for _ in range(states):
        q, qd, qdd = random_state(robot, rng)
        Y = np.asarray(f(q, qd, qdd, [] if params is None else list(params)), dtype=float)
        assert Y.shape == (robot.n, 13 * robot.nb)
        assert_close(Y, oracle_regressor(robot, q, qd, qdd, params), RTOL, robot.name)
        assert_close(Y @ pi, symdyn.rnea(robot, q, qd, qdd, params), RTOL, robot.name)


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_example_robot(name):
    check(derived(name, "newton-euler"), seed=len(name))


@settings(max_examples=8, deadline=None)
@given(robot_specs(max_joints=5))
def test_random_dh_and_general_robots(spec):
    """Standard DH, modified DH and general links; revolute and prismatic; friction and motors."""
    check(symdyn.derive(build_robot(spec), simplify=False), seed=spec.seed % 1000, states=2)


@pytest.mark.parametrize("name", URDFS)
def test_urdf_robots(name):
    check(symdyn.derive(symdyn.load_urdf(URDF_DIR / f"{name}.urdf"), simplify=False), seed=len(name))


def test_trees_and_mimic_joints():
    check(derived_robot(y_robot(), "newton-euler"), seed=1)
    mimic = {3: Mimic(1, sp.Float(1.5), sp.Float(-0.2))}  # link 4 follows link 2 across a fork
    joints = ("revolute", "prismatic", "revolute", "revolute", "prismatic", "revolute")
    robot = tree_robot("tree6", (-1, 0, 0, 2, -1, 4), joints, seed=7, mimic=mimic)
    assert (robot.n, robot.nb) == (5, 6)
    check(derived_robot(robot, "newton-euler"), seed=3)


def test_closed_form_times_parameters_is_lagranges_tau():
    """roger_arm (free masses and lengths): Y pi - tau == 0 symbolically, tau by the Lagrange route."""
    robot = example("roger_arm")
    dyn = symdyn.derive(robot, simplify=False)
    pi = sp.Matrix(standard_parameters(robot)[1])
    tau = symdyn.derive(robot, method="lagrange", simplify=False).tau
    assert dyn.regressor.shape == (2, 26)
    assert sp.simplify(dyn.regressor * pi - tau) == sp.zeros(2, 1)


def test_regressor_does_not_depend_on_the_inertial_values():
    """Y is the same for two robots that differ only in their masses."""
    robot = example("planar_3r")
    heavier = replace(robot, links=tuple(replace(lk, mass=2 * lk.mass) for lk in robot.links))
    a = derived("planar_3r", "newton-euler").regressor
    assert sp.simplify(a - symdyn.derive(heavier, simplify=False).regressor) == sp.zeros(*a.shape)


def test_direction_dependent_coulomb_friction():
    """Two Coulomb columns per joint with c+ and c- (fcp, and fcn after the 13 nb others): the
    compact Y equals the oracle's regressor and Y pi the oracle's tau at rates of both signs and 0."""
    robot = asymmetric_friction()
    dyn = derived_robot(robot, "newton-euler")
    f = compact_function(dyn)
    pi = numeric_parameters(robot, ASYMMETRIC_PARAMS)
    p = [ASYMMETRIC_PARAMS[str(s)] for s in dyn.params]
    assert standard_parameters(robot)[0][39:] == ("fcn1", "fcn3")
    for q, qd, qdd, _ in zip(*friction_states(), strict=True):
        Y = np.asarray(f(q, qd, qdd, p), dtype=float)
        assert Y.shape == (3, 41)
        assert_close(Y, oracle_regressor(robot, q, qd, qdd, ASYMMETRIC_PARAMS), RTOL, robot.name)
        assert_close(Y @ pi, symdyn.rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS), RTOL, robot.name)
