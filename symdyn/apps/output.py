"""Writing results: files written all at once (or streamed into a device or FIFO, never replacing
one: symdyn.destination), and Matplotlib figures rendered to bytes.

Shared by the applications that write files (symdyn.apps.simulation.trajectory, analysis_plots
and the command line). Figures use the Agg canvas directly, never pyplot, so no
global backend is changed; plot formats are png, pdf and svg, chosen by the suffix.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

from ..destination import destination, sweep, write_to
from ..errors import SymdynError

__all__ = ["write_atomic", "check_output", "figure", "figure_bytes", "plot_format", "PLOT_FORMATS"]

#: The image formats of --plot, by file suffix.
PLOT_FORMATS = ("png", "pdf", "svg")


def check_output(path: str | os.PathLike | None, option: str = "") -> None:
    """Refuse, before any work is done, an output path that write_atomic would refuse (the message
    starts with `option`, the flag that gave it); None passes."""
    if path is None:
        return
    try:
        destination(path)
    except SymdynError as exc:
        raise SymdynError(f"{option} {exc}".strip()) from None


def write_atomic(path: str | os.PathLike, content: str | bytes) -> Path:
    """Write a file all at once by symdyn.destination's rules: a regular file (new, or
    existing: its mode and owner kept; a link's target) through a temporary beside it and one
    rename; a character device, a FIFO or /dev/stdout streamed in place; anything else refused."""
    dest = destination(path)
    if dest.kind in ("new", "file"):
        sweep(dest.real.parent, [dest.real.name])
    write_to(dest, content)
    return Path(path)


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
