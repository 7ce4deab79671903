"""The numeric oracle on a floating base (symdyn.oracle.floating) against Pinocchio's free flyer.

Every legged, humanoid and flying robot of example-robot-data (FLOATING) is loaded with
`symdyn.load_urdf(path, floating=True)` and built by Pinocchio with
`pinocchio.buildModelFromUrdf(path, pinocchio.JointModelFreeFlyer(), mimic=True)`; at random
configurations with random unit quaternions the oracle's rnea, mass_matrix, bias_torque +
gravity_torque, gravity_torque must equal Pinocchio's rnea, crba, nonLinearEffects and
computeGeneralizedGravity, and forward_dynamics Pinocchio's aba (within the conditioning of M: the
two round differently; Pinocchio's rnea takes the oracle's acceleration back to tau). Joints are
matched by name (as in tests/test_urdf_sweep.py, whose helpers this reuses); where Pinocchio
cannot place the mimic joints its model without them is projected onto the independent
coordinates. The worst error per file prints with `pytest -s`.
"""

from __future__ import annotations

import warnings
import zlib

import numpy as np
import pytest
from test_urdf_sweep import PINOCCHIO_MIMIC_FAILS, REFUSED, ROBOTS, _child_links, _mimics, _pin_state, _rel
from test_urdf_sweep import pytestmark as sweep_marks

import symdyn
from symdyn import SymdynError
from symdyn.rnea import (
    bias_torque,
    forward_dynamics,
    friction_torque,
    gravity_torque,
    kinetic_energy,
    mass_matrix,
)

pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")

pytestmark = sweep_marks

#: the folders of the robots whose base floats: quadrupeds, bipeds, humanoids, flying robots
FLOATING_FOLDERS = (
    "a1_description", "alex_description", "alexander_description", "anymal_b_simple_description",
    "anymal_c_simple_description", "b1_description", "bolt_description", "borinot_description",
    "centauro_description", "g1_description", "go1_description", "go2_description", "hector_description",
    "hextilt_description", "human_description", "hyq_description", "icub_description", "iris_description",
    "laikago_description", "quadruped_description", "romeo_description", "simple_humanoid_description",
    "solo_description", "talos_data",
)  # fmt: skip
#: fixed-base arms among those folders
NOT_FLOATING = {"talos_data/robots/talos_left_arm.urdf"}
FILES = (
    [
        p
        for p in sorted(ROBOTS.rglob("*.urdf"))
        if p.relative_to(ROBOTS).parts[0] in FLOATING_FOLDERS and _rel(p) not in NOT_FLOATING
    ]
    if ROBOTS
    else []
)
STATES = 2
TOL = 1e-9  # relative to the largest entry (and absolute below 1): two double-precision algorithms


def _quaternion(rng) -> np.ndarray:
    x = rng.normal(size=4)
    return x / np.linalg.norm(x)


class _Pinocchio:
    """Pinocchio's free-flyer model of a file and symdyn's vectors in its order (joints by name);
    without mimic joints (each free), projected by S, where Pinocchio cannot place them."""

    def __init__(self, path, robot, mimic: bool):
        self.model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer(), mimic)
        self.data = self.model.createData()
        joint_of = {child: joint for joint, child in _child_links(path).items()}
        self.names = [joint_of[link.name] for link in robot.links if link.mimic is None]
        self.mimic = mimic
        nv = self.model.nv
        self.S = np.zeros((nv, robot.nv))
        self.S[:6, :6] = np.eye(6)
        self.offset = np.zeros(nv)
        if not mimic:
            col = {name: 6 + k for k, name in enumerate(self.names)}
            mimics = _mimics(path)
            for j in range(2, self.model.njoints):
                joint, name = self.model.joints[j], self.model.names[j]
                master, k, o = mimics.get(name, (name, 1.0, 0.0))
                self.S[joint.idx_v, col[master]] = k
                self.offset[joint.idx_v] = o
        else:
            assert nv == robot.nv, (nv, robot.nv)

    def state(self, q, v, a):
        """Pinocchio's (q, v, a) and the projection P (NV_pin x NV) back onto symdyn's order."""
        if self.mimic:
            n = len(self.names)
            qp, vp, ap, order = _pin_state(self.model, self.names, q[7:], v[6:], a[6:])
            qp[:7], vp[:6], ap[:6] = q[:7], v[:6], a[:6]
            P = np.zeros((self.model.nv, 6 + n))
            P[:6, :6] = np.eye(6)
            P[order, 6 + np.arange(n)] = 1.0
            return qp, vp, ap, P
        qb = self.S[6:, 6:] @ q[7:] + self.offset[6:]
        qp = pin.neutral(self.model)
        qp[:7] = q[:7]
        for j in range(2, self.model.njoints):
            joint = self.model.joints[j]
            x = qb[joint.idx_v - 6]
            if joint.nq == 2:
                qp[joint.idx_q : joint.idx_q + 2] = np.cos(x), np.sin(x)
            else:
                qp[joint.idx_q] = x
        return qp, self.S @ v, self.S @ a, self.S

    def dynamics(self, q, v, a):
        """tau, M, nonlinear effects, G and aba's acceleration for (tau - its own tau), in symdyn's order."""
        qp, vp, ap, P = self.state(q, v, a)
        m, d = self.model, self.data
        M = pin.crba(m, d, qp)
        M = np.triu(M) + np.triu(M, 1).T
        tau = pin.rnea(m, d, qp, vp, ap)
        out = [P.T @ tau, P.T @ M @ P, P.T @ pin.nonLinearEffects(m, d, qp, vp)]
        out.append(P.T @ pin.computeGeneralizedGravity(m, d, qp))
        out.append(P.T @ pin.aba(m, d, qp, vp, tau) if self.mimic else None)
        return out


