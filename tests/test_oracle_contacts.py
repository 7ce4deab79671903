"""The oracle's contact dynamics (symdyn.oracle.contacts, .contact_kinematics,
.contact_derivatives) against Pinocchio and against identities.

Robots of example-robot-data matched with Pinocchio's models as tests/test_oracle_floating.py does
(bench/pin_urdf.py: free flyer, joints by name): Solo-12 on its four feet (and subsets through
the mask), ANYmal on its four feet, Talos on both soles as 6d contacts, and the fixed-base Z1 arm
with a 6d contact at its gripper. Pinocchio's side: RigidConstraintModel (CONTACT_3D with
LOCAL_WORLD_ALIGNED for a point, CONTACT_6D with LOCAL for a 6d contact) on the frame's joint and
placement, constraintDynamics, impulseDynamics, computeConstraintDynamicsDerivatives and
computeImpulseDynamicsDerivatives with a proximal damping of zero; Jc and gamma against
getFrameJacobian and getFrameClassicalAcceleration / getFrameAcceleration. Pinocchio has no joint
friction: symdyn's tau is Pinocchio's plus the URDF's friction at qd (as bench/pin_urdf.py does),
and the viscous part's derivative D (read from the links) is added to Pinocchio's d/dqd. Its
computeImpulseDynamicsDerivatives gives the derivative of the jump qd+ - qd in qd (ddq_dv):
d qd+ / d qd is that plus the identity. The worst errors print with `pytest -s`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cache

import numpy as np
import pytest
from test_urdf_sweep import ROBOTS, pin_urdf
from timebound import within

import symdyn
from symdyn import SymdynError
from symdyn.oracle.centroidal import centroidal
from symdyn.oracle.contacts import (
    contact_drift,
    contact_forward_dynamics,
    contact_forward_dynamics_derivatives,
    contact_jacobian,
    impulse_dynamics,
    impulse_dynamics_derivatives,
)
from symdyn.rnea import forward_dynamics, friction_torque, gravity_torque, mass_matrix, rnea

pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")

pytestmark = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")

TOL = 1e-9  # relative to the largest entry (and absolute below 1): two double-precision solves
#: d/dq by the oracle's five-point difference through the KKT solve: seen at most 3.3e-10 (Solo-12,
#: four feet); the differences' truncation and rounding are 1e-12 of M's scale, the rest the KKT
#: system's conditioning
TOL_DQ = 1e-8
FEET = {
    "solo12": ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"),
    "anymal": ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"),
}
TALOS = "talos_data/robots/talos_reduced.urdf"
#: name: (file, floating, contacts)
CASES = {
    "solo12": ("solo_description/robots/solo12.urdf", True, tuple((f, "point") for f in FEET["solo12"])),
    "anymal": (
        "anymal_b_simple_description/robots/anymal.urdf",
        True,
        tuple((f, "point") for f in FEET["anymal"]),
    ),
    "talos": (TALOS, True, (("left_sole_link", "6d"), ("right_sole_link", "6d"))),
    "z1": ("z1_description/urdf/z1.urdf", False, (("gripperStator", "6d"),)),
    # one of each kind, rows 0-5 a 6d sole and 6-8 a point: the stacking order
    "talos_mixed": (TALOS, True, (("right_sole_link", "6d"), ("left_sole_link", "point"))),
}
#: (case, mask): every contact, and Solo-12's subsets (two diagonal feet, three feet, none)
RUNS = [
    ("solo12", None),
    ("solo12", (1, 0, 0, 1)),
    ("solo12", (0, 1, 1, 1)),
    ("solo12", (0, 0, 0, 0)),
    ("anymal", None),
    ("talos", None),
    ("talos_mixed", None),
    ("z1", None),
]
KIND = {"point": 3, "6d": 6}


@dataclass(frozen=True)
class Case:
    """symdyn's robot, Pinocchio's projected model and the contacts."""

    robot: object
    theirs: object
    contacts: tuple

    def rows(self, mask) -> np.ndarray:
        """The active contacts' rows among the NLAMBDA."""
        out, start = [], 0
        for k, (_, kind) in enumerate(self.contacts):
            if mask is None or mask[k]:
                out += range(start, start + KIND[kind])
            start += KIND[kind]
        return np.array(out, dtype=int)


