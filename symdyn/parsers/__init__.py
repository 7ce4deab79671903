"""Loaders from robot description formats onto the general model of `symdyn.model.robot`.

The loaders are imported when first asked for (PEP 562), so that a light module of this floor
(the hardened XML parser, the xacro test) can be imported without SymPy: the warm command-line
path reads a file's kind that way (symdyn.cli.cache).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and the API reference, which read the source
    from .by_content import load_robot
    from .mjcf import load_mjcf
    from .poe import robot_from_poe
    from .robot_file import robot_from_data
    from .urdf import load_urdf

    load = load_robot

__all__ = ["load", "load_mjcf", "load_robot", "load_urdf", "robot_from_data", "robot_from_poe"]

#: where each public name lives; `load` is the name the command line and `symdyn.generate` use
#: (one loader: by content)
_HOMES = {
    "load": ("by_content", "load_robot"),
    "load_robot": ("by_content", "load_robot"),
    "load_mjcf": ("mjcf", "load_mjcf"),
    "load_urdf": ("urdf", "load_urdf"),
    "robot_from_data": ("robot_file", "robot_from_data"),
    "robot_from_poe": ("poe", "robot_from_poe"),
}


def __getattr__(name: str) -> Any:
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, attribute = _HOMES[name]
    value = getattr(importlib.import_module(f".{module}", __name__), attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
