"""Sketches (symdyn.apps.drawing.sketch) as pixels with Matplotlib's Agg canvas: a PNG, and the
frames of a GIF assembled by Pillow (Matplotlib's own dependency).

The primitives are drawn in pixel coordinates (y down, as in the SVG), so the raster picture is
the SVG's. Labels are plain text (Matplotlib's mathtext is off: a name with `$` stays as written).
"""

from __future__ import annotations

import io

from ...errors import SymdynError
from .sketch import Dot, Label, Line, Sketch

__all__ = ["png_bytes", "gif_bytes", "DPI"]

DPI = 100


def _figure(sk: Sketch):
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is in the test extras
        raise SymdynError("PNG and GIF pictures need matplotlib (pip install 'symdyn[plot]')") from exc
    fig = Figure(figsize=(sk.width / DPI, sk.height / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, sk.width)
    ax.set_ylim(sk.height, 0)
    ax.set_axis_off()
    return fig, ax


def _dashes(dash: str):
    return "solid" if not dash else (0, tuple(float(x) / 1.5 for x in dash.split()))


def _head(item: Line):
    """The arrowhead of a Line: a triangle at its end, 9 px long (the SVG marker's size)."""
    import numpy as np

    d = np.array([item.x2 - item.x1, item.y2 - item.y1])
    n = float(np.hypot(*d))
    if n < 1e-9:
        return None
    d /= n
    e = np.array([-d[1], d[0]])
    tip = np.array([item.x2, item.y2])
    return [tip, tip - 9 * d + 3.5 * e, tip - 9 * d - 3.5 * e]


def _text(item: Label) -> tuple[str, bool]:
    """(text, parse_math): a frame's subscript (digits) as mathtext, anything else as written."""
    if item.sub.isdigit() and item.text in ("x", "y", "z"):
        return f"${item.text}_{{{item.sub}}}$", True
    return item.text + (f" {item.sub}" if item.sub else ""), False


def _draw(ax, sk: Sketch, extra=()) -> None:
    """Every primitive, in order, as few artists as possible (one collection per group and kind)."""
    from matplotlib.collections import LineCollection, PatchCollection, PolyCollection
    from matplotlib.patches import Circle

    for group in sk.groups:
        lines = [i for i in group.items if isinstance(i, Line)]
        if lines:
            ax.add_collection(
                LineCollection(
                    [[(i.x1, i.y1), (i.x2, i.y2)] for i in lines],
                    colors=[i.color for i in lines],
                    linewidths=[i.width * 0.75 for i in lines],
                    linestyles=[_dashes(i.dash) for i in lines],
                    capstyle="round",
                )
            )
            heads = [(h, i.color) for i in lines if i.arrow and (h := _head(i)) is not None]
            if heads:
                ax.add_collection(
                    PolyCollection([h for h, _ in heads], facecolors=[c for _, c in heads], linewidths=0)
                )
        dots = [i for i in group.items if isinstance(i, Dot)]
        if dots:
            ax.add_collection(
                PatchCollection(
                    [Circle((i.x, i.y), i.r) for i in dots],
                    facecolors=["none" if i.fill == "none" else i.fill for i in dots],
                    edgecolors=["none" if i.stroke == "none" else i.stroke for i in dots],
                    linewidths=1.2,
                )
            )
        for item in group.items:
            if isinstance(item, Label):
                text, math = _text(item)
                ax.text(
                    item.x,
                    item.y,
                    text,
                    parse_math=math,
                    color=item.color,
                    fontsize=item.size * 0.75,
                )
    for draw in extra:
        draw(ax)


def png_bytes(sk: Sketch) -> bytes:
    """The sketch as a PNG (its width and height in pixels), deterministic: no metadata."""
    fig, ax = _figure(sk)
    _draw(ax, sk)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    return buf.getvalue()


def gif_bytes(sketches: list[Sketch], seconds_per_frame: float, extras=None) -> bytes:
    """An animated GIF of the sketches, one frame each (all of the first one's size), looping;
    `extras[k]` are callables drawing more on frame k's axes (the tool's trace)."""
    import numpy as np
    from PIL import Image

    w, h = sketches[0].width, sketches[0].height
    fig, ax = _figure(sketches[0])
    frames = []
    for k, sk in enumerate(sketches):
        ax.clear()
        ax.set_xlim(0, w)
        ax.set_ylim(h, 0)
        ax.set_axis_off()
        _draw(ax, sk, () if extras is None else extras[k])
        fig.canvas.draw()
        rgb = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy()
        frames.append(
            Image.fromarray(rgb).quantize(64, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
        )
    buf = io.BytesIO()
    duration = max(20, int(round(1000 * seconds_per_frame)))
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:], duration=duration, loop=0)
    return buf.getvalue()