@cache
def case(name: str) -> Case:
    path, floating, contacts = CASES[name]
    if name == "talos_mixed":
        base = case("talos")
        return Case(base.robot, base.theirs, contacts)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = symdyn.load_urdf(ROBOTS / path, floating=floating)
    return Case(robot, pin_urdf.Projected.of(ROBOTS / path, robot), contacts)


@cache
def state(name: str, seed: int = 0):
    """A random (q, qd, tau) of symdyn's robot (unit quaternion; entries in [-1, 1])."""
    robot = case(name).robot
    rng = np.random.default_rng(seed)
    q, v, tau = pin_urdf.random_state(robot, rng)
    if not robot.floating:
        q, v, tau = q[7:], rng.uniform(-1, 1, robot.n), rng.uniform(-1, 1, robot.n)
    return q, v, tau


def rel(ours, theirs) -> float:
    return pin_urdf.rel_error(ours, theirs)


def _constraints(c: Case, mask):
    """Pinocchio's constraint models and datas of the active contacts."""
    model = c.theirs.model
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    for k, (frame, kind) in enumerate(c.contacts):
        if mask is not None and not mask[k]:
            continue
        f = model.frames[model.getFrameId(frame, pin.FrameType.BODY)]
        if kind == "point":
            kinds = (pin.ContactType.CONTACT_3D, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        else:
            kinds = (pin.ContactType.CONTACT_6D, pin.ReferenceFrame.LOCAL)
        m = pin.RigidConstraintModel(kinds[0], model, f.parentJoint, f.placement, kinds[1])
        models.append(m)
        datas.append(m.createData())
    return models, datas


def _viscous(robot) -> np.ndarray:
    """dF/dqd from the links' viscous coefficients (no mimic joints in these robots)."""
    d = [float(link.friction.viscous) for link in robot.links]
    return np.diag(([0.0] * 6 if robot.floating else []) + d)


@cache
def pinocchio(name: str, mask, seed: int = 0) -> dict[str, np.ndarray]:
    """Pinocchio's answers in symdyn's coordinates and rows (zero rows for free contacts)."""
    c = case(name)
    S, model, data = c.theirs.S, c.theirs.model, c.theirs.data
    q, v, tau = state(name, seed)
    qp, vp, _ = c.theirs.state(q, v, v)
    r, nl = c.rows(mask), c.rows(None).size
    models, datas = _constraints(c, mask)
    prox = pin.ProximalSettings(1e-14, 0.0, 1)
    pin.initConstraintDynamics(model, data, models, datas)
    out = {}

    def rows(x):  # Pinocchio's active rows (NACTIVE, ...) into NLAMBDA rows
        full = np.zeros((nl,) + x.shape[1:])
        full[r] = x
        return full

    if r.size:
        out["qdd"] = S.T @ pin.constraintDynamics(model, data, qp, vp, S @ tau, models, datas, prox)
        out["lambda"] = rows(data.lambda_c.copy())
        d = pin.computeConstraintDynamicsDerivatives(model, data, models, datas, prox)
        names = ("dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dlambda_dq", "dlambda_dqd", "dlambda_dtau")
        for k, (key, x) in enumerate(zip(names, d, strict=True)):
            out[key] = S.T @ x @ S if k < 3 else rows(x @ S)
        D = _viscous(c.robot)
        out["dqdd_dqd"] = out["dqdd_dqd"] - out["dqdd_dtau"] @ D
        out["dlambda_dqd"] = out["dlambda_dqd"] - out["dlambda_dtau"] @ D
        out["qd_plus"] = S.T @ pin.impulseDynamics(model, data, qp, vp, models, datas, 0.5, prox)
        out["impulse"] = rows(data.impulse_c.copy())
        pin.computeImpulseDynamicsDerivatives(model, data, models, datas, 0.5, prox)
        out["dqd_plus_dq"] = S.T @ data.ddq_dq @ S
        out["dqd_plus_dqd"] = np.eye(c.robot.nv) + S.T @ data.ddq_dv @ S
        out["dimpulse_dq"], out["dimpulse_dqd"] = rows(data.dlambda_dq @ S), rows(data.dlambda_dv @ S)
    else:  # no contact: the unconstrained dynamics
        out["qdd"] = S.T @ pin.aba(model, data, qp, vp, S @ tau)
        out["lambda"] = np.zeros(nl)
    # Jc and gamma of every contact, Pinocchio's frame functions
    pin.computeJointJacobians(model, data, qp)
    pin.forwardKinematics(model, data, qp, vp, 0 * vp)
    pin.updateFramePlacements(model, data)
    J, gamma = [], []
    for frame, kind in c.contacts:
        f = model.getFrameId(frame, pin.FrameType.BODY)
        if kind == "point":
            J.append(pin.getFrameJacobian(model, data, f, pin.LOCAL_WORLD_ALIGNED)[:3])
            gamma.append(pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).linear)
        else:
            J.append(pin.getFrameJacobian(model, data, f, pin.LOCAL))
            gamma.append(pin.getFrameAcceleration(model, data, f, pin.LOCAL).vector)
    out["Jc"], out["gamma"] = np.vstack(J) @ S, np.concatenate(gamma)
    return out


