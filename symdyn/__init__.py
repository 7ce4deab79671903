"""symdyn: symbolic equations of motion for robot manipulators, and code generated from them.

robot = symdyn.load_robot("examples/roger_arm.yaml")
dyn = symdyn.derive(robot, method="newton-euler")   # or "lagrange"
dyn.M, dyn.C, dyn.V, dyn.G, dyn.F, dyn.tau
symdyn.rnea(robot, q, qd, qdd, params)              # independent numeric oracle
symdyn.generate(robot, targets=("c", "casadi"), out_dir="out")

The package is layered, each floor importing only the ones below it:
spatial -> model -> parsers; symbolic -> algorithms -> dynamics -> codegen -> apps -> cli.
`rnea` (the numeric oracle) reads only the model.
"""

__version__ = "0.1.0"

import sys as _sys

from . import rnea  # noqa: E402  (a callable module: symdyn.rnea(robot, q, qd, qdd))
from .algorithms import kinematics  # noqa: E402
from .codegen import generate  # noqa: E402
from .dynamics import Dynamics, derive  # noqa: E402
from .errors import SymdynError, SymdynWarning  # noqa: E402
from .model import inertia  # noqa: E402
from .model.parameters import standard_parameters  # noqa: E402
from .model.robot import Link, Robot  # noqa: E402
from .parsers import load_robot, load_urdf, robot_from_data, robot_from_poe  # noqa: E402

# `symdyn.inertia` and `symdyn.kinematics` are public modules: keep `import symdyn.inertia` working.
_sys.modules[__name__ + ".inertia"] = inertia
_sys.modules[__name__ + ".kinematics"] = kinematics

__all__ = [
    "__version__",
    "Dynamics",
    "Link",
    "Robot",
    "SymdynError",
    "SymdynWarning",
    "derive",
    "generate",
    "inertia",
    "kinematics",
    "load_robot",
    "load_urdf",
    "rnea",
    "robot_from_data",
    "robot_from_poe",
    "standard_parameters",
]
