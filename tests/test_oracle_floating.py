"""The numeric oracle on a floating base (symdyn.oracle.floating, .centroidal, .derivatives)
against Pinocchio's free flyer, algorithm by algorithm.

Every legged, humanoid and flying robot of example-robot-data (FILES) is loaded with
`symdyn.load_urdf(path, floating=True)` and built by Pinocchio with a `JointModelFreeFlyer` root;
at random configurations with random unit quaternions the oracle's rnea, mass_matrix,
bias_torque + gravity_torque, gravity_torque, forward_dynamics, centroidal (A_g, its drift
Adot_g v, the centre of mass, the total mass) and rnea_derivatives (dtau/dq in the tangent
space, dtau/dv, M) must equal Pinocchio's rnea, crba, nonLinearEffects, computeGeneralizedGravity,
aba (within the conditioning of M: the two round differently), computeCentroidalMap,
computeCentroidalMapTimeVariation, centerOfMass, computeTotalMass and computeRNEADerivatives.
Joints are matched by name and mimic joints projected by bench/pin_urdf.py (which
bench/floating_sweep.py uses for the table of every file); the worst error per file prints with
`pytest -s`. The oracle's q (+) dq is Pinocchio's integrate, and one generated function of each
kind (centroidal, derivatives) is checked against Pinocchio on Solo-12 and a humanoid.
"""

from __future__ import annotations

import re
import warnings
import zlib

import numpy as np
import pytest
from test_urdf_sweep import REFUSED, ROBOTS, SINGLE_BODIES, _rel, pin_urdf
from test_urdf_sweep import pytestmark as sweep_marks

import symdyn
from symdyn import SymdynError
from symdyn.oracle.derivatives import integrate, rnea_derivatives
from symdyn.rnea import gravity_torque, kinetic_energy, mass_matrix

pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")

pytestmark = sweep_marks

FILES = pin_urdf.floating_files(ROBOTS) if ROBOTS else []
STATES = 2
TOL = 1e-9  # relative to the largest entry (and absolute below 1): two double-precision algorithms
#: dtau/dq by the oracle's five-point difference: about 1e-12 of the largest entry (its truncation
#: and rounding, symdyn.oracle.derivatives); seen: at most 7e-13 on every file
TOL_DQ = 1e-11
#: what symdyn refuses on a floating base: the fixed sweep's refusals but the single rigid bodies
FLOATING_REFUSED = {rel: why for rel, why in REFUSED.items() if rel not in SINGLE_BODIES}


