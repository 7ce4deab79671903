"""Lecture slide 24 reproduced: Roger's arm, dynamic manipulability and acceleration polytopes.

Roger's arm (examples/roger_arm_values.yaml): m1 = m2 = 0.2 kg, l1 = l2 = 0.25 m,
g = 9.81 m/s^2, hanging along base +x (gravity [g, 0, 0]). At each hand position
below, with qd = 0, the picture shows at the hand (drawn to scale):
  - the unbiased dynamic manipulability ellipse (dashed),
  - the same ellipse shifted by the gravity bias v_grav = -J M^-1 G (red),
  - the acceleration polytope with gravity bias (green),
  - the bias itself (black arrow from the hand).

Torque bound: |tau_1|, |tau_2| <= 2 N m. The largest holding torque anywhere in the
workspace is (m1 + m2) g l1 + m2 g l2 = 1.47 N m (arm stretched horizontally), so with
2 N m the arm can hold itself everywhere (every biased polytope contains zero
acceleration), and the gravity bias (at most about g = 9.8 m/s^2 at the hand) is
clearly visible yet about half the ellipses' smaller semi-axis (about 18 m/s^2).
With 1 N m the bias would be as large as the smaller semi-axis and the arm could not
hold itself near the horizontal.

Hand positions (m, base frame): along the gravity axis x = 0.30 and 0.45 (not 0.50,
the fully stretched, singular configuration), and laterally (x, y) = (0.20, +-0.30) and
(0.00, +-0.40) (hand level with the shoulder); of the two elbow solutions the one with
the elbow hanging lower.

Run from the repository root:  python examples/slide24.py  (writes examples/slide24.png)
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import symdyn
from symdyn.apps.analysis import analyze, plot_workspace

HERE = Path(__file__).resolve().parent
TORQUE_LIMIT = 2.0  # N m, both joints
HAND_POSITIONS = [(0.30, 0.0), (0.45, 0.0), (0.20, 0.30), (0.20, -0.30), (0.0, 0.40), (0.0, -0.40)]
L1 = L2 = 0.25


def inverse_kinematics(x: float, y: float) -> tuple[float, float]:
    """Joint angles putting the hand of the planar 2R arm at (x, y), the elbow hanging lower.

    Of the two solutions (q2 > 0 and q2 < 0) the one whose elbow lies further along
    gravity (+x) is taken, so the picture is symmetric about the x axis.
    """
    c2 = (x * x + y * y - L1 * L1 - L2 * L2) / (2 * L1 * L2)
    if not -1 < c2 < 1:
        raise ValueError(f"({x}, {y}) is outside the workspace or singular")
    best = None
    for q2 in (math.acos(c2), -math.acos(c2)):
        q1 = math.atan2(y, x) - math.atan2(L2 * math.sin(q2), L1 + L2 * math.cos(q2))
        elbow_x = L1 * math.cos(q1)
        if best is None or elbow_x > best[0] + 1e-12:
            best = (elbow_x, q1, q2)
    return best[1], best[2]


def main(out: Path = HERE / "slide24.png") -> Path:
    robot = symdyn.load_robot(HERE / "roger_arm_values.yaml")
    results = [
        analyze(robot, inverse_kinematics(x, y), torque_limits=TORQUE_LIMIT, axes="x,y")
        for x, y in HAND_POSITIONS
    ]
    plot_workspace(
        robot,
        results,
        out,
        title="Roger's arm (slide 24): m1 = m2 = 0.2 kg, l1 = l2 = 0.25 m, |tau_i| <= 2 N m, qd = 0",
    )
    return out


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "slide24.png"))
