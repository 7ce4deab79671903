"""A Scene (symdyn.model.scene) projected onto the picture plane as 2-D primitives in pixels.

The views look at the world from fixed directions (right-handed, world z up unless looking down
it): `front` from -y (x right, z up), `side` from +x (y right, z up), `top` from +z (x right,
y up), `iso` from (1, 1, 1) (x towards the lower left, y the lower right, z up, as textbook
figures draw frames). A point p goes to (u, v) = (right . p, up . p), then to pixels: scaled to fit
the canvas with a margin, v flipped (pixels grow downwards). The SVG and raster writers
(symdyn.apps.drawing.svg, .raster) draw the same primitives, so the two pictures agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import SymdynError
from ...model.scene import Scene

__all__ = [
    "VIEWS",
    "Line",
    "Dot",
    "Label",
    "Group",
    "Sketch",
    "sketch",
    "extent",
    "pixel_map",
    "view_basis",
    "COLORS",
    "DHText",
    "dh_texts",
    "dh_table",
]

#: The views of --view: name -> (right, up) unit vectors of the picture plane, world frame.
_S2, _S6 = math.sqrt(2.0), math.sqrt(6.0)
VIEWS = {
    "iso": ((-1 / _S2, 1 / _S2, 0.0), (-1 / _S6, -1 / _S6, 2 / _S6)),
    "front": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "side": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
}
#: Axis colours (x, y, z: red, green, blue), the skeleton, joints, masses, DH marks, contacts.
COLORS = {
    "x": "#d62728",
    "y": "#2ca02c",
    "z": "#1f77b4",
    "link": "#555555",
    "loop": "#8c564b",
    "joint": "#ff7f0e",
    "mass": "#7f7f7f",
    "dh": "#9467bd",
    "contact": "#e377c2",
}
WIDTH = 800
MARGIN = 70.0


@dataclass(frozen=True)
class Line:
    """A line in pixels; `arrow`: an arrowhead at the end; `dash`: an SVG dash pattern or ""."""

    x1: float
    y1: float
    x2: float
    y2: float
    color: str
    width: float = 1.5
    arrow: bool = False
    dash: str = ""


@dataclass(frozen=True)
class Dot:
    x: float
    y: float
    r: float
    fill: str
    stroke: str = "none"


@dataclass(frozen=True)
class Label:
    """Text at (x, y) in pixels, with an optional subscript ("x" with "1": x_1)."""

    x: float
    y: float
    text: str
    sub: str = ""
    color: str = "#000000"
    size: float = 13.0


@dataclass(frozen=True)
class Group:
    """Primitives drawn together; `attrs` become the SVG group's attributes (data-frame ...)."""

    kind: str
    items: tuple = ()
    attrs: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Sketch:
    width: int
    height: int
    groups: tuple[Group, ...] = field(default_factory=tuple)
    title: str = ""


def view_basis(view: str) -> np.ndarray:
    """The 2 x 3 projection (rows: right, up) of a view name; SymdynError for an unknown one."""
    if view not in VIEWS:
        raise SymdynError(f"draw: unknown view {view!r} (use {', '.join(VIEWS)})")
    return np.array(VIEWS[view], dtype=float)


def _number(v: float) -> str:
    """A number as a figure writes it: 4 significant digits, never "-0"."""
    text = f"{v:.4g}"
    return "0" if text in ("-0", "0") else text


def _degrees(v: float) -> str:
    text = f"{math.degrees(v):.1f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "0") else text


class _Pixels:
    """World -> pixel map of one picture: the projection, then a fit into the canvas."""

    def __init__(self, P: np.ndarray, points: np.ndarray, width: int, pad: float = 0.0) -> None:
        uv = points @ P.T  # finite and below 1e15 m (symdyn.algorithms.drawing checks)
        lo, hi = uv.min(axis=0), uv.max(axis=0)
        span = np.maximum(hi - lo, 1e-9)
        self.s = (width - 2 * MARGIN) / max(span[0], span[1] * 0.75, 1e-9)
        self.lo, self.P, self.pad = lo, P, pad
        self.height = int(math.ceil(span[1] * self.s + 2 * MARGIN + pad))
        self.top = hi[1]

    def __call__(self, p: np.ndarray) -> tuple[float, float]:
        u, v = self.P @ p
        return MARGIN + (u - self.lo[0]) * self.s, MARGIN + self.pad + (self.top - v) * self.s


