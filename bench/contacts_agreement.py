"""The agreement of the generated contact functions (issue 36) with Pinocchio, per robot and function.

    python bench/contacts_agreement.py [--robots solo,anymal,talos,xarm7] [--c]

For each robot (example-robot-data; Solo-12 with its four feet as point contacts, ANYmal's four
feet, Talos' two soles as 6d contacts, the xArm 7 with a 6d contact at its tool) the groups
contacts and contact_derivatives are generated (the CPU and wall time of the derivation and the
two groups are printed: the Talos target is <= 120 s) and the NumPy module (and with --c the C,
compiled unoptimised) is compared with Pinocchio's constraintDynamics, impulseDynamics,
computeConstraintDynamicsDerivatives and computeImpulseDynamicsDerivatives at two random states,
all contacts active and then the first and last only: the largest absolute error and the error
relative to the largest entry (at least 1) per function output. The comparisons are those of
tests/test_contact_functions.py, whose helpers this script uses; the suite runs them on the xArm 7
and on Solo-12's functions without the derivatives, which take too long to derive there.
The machine may be loaded by other work: the times are CPU seconds of this process beside the wall.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import test_contact_functions as t  # noqa: E402

ROBOTS = {
    "solo": ("solo_description/robots/solo12.urdf", True, ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")),
    "anymal": (
        "anymal_b_simple_description/robots/anymal.urdf",
        True,
        ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"),
    ),
    "talos": ("talos_data/robots/talos_reduced.urdf", True, ("left_sole_link:6d", "right_sole_link:6d")),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", False, ("link_eef:6d",)),
}
OUTPUTS = {
    "contact_jacobian": ("Jc",),
    "contact_drift": ("gamma",),
    "contact_forward_dynamics": ("qdd", "lam"),
    "impulse_dynamics": ("qd_plus", "impulse"),
    "contact_forward_dynamics_derivatives": (
        "dqdd_dq",
        "dqdd_dqd",
        "dqdd_dtau",
        "dlambda_dq",
        "dlambda_dqd",
        "dlambda_dtau",
    ),
    "impulse_dynamics_derivatives": ("dqd_plus_dq", "dqd_plus_dqd", "dimpulse_dq", "dimpulse_dqd"),
}


def _args(name: str, q, v, tau, mask) -> tuple:
    return {
        "contact_jacobian": (q,),
        "contact_drift": (q, v),
        "contact_forward_dynamics": (q, v, tau, mask),
        "impulse_dynamics": (q, v, mask, [0.0]),
        "contact_forward_dynamics_derivatives": (q, v, tau, mask),
        "impulse_dynamics_derivatives": (q, v, mask, [0.0]),
    }[name]


def agreement(key: str, with_c: bool) -> None:
    path, floating, contacts = ROBOTS[key]
    t.ROBOTS[key] = (path, floating, contacts, ("contacts", "contact_derivatives"))
    cpu, wall = time.process_time(), time.time()
    g = t.Generated(key, Path(tempfile.mkdtemp(prefix=f"contacts-{key}-")), c=with_c)
    print(
        f"{key}: {len(g.robot.contacts)} contacts, NLAMBDA {sum(c.rows for c in g.robot.contacts)}, NV "
        f"{g.robot.nv}; derived, generated and rendered in {time.process_time() - cpu:.1f} s CPU "
        f"({time.time() - wall:.1f} s wall)"
    )
    worst: dict[tuple, list[float]] = {}
    n = len(g.robot.contacts)
    for seed in (1, 2):
        q, v, tau = t._state(g, seed)
        if floating:
            tau[:6] = 0
        Jc, gamma = t._kinematics(g, q, v)
        for active in ([1] * n, [1] + [0] * (n - 2) + [1] if n > 2 else [1] * n):
            want = t._pinocchio(g, q, v, tau, active) | {"Jc": Jc, "gamma": gamma}
            mask = np.array(active, dtype=float)
            for target in g.targets():
                for fname, outs in OUTPUTS.items():
                    got = g.call(target, fname, *_args(fname, q, v, tau, mask))
                    for name, x in zip(outs, got, strict=True):
                        err = np.abs(np.reshape(x, np.shape(want[name])) - want[name]).max()
                        rel = err / max(1.0, np.abs(want[name]).max())
                        old = worst.setdefault((target, fname, name), [0.0, 0.0])
                        worst[(target, fname, name)] = [max(old[0], err), max(old[1], rel)]
    print(f"  {'target':6}  {'function':38}  {'output':13}  {'max abs error':>13}  {'relative':>9}")
    for (target, fname, name), (err, rel) in worst.items():
        print(f"  {target:6}  {fname:38}  {name:13}  {err:13.2e}  {rel:9.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="solo,talos", help="comma-separated: " + ", ".join(ROBOTS))
    parser.add_argument("--c", action="store_true", help="also compile and compare the C")
    args = parser.parse_args()
    for key in args.robots.split(","):
        agreement(key, args.c)


if __name__ == "__main__":
    main()