def test_the_floating_robots_are_all_there():
    if ROBOTS is None:
        pytest.skip("example-robot-data is not installed")
    assert len(FILES) >= 35, [_rel(p) for p in FILES]


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
@pytest.mark.parametrize("path", FILES, ids=lambda p: _rel(p) if ROBOTS else str(p))
def test_floating_robot_against_pinocchio(path):
    rel = _rel(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot = symdyn.load_urdf(path, floating=True)
    except SymdynError as exc:
        assert rel in FLOATING_REFUSED, f"symdyn refuses {rel}: {exc}"
        assert FLOATING_REFUSED[rel] in str(exc)
        print(f"{rel}: refused by symdyn: {exc}")
        return
    assert (robot.nq, robot.nv) == (robot.n + 7, robot.n + 6)
    theirs = pin_urdf.Projected.of(path, robot)
    permutation = theirs.S.shape[0] == theirs.S.shape[1]  # no mimic joints: Pinocchio's aba applies
    rng = np.random.default_rng(zlib.crc32(rel.encode()))
    rows = []
    for _ in range(STATES):
        errors, cond = pin_urdf.floating_errors(theirs, robot, *pin_urdf.random_state(robot, rng))
        rows.append(errors)
        if np.isnan(errors["aba"]):  # the oracle refused M as singular: it is
            assert cond > 1e15, (rel, cond)
        elif permutation:  # the forward error, within what the conditioning of M allows
            assert errors["aba"] < 1e-12 * cond, (rel, errors["aba"], cond)
    worst = pin_urdf.worst(rows)
    table = " ".join(f"{name} {err:.0e}" for name, err in worst.items())
    print(f"{rel}: {robot.n} joints + free flyer: {table}")
    # the backward error of aba (Pinocchio's rnea at the oracle's acceleration) where mimic joints
    # leave no aba to compare with
    checked = {k: e for k, e in worst.items() if k != "aba" or not permutation and not np.isnan(e)}
    bad = {k: e for k, e in checked.items() if not e < (TOL_DQ if k == "dtau_dq" else TOL)}
    assert not bad, f"{rel}: {bad}"


def test_energy_and_free_flyer_conventions():
    """T = 1/2 v^T M v; M does not depend on the base pose; G rotates with the base."""
    path = ROBOTS / "solo_description/robots/solo12.urdf"
    robot = symdyn.load_urdf(path, floating=True)
    rng = np.random.default_rng(3)
    q, v, _ = pin_urdf.random_state(robot, rng)
    M = mass_matrix(robot, q)
    assert np.isclose(kinetic_energy(robot, q, v), 0.5 * v @ M @ v)
    moved = q.copy()
    moved[:7] = pin_urdf.random_state(robot, rng)[0][:7]
    np.testing.assert_allclose(mass_matrix(robot, moved), M, atol=1e-12)
    # the base rows of G: the weight m g seen in the base frame, R^T (0, 0, 9.81) m
    x, y, z, w = q[3:7]
    R = pin.Quaternion(w, x, y, z).toRotationMatrix()
    mass = M[0, 0]
    np.testing.assert_allclose(gravity_torque(robot, q)[:3], R.T @ [0, 0, 9.81 * mass], atol=1e-10)


def _solo12(floating: bool):
    path = ROBOTS / "solo_description/robots/solo12.urdf"
    root = (pin.JointModelFreeFlyer(),) if floating else ()
    return symdyn.load_urdf(path, floating=floating), pin.buildModelFromUrdf(str(path), *root)


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
def test_integrate_is_pinocchios():
    """q (+) dq on SE(3) x R^n, from steps of 1e-9 rad to rotations past pi (Solo-12's joints are
    in the same order in both)."""
    robot, model = _solo12(True)
    rng = np.random.default_rng(7)
    for scale in (1e-9, 1e-3, 0.5, 4.0):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        dq = rng.normal(size=model.nv) * scale
        np.testing.assert_allclose(integrate(robot, q, dq), pin.integrate(model, q, dq), atol=1e-14)
    batch = integrate(robot, np.tile(q, (3, 1)), np.zeros((3, robot.nv)))
    np.testing.assert_allclose(batch, np.tile(q, (3, 1)), atol=1e-15)
    fixed = _solo12(False)[0]
    np.testing.assert_array_equal(integrate(fixed, np.ones(12), np.arange(12.0)), 1 + np.arange(12.0))


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
def test_fixed_base_derivatives_equal_pinocchio():
    robot, model = _solo12(False)
    data = model.createData()
    q, v, a = np.random.default_rng(4).uniform(-1, 1, (3, 12))
    theirs = pin.computeRNEADerivatives(model, data, q, v, a)
    ours = rnea_derivatives(robot, q, v, a)
    assert pin_urdf.rel_error(ours.dtau_dq, theirs[0]) < TOL_DQ
    assert pin_urdf.rel_error(ours.dtau_dv, theirs[1]) < TOL
    assert pin_urdf.rel_error(ours.M, pin_urdf.symmetric(theirs[2])) < TOL


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
@pytest.mark.parametrize(
    "args, message",
    [
        ((np.zeros(18), np.zeros(18), np.zeros(18)), "q must be 19 finite numbers"),
        ((np.r_[np.zeros(7), np.zeros(12)], np.zeros(18), np.zeros(18)), "quaternion q[3:7] is zero"),
        ((np.r_[0, 0, 0, 0, 0, 0, 1, np.zeros(12)], np.zeros(17), np.zeros(18)), "v must be 18 finite"),
        ((np.r_[0, 0, 0, 0, 0, 0, 1, np.zeros(12)], np.zeros(18), [np.nan] * 18), "a must be 18 finite"),
        ((np.zeros((2, 19)), np.zeros((2, 18)), np.zeros((2, 18))), "give one state"),
        ((np.r_[0, 0, 0, 0, 0, 0, 1, np.zeros(12)], "fast", np.zeros(18)), "v is not a vector of numbers"),
    ],
)
def test_derivatives_refuse_bad_input(args, message):
    robot = _solo12(True)[0]
    with pytest.raises(SymdynError, match=re.escape(message)):
        rnea_derivatives(robot, *args)
