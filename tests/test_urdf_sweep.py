"""Every URDF that example-robot-data ships, loaded as a whole fixed-base tree, against Pinocchio.

Pinocchio (`pin` in the test extra) is a peer library that no code of symdyn shares: each file is
built with `pinocchio.buildModelFromUrdf(path, mimic=True)` (fixed base, mimic joints slaved to
the joints they follow) and compared with symdyn's numeric oracle (`symdyn.rnea`) on the robot
that `symdyn.load_urdf(path)` makes of the same file, at random states: tau = RNEA(q, qd, qdd),
M = CRBA(q) and G = RNEA(q, 0, 0). The joint order may differ (symdyn names a joint's link
after its child link); the comparison maps coordinates by joint name.

A file symdyn refuses must be refused for a reason listed in REFUSED (and documented in
docs/urdf.md). Where Pinocchio refuses `mimic=True` (a mimic joint it cannot place) but symdyn
loads the file, Pinocchio's model without mimic joints (every joint free) is used instead, and
its dynamics are projected onto the independent coordinates with the selection S read from the
XML's <mimic> elements: tau = S^T tau_b(S q + o, S qd, S qdd), M = S^T M_b S, G = S^T G_b
(bench/pin_urdf.py, shared with bench/floating_sweep.py and tests/test_oracle_floating.py).
A file neither can use is listed in PINOCCHIO_REFUSES with Pinocchio's message. No file gives
the warning about a massless link in the middle of a chain; the other warnings about the
published data pass silently.
The table of the sweep prints with `pytest -s tests/test_urdf_sweep.py`.
"""

from __future__ import annotations

import importlib.util
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest

import symdyn
from symdyn import SymdynError
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import gravity_torque, mass_matrix

pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")


