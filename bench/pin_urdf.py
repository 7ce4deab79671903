"""symdyn's numeric oracle against Pinocchio on a URDF of example-robot-data: the joints matched by
name, the mimic joints projected, and the comparison of a floating robot algorithm by algorithm.

Shared by bench/floating_sweep.py (the table of every floating URDF) and the tests that check
the same files (tests/test_urdf_sweep.py, tests/test_oracle_floating.py load this file by its
path). It imports symdyn, NumPy and Pinocchio only.

Pinocchio's model of a file is built without mimic joints (every joint free, in its own order,
continuous joints as (cos, sin)); symdyn's n independent coordinates reach it through the
selection S and offset o read from the XML's <mimic> elements (not from symdyn's parse):
q_b = S q + o, v_b = S v, a_b = S a, and back by virtual work, tau = S^T tau_b, M = S^T M_b S,
A_g = A_g,b S. On a floating base S keeps the free flyer's six tangent entries (and its seven
configuration entries) first. Without mimic joints S is a permutation.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

import symdyn
from symdyn import SymdynError
from symdyn.oracle.centroidal import centroidal
from symdyn.oracle.derivatives import rnea_derivatives
from symdyn.rnea import bias_torque, forward_dynamics, friction_torque, gravity_torque

__all__ = [
    "FLOATING_FOLDERS",
    "NOT_FLOATING",
    "ALGORITHMS",
    "floating_files",
    "child_links",
    "mimics",
    "joint_names",
    "Projected",
    "symmetric",
    "rel_error",
    "random_state",
    "floating_errors",
    "worst",
]

#: the folders of example-robot-data whose robots' bases float: quadrupeds, bipeds, humanoids, flying robots
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
#: the columns of floating_errors: Pinocchio's rnea, crba (and computeRNEADerivatives' M),
#: nonLinearEffects, computeGeneralizedGravity, aba, computeCentroidalMap, the drift dAg v of
#: computeCentroidalMapTimeVariation, centerOfMass, computeTotalMass, computeRNEADerivatives
ALGORITHMS = ("rnea", "crba", "nle", "G", "aba", "A_g", "drift", "com", "mass", "dtau_dq", "dtau_dv")


def floating_files(robots: Path) -> list[Path]:
    """The URDFs of the floating robots below example-robot-data's `robots` folder, sorted."""
    return [
        p
        for p in sorted(robots.rglob("*.urdf"))
        if p.relative_to(robots).parts[0] in FLOATING_FOLDERS
        and str(p.relative_to(robots)) not in NOT_FLOATING
    ]


def child_links(path: Path) -> dict[str, str]:
    """URDF joint name -> its child link's name (symdyn names a joint's Link after its child)."""
    root = ET.parse(path).getroot()
    return {j.get("name"): j.find("child").get("link") for j in root.findall("joint")}


