"""symdyn: symbolic equations of motion for robot manipulators, and code generated from them.

robot = symdyn.load_robot("examples/roger_arm.yaml")
dyn = symdyn.derive(robot, method="newton-euler")   # or "lagrange"
dyn.M, dyn.C, dyn.V, dyn.G, dyn.F, dyn.tau
symdyn.rnea(robot, q, qd, qdd, params)              # independent numeric oracle
symdyn.generate(robot, targets=("c", "casadi"), out_dir="out")
"""

__version__ = "0.1.0"

from . import (
    inertia,  # noqa: E402
    rnea,  # noqa: E402  (a callable module: symdyn.rnea(robot, q, qd, qdd))
)
from .codegen import generate  # noqa: E402
from .dynamics import Dynamics, derive  # noqa: E402
from .errors import SymdynError, SymdynWarning  # noqa: E402
from .loaders import load_robot, load_urdf, robot_from_data  # noqa: E402
from .robot import Link, Robot  # noqa: E402

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
    "load_robot",
    "load_urdf",
    "rnea",
    "robot_from_data",
]