@cache
def ours(name: str, mask, seed: int = 0) -> dict[str, np.ndarray]:
    """The oracle's answers at the same state (tau plus the joints' friction: module docstring)."""
    c = case(name)
    q, v, tau = state(name, seed)
    tau = tau + friction_torque(c.robot, v)
    out = {"Jc": contact_jacobian(c.robot, c.contacts, q), "gamma": contact_drift(c.robot, c.contacts, q, v)}
    out["qdd"], out["lambda"] = contact_forward_dynamics(c.robot, c.contacts, q, v, tau, mask)
    if mask is None or any(mask):
        out |= contact_forward_dynamics_derivatives(c.robot, c.contacts, q, v, tau, mask)
        out["qd_plus"], out["impulse"] = impulse_dynamics(c.robot, c.contacts, q, v, mask, restitution=0.5)
        out |= impulse_dynamics_derivatives(c.robot, c.contacts, q, v, mask, restitution=0.5)
    return out


@pytest.mark.parametrize(("name", "mask"), RUNS, ids=lambda x: x if isinstance(x, str) else str(x))
def test_the_oracle_agrees_with_pinocchio(name, mask):
    theirs, mine = pinocchio(name, mask), ours(name, mask)
    errors = {key: rel(mine[key], theirs[key]) for key in theirs}
    print(f"{name} {mask}: " + " ".join(f"{k} {e:.0e}" for k, e in errors.items()))
    bad = {k: e for k, e in errors.items() if not e < (TOL_DQ if k.endswith("_dq") else TOL)}
    assert not bad, (name, mask, bad)


@pytest.mark.parametrize(
    ("name", "mask"), RUNS[:3] + RUNS[4:], ids=lambda x: x if isinstance(x, str) else str(x)
)
def test_identities(name, mask):
    """The KKT rows, zero free rows, the impulse's restitution law and its energy."""
    c = case(name)
    robot, q, v, tau = c.robot, *state(name)
    got = ours(name, mask)
    J, gamma, qdd, lam = got["Jc"], got["gamma"], got["qdd"], got["lambda"]
    r = c.rows(mask)
    free = np.setdiff1d(np.arange(len(lam)), r)
    h = rnea(robot, q, v, np.zeros(robot.nv))  # b + F
    M = mass_matrix(robot, q)
    tau_f = tau + friction_torque(robot, v)
    scale = max(1.0, np.abs(tau_f).max(), np.abs(h).max(), np.abs(J.T @ lam).max())
    assert np.abs(M @ qdd + h - tau_f - J.T @ lam).max() < 1e-10 * scale
    assert np.abs(J[r] @ qdd + gamma[r]).max() < 1e-10 * max(1.0, np.abs(gamma).max(), np.abs(qdd).max())
    assert not np.any(lam[free]) and not np.any(got["impulse"][free])
    for e in (0.0, 0.5, 1.0):
        plus, P = impulse_dynamics(robot, c.contacts, q, v, mask, restitution=e)
        assert not np.any(P[free])
        np.testing.assert_allclose(J[r] @ plus, -e * J[r] @ v, atol=1e-12 * max(1.0, np.abs(v).max()))
        np.testing.assert_allclose(M @ (plus - v), J.T @ P, atol=1e-11 * max(1.0, np.abs(P).max()))
        before, after = v @ M @ v / 2, plus @ M @ plus / 2
        assert after <= before * (1 + 1e-12)  # no energy gained
        if e == 1.0:
            assert after == pytest.approx(before, rel=1e-10)  # elastic