def mimics(path: Path) -> dict[str, tuple[str, float, float]]:
    """Movable URDF joint -> (master joint, multiplier, offset) for each <mimic>, read from the XML."""
    out = {}
    for j in ET.parse(path).getroot().findall("joint"):
        m = j.find("mimic")
        if m is not None and j.get("type") != "fixed":
            out[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
    return out


def joint_names(path: Path, robot) -> list[str]:
    """The URDF joint names of symdyn's independent coordinates of `robot` loaded from `path`."""
    joint_of = {child: joint for joint, child in child_links(path).items()}
    return [joint_of[link.name] for link in robot.links if link.mimic is None]


class Projected:
    """Pinocchio's model of a URDF without mimic joints (a free flyer at the root if floating) and
    the selection S (NV_pin x NV), offset o from symdyn's independent coordinates, whose joints
    are `names` (URDF joint names, in symdyn's order)."""

    def __init__(self, path: Path, names: list[str], floating: bool):
        root = (pin.JointModelFreeFlyer(),) if floating else ()
        self.model = pin.buildModelFromUrdf(str(path), *root)
        self.data = self.model.createData()
        self.base, self.base_q = (6, 7) if floating else (0, 0)  # the free flyer's entries in v and q
        self.first = 2 if floating else 1  # Pinocchio's first joint of the URDF (0 is the universe)
        nv = self.model.nv
        self.S = np.zeros((nv, self.base + len(names)))
        self.S[: self.base, : self.base] = np.eye(self.base)
        self.offset = np.zeros(nv)
        col = {name: self.base + k for k, name in enumerate(names)}
        found = mimics(path)
        for j in range(self.first, self.model.njoints):
            joint, name = self.model.joints[j], self.model.names[j]
            master, k, o = found.get(name, (name, 1.0, 0.0))
            self.S[joint.idx_v, col[master]] = k
            self.offset[joint.idx_v] = o

    @classmethod
    def of(cls, path: Path, robot) -> Projected:
        """The projection for symdyn's `robot` loaded from `path`."""
        return cls(path, joint_names(path, robot), robot.floating)

    def state(self, q, v, a):
        """Pinocchio's (q, v, a) of symdyn's (q, v, a) (a floating base's 7 and 6 entries first)."""
        qb = self.S[self.base :, self.base :] @ q[self.base_q :] + self.offset[self.base :]
        qp = pin.neutral(self.model)
        qp[: self.base_q] = q[: self.base_q]
        for j in range(self.first, self.model.njoints):
            joint = self.model.joints[j]
            x = qb[joint.idx_v - self.base]
            if joint.nq == 2:
                qp[joint.idx_q : joint.idx_q + 2] = np.cos(x), np.sin(x)
            else:
                qp[joint.idx_q] = x
        return qp, self.S @ v, self.S @ a

    def back(self, x: np.ndarray) -> np.ndarray:
        """Pinocchio's efforts (NV_pin) or matrix (NV_pin x NV_pin) on symdyn's coordinates:
        S^T x or S^T x S."""
        return self.S.T @ x if x.ndim == 1 else self.S.T @ x @ self.S


def rel_error(ours, theirs) -> float:
    """max |ours - theirs| over the largest entry of theirs (at least 1)."""
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    if not theirs.size:
        return 0.0
    return float(np.max(np.abs(ours - theirs))) / max(1.0, float(np.max(np.abs(theirs))))


def random_state(robot, rng: np.random.Generator):
    """q (base position and joints uniform in [-1, 1], a random unit quaternion), v, a in [-1, 1]."""
    quat = rng.normal(size=4)
    q = np.concatenate([rng.uniform(-1, 1, 3), quat / np.linalg.norm(quat), rng.uniform(-1, 1, robot.n)])
    return q, rng.uniform(-1, 1, robot.nv), rng.uniform(-1, 1, robot.nv)


def symmetric(M: np.ndarray) -> np.ndarray:
    """Pinocchio's M from its upper triangle (crba and computeRNEADerivatives fill only that)."""
    return np.triu(M) + np.triu(M, 1).T


def _aba_error(theirs: Projected, robot, q, v, tau) -> float:
    """The "aba" entry of floating_errors: the oracle's forward dynamics at Pinocchio's tau."""
    try:
        fd = forward_dynamics(robot, q, v, tau + friction_torque(robot, v))
    except SymdynError:  # M singular (massless bodies moved by a joint): no forward dynamics
        return float("nan")
    m, d = theirs.model, theirs.data
    qp, vp, _ = theirs.state(q, v, fd)
    if theirs.S.shape[0] == theirs.S.shape[1]:  # a permutation: S^-T = S
        return rel_error(fd, theirs.back(pin.aba(m, d, qp, vp, theirs.S @ tau)))
    return rel_error(theirs.back(pin.rnea(m, d, *theirs.state(q, v, fd))), tau)


def floating_errors(theirs: Projected, robot, q, v, a) -> tuple[dict[str, float], float]:
    """The relative error (rel_error) of each of ALGORITHMS at one state of a floating robot, and
    the condition number of M.

    Every value is the oracle's (symdyn.rnea, symdyn.oracle.centroidal, .derivatives) against
    Pinocchio's on the projected model. aba is the forward error of the oracle's forward dynamics
    at Pinocchio's tau against aba's acceleration (the two agree within cond(M) eps) where S is a
    permutation; with mimic joints Pinocchio's aba has no counterpart, and the error is that of
    Pinocchio's rnea at the oracle's acceleration (the backward error); NaN where M is singular.
    """
    m, d = theirs.model, theirs.data
    qp, vp, ap = theirs.state(q, v, a)
    tau = theirs.back(pin.rnea(m, d, qp, vp, ap))
    M = theirs.back(symmetric(pin.crba(m, d, qp)))
    nle = theirs.back(pin.nonLinearEffects(m, d, qp, vp))
    G = theirs.back(pin.computeGeneralizedGravity(m, d, qp))
    dq, dv, M_d = pin.computeRNEADerivatives(m, d, qp, vp, ap)
    dq, dv, M_d = theirs.back(dq), theirs.back(dv), theirs.back(symmetric(M_d))
    pin.computeCentroidalMapTimeVariation(m, d, qp, vp)
    Ag, drift = d.Ag @ theirs.S, d.dAg @ vp
    com, mass = pin.centerOfMass(m, d, qp), pin.computeTotalMass(m)
    aba = _aba_error(theirs, robot, q, v, tau)
    st = centroidal(robot, q, v)
    der = rnea_derivatives(robot, q, v, a)  # its M is the oracle's mass_matrix
    errors = {
        "rnea": rel_error(symdyn.rnea(robot, q, v, a, friction=False), tau),
        "crba": max(rel_error(der.M, M), rel_error(der.M, M_d)),
        "nle": rel_error(bias_torque(robot, q, v) + gravity_torque(robot, q), nle),
        "G": rel_error(gravity_torque(robot, q), G),
        "aba": aba,
        "A_g": rel_error(st.Ag, Ag),
        "drift": rel_error(st.drift, drift),
        "com": rel_error(st.com, com),
        "mass": rel_error(st.mass, mass),
        "dtau_dq": rel_error(der.dtau_dq, dq),
        "dtau_dv": rel_error(der.dtau_dv, dv),
    }
    return errors, float(np.linalg.cond(der.M))


def worst(rows: list[dict[str, float]]) -> dict[str, float]:
    """The largest error of each algorithm over the states' rows (NaN where every row has NaN)."""
    return {
        k: float(np.nanmax([r[k] for r in rows])) if any(r[k] == r[k] for r in rows) else float("nan")
        for k in rows[0]
    }
