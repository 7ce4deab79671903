"""Writing results: files written all at once, and Matplotlib figures rendered to bytes.

Shared by the applications that write files (symdyn.apps.trajectory, analysis_plots
and the command line). Figures use the Agg canvas directly, never pyplot, so no
global backend is changed; plot formats are png, pdf and svg, chosen by the suffix.
"""

from __future__ import annotations

import io
import os
import tempfile
from pathlib import Path

from ..errors import SymdynError

__all__ = ["write_atomic", "figure", "figure_bytes", "plot_format", "PLOT_FORMATS"]

#: The image formats of --plot, by file suffix.
PLOT_FORMATS = ("png", "pdf", "svg")


def write_atomic(path: str | os.PathLike, content: str | bytes) -> Path:
    """Write a file all at once: a temporary file beside it, then os.replace."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise SymdynError(f"{target}: folder {folder} does not exist")
    if target.is_dir():
        raise SymdynError(f"{target}: is a folder")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(content.encode() if isinstance(content, str) else content)
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return target


def figure(rows: int, width: float = 8.0, height_per_row: float = 2.6):
    """A Matplotlib Figure with the Agg canvas (no pyplot, no global backend change)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is in the test extras
        raise SymdynError("plots need matplotlib (pip install 'symdyn[plot]')") from exc
    fig = Figure(figsize=(width, height_per_row * rows), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def figure_bytes(fig, fmt: str = "png", dpi: int = 120) -> bytes:
    """A figure rendered to bytes (written by the caller with write_atomic)."""
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi)
    return buf.getvalue()


def plot_format(path: str | os.PathLike) -> str:
    """The image format named by the suffix of `path` (png when it has none); SymdynError otherwise."""
    fmt = Path(path).suffix.lower().lstrip(".") or "png"
    if fmt not in PLOT_FORMATS:
        raise SymdynError(f"{path}: plot format '{fmt}' is not supported (use .png, .pdf or .svg)")
    return fmt