def _close(ours, theirs) -> float:
    scale = max(1.0, float(np.max(np.abs(theirs))))
    return float(np.max(np.abs(ours - theirs))) / scale


WORST: dict[str, float] = {}


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
def test_every_floating_robot_against_pinocchio():
    assert len(FILES) >= 35, [_rel(p) for p in FILES]
    for path in FILES:
        rel = _rel(path)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                robot = symdyn.load_urdf(path, floating=True)
        except SymdynError as exc:
            assert rel in REFUSED, f"symdyn refuses {rel}: {exc}"
            assert REFUSED[rel] in str(exc)
            WORST[rel] = float("nan")
            print(f"{rel}: refused by symdyn: {exc}")
            continue
        assert (robot.nq, robot.nv) == (robot.n + 7, robot.n + 6)
        theirs = _Pinocchio(path, robot, rel not in PINOCCHIO_MIMIC_FAILS)
        rng = np.random.default_rng(zlib.crc32(rel.encode()))
        worst = 0.0
        for _ in range(STATES):
            q = np.concatenate([rng.uniform(-1, 1, 3), _quaternion(rng), rng.uniform(-1, 1, robot.n)])
            v, a = rng.uniform(-1, 1, robot.nv), rng.uniform(-1, 1, robot.nv)
            tau, M, nle, G, a_aba = theirs.dynamics(q, v, a)
            ours = [
                (symdyn.rnea(robot, q, v, a, friction=False), tau),
                (mass_matrix(robot, q), M),
                (bias_torque(robot, q, v) + gravity_torque(robot, q), nle),
                (gravity_torque(robot, q), G),
            ]
            worst = max(worst, *(_close(x, y) for x, y in ours))
            if a_aba is not None:
                fd = forward_dynamics(robot, q, v, tau + friction_torque(robot, v))
                # backward error: Pinocchio's inverse dynamics takes our acceleration back to tau;
                # forward error: ABA's acceleration, within what the conditioning of M allows
                worst = max(worst, _close(theirs.dynamics(q, v, fd)[0], tau))
                cond = np.linalg.cond(M)
                assert _close(fd, a_aba) < 1e-12 * cond, (rel, _close(fd, a_aba), cond)
        WORST[rel] = worst
        print(f"{rel}: {robot.n} joints + free flyer, max relative error {worst:.1e}")
        assert worst < TOL, f"{rel}: {worst:.2e}"


def test_energy_and_free_flyer_conventions():
    """T = 1/2 v^T M v; M does not depend on the base pose; G rotates with the base."""
    path = ROBOTS / "solo_description/robots/solo12.urdf"
    robot = symdyn.load_urdf(path, floating=True)
    rng = np.random.default_rng(3)
    q = np.concatenate([rng.normal(size=3), _quaternion(rng), rng.uniform(-1, 1, 12)])
    v = rng.normal(size=18)
    M = mass_matrix(robot, q)
    assert np.isclose(kinetic_energy(robot, q, v), 0.5 * v @ M @ v)
    moved = q.copy()
    moved[:7] = [*rng.normal(size=3), *_quaternion(rng)]
    np.testing.assert_allclose(mass_matrix(robot, moved), M, atol=1e-12)
    # the base rows of G: the weight m g seen in the base frame, R^T (0, 0, 9.81) m
    x, y, z, w = q[3:7]
    R = pin.Quaternion(w, x, y, z).toRotationMatrix()
    mass = M[0, 0]
    np.testing.assert_allclose(gravity_torque(robot, q)[:3], R.T @ [0, 0, 9.81 * mass], atol=1e-10)
