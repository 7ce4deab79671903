"""`symdyn simulate --animate`: a trajectory's motion as one self-contained HTML page (three.js, a
time slider and play/pause) or an animated GIF, with the tool frame's path and contact forces.

`frames` samples are taken evenly over the run (the first and the last included; all of them
when the run has fewer), the scene of each computed by symdyn.algorithms.drawing (world frame);
the tool's path uses every sample of runs of up to TRACE_POINTS samples (that many, evenly
spaced, of a longer run). A GIF has exactly `frames` frames (each shows its time, so no
two are merged), one picture map for all of them so that the robot does not jump.
"""

from __future__ import annotations

import os

import numpy as np

from ...algorithms.drawing import scene_function
from ...errors import SymdynError
from ..output import check_output, write_atomic
from .draw import picture_format
from .page import html_page
from .sketch import Label, extent, pixel_map, sketch, view_basis

__all__ = ["animate", "ANIMATION_FORMATS", "MAX_FRAMES"]

ANIMATION_FORMATS = ("html", "gif")
#: The most frames an animation holds (a GIF of 2,000 pictures takes minutes and hundreds of MB).
MAX_FRAMES = 2000
#: The most samples of the tool's path (a run may have millions of steps).
TRACE_POINTS = 2000


def _tool(robot, tool: str | None) -> str:
    """The frame whose path is drawn: `tool`, else the last link's frame."""
    if tool is None:
        return robot.links[-1].name
    robot.frame(tool, "animate")  # refuses an unknown name, naming the near matches
    return tool


def animate(
    robot,
    t,
    q,
    out: str | os.PathLike,
    *,
    frames: int = 60,
    view: str = "iso",
    params=None,
    tool: str | None = None,
    forces=None,
) -> bytes:
    """Write the animation of the run (t (N,), q (N, nq)) to `out` (.html or .gif) and return its bytes.

    Args:
        robot: the simulated `symdyn.Robot`.
        t, q: the sample times and configurations (a `Trajectory`'s t and q).
        out: the file to write (atomically); its suffix gives the format.
        frames: how many pictures (1 to MAX_FRAMES).
        view: iso, front, side or top.
        params: the free parameters' values.
        tool: the frame whose path is drawn (default: the last link's).
        forces: contact forces (N, number of Robot.contacts, 3), world frame, drawn as arrows at
            the contacts; None: none.

    Raises:
        SymdynError: a bad frame count, view, suffix or output path, t and q that disagree.
    """
    check_output(out, "--animate")
    fmt = picture_format(out, ANIMATION_FORMATS, "--animate")
    if not 1 <= int(frames) <= MAX_FRAMES:
        raise SymdynError(f"--frames {frames}: must be from 1 to {MAX_FRAMES:,}")
    view_basis(view)
    t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
    if t.ndim != 1 or q.ndim != 2 or len(t) != len(q) or len(t) == 0:
        raise SymdynError(f"animate: t {t.shape} and q {q.shape} must be (N,) and (N, nq)")
    make = scene_function(robot, params)
    name = _tool(robot, tool)
    picks = np.unique(np.round(np.linspace(0, len(t) - 1, min(int(frames), len(t)))).astype(int))
    scenes = [make(q[k]) for k in picks]
    along = np.unique(np.round(np.linspace(0, len(t) - 1, min(len(t), TRACE_POINTS))).astype(int))
    trace = np.array([make(q[k]).frame(name).origin for k in along]) if len(q) > 1 else None
    pairs = None
    if forces is not None:
        F = np.asarray(forces, dtype=float)
        contacts = [[f for f in s.frames if f.kind == "contact"] for s in scenes]
        pairs = [
            [(c.origin, F[k, j]) for j, c in enumerate(cs) if j < F.shape[1]]
            for k, cs in zip(picks, contacts, strict=True)
        ]
    if fmt == "html":
        step = float(t[picks[1]] - t[picks[0]]) if len(picks) > 1 else 0.05
        data = html_page(scenes, view, t[picks], trace, pairs, int(max(20, min(1000, 1000 * step)))).encode()
    else:
        data = _gif(scenes, t[picks], trace, view)
    write_atomic(out, data)
    return data


def _gif(scenes, times, trace, view: str) -> bytes:
    from .raster import gif_bytes

    pts = np.vstack([extent(s) for s in scenes] + ([trace] if trace is not None else []))
    px = pixel_map(view, pts)
    path = None if trace is None else np.array([px(p) for p in trace])
    sketches, extras = [], []
    for s, time in zip(scenes, times, strict=True):
        sk = sketch(s, view, px=px, dh=False)
        stamp = Label(10, float(sk.height - 12), f"t = {time:.3f} s", "", "#000000", 13)
        sketches.append(
            type(sk)(sk.width, sk.height, (*sk.groups, type(sk.groups[0])("time", (stamp,))), sk.title)
        )
        extras.append(
            () if path is None else (lambda ax, p=path: ax.plot(p[:, 0], p[:, 1], color="#17becf", lw=1.2),)
        )
    step = float(times[1] - times[0]) if len(times) > 1 else 0.1
    return gif_bytes(sketches, step, extras)
