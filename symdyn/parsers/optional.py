"""Optional packages a loader needs only for some formats, imported on first use: `mujoco` (the
`mjcf` extra) for MJCF files, `xacro` (the `xacro` extra) for xacro files."""

from __future__ import annotations

import importlib
from types import ModuleType

from ..errors import SymdynError

__all__ = ["optional_module"]


def optional_module(name: str, extra: str, purpose: str, file: str | None = None) -> ModuleType:
    """The module `name`, imported now; SymdynError naming the extra to install when it is missing.

    purpose: what needs it, for the message ("reading an MJCF file").
    """
    try:
        return importlib.import_module(name)
    except ImportError:
        raise SymdynError(
            f"{purpose} needs the Python package '{name}', which is not installed: "
            f"pip install 'symdyn[{extra}]'",
            file=file,
        ) from None
