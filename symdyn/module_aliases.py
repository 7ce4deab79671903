"""Other import paths of symdyn's modules: public short names, and the old paths of moved modules.

`symdyn.inertia` and `symdyn.kinematics` are short names of `symdyn.model.inertia` and
`symdyn.algorithms.kinematics`. The applications moved from `symdyn/apps/` into one package each
(issue 35; docs/layout.md, "Moved modules"): `symdyn.apps.compile` is now `symdyn.apps.compilation.compile`,
and so on (`MOVED`). Importing an alias gives the very module object of its new home (not a
copy, and its code runs once), so that classes compare equal, module state is shared and a
pickle written under an old path still loads.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types

__all__ = ["ALIASES", "MOVED", "install"]

#: The applications' packages and the modules that moved into each (from symdyn.apps).
_APPLICATIONS = {
    "compilation": (
        "build",
        "cache",
        "calling",
        "compile",
        "compiled",
        "compiled_frames",
        "robot_key",
        "singular",
    ),
    "simulation": (
        "control",
        "csv_format",
        "floating_stepping",
        "loop_simulate",
        "simulate",
        "stepping",
        "trajectory",
    ),
    "identification": (
        "csv_read",
        "excite",
        "identify",
        "least_squares",
        "measurements",
        "measurements_binary",
    ),
    "checking": ("check", "check_explain", "check_state", "check_steps", "steps", "steps_output"),
    "analysis": ("analysis_plots", "conditioning", "geometry", "task_space"),
}

#: old module path -> where the module lives now (issue 35; docs/layout.md)
MOVED = {
    **{f"symdyn.apps.{m}": f"symdyn.apps.{p}.{m}" for p, modules in _APPLICATIONS.items() for m in modules},
    "symdyn.module_files": "symdyn.generated_modules",
    "symdyn.parsers.loading": "symdyn.parsers.by_content",
}

#: every alias -> the module it stands for
ALIASES = {
    "symdyn.inertia": "symdyn.model.inertia",
    "symdyn.kinematics": "symdyn.algorithms.kinematics",
    **MOVED,
}


class _Existing(importlib.abc.Loader):
    """Loads an alias as the module it stands for, imported once under its own name."""

    def __init__(self, target: str) -> None:
        self.target = target
        self.spec: importlib.machinery.ModuleSpec | None = None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        module = importlib.import_module(self.target)
        self.spec = module.__spec__
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        # the import system has just given the module the alias's spec: give it back its own
        module.__spec__ = self.spec


class _AliasFinder(importlib.abc.MetaPathFinder):
    """Finds each name of ALIASES as the module it stands for."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in ALIASES:
            return None
        return importlib.machinery.ModuleSpec(fullname, _Existing(ALIASES[fullname]))


def install() -> None:
    """Put the finder first on sys.meta_path (once)."""
    if not any(isinstance(finder, _AliasFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, _AliasFinder())