def _origin_text(p: np.ndarray) -> str:
    """data-origin: x y z in metres, 12 significant digits (1e-12 m on a robot of a metre; the
    last bits, which libm may round differently on another machine, left out)."""
    return " ".join("0" if (t := f"{float(x):.12g}") == "-0" else t for x in p)


def extent(scene: Scene) -> np.ndarray:
    """The points a picture of `scene` must hold (k x 3, world): its points and its arrows' tips."""
    L = scene.scale
    tips = [f.origin + L * f.axes[:, k] for f in scene.frames for k in range(3)]
    return np.vstack([scene.points(), np.array(tips).reshape(-1, 3)])


def pixel_map(view: str, points: np.ndarray, width: int = WIDTH) -> _Pixels:
    """The world -> pixel map of a picture from `view` that holds `points` (k x 3)."""
    return _Pixels(view_basis(view), points, width)


def sketch(
    scene: Scene, view: str = "iso", width: int = WIDTH, px: _Pixels | None = None, dh: bool = True
) -> Sketch:
    """The primitives of `scene` seen from `view` (module docstring), in drawing order: skeleton,
    joint axes, masses, DH marks, frames (each frame a Group with data-frame and data-origin);
    `px`: the pixel map to use (the same for every frame of an animation), else one fitting it;
    `dh`: mark a DH robot's parameters (an animation leaves them out)."""
    if px is None:  # room above the drawing for the DH table
        pad = 16.0 * (len(scene.dh) + 1) if scene.dh and dh else 0.0
        px = _Pixels(view_basis(view), extent(scene), width, pad)
    L = scene.scale
    groups = [_skeleton(scene, px), _joints(scene, px, L), _masses(scene, px)]
    if scene.dh and dh:
        groups.append(_dh(scene, px))
    groups += [_frame(f, px, L) for f in scene.frames]
    return Sketch(width, px.height, tuple(groups), scene.name)


def _skeleton(scene: Scene, px: _Pixels) -> Group:
    items = []
    for s in scene.segments:
        (x1, y1), (x2, y2) = px(s.start), px(s.end)
        if s.kind == "loop":
            items.append(Line(x1, y1, x2, y2, COLORS["loop"], 3.0, dash="6 4"))
        else:
            items.append(Line(x1, y1, x2, y2, COLORS["link"], 5.0))
    return Group("skeleton", tuple(items))


def _joints(scene: Scene, px: _Pixels, L: float) -> Group:
    items = []
    for j in scene.joints:
        (x1, y1), (x2, y2) = px(j.origin - 0.6 * L * j.axis), px(j.origin + 0.6 * L * j.axis)
        dash = "" if j.joint == "revolute" else "3 3"
        items.append(Line(x1, y1, x2, y2, COLORS["joint"], 3.0, dash=dash))
        x, y = px(j.origin)
        items.append(Dot(x, y, 5.0, "#ffffff", COLORS["joint"]))
    return Group("joints", tuple(items))


def _masses(scene: Scene, px: _Pixels) -> Group:
    heaviest = max((m.mass for m in scene.masses), default=0.0)
    items = []
    for m in scene.masses:
        if not m.mass > 0 or not heaviest > 0:
            continue
        x, y = px(m.position)
        items.append(Dot(x, y, 3.0 + 9.0 * (m.mass / heaviest) ** (1 / 3), COLORS["mass"], "#333333"))
    return Group("masses", tuple(items))


@dataclass(frozen=True)
class DHText:
    """One DH parameter as a picture writes it: `text` with the subscript `sub` ("d" with
    "2 = 0.15"), beside the world point `at`, moved by `shift` pixels (right, down); a length
    has `span`, the two world points of its dashed line (`at` is their midpoint)."""

    text: str
    sub: str
    at: np.ndarray
    shift: tuple[float, float]
    span: tuple[np.ndarray, np.ndarray] | None = None


