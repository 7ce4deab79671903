"""The Robotics Toolbox for Python's PUMA 560 at fixed states: the reference values of
tests/test_toolbox_tables.py, written to puma560_toolbox.json.

Run by hand with the toolbox installed (roboticstoolbox-python 1.5.0; it is not in symdyn's test
extra, whose dependencies it would more than double):

    python tests/data/toolbox/puma560_toolbox.py

For each state: rne(q, qd, qdd) (gravity, the motor inertia G^2 Jm and the motor-side friction
included), inertia(q), gravload(q) and coriolis(q, qd) @ qd.
"""

import json
from pathlib import Path

import numpy as np
import roboticstoolbox as rtb

robot = rtb.models.DH.Puma560()
rng = np.random.default_rng(560)
states = []
for _ in range(4):
    q, qd, qdd = rng.uniform(-2, 2, (3, 6))
    states.append(
        {
            "q": q.tolist(),
            "qd": qd.tolist(),
            "qdd": qdd.tolist(),
            "rne": robot.rne(q, qd, qdd).tolist(),
            "inertia": robot.inertia(q).tolist(),
            "gravload": robot.gravload(q).tolist(),
            "coriolis_qd": (robot.coriolis(q, qd) @ qd).tolist(),
        }
    )
out = {"toolbox": f"roboticstoolbox-python {rtb.__version__}", "robot": "models.DH.Puma560", "states": states}
Path(__file__).with_name("puma560_toolbox.json").write_text(json.dumps(out, indent=1) + "\n")
