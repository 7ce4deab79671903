"""A self-contained HTML page drawing scenes (symdyn.model.scene) with three.js: one scene (a
drawing) or many (an animation, with a time slider and play/pause), in one file.

three.js (symdyn/apps/drawing/vendor/three, its version in VERSION) is inlined as a data: URL
in an import map, so the page loads nothing from the network; the page's own script is
page.js beside this module. The scenes go in as JSON inside <script type="application/json">,
with <, > and & written as \\u escapes, so no name can close the element; the script puts user
text into the page only through textContent. World frame, metres.

The labels are the SVG's (symdyn.apps.drawing.sketch): each link frame's x_i and z_i, the named
frames' and contacts' names, and a DH robot's parameters (sketch.dh_texts, with their dashed
lines, and sketch.dh_table in the corner), HTML elements placed each time the view is drawn at
their 3-D points projected by the camera, so they follow dragging and the animation's steps.
"""

from __future__ import annotations

import base64
import json
from functools import lru_cache
from html import escape
from pathlib import Path

import numpy as np

from ...model.scene import Scene
from .sketch import dh_table, dh_texts

__all__ = ["html_page", "THREE_VERSION"]

_HERE = Path(__file__).parent
THREE_VERSION = "0.170.0"

_STYLE = (
    "body{margin:0;font-family:sans-serif;background:#fff}#view{position:relative;width:960px;"
    "height:720px;overflow:hidden}#labels{position:absolute;left:0;top:0;pointer-events:none}"
    ".label{position:absolute;font-size:13px;transform:translate(-50%,-50%);white-space:pre}"
    ".label.dh{font-size:12px;transform:translate(0,-80%)}#dh-table{position:absolute;left:8px;top:4px;"
    "color:#9467bd;font-size:12px;border-collapse:collapse}#dh-table td{padding:0 12px 0 0}"
    "#controls{padding:6px 10px}#slider{width:600px;vertical-align:middle}h1{font-size:16px;"
    "margin:8px 10px}"
)


@lru_cache(maxsize=1)
def _three_url() -> str:
    data = (_HERE / "vendor" / "three" / "three.module.min.js").read_bytes()
    return "data:text/javascript;base64," + base64.b64encode(data).decode("ascii")


def _r(a) -> list:
    """Numbers rounded to 1e-9 (m), -0 written 0: compact and deterministic."""
    return (np.round(np.asarray(a, dtype=float), 9) + 0.0).tolist()


def _step(s: Scene, forces=None) -> dict:
    out = {
        "frames": [[_r(f.origin), _r(f.axes.reshape(-1))] for f in s.frames],
        "segments": [[_r(g.start), _r(g.end)] for g in s.segments],
        "joints": [
            [_r(j.origin - 0.6 * s.scale * j.axis), _r(j.origin + 0.6 * s.scale * j.axis)] for j in s.joints
        ],
        "masses": [_r(m.position) for m in s.masses],
        "dh": [
            [t.text, t.sub, _r(t.at), list(t.shift), None if t.span is None else [_r(p) for p in t.span]]
            for t in dh_texts(s)
        ],
        "table": dh_table(s),
    }
    if forces:
        out["forces"] = [[_r(p), _r(f)] for p, f in forces]
    return out


def _json(data: dict) -> str:
    text = json.dumps(data, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def html_page(
    scenes: list[Scene],
    view: str = "iso",
    times=None,
    trace=None,
    forces=None,
    frame_ms: int = 50,
    title: str | None = None,
) -> str:
    """The page (module docstring) of `scenes` (one per time in `times`; the first one's frames,
    segments and masses name every later one's), seen first from `view` (iso, front, side, top;
    dragging turns it); `trace`: points (k x 3) of the tool's path; `forces[k]`: (point, force)
    pairs of scene k, drawn as arrows (N, scaled to the robot's size)."""
    first = scenes[0]
    pts = np.vstack(
        [s.points() for s in scenes] + ([np.asarray(trace).reshape(-1, 3)] if trace is not None else [])
    )
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    peak = max((float(np.linalg.norm(f)) for fs in forces or () for _, f in fs), default=0.0)
    data = {
        "name": first.name,
        "view": view,
        "center": _r((lo + hi) / 2),
        "radius": float(max(np.linalg.norm(hi - lo) / 2, first.scale)),
        "scale": float(first.scale),
        "force_scale": float(3 * first.scale / peak) if peak > 0 else 0.0,
        "frames": [{"name": f.name, "kind": f.kind, "label": f.label} for f in first.frames],
        "segment_kinds": [g.kind for g in first.segments],
        "masses": [float(m.mass) for m in first.masses],
        "times": _r([0.0] if times is None else times),
        "frame_ms": int(frame_ms),
        "trace": [] if trace is None else [_r(p) for p in trace],
        "steps": [_step(s, None if forces is None else forces[k]) for k, s in enumerate(scenes)],
    }
    heading = escape(title if title is not None else first.name)
    imports = json.dumps({"imports": {"three": _three_url()}})
    script = (_HERE / "page.js").read_text(encoding="utf-8")
    return "\n".join(
        [
            "<!DOCTYPE html>",
            '<html lang="en"><head><meta charset="utf-8">',
            f"<title>{heading}</title>",
            f"<style>{_STYLE}</style>",
            "<script>window.addEventListener('error',(e)=>{document.documentElement.dataset.status="
            "'error: '+e.message});window.addEventListener('unhandledrejection',(e)=>{"
            "document.documentElement.dataset.status='error: '+e.reason});</script>",
            f'<script type="importmap">{imports}</script>',
            "</head><body>",
            f"<h1>{heading}</h1>",
            '<div id="view"><div id="labels"></div><table id="dh-table"></table></div>',
            '<div id="controls"><button id="play" type="button">play</button> '
            '<input id="slider" type="range" min="0" max="0" step="1" value="0"> '
            '<span id="time"></span></div>',
            f'<script type="application/json" id="symdyn-data">{_json(data)}</script>',
            f'<script type="module">\n{script}</script>',
            "</body></html>",
            "",
        ]
    )