def dh_texts(scene: Scene) -> list[DHText]:
    """Each DH row's d and a (non-zero) along their dashed lines, theta beside the foot and alpha
    beside the frame it turns (the SVG's marks, the HTML page's labels). A modified row i holds
    Craig's a_{i-1} and alpha_{i-1}."""
    out = []
    for row in scene.dh:
        i = str(row.index)
        standard = row.convention == "standard"
        before = i if standard else str(row.index - 1)  # the subscript of a and alpha
        d_span = (row.start, row.foot) if standard else (row.foot, row.end)
        a_span = (row.foot, row.end) if standard else (row.start, row.foot)
        for name, sub, span, value in (("d", i, d_span, row.d), ("a", before, a_span, row.a)):
            if abs(value) > 1e-9:
                mid = (np.asarray(span[0]) + np.asarray(span[1])) / 2
                out.append(DHText(name, f"{sub} = {_number(value)}", mid, (6.0, -6.0), span))
        if abs(row.theta) > 1e-9:
            out.append(DHText("θ", f"{i} = {_degrees(row.theta)}°", row.foot, (8.0, 16.0)))
        if abs(row.alpha) > 1e-9:
            at = row.end if standard else row.foot
            out.append(DHText("α", f"{before} = {_degrees(row.alpha)}°", at, (8.0, 30.0)))
    return out


def dh_table(scene: Scene) -> list[list[tuple[str, str]]]:
    """A DH robot's table at q as (text, subscript) cells: the header (i, a, d, alpha, theta),
    then one row per joint (lengths in m, angles in degrees); [] for another robot."""
    if not scene.dh:
        return []
    before = "i" if scene.dh[0].convention == "standard" else "i-1"
    rows = [[("i", ""), ("a", before), ("d", "i"), ("α", before), ("θ", "i")]]
    for r in scene.dh:
        cells = (str(r.index), _number(r.a), _number(r.d), _degrees(r.alpha) + "°", _degrees(r.theta) + "°")
        rows.append([(text, "") for text in cells])
    return rows


def _dh(scene: Scene, px: _Pixels) -> Group:
    """Each row's d and a as dashed lines with their values, alpha and theta beside them
    (dh_texts), and the table (dh_table) in the top left corner."""
    c = COLORS["dh"]
    items = []
    for t in dh_texts(scene):
        if t.span is not None:
            (x1, y1), (x2, y2) = px(t.span[0]), px(t.span[1])
            items.append(Line(x1, y1, x2, y2, c, 1.5, dash="4 3"))
            x, y = (x1 + x2) / 2, (y1 + y2) / 2
        else:
            x, y = px(t.at)
        items.append(Label(x + t.shift[0], y + t.shift[1], t.text, t.sub, c, 12))
    for k, row in enumerate(dh_table(scene)):  # the table, in the top left corner
        for j, (text, sub) in enumerate(row):
            items.append(Label(10 + 70 * j, 18 + 16 * k, text, sub, c, 12))
    return Group("dh", tuple(items), (("data-convention", scene.dh[0].convention),))


def _frame(f, px: _Pixels, L: float) -> Group:
    x0, y0 = px(f.origin)
    items = []
    named = f.kind in ("frame", "contact")
    width = 1.5 if named else 2.2
    length = 0.6 * L if named else L
    for k, axis in enumerate("xyz"):
        x, y = px(f.origin + length * f.axes[:, k])
        items.append(Line(x0, y0, x, y, COLORS[axis], width, arrow=True, dash="5 2" if named else ""))
        if f.kind in ("link", "base") and axis != "y":
            dx, dy = x - x0, y - y0
            norm = math.hypot(dx, dy) or 1.0
            items.append(Label(x + 9 * dx / norm - 4, y + 9 * dy / norm + 4, axis, f.label, COLORS[axis]))
    if f.kind == "contact":
        items.append(Dot(x0, y0, 6.0, "none", COLORS["contact"]))
    if named:
        items.append(
            Label(x0 + 6, y0 - 8, f.label, "", COLORS["contact"] if f.kind == "contact" else "#333333", 11)
        )
    attrs = (("data-frame", f.name), ("data-kind", f.kind), ("data-origin", _origin_text(f.origin)))
    return Group(f"frame {f.kind}", tuple(items), attrs)
