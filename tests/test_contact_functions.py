"""The generated contact functions (symdyn.codegen.contact_functions), in NumPy and in strict C,
against Pinocchio (getFrameJacobian, getFrameClassicalAcceleration / getFrameAcceleration,
constraintDynamics, impulseDynamics, computeConstraintDynamicsDerivatives,
computeImpulseDynamicsDerivatives) and identities:

- the xArm 7 (fixed base, 7 joints, viscous and Coulomb friction) with a 6d contact at its tool
  link_eef: every function of the groups contacts and contact_derivatives; the free contact
  (mask 0) gives Pinocchio's aba and zero forces;
- Solo-12 on a free flyer with its four feet as point contacts, and the subset FL + HR by the
  mask: Jc, the drift, the constrained and impulse dynamics (restitution 0 and 0.5), the KKT
  residuals;
- a redundant set on the UR5's tool0 (two point contacts and a 6d one: 12 rows for 6 joints):
  finite values (the damped solve), the same accelerations and total wrench as the 6d contact
  alone;
- Baumgarte's functions (group contact_baumgarte) on the xArm 7 (6d) and Solo-12 (points): the
  position error and the stabilised dynamics against the oracle's own (symdyn.oracle.
  contact_baumgarte), gains 0 giving contact_forward_dynamics, the stabilised constraint on the
  active rows and lam 0 on the free ones;
- a small floating robot's derivatives (point contacts on its base and its hand, or a 6d one at
  the hand) against central differences of its own generated functions, q perturbed on the
  manifold (q (+) dq);
- that robot's three contact groups in CasADi, JAX and Octave against its NumPy module (the
  matrix layouts, the mask, the restitution and the anchors of each target's printer).

Pinocchio's computeImpulseDynamicsDerivatives gives d(qd_plus - qd)/dqd (its ddq_dv), symdyn's
dqd_plus_dqd is d qd_plus/dqd: the two differ by the identity. The Solo-12 and Talos derivatives
against Pinocchio are measured by bench/contacts_agreement.py (too slow to derive for the suite).
"""

from __future__ import annotations

import ctypes
import importlib.util
import warnings
from functools import cache

import numpy as np
import pytest
from cbuild import compile_shared, compilers, write_files
from octave_run import OCTAVE, octave_numbers, octave_values

import symdyn
from symdyn.algorithms.contact_dynamics import DAMPING
from symdyn.codegen import c as c_target
from symdyn.codegen import casadi as casadi_target
from symdyn.codegen import context
from symdyn.codegen import jax as jax_target
from symdyn.codegen import matlab as matlab_target
from symdyn.codegen import python as numpy_target
from symdyn.oracle.contact_baumgarte import contact_error, contact_forward_dynamics_baumgarte
from symdyn.oracle.contact_kinematics import contact_poses, contact_rows
from symdyn.oracle.derivatives import integrate
from symdyn.regenerate import example_robot_data_folder

pin = pytest.importorskip("pinocchio")
FOLDER = example_robot_data_folder()
pytestmark = pytest.mark.skipif(FOLDER is None, reason="example-robot-data is not installed")
MU = float(DAMPING)
RTOL = 1e-7  # the damping mu = 1e-10 moves lambda by about mu |A0^-1| (symdyn.algorithms.contact_dynamics)

ROBOTS = {
    "xarm7": (
        "xarm_description/urdf/xarm7.urdf",
        False,
        ("link_eef:6d",),
        ("contacts", "contact_derivatives", "contact_baumgarte"),
    ),
    "solo": (
        "solo_description/robots/solo12.urdf",
        True,
        ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"),
        ("contacts", "contact_baumgarte"),
    ),
    "ur5": (
        "ur_description/urdf/ur5_robot.urdf",
        False,
        ("tool0", {"name": "again", "frame": "tool0"}, {"name": "held", "frame": "tool0", "type": "6d"}),
        ("contacts",),
    ),
}