def test_the_contact_forces_carry_the_robot():
    """Solo-12 on its four feet: the forces on the robot sum to m (a_com - g) (Newton on the whole
    robot, the centre of mass's acceleration from the oracle's centroidal momentum), and at
    rest with the joints holding a static stance they sum to the weight exactly."""
    c = case("solo12")
    robot, (q, v, tau) = c.robot, state("solo12")
    tau = np.r_[np.zeros(6), tau[6:]]  # no force on the base but the contacts'
    qdd, lam = contact_forward_dynamics(robot, c.contacts, q, v, tau)
    cen = centroidal(robot, q, v)
    total = lam.reshape(4, 3).sum(0)  # world-aligned rows: the forces add up
    weight = cen.mass * np.array([0.0, 0.0, -9.81])
    np.testing.assert_allclose(
        total, cen.Ag[:3] @ qdd + cen.drift[:3] - weight, atol=1e-10 * np.abs(total).max()
    )
    # standing: qd = 0 and the joint torques that make qdd = 0 with the least-norm forces
    J = contact_jacobian(robot, c.contacts, q)
    G = gravity_torque(robot, q)
    lam0 = np.linalg.lstsq(J[:, :6].T, G[:6], rcond=None)[0]  # the base rows: G_base = J_base^T lambda
    held = np.r_[np.zeros(6), G[6:] - J[:, 6:].T @ lam0]
    qdd, lam = contact_forward_dynamics(robot, c.contacts, q, np.zeros(robot.nv), held)
    assert np.abs(qdd).max() < 1e-9
    np.testing.assert_allclose(lam, lam0, atol=1e-9)
    np.testing.assert_allclose(lam.reshape(4, 3).sum(0), -weight, atol=1e-12 * np.abs(weight).max())


def test_a_redundant_set_needs_damping():
    """Two point contacts at one frame: Jc M^-1 Jc^T is singular. Without damping the oracle
    refuses; with a damping mu it gives Pinocchio's forwardDynamics(..., damping=mu) and
    impulseDynamics(..., damping=mu), and the two rows share the foot's force."""
    c = case("solo12")
    robot, (q, v, tau) = c.robot, state("solo12")
    twice = (("FL_FOOT", "point"), ("FL_FOOT", "point"), ("HR_FOOT", "point"))
    with pytest.raises(SymdynError, match="rows are dependent"):
        contact_forward_dynamics(robot, twice, q, v, tau)
    with pytest.raises(SymdynError, match="rows are dependent"):
        impulse_dynamics(robot, twice, q, v)
    model, data, S = c.theirs.model, c.theirs.data, c.theirs.S
    qp, vp, _ = c.theirs.state(q, v, v)
    J = contact_jacobian(robot, twice, q) @ S.T  # Pinocchio's columns
    gamma = contact_drift(robot, twice, q, v)
    M = mass_matrix(robot, q)
    largest = np.linalg.eigvalsh(J @ S @ np.linalg.solve(M, S.T @ J.T))[-1]
    summed = {}
    for mu in (1e-8, 1e-3):
        tol = 1e-9 + 1e-15 * largest / mu  # two solves of a matrix of condition number largest / mu
        qdd, lam = contact_forward_dynamics(robot, twice, q, v, tau + friction_torque(robot, v), damping=mu)
        expected = S.T @ pin.forwardDynamics(model, data, qp, vp, S @ tau, J, gamma, mu)
        assert rel(qdd, expected) < tol and rel(lam, data.lambda_c) < tol
        np.testing.assert_allclose(lam[:3], lam[3:6], atol=tol * np.abs(lam).max())  # shared evenly
        plus, P = impulse_dynamics(robot, twice, q, v, damping=mu)
        assert rel(plus, S.T @ pin.impulseDynamics(model, data, qp, vp, J, 0.0, mu)) < tol
        assert rel(P, data.impulse_c) < tol
        summed[mu] = lam[:3] + lam[3:6]
    # the damping moves the forces by about mu over the smallest nonzero eigenvalue (docs/contacts.md)
    single = contact_forward_dynamics(robot, twice[1:], q, v, tau + friction_torque(robot, v))[1][:3]
    assert rel(summed[1e-8], single) < 1e-6
    assert 1e-5 < rel(summed[1e-3], single) < 1e-2


@dataclass(frozen=True)
class _Contact:  # what symdyn.model.contacts.Contact offers the oracle
    name: str
    frame: str
    kind: str


