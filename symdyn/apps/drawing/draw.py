"""`symdyn.draw` and `symdyn draw`: a picture of a robot at q, as SVG, PNG or self-contained HTML.

The geometry comes from symdyn.algorithms.drawing (world frame, metres); the SVG and PNG draw
its projection (symdyn.apps.drawing.sketch) from --view iso, front, side or top; the HTML page
draws it in 3-D with three.js (symdyn.apps.drawing.page). The format is the output's suffix.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ...algorithms.drawing import default_configuration, scene
from ...errors import SymdynError
from ..output import check_output, write_atomic
from .page import html_page
from .sketch import sketch, view_basis
from .svg import svg_text

__all__ = ["draw", "picture", "FORMATS", "picture_format"]

#: The formats of a drawing, by the output file's suffix.
FORMATS = ("svg", "png", "html")


def picture_format(path: str | os.PathLike, formats=FORMATS, option: str = "--out") -> str:
    """The format named by the suffix of `path` among `formats`; SymdynError otherwise."""
    fmt = Path(path).suffix.lower().lstrip(".")
    if fmt == "htm":
        fmt = "html"
    if fmt not in formats:
        listed = ", ".join("." + f for f in formats)
        raise SymdynError(f"{option} {path}: the suffix must be one of {listed}")
    return fmt


def _q_text(q: np.ndarray) -> str:
    return "[" + ", ".join(f"{x:.6g}" for x in q) + "]"


def picture(scn, fmt: str, view: str = "iso") -> bytes:
    """The bytes of a drawing of the scene `scn` in format `fmt` (svg, png, html) from `view`."""
    view_basis(view)
    if fmt == "html":
        return html_page([scn], view).encode("utf-8")
    sk = sketch(scn, view)
    if fmt == "png":
        from .raster import png_bytes

        return png_bytes(sk)
    return svg_text(sk, view, _q_text(scn.q)).encode("utf-8")


def draw(robot, q=None, out=None, *, view: str = "iso", params=None, fmt: str | None = None) -> bytes:
    """Draw `robot` at q: its skeleton, joint axes, every link frame (x/y/z arrows, red/green/blue,
    labelled x_i, z_i), named frames and contacts, centres of mass (sized by mass) and, for a DH
    robot, the parameters a_i, d_i, alpha_i, theta_i at q.

    Args:
        robot: a `symdyn.Robot` (any: DH, PoE, URDF, MJCF; floating: q starts with the base's
            position and quaternion; closed loops: the closures are drawn dashed).
        q: the configuration (nq numbers; None: zeros, the identity quaternion).
        out: the file to write (atomically); its suffix gives the format (.svg, .png, .html).
        view: iso, front, side or top (the HTML page starts there and turns with the mouse).
        params: the free parameters' values, as in `symdyn.rnea`.
        fmt: the format when `out` is None (default svg).

    Returns:
        The picture's bytes (also written to `out`).

    Raises:
        SymdynError: a bad q, view, suffix or output path, missing parameter values.
    """
    if out is not None:
        check_output(out, "out")
        fmt = picture_format(out, option="out")
    fmt = fmt or "svg"
    if fmt not in FORMATS:
        raise SymdynError(f"draw: format {fmt!r} is not one of {', '.join(FORMATS)}")
    view_basis(view)  # an unknown view refused before any work
    scn = scene(robot, default_configuration(robot) if q is None else q, params)
    data = picture(scn, fmt, view)
    if out is not None:
        write_atomic(out, data)
    return data