def numpy_module(ctx, directory):
    """The NumPy target's module of `ctx`, written to `directory` and imported."""
    ((file, text),) = numpy_target.render(ctx).items()
    (directory / file).write_text(text)
    spec = importlib.util.spec_from_file_location(f"contacts_{ctx.name}", directory / file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Generated:
    """One robot's generated contact functions in NumPy and C: call(target, name, *inputs)."""

    def __init__(self, key: str, directory, c: bool = True) -> None:
        path, floating, contacts, groups = ROBOTS[key]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            self.robot = symdyn.load_urdf(FOLDER / path, floating=floating, contacts=list(contacts))
            self.ctx = context(self.robot, functions=groups)
        self.path, self.floating = FOLDER / path, floating
        self.specs = {f.name: f for f in self.ctx.functions}
        self.numpy = numpy_module(self.ctx, directory)
        self.lib = None
        if c and compilers():
            paths = write_files(c_target.render(self.ctx), directory)
            self.lib = ctypes.CDLL(
                str(compile_shared([p for p in paths if p.suffix == ".c"], directory / "l.so"))
            )

    def call(self, target: str, name: str, *args) -> list[np.ndarray]:
        f = self.specs[name]
        if target == "numpy":
            out = getattr(self.numpy, name)(*args)
            return [np.asarray(o) for o in (out if isinstance(out, tuple) else (out,))]
        ptr = ctypes.POINTER(ctypes.c_double)
        given = [np.ascontiguousarray(a, dtype=np.float64) for a in args] + [np.zeros(1)]
        outs = [np.full((r.rows, r.cols) if r.matrix else r.rows, np.nan) for r in f.results]
        fn = getattr(self.lib, f"{self.ctx.name}_{name}")
        fn.restype = None
        fn(*[a.ctypes.data_as(ptr) for a in given + outs])
        return outs

    def targets(self) -> list[str]:
        return ["numpy", "c"] if self.lib is not None else ["numpy"]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    @cache
    def make(key: str) -> Generated:
        return Generated(key, tmp_path_factory.mktemp(key))

    return make


def _close(got, want, what: str, rtol: float = RTOL) -> float:
    err = float(np.abs(np.reshape(got, np.shape(want)) - want).max() / max(1.0, np.abs(want).max()))
    assert err < rtol, f"{what}: {err:.2e}"
    return err


def _model(g: Generated):
    if g.floating:
        return pin.buildModelFromUrdf(str(g.path), pin.JointModelFreeFlyer())
    return pin.buildModelFromUrdf(str(g.path))


def _constraints(model, contacts):
    """Pinocchio's constraint models and datas of symdyn contacts (point: 3D world-aligned, 6d: LOCAL)."""
    cms = []
    for c in contacts:
        frame = model.frames[model.getFrameId(c.frame)]
        if c.kind == "point":
            kind, ref = pin.ContactType.CONTACT_3D, pin.LOCAL_WORLD_ALIGNED
        else:
            kind, ref = pin.ContactType.CONTACT_6D, pin.LOCAL
        cms.append(pin.RigidConstraintModel(kind, model, frame.parentJoint, frame.placement, ref))
    cms = pin.StdVec_RigidConstraintModel(cms)
    return cms, pin.StdVec_RigidConstraintData([c.createData() for c in cms])


def _rows(contacts, active) -> np.ndarray:
    """The indices of the rows of the active contacts."""
    out, k = [], 0
    for c, a in zip(contacts, active, strict=True):
        if a:
            out += list(range(k, k + c.rows))
        k += c.rows
    return np.array(out, dtype=int)


def _friction(g: Generated, v) -> tuple[np.ndarray, np.ndarray]:
    """(F(v), dF/dv diagonal) of the robot's joint friction (Pinocchio's dynamics have none)."""
    nb = 6 if g.floating else 0
    visc = np.array([0.0] * nb + [float(link.friction.viscous) for link in g.robot.links])
    coul = np.array([0.0] * nb + [float(link.friction.coulomb) for link in g.robot.links])
    return visc * v + coul * np.sign(v), visc


def _pinocchio(g: Generated, q, v, tau, active, e=0.0) -> dict:
    """Pinocchio's solution at one state, inactive rows zero (friction moved into tau)."""
    model = _model(g)
    data = model.createData()
    contacts = [c for c, a in zip(g.robot.contacts, active, strict=True) if a]
    rows = _rows(g.robot.contacts, active)
    m = sum(c.rows for c in g.robot.contacts)
    F, visc = _friction(g, v)
    prox = pin.ProximalSettings(1e-14, 1e-14, 0, 1)
    out = {}
    if not contacts:
        out["qdd"] = pin.aba(model, data, q, v, tau - F)
        out["lam"] = np.zeros(m)
        return out
    cms, cds = _constraints(model, contacts)
    pin.initConstraintDynamics(model, data, cms, cds)
    out["qdd"] = pin.constraintDynamics(model, data, q, v, tau - F, cms, cds, prox).copy()
    out["lam"] = np.zeros(m)
    out["lam"][rows] = data.lambda_c
    pin.computeConstraintDynamicsDerivatives(model, data, cms, cds, prox)
    full = lambda block: _scatter(block, rows, m)  # noqa: E731
    out["dqdd_dq"], out["dqdd_dtau"] = data.ddq_dq.copy(), data.ddq_dtau.copy()
    out["dqdd_dqd"] = data.ddq_dv - data.ddq_dtau @ np.diag(visc)
    out["dlambda_dq"], out["dlambda_dtau"] = full(data.dlambda_dq), full(data.dlambda_dtau)
    out["dlambda_dqd"] = full(data.dlambda_dv - data.dlambda_dtau @ np.diag(visc))
    pin.initConstraintDynamics(model, data, cms, cds)
    out["qd_plus"] = pin.impulseDynamics(model, data, q, v, cms, cds, e, prox).copy()
    out["impulse"] = _scatter(data.impulse_c, rows, m)
    pin.computeImpulseDynamicsDerivatives(model, data, cms, cds, e, prox)
    out["dqd_plus_dq"], out["dqd_plus_dqd"] = data.ddq_dq.copy(), data.ddq_dv + np.eye(model.nv)
    out["dimpulse_dq"], out["dimpulse_dqd"] = full(data.dlambda_dq), full(data.dlambda_dv)
    return out


def _scatter(block, rows, m):
    block = np.asarray(block)
    out = np.zeros((m, *block.shape[1:]))
    out[rows] = block
    return out


def _kinematics(g: Generated, q, v) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's Jc and gamma of the robot's contacts (the contract's conventions)."""
    model = _model(g)
    data = model.createData()
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J, drift = [], []
    for c in g.robot.contacts:
        fid = model.getFrameId(c.frame)
        if c.kind == "point":
            J.append(pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:3])
            drift.append(pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear)
        else:
            J.append(pin.getFrameJacobian(model, data, fid, pin.LOCAL))
            acc = pin.getFrameAcceleration(model, data, fid, pin.LOCAL)
            drift.append(np.r_[acc.linear, acc.angular])
    return np.vstack(J), np.concatenate(drift)


def _state(g: Generated, seed: int):
    model = _model(g)
    pin.seed(seed)
    rng = np.random.default_rng(seed)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    return q, rng.normal(size=model.nv), 5 * rng.normal(size=model.nv)


def test_the_arm_with_a_6d_contact_at_its_tool_agrees_with_pinocchio(built):
    g = built("xarm7")
    for target in g.targets():
        for seed in (1, 2):
            q, v, tau = _state(g, seed)
            Jc, gamma = _kinematics(g, q, v)
            _close(g.call(target, "contact_jacobian", q)[0], Jc, f"{target} Jc")
            _close(g.call(target, "contact_drift", q, v)[0], gamma, f"{target} gamma")
            want = _pinocchio(g, q, v, tau, [1])
            qdd, lam = g.call(target, "contact_forward_dynamics", q, v, tau, [1.0])
            _close(qdd, want["qdd"], f"{target} qdd")
            _close(lam, want["lam"], f"{target} lam")
            qd_plus, imp = g.call(target, "impulse_dynamics", q, v, [1.0], [0.0])
            _close(qd_plus, want["qd_plus"], f"{target} qd_plus")
            _close(imp, want["impulse"], f"{target} impulse")
            names = ("dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dlambda_dq", "dlambda_dqd", "dlambda_dtau")
            got = g.call(target, "contact_forward_dynamics_derivatives", q, v, tau, [1.0])
            for name, x in zip(names, got, strict=True):
                _close(x, want[name], f"{target} {name}", 1e-6)
            names = ("dqd_plus_dq", "dqd_plus_dqd", "dimpulse_dq", "dimpulse_dqd")
            got = g.call(target, "impulse_dynamics_derivatives", q, v, [1.0], [0.0])
            for name, x in zip(names, got, strict=True):
                _close(x, want[name], f"{target} {name}", 1e-6)
        # the free contact: Pinocchio's aba, no force, no derivative of the force
        want = _pinocchio(g, q, v, tau, [0])
        qdd, lam = g.call(target, "contact_forward_dynamics", q, v, tau, [0.0])
        _close(qdd, want["qdd"], f"{target} free qdd")
        assert np.all(lam == 0)
        qd_plus, imp = g.call(target, "impulse_dynamics", q, v, [0.0], [0.0])
        assert np.all(imp == 0) and np.allclose(qd_plus, v, rtol=0, atol=1e-12)
        derivatives = g.call(target, "contact_forward_dynamics_derivatives", q, v, tau, [0.0])
        assert all(np.all(d == 0) for d in derivatives[3:])


@pytest.mark.parametrize("active", [(1, 1, 1, 1), (1, 0, 0, 1)])
def test_solo_on_its_feet_agrees_with_pinocchio(built, active):
    g = built("solo")
    model = _model(g)
    data = model.createData()
    rows = _rows(g.robot.contacts, active)
    mask = np.array(active, dtype=float)
    for target in g.targets():
        q, v, tau = _state(g, 5)
        tau[:6] = 0  # the base is not actuated
        Jc, gamma = _kinematics(g, q, v)
        _close(g.call(target, "contact_jacobian", q)[0], Jc, f"{target} Jc")
        _close(g.call(target, "contact_drift", q, v)[0], gamma, f"{target} gamma")
        want = _pinocchio(g, q, v, tau, active)
        qdd, lam = g.call(target, "contact_forward_dynamics", q, v, tau, mask)
        _close(qdd, want["qdd"], f"{target} qdd")
        _close(lam, want["lam"], f"{target} lam")
        free = np.setdiff1d(np.arange(12), rows)
        assert np.all(lam[free] == 0)
        # the KKT residuals: M qdd + b - tau - Jc^T lam = 0 and, on the active rows, Jc qdd + gamma =
        # -mu lam (the damped solve: (A0 + mu I) lam = -(gamma + Jc M^-1 (tau - b)))
        _close(pin.rnea(model, data, q, v, qdd) - tau - Jc.T @ lam, np.zeros(18), f"{target} dynamics", 1e-9)
        _close((Jc @ qdd + gamma + MU * lam)[rows], np.zeros(len(rows)), f"{target} constraint", 1e-10)
        for e in (0.0, 0.5):
            want = _pinocchio(g, q, v, tau, active, e)
            qd_plus, imp = g.call(target, "impulse_dynamics", q, v, mask, [e])
            _close(qd_plus, want["qd_plus"], f"{target} qd_plus e={e}")
            _close(imp, want["impulse"], f"{target} impulse e={e}")
            assert np.all(imp[free] == 0)
            M = pin.crba(model, data, q)
            _close(M @ (qd_plus - v) - Jc.T @ imp, np.zeros(18), f"{target} impulse balance", 1e-9)
            _close((Jc @ qd_plus + MU * imp)[rows], -e * (Jc @ v)[rows], f"{target} restitution", 1e-10)


def test_a_redundant_set_is_solved_damped_and_finite(built):
    g = built("ur5")
    assert [c.rows for c in g.robot.contacts] == [3, 3, 6]
    model = _model(g)
    data = model.createData()
    for target in g.targets():
        q, _, tau = _state(g, 8)
        v = np.zeros(6)  # at rest: a point's classical and spatial accelerations agree (at speed the
        Jc, gamma = _kinematics(g, q, v)  # points' and the 6d rows contradict each other by w x v)
        qdd, lam = g.call(target, "contact_forward_dynamics", q, v, tau, [1.0, 1.0, 1.0])
        assert np.all(np.isfinite(qdd)) and np.all(np.isfinite(lam))
        # the set holds tool0 as the 6d contact alone does: the same accelerations and total wrench
        cms, cds = _constraints(model, g.robot.contacts[2:])
        pin.initConstraintDynamics(model, data, cms, cds)
        want = pin.constraintDynamics(
            model, data, q, v, tau, cms, cds, pin.ProximalSettings(1e-14, 1e-14, 0, 1)
        )
        _close(qdd, want, f"{target} qdd", 1e-5)
        _close(Jc.T @ lam, Jc[6:].T @ data.lambda_c, f"{target} J^T lam", 1e-5)
        qd_plus, imp = g.call(target, "impulse_dynamics", q, q - q[::-1], [1.0, 1.0, 1.0], [0.0])
        assert np.all(np.isfinite(imp)) and np.abs(qd_plus).max() < 1e-6


def _anchors(g: Generated, q, rng) -> np.ndarray:
    """Anchors near the contacts' poses at q (moved by up to 2 cm, turned by up to 0.2 rad), flat."""
    poses = contact_poses(g.robot, contact_rows(g.robot, g.robot.contacts), np.asarray(q)[None])[0]
    out = []
    for T in poses:
        w = 0.1 * rng.normal(size=3)
        K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        turn = np.eye(3) + np.sin(np.linalg.norm(w)) / np.linalg.norm(w) * K
        turn += (1 - np.cos(np.linalg.norm(w))) / np.linalg.norm(w) ** 2 * K @ K  # Rodrigues
        out.append(np.r_[T[:3, 3] + 0.01 * rng.normal(size=3), (T[:3, :3] @ turn).reshape(-1)])
    return np.concatenate(out)


@pytest.mark.parametrize("key, masks", [("xarm7", [(1,), (0,)]), ("solo", [(1, 1, 1, 1), (0, 1, 1, 0)])])
def test_baumgarte_functions_agree_with_the_oracle(built, key, masks):
    g = built(key)
    rng = np.random.default_rng(11)
    for target in g.targets():
        q, v, tau = _state(g, 7)
        anchor = _anchors(g, q, rng)
        err = contact_error(g.robot, None, q, anchor)
        assert 1e-4 < np.abs(err).max() < 0.3
        _close(g.call(target, "contact_error", q, anchor)[0], err, f"{target} err", 1e-12)
        Jc, gamma = _kinematics(g, q, v)
        for active in masks:
            mask, rows = np.array(active, dtype=float), _rows(g.robot.contacts, active)
            free = np.setdiff1d(np.arange(len(gamma)), rows)
            exact = g.call(target, "contact_forward_dynamics", q, v, tau, mask)
            zero = g.call(target, "contact_forward_dynamics_baumgarte", q, v, tau, mask, anchor, [0.0, 0.0])
            for got, want, name in zip(zero, exact, ("qdd", "lam"), strict=True):
                _close(got, want, f"{target} {active} gains 0 {name}", 1e-12)
            kp, kd = 400.0, 40.0
            qdd, lam = g.call(target, "contact_forward_dynamics_baumgarte", q, v, tau, mask, anchor, [kp, kd])
            want = contact_forward_dynamics_baumgarte(
                g.robot, None, q, v, tau, mask, anchor, (kp, kd), damping=MU
            )
            _close(qdd, want[0], f"{target} {active} qdd")
            _close(lam, want[1], f"{target} {active} lam")
            assert np.all(lam[free] == 0)
            # the stabilised constraint on the active rows (Pinocchio's Jc and gamma; mu lam: the damping)
            lhs = (Jc @ qdd + gamma + MU * lam)[rows]
            if len(rows):
                _close(lhs, (-kd * Jc @ v - kp * err)[rows], f"{target} {active} constraint", 1e-9)
            if len(rows) and len(free):  # the free rows' error changes nothing
                moved = anchor.copy()
                moved[12 * int(np.flatnonzero(mask == 0)[0])] += 1.0
                again = g.call(target, "contact_forward_dynamics_baumgarte", q, v, tau, mask, moved, [kp, kd])
                assert np.array_equal(again[0], qdd) and np.array_equal(again[1], lam)


FLYER2 = """name: flyer2
base: {floating: true, mass: 3, com: [0.02, -0.01, 0.05],
       inertia: {ixx: 0.05, iyy: 0.06, izz: 0.07, ixy: 0.004}}
links:
  - {name: l1, joint: revolute, a: 0.4, alpha: 0.7, d: 0.1, mass: 1, com: [-0.2, 0.01, 0.02],
     inertia: {ixx: 0.002, iyy: 0.01, izz: 0.01}, friction: {viscous: 0.3}}
frames:
  - {name: foot, link: base, xyz: [0.1, 0.2, -0.3], rpy: [0.3, -0.2, 0.1]}
  - {name: hand, link: l1, xyz: [0.05, 0, 0.02], rpy: [0, 0.5, 0]}
contacts:
  - {name: foot, frame: foot}
  - {name: hand, frame: hand}
  - {name: grip, frame: hand, type: 6d}
"""


@pytest.fixture(scope="module")
def flyer(tmp_path_factory):
    """The floating flyer's three contact groups, derived once: (robot, context, NumPy module)."""
    robot = symdyn.robot_from_data(__import__("yaml").safe_load(FLYER2))
    ctx = context(robot, functions=("contacts", "contact_derivatives", "contact_baumgarte"))
    return robot, ctx, numpy_module(ctx, tmp_path_factory.mktemp("flyer"))


def test_floating_derivatives_equal_differences_of_the_generated_functions(flyer):
    robot, _, g = flyer
    rng = np.random.default_rng(3)
    quat = rng.normal(size=4)
    q = np.r_[rng.normal(size=3), quat / np.linalg.norm(quat), rng.normal(size=1)]
    v, tau = rng.normal(size=7), rng.normal(size=7)
    h = 1e-6
    for active in ([1.0, 1.0, 0.0], [0.0, 0.0, 1.0]):

        def fd(x, y, active=active):
            return np.concatenate(g.contact_forward_dynamics(x, y, tau, active))

        def imp(x, y, active=active):
            return np.concatenate(g.impulse_dynamics(x, y, active, [0.3]))

        for f, name, got in (
            (fd, "forward", g.contact_forward_dynamics_derivatives(q, v, tau, active)),
            (imp, "impulse", g.impulse_dynamics_derivatives(q, v, active, [0.3])),
        ):
            dq = np.column_stack(
                [
                    (f(integrate(robot, q, h * e), v) - f(integrate(robot, q, -h * e), v)) / (2 * h)
                    for e in np.eye(7)
                ]
            )
            dv = np.column_stack([(f(q, v + h * e) - f(q, v - h * e)) / (2 * h) for e in np.eye(7)])
            k = 2 if name == "forward" else 1  # the outputs by q come first, then by qd (and tau)
            _close(np.vstack([got[0], got[k + 1]]), dq, f"{name} {active} by q", 1e-6)
            _close(np.vstack([got[1], got[k + 2]]), dv, f"{name} {active} by qd", 1e-6)
        dt = np.column_stack(
            [
                (fd(q, v) - np.concatenate(g.contact_forward_dynamics(q, v, tau - h * e, active))) / h
                for e in np.eye(7)
            ]
        )
        got = g.contact_forward_dynamics_derivatives(q, v, tau, active)
        _close(np.vstack([got[2], got[5]]), dt, f"{active} by tau", 1e-5)


def test_symdyn_compile_binds_the_contact_functions(tmp_path, monkeypatch):
    monkeypatch.setenv("SYMDYN_CACHE_DIR", str(tmp_path))
    data = __import__("yaml").safe_load(FLYER2.replace("flyer2", "flyer3"))
    robot = symdyn.robot_from_data(data)
    cd = symdyn.compile(robot, functions=["contacts"])
    rng = np.random.default_rng(9)
    quat = rng.normal(size=4)
    q = np.r_[rng.normal(size=3), quat / np.linalg.norm(quat), rng.normal(size=1)]
    v, tau = rng.normal(size=7), rng.normal(size=7)
    active = np.array([1.0, 1.0, 0.0])
    qdd, lam = cd.contact_forward_dynamics(q, v, tau, active)
    Jc = cd.contact_jacobian(q)
    # the oracle's M qdd + b (symdyn.rnea, friction included) equals tau + Jc^T lam
    _close(symdyn.rnea(robot, q, v, qdd) - tau - Jc.T @ lam, np.zeros(7), "dynamics", 1e-9)
    assert np.all(lam[6:] == 0)
    Q, V, T = (np.tile(x, (20, 1)) for x in (q, v, tau))
    batch = cd.contact_forward_dynamics(Q, V, T, np.tile(active, (20, 1)))
    assert np.array_equal(batch[0][7], qdd) and np.array_equal(batch[1][3], lam)
    qd_plus, imp = cd.impulse_dynamics(q, v, active, [0.0])
    _close((Jc @ qd_plus + MU * imp)[:6], np.zeros(6), "impact", 1e-9)


@pytest.mark.skipif(OCTAVE is None, reason="GNU Octave (octave-cli) is not installed")
def test_casadi_jax_and_octave_agree_with_numpy_on_every_contact_function(flyer, tmp_path):
    """Every function of the groups contacts, contact_derivatives and contact_baumgarte of the
    floating flyer in CasADi, JAX and Octave against its NumPy module (which the test above checks
    against differences, and Pinocchio checks on the xArm and Solo-12): what is target-specific is
    the printers' matrix layout (row-major in C and NumPy, column-major in CasADi and MATLAB), the
    mask, the restitution input and the anchors."""
    jax = pytest.importorskip("jax")
    jax.config.update("jax_enable_x64", True)
    robot, ctx, reference = flyer
    files = casadi_target.render(ctx) | jax_target.render(ctx) | matlab_target.render(ctx)
    write_files(files, tmp_path)
    casadi_functions: dict = {}
    exec(compile(files["flyer2_casadi.py"], "flyer2_casadi.py", "exec"), casadi_functions)  # symdyn's own
    built = casadi_functions["functions"]()
    jax_module: dict = {}
    exec(compile(files["flyer2_jax.py"], "flyer2_jax.py", "exec"), jax_module)  # symdyn's own

    rng = np.random.default_rng(21)
    quat = rng.normal(size=4)
    q = np.r_[rng.normal(size=3), quat / np.linalg.norm(quat), rng.normal(size=1)]
    poses = contact_poses(robot, contact_rows(robot, robot.contacts), q[None])[0]
    anchor = np.concatenate(
        [np.r_[T[:3, 3] + rng.normal(scale=0.01, size=3), T[:3, :3].reshape(-1)] for T in poses]
    )
    values = {
        "q": q,
        "qd": rng.normal(size=7),
        "tau": rng.normal(size=7),
        "e": np.array([0.4]),
        "anchor": anchor,
        "gains": np.array([40.0, 6.0]),
        "p": np.zeros(0),
    }
    calls, want = {}, {}
    for active in ([1.0, 1.0, 0.0], [0.0, 0.0, 1.0]):  # two points or the 6d grip: regular sets
        values["active"] = np.array(active)
        for f in ctx.functions:
            args = [values[i.name] for i in f.inputs]
            out = getattr(reference, f.name)(*args[:-1])
            want[f.name, active[0]] = [np.asarray(o) for o in (out if isinstance(out, tuple) else (out,))]
            got_casadi = built[f.name](*args)
            got_jax = jax_module[f.name](*args[:-1])
            for target, got in (("casadi", got_casadi), ("jax", got_jax)):
                got = got if isinstance(got, tuple) else (got,)
                for r, g, w in zip(f.results, got, want[f.name, active[0]], strict=True):
                    _close(np.array(g, dtype=float), w, f"{target} {f.name} {r.name} {active}", 1e-12)
            numbers = ", ".join(octave_numbers(a) for a in args)
            calls[f.name, active[0]] = f"symdyn_outputs(@flyer2_{f.name}, {len(f.results)}, {numbers})"
    (tmp_path / "symdyn_outputs.m").write_text(
        "function o = symdyn_outputs(f, n, varargin)\n"
        "  [c{1:n}] = f(varargin{:});\n"
        "  o = [];\n"
        "  for k = 1:n\n    x = c{k}.';\n    o = [o; x(:)];\n  end\n"
        "end\n"
    )
    got = octave_values(tmp_path, calls)
    for key, outs in want.items():
        _close(got[key], np.concatenate([o.reshape(-1) for o in outs]), f"octave {key}", 1e-12)
