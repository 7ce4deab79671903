"""The drawing of a robot at one configuration: what a picture of its kinematics shows, in numbers.

A `Scene` is the robot's geometry at q, every quantity a NumPy array in the *world* frame (metres,
the frame in which Robot.base places the base; a floating robot's base pose comes from q):

* `frames`: every link's convention frame (the DH frame i of a DH file, the URDF link frame,
  PoE's {i}), every named frame (Robot.frames), the base frame and the contacts
  (`FrameMarker.kind` says which), each as its origin and its axes (the columns of world_R_F);
* `joints`: each joint's origin and unit axis (z of the body frame of a DH link), revolute or
  prismatic;
* `segments`: the skeleton, the line from each joint origin to its parent's joint origin (the
  base frame's origin for a link on the base), and the closures of kinematic loops (the two
  points a loop makes coincide);
* `masses`: each link's centre of mass and mass;
* `dh`: a DH robot's parameters (a_i, d_i, alpha_i, theta_i at q) read back from its frames
  (symdyn.algorithms.drawing), with the points where a picture marks them.

Writers (symdyn.apps.drawing) turn a Scene into SVG, PNG or HTML; they compute nothing about the
robot. Names are the user's text, escaped by each writer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrameMarker", "JointMarker", "Segment", "MassMarker", "DHMark", "Scene", "FRAME_KINDS"]

#: The kinds of frame markers: the base frame, a link's own frame, a named frame, a contact.
FRAME_KINDS = ("base", "link", "frame", "contact")


@dataclass(frozen=True)
class FrameMarker:
    """A frame drawn as x/y/z arrows: `origin` (3,) and `axes` (3 x 3, columns x, y, z), world.

    `label` is the textbook subscript ("1" for x_1, z_1) of a link's frame, "0" for the base, and
    the frame's name for the others."""

    name: str
    kind: str
    origin: np.ndarray
    axes: np.ndarray
    label: str


@dataclass(frozen=True)
class JointMarker:
    """Joint i: its origin and unit axis (world), "revolute" or "prismatic"."""

    name: str
    joint: str
    origin: np.ndarray
    axis: np.ndarray


@dataclass(frozen=True)
class Segment:
    """A line of the skeleton (`kind` "link") or of a loop's closure (`kind` "loop"), world."""

    start: np.ndarray
    end: np.ndarray
    kind: str = "link"


@dataclass(frozen=True)
class MassMarker:
    """Link `name`'s centre of mass (world) and mass (kg)."""

    name: str
    position: np.ndarray
    mass: float


@dataclass(frozen=True)
class DHMark:
    """Row i (1-based) of a DH table at q, with where a picture writes each parameter.

    Standard (distal) rows: frame_i = frame_{i-1} Rz(theta) Tz(d) Tx(a) Rx(alpha); d is measured
    along z_{i-1} from origin_{i-1} to `foot`, a along x_i from `foot` to origin_i. Modified
    (proximal) rows: frame_i = frame_{i-1} Rx(alpha) Tx(a) Rz(theta) Tz(d); a along x_{i-1} from
    origin_{i-1} to `foot`, d along z_i from `foot` to origin_i. Angles in rad."""

    index: int
    convention: str
    a: float
    d: float
    alpha: float
    theta: float
    start: np.ndarray
    foot: np.ndarray
    end: np.ndarray


@dataclass(frozen=True)
class Scene:
    """A robot's drawing at one configuration (module docstring); `scale` (m) is the length of
    the frame arrows, about a tenth of the robot's size."""

    name: str
    q: np.ndarray
    frames: tuple[FrameMarker, ...]
    joints: tuple[JointMarker, ...]
    segments: tuple[Segment, ...]
    masses: tuple[MassMarker, ...]
    dh: tuple[DHMark, ...]
    scale: float

    def points(self) -> np.ndarray:
        """Every point of the drawing (k x 3), for its bounds."""
        pts = [f.origin for f in self.frames] + [m.position for m in self.masses]
        pts += [p for s in self.segments for p in (s.start, s.end)]
        return np.array(pts, dtype=float).reshape(-1, 3)

    def frame(self, name: str) -> FrameMarker:
        """The frame marker named `name` (KeyError when there is none)."""
        for f in self.frames:
            if f.name == name:
                return f
        raise KeyError(name)
