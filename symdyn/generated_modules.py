"""Loading a generated Python file as a module: imported from its file, never exec'd from a string.

The file is symdyn's own output (a target's module, or a cache entry verified against its
manifest); importing it from the file keeps tracebacks pointing at real lines and means that no
text is ever executed that is not on disk to be read. No bytecode is written beside it (the
cache and output folders hold only what symdyn listed), and the module is not put in
sys.modules (two robots may have modules of the same name).
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import types
from collections.abc import Mapping
from pathlib import Path

from .errors import SymdynError

__all__ = ["load_module"]


class _SourceOnlyLoader(importlib.machinery.SourceFileLoader):
    """A source loader that never writes a __pycache__ folder beside the file."""

    def set_data(self, path, data, *, _mode=0o666) -> None:  # noqa: D102 - see the class docstring
        return None


def load_module(path: str | Path, name: str, preset: Mapping[str, object] | None = None) -> types.ModuleType:
    """Import the Python file at `path` as a fresh module called `name`.

    Args:
        path: the generated file.
        name: the module's __name__.
        preset: globals set before the file runs (the NumPy functions a lambdify source calls).
    """
    path = Path(path)
    loader = _SourceOnlyLoader(name, str(path))
    spec = importlib.util.spec_from_file_location(name, path, loader=loader)
    if spec is None:  # pragma: no cover - a .py path always has a spec
        raise SymdynError(f"{path}: cannot be imported as a Python module")
    module = importlib.util.module_from_spec(spec)
    if preset:
        module.__dict__.update(preset)
    try:
        loader.exec_module(module)
    except OSError as e:
        raise SymdynError(f"{path}: cannot read the generated module ({e.strerror or e})") from None
    return module