def _bench_module(name: str):
    """A helper module of bench/ that the benchmark scripts share with these tests (bench/ is no
    package: the module is loaded from its file)."""
    spec = importlib.util.spec_from_file_location(
        name, Path(__file__).resolve().parents[1] / "bench" / f"{name}.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: the joints matched by name, the mimic joints projected (bench/pin_urdf.py)
pin_urdf = _bench_module("pin_urdf")

#: the published files' own oddities, which symdyn reports while loading them (tests/test_inertia.py,
#: test_angles.py and test_urdf.py assert these warnings): not the subject of the sweep
pytestmark = [
    pytest.mark.filterwarnings(f"ignore:{message}:symdyn.errors.SymdynWarning")
    for message in (
        r".* rad is .* rad from .*, so it is kept as written",
        r".*break the triangle inequality",
        r".*mass is zero but the inertia tensor is not",
    )
]


ROBOTS = example_robot_data_folder()
FILES = sorted(ROBOTS.rglob("*.urdf")) if ROBOTS else []

#: files symdyn refuses, with the documented reason (a fragment of its message)
#: single rigid bodies: no movable joint, so nothing to derive on a fixed base (Pinocchio builds a
#: model with nv = 0); a floating one is a free body (tests/test_oracle_floating.py loads them)
SINGLE_BODIES = {
    "hector_description/robots/quadrotor_base.urdf": "has no links below it",
    "iris_description/robots/iris_simple.urdf": "no movable joint below the base link",
}
REFUSED = {
    **SINGLE_BODIES,
    # two hip links carry inertia tensors with a negative principal moment: impossible data
    "romeo_description/urdf/romeo_laas_small.urdf": "inertia tensor is not positive semi-definite",
    # a <mimic> names joints missing from the file (index_q1 for Left_index_q1, ...)
    "alex_description/urdf/alex_psyonic_hands.urdf": "mimics joint 'index_q1', which does not exist",
}
#: files Pinocchio 4.1 itself cannot build (nothing to compare), with a fragment of its message
PINOCCHIO_REFUSES = {
    "ur_description/urdf/ur3.urdf": "does not contain a valid URDF model",  # <robot> without a name
}
#: files whose mimic joints Pinocchio 4.1 cannot place (compared through the projection above)
PINOCCHIO_MIMIC_FAILS = {
    "alex_description/urdf/alex_psyonic_hands.urdf",
    "romeo_description/urdf/romeo.urdf",
    "talos_data/robots/talos_full_v2.urdf",
    "talos_data/robots/talos_full_v2_box.urdf",
}
STATES = 2
TOL = 1e-9  # relative to the largest entry (and 1e-9 absolute): both are double-precision RNEAs


def _rel(path: Path) -> str:
    return str(path.relative_to(ROBOTS))


def _pin_state(model, names: list[str], q, qd, qdd):
    """Pinocchio's (q, v, a) for symdyn's independent coordinates named `names` (joint names).

    Continuous joints are (cos, sin) in Pinocchio's q; mimic joints have no entry of their own."""
    qp = pin.neutral(model)
    v = np.zeros(model.nv)
    a = np.zeros(model.nv)
    order = []
    for k, name in enumerate(names):
        j = model.getJointId(name)
        joint = model.joints[j]
        if joint.nq == 2:
            qp[joint.idx_q : joint.idx_q + 2] = np.cos(q[k]), np.sin(q[k])
        else:
            qp[joint.idx_q] = q[k]
        v[joint.idx_v], a[joint.idx_v] = qd[k], qdd[k]
        order.append(joint.idx_v)
    return qp, v, a, order


def _close(ours: np.ndarray, theirs: np.ndarray) -> float:
    scale = max(1.0, float(np.max(np.abs(theirs))))
    return float(np.max(np.abs(ours - theirs))) / scale if ours.size else 0.0


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
@pytest.mark.parametrize("path", FILES, ids=lambda p: _rel(p) if ROBOTS else str(p))
def test_whole_tree_against_pinocchio(path):
    rel = _rel(path)
    mimic_fails = rel in PINOCCHIO_MIMIC_FAILS
    try:
        model = pin.buildModelFromUrdf(str(path), mimic=not mimic_fails)
    except Exception as exc:  # Pinocchio's own refusal: nothing to compare with
        assert rel in PINOCCHIO_REFUSES, f"Pinocchio refuses {rel}: {exc}"
        assert PINOCCHIO_REFUSES[rel] in str(exc)
        return
    assert rel not in PINOCCHIO_REFUSES, f"{rel}: Pinocchio builds it now: compare it"
    if mimic_fails:
        with pytest.raises(Exception, match="mimic"):
            pin.buildModelFromUrdf(str(path), mimic=True)
    try:
        with warnings.catch_warnings(record=True) as caught:  # published data: its warnings pass
            warnings.simplefilter("always")
            robot = symdyn.load_urdf(path)
    except SymdynError as exc:
        assert rel in REFUSED, f"symdyn refuses {rel}: {exc}"
        assert REFUSED[rel] in str(exc)
        return
    assert rel not in REFUSED, f"{rel}: symdyn loads it now"
    # no file has a massless link mid-chain (docs/urdf.md): the warning fires on none of them
    assert not [str(w.message) for w in caught if "has no <inertial>" in str(w.message)]
    names = pin_urdf.joint_names(path, robot)
    projected = pin_urdf.Projected(path, names, floating=False) if mimic_fails else None
    if projected is None:
        assert robot.n == model.nv, (robot.n, model.nv)
    data = model.createData()
    rng = np.random.default_rng(zlib.crc32(rel.encode()))
    worst = 0.0
    for _ in range(STATES):
        q, qd, qdd = (rng.uniform(-1, 1, robot.n) for _ in range(3))
        if projected is not None:
            qp, v, a = projected.state(q, qd, qdd)
            m, d = projected.model, projected.data
            tau_pin = projected.back(pin.rnea(m, d, qp, v, a))
            M_pin = projected.back(pin_urdf.symmetric(pin.crba(m, d, qp)))
            G_pin = projected.back(pin.computeGeneralizedGravity(m, d, qp))
        else:
            qp, v, a, order = _pin_state(model, names, q, qd, qdd)
            tau_pin = pin.rnea(model, data, qp, v, a)[order]
            M_pin = pin_urdf.symmetric(pin.crba(model, data, qp))[np.ix_(order, order)]
            G_pin = pin.computeGeneralizedGravity(model, data, qp)[order]
        tau = symdyn.rnea(robot, q, qd, qdd, friction=False)
        worst = max(
            worst,
            _close(tau, tau_pin),
            _close(mass_matrix(robot, q), M_pin),
            _close(gravity_torque(robot, q), G_pin),
        )
    how = " (Pinocchio without mimic, projected)" if mimic_fails else ""
    print(f"{rel}: {robot.n} joints ({robot.nb} bodies), max relative error {worst:.1e}{how}")
    assert worst < TOL, f"{rel}: {worst:.2e}"