def test_contacts_as_objects_and_frames_on_the_base():
    c = case("z1")
    robot, (q, v, tau) = c.robot, state("z1")
    as_objects = [_Contact("tool", "gripperStator", "6d")]
    np.testing.assert_array_equal(
        contact_forward_dynamics(robot, as_objects, q, v, tau)[0],
        contact_forward_dynamics(robot, c.contacts, q, v, tau)[0],
    )
    # a frame on the fixed base never moves: zero rows, refused undamped, lambda 0 when damped
    assert not np.any(contact_jacobian(robot, [("link00", "6d")], q))
    with pytest.raises(SymdynError, match="rows are dependent"):
        contact_forward_dynamics(robot, [("link00", "6d")], q, v, tau)
    qdd, lam = contact_forward_dynamics(robot, [("link00", "6d")], q, v, tau, damping=1e-6)
    assert not np.any(lam)
    np.testing.assert_allclose(qdd, forward_dynamics(robot, q, v, tau), atol=1e-12)


BAD = [
    ({"contacts": "FL_FOOT"}, "list of"),
    ({"contacts": [("NOPE", "point")]}, "NOPE"),
    ({"contacts": [("FL_FOOT", "line")]}, "expected 'point' or '6d'"),
    ({"contacts": [("FL_FOOT",)]}, "not a \\(frame, kind\\) pair"),
    ({"contacts": [(3, "point")]}, "not a name"),
    ({"contacts": [("FL\nFOOT", "point")]}, "unknown frame 'FL\\\\nFOOT'"),
    ({"contacts": [("x" * 100_000, "point")]}, "no frame is named 'xxx"),
    ({"contacts": [("FL_FOOT", "\x1b[2J" * 50_000)]}, "has kind '\\\\x1b"),
    ({"contacts": [list(range(100_000))]}, "not a \\(frame, kind\\) pair: \\[0, 1"),
    ({"active": [1] * 100_000}, "4 entries of 0 or 1"),
    ({"active": [1, 0]}, "4 entries of 0 or 1"),
    ({"active": [1, 0.5, 1, 1]}, "0 or 1"),
    ({"active": [1, float("nan"), 1, 1]}, "0 or 1"),
    ({"active": "1111"}, "0 or 1"),
    ({"damping": -1.0}, "damping"),
    ({"damping": float("nan")}, "damping"),
    ({"damping": "x"}, "damping must be a number"),
    ({"q": np.zeros(5)}, "q has 5 entries"),
    ({"q": np.r_[np.zeros(3), np.zeros(4), np.zeros(12)]}, "quaternion"),
    ({"qd": np.full(18, np.inf)}, "qd has entries that are not finite"),
    ({"tau": np.full(18, np.nan)}, "tau has entries that are not finite"),
    ({"q": "many"}, "q must hold numbers"),
    ({"q": None}, "one state"),  # two states: set below
]


@pytest.mark.parametrize(("change", "match"), BAD, ids=[str(i) for i in range(len(BAD))])
def test_bad_arguments_are_refused_in_one_line(change, match):
    c = case("solo12")
    q, v, tau = state("solo12")
    args = {"contacts": c.contacts, "q": q, "qd": v, "tau": tau, "active": None, "damping": 0.0} | change
    if args["q"] is None:
        args["q"], args["qd"], args["tau"] = np.tile(q, (2, 1)), np.tile(v, (2, 1)), np.tile(tau, (2, 1))
    with within(10), pytest.raises(SymdynError, match=match) as info:
        contact_forward_dynamics(c.robot, **args)
    message = str(info.value)
    assert "\n" not in message and "\x1b" not in message and len(message) < 1000, message[:2000]


def test_bad_restitution_and_impulse_arguments():
    c = case("solo12")
    q, v, _ = state("solo12")
    for e, match in ((1.5, r"restitution must be in \[0, 1\]"), (-0.1, "restitution"), (None, "restitution")):
        with pytest.raises(SymdynError, match=match):
            impulse_dynamics(c.robot, c.contacts, q, v, restitution=e)
        with pytest.raises(SymdynError, match=match):
            impulse_dynamics_derivatives(c.robot, c.contacts, q, v, restitution=e)
    with pytest.raises(SymdynError, match="active"):
        contact_forward_dynamics_derivatives(c.robot, c.contacts, q, v, v, active=[2, 0, 0, 0])
