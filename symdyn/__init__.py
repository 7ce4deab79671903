"""symdyn: symbolic equations of motion for robot manipulators, and code generated from them.

robot = symdyn.load_robot("examples/roger_arm.yaml")
dyn = symdyn.derive(robot, method="newton-euler")   # or "lagrange"
dyn.M, dyn.C, dyn.V, dyn.G, dyn.F, dyn.tau
symdyn.rnea(robot, q, qd, qdd, params)              # independent numeric oracle
symdyn.generate(robot, targets=("c", "casadi"), out_dir="out")
symdyn.draw(robot, q, "robot.svg")                  # the robot with its frames (.svg, .png, .html)

The package is layered, each floor importing only the ones below it:
spatial -> model -> parsers; symbolic -> algorithms -> dynamics -> codegen -> apps -> cli.
`oracle` (the numeric oracle; its public entry is `symdyn.rnea`) reads only the model.
"""

__version__ = "0.1.0"

import importlib as _importlib
from typing import TYPE_CHECKING

from . import module_aliases as _module_aliases
from .errors import SymdynError, SymdynWarning  # noqa: E402

if TYPE_CHECKING:  # what the names below are, for type checkers and the API reference
    from . import rnea
    from .algorithms import kinematics
    from .apps.compilation.compile import compile
    from .apps.drawing.draw import draw
    from .codegen import generate
    from .dynamics import Dynamics, derive
    from .model import inertia
    from .model.frames import Frame
    from .model.parameters import standard_parameters
    from .model.robot import Link, Robot
    from .parsers import load_mjcf, load_robot, load_urdf, robot_from_data, robot_from_poe

# Every other public name is imported on first use (PEP 562), so that `import symdyn` and a
# cached `symdyn simulate` start without SymPy: name -> (module, attribute or None for the module).
_LAZY = {
    "rnea": (".rnea", None),  # a callable module: symdyn.rnea(robot, q, qd, qdd)
    "kinematics": (".algorithms.kinematics", None),
    "inertia": (".model.inertia", None),
    "generate": (".codegen", "generate"),
    "compile": (".apps.compilation.compile", "compile"),
    "draw": (".apps.drawing.draw", "draw"),
    "Dynamics": (".dynamics", "Dynamics"),
    "derive": (".dynamics", "derive"),
    "standard_parameters": (".model.parameters", "standard_parameters"),
    "Link": (".model.robot", "Link"),
    "Frame": (".model.frames", "Frame"),
    "Robot": (".model.robot", "Robot"),
    "load_robot": (".parsers", "load_robot"),
    "load_urdf": (".parsers", "load_urdf"),
    "load_mjcf": (".parsers", "load_mjcf"),
    "robot_from_data": (".parsers", "robot_from_data"),
    "robot_from_poe": (".parsers", "robot_from_poe"),
}
#: `symdyn.inertia` and `symdyn.kinematics` are public modules (`import symdyn.inertia` works too),
#: and the old paths of moved modules (`symdyn.apps.compile`) still import: symdyn.module_aliases.
_module_aliases.install()


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'symdyn' has no attribute '{name}'")
    module_name, attribute = _LAZY[name]
    module = _importlib.import_module(module_name, __name__)
    value = module if attribute is None else getattr(module, attribute)
    globals()[name] = value
    return value


def __dir__():
    return sorted([*globals(), *_LAZY])


__all__ = [
    "__version__",
    "compile",
    "Dynamics",
    "Link",
    "Frame",
    "Robot",
    "SymdynError",
    "SymdynWarning",
    "derive",
    "draw",
    "generate",
    "inertia",
    "kinematics",
    "load_robot",
    "load_mjcf",
    "load_urdf",
    "rnea",
    "robot_from_data",
    "robot_from_poe",
    "standard_parameters",
]
