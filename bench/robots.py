"""The robots of both benchmarks: bench/derive.py's arms and bench/run.py's robot files.

For bench/derive.py (built in memory as symdyn Robots):

* `generic_arm(n)`: an n-joint spatial arm in standard DH, every joint revolute,
  twists cycling 0, +pi/2, -pi/2, nonzero a and d, numeric masses, centres of
  mass and diagonal inertias (given in DH frame i, converted to the body frame
  as a loader would).
* `puma560_symbolic()`: the PUMA 560 geometry of examples/puma560.yaml (or the
  standard DH table if the file or loader is missing) with every link's mass,
  centre of mass (3) and inertia tensor (6) replaced by free symbols, written in
  DH frame i and converted to the body frame. Motor inertia and friction are
  left out so that all three methods derive the same rigid-body equations.
  Its sympy.physics.mechanics twin is built by bench/kane.py.

For bench/run.py (robot files, as `symdyn generate` reads them):

* `ROBOTS`: name -> robot file; `QUICK_ROBOTS`, `ARMS` (the arms the targets judge),
  `TREES` (the kinematic trees the targets judge), `URDF_TIPS` (URDF file -> tip link)
  and `load(path)`. The URDF robots come from example-robot-data when it is installed:
  `panda_urdf` (a chain cut out by its tip), and the whole trees on a fixed base
  `talos_reduced` (32 joints: two legs, torso, two arms with grippers, head) and
  `solo12` (12 joints, four legs), loaded without a tip.
* `puma560_float_text()`: examples/puma560.yaml with every twist pi/2 written as the
  float 1.5707963267948966 (the robot `puma560_float`, file bench/chains/puma560_float.yaml,
  written by `write_robot_files()` with the chains of bench/chains.py).
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import replace
from pathlib import Path

import chains
import sympy as sp

from symdyn.model.robot import Friction, Link, Motor, Robot
from symdyn.spatial.transform import Transform

__all__ = [
    "generic_arm",
    "example_robot_file",
    "puma560_symbolic",
    "puma560_float_text",
    "write_robot_files",
    "load",
    "PUMA_FILE",
    "ROBOTS",
    "QUICK_ROBOTS",
    "ARMS",
    "URDF_TIPS",
    "TREES",
]

PUMA_FILE = chains.PUMA_FILE
GRAVITY = (0, 0, -9.81)
_TWISTS = (sp.S.Zero, sp.pi / 2, -sp.pi / 2)
_INERTIA_KEYS = ("xx", "xy", "xz", "yy", "yz", "zz")


def _dh_link(a, alpha, d, prev_frame: Transform) -> tuple[Transform, sp.ImmutableMatrix, Transform]:
    """(placement, axis, frame) of a standard-DH revolute row with theta offset 0."""
    try:
        from symdyn.parsers.dh import dh_link
    except ImportError:  # fall back to the same construction written out
        placement = prev_frame @ Transform.tz(d)
        frame = Transform.tx(a) @ Transform.rx(alpha)
        return placement, sp.ImmutableMatrix([0, 0, 1]), frame
    return dh_link("standard", "revolute", a, alpha, d, 0, prev_frame)


def _to_body(frame: Transform, com, inertia) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Centre of mass and inertia given in DH frame i, re-expressed in the body frame."""
    from symdyn.parsers.dh import to_body

    return to_body(frame, com, inertia)


def _link(name: str, a, alpha, d, prev: Transform, mass, com, inertia) -> Link:
    placement, axis, frame = _dh_link(a, alpha, d, prev)
    com_b, inertia_b = _to_body(frame, com, inertia)
    return Link(
        name=name,
        joint="revolute",
        placement=placement,
        axis=sp.ImmutableMatrix(axis),
        mass=sp.sympify(mass),
        com=com_b,
        inertia=inertia_b,
        frame=frame,
    )


def generic_arm(n: int) -> Robot:
    """A generic n-joint spatial arm with numeric inertial parameters (see the module docstring)."""
    links = []
    prev = Transform.identity()
    for i in range(n):
        k = i + 1
        a = sp.Float(round(0.30 - 0.02 * i, 4))
        d = sp.Float(round(0.10 + 0.03 * ((i * 5) % 4), 4))
        alpha = _TWISTS[i % 3]
        mass = sp.Float(round(4.0 - 0.4 * i, 4))
        com = [sp.Float(round(v, 4)) for v in (-0.45 * float(a), 0.01 * k, 0.02 - 0.005 * i)]
        inertia = sp.diag(*[sp.Float(round(v, 5)) for v in (0.05 / k, 0.06 / k, 0.03 / k)])
        link = _link(f"link{k}", a, alpha, d, prev, mass, com, inertia)
        prev = link.frame
        links.append(link)
    return Robot(name=f"generic{n}", links=tuple(links), gravity=sp.ImmutableMatrix(GRAVITY))


def _puma_geometry() -> list[tuple[sp.Expr, sp.Expr, sp.Expr]]:
    """(a, alpha, d) per link: the standard PUMA 560 DH table (Corke, mdl_puma560.m)."""
    a = [0, 0.4318, 0.0203, 0, 0, 0]
    d = [0, 0, 0.15005, 0.4318, 0, 0]
    alpha = [sp.pi / 2, 0, -sp.pi / 2, sp.pi / 2, -sp.pi / 2, 0]
    return [(sp.sympify(x), al, sp.sympify(y)) for x, al, y in zip(a, alpha, d, strict=True)]


def _inertial_symbols(k: int) -> tuple[sp.Symbol, list[sp.Symbol], sp.Matrix, list[sp.Symbol]]:
    m = sp.Symbol(f"m_{k}")
    com = [sp.Symbol(f"c{ax}_{k}") for ax in "xyz"]
    I = {key: sp.Symbol(f"I{key}_{k}") for key in _INERTIA_KEYS}
    tensor = sp.Matrix(
        [
            [I["xx"], I["xy"], I["xz"]],
            [I["xy"], I["yy"], I["yz"]],
            [I["xz"], I["yz"], I["zz"]],
        ]
    )
    return m, com, tensor, [m, *com, *I.values()]


def puma560_symbolic() -> tuple[Robot, str]:
    """The PUMA 560 with all 60 inertial parameters symbolic, and where its geometry came from."""
    base = None
    if PUMA_FILE.exists():
        try:
            from symdyn.parsers import load_robot
        except ImportError:
            load_robot = None
        if load_robot is not None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the file's implausible-inertia warnings
                base = load_robot(PUMA_FILE).resolved()
    links, params = [], []
    if base is not None:
        origin = f"geometry from {PUMA_FILE.relative_to(chains.ROOT)}"
        for k, link in enumerate(base.links, start=1):
            m, com, tensor, syms = _inertial_symbols(k)
            com_b, inertia_b = _to_body(link.frame, com, tensor)
            links.append(
                replace(link, mass=m, com=com_b, inertia=inertia_b, friction=Friction(), motor=Motor())
            )
            params += syms
        gravity = base.gravity
    else:
        origin = "geometry from the built-in standard PUMA 560 DH table"
        prev = Transform.identity()
        for k, (a, alpha, d) in enumerate(_puma_geometry(), start=1):
            m, com, tensor, syms = _inertial_symbols(k)
            link = _link(f"link{k}", a, alpha, d, prev, m, com, tensor)
            prev = link.frame
            links.append(link)
            params += syms
        gravity = sp.ImmutableMatrix(GRAVITY)
    robot = Robot(name="puma560_symbolic", links=tuple(links), gravity=gravity, params=tuple(params))
    return robot, origin


# --------------------------------------------------------------------------- bench/run.py's robots


EXAMPLES = chains.ROOT / "examples"
FLOAT_PUMA_FILE = chains.CHAIN_DIR / "puma560_float.yaml"
HALF_PI = repr(math.pi / 2)  # "1.5707963267948966", the double nearest pi/2
_PI_HALF_TWIST = re.compile(r"^(\s*alpha:\s*)(-?)pi/2\s*$", re.MULTILINE)


def puma560_float_text(path: Path = PUMA_FILE) -> str:
    """examples/puma560.yaml with every twist `pi/2` written as the float 1.5707963267948966.

    Text substitution on the file, so every other field (and the source comments) stays as
    published; only the twists alpha_i = +-pi/2 of the standard DH table and the robot's name
    change. cos(1.5707963267948966) is 6.1e-17, not 0: a loader that keeps the float carries
    those terms through the derivation, where the exact pi/2 makes them vanish.
    """
    text, count = _PI_HALF_TWIST.subn(rf"\g<1>\g<2>{HALF_PI}", path.read_text(encoding="utf-8"))
    assert count == 4, f"expected the PUMA 560's four pi/2 twists, found {count}"
    text, renamed = re.subn(r"^name: puma560$", "name: puma560_float", text, flags=re.MULTILINE)
    assert renamed == 1
    header = (
        f"# examples/puma560.yaml with every twist pi/2 written as the float {HALF_PI}.\n"
        "# Written by bench/robots.py; do not edit by hand.\n"
    )
    return header + text


def example_robot_file(inside: str) -> Path | None:
    """A URDF that example-robot-data (the test extra) ships under robots/, if installed."""
    try:
        from importlib.metadata import PackageNotFoundError, distribution

        share = "cmeel.prefix/share/example-robot-data/robots"
        robots = distribution("example-robot-data").locate_file(share)
    except (ImportError, PackageNotFoundError):
        return None
    path = Path(str(robots)) / inside
    return path if path.is_file() else None


ROBOTS = {  # name -> robot file (chains are written by bench/chains.py)
    "roger_arm_values": EXAMPLES / "roger_arm_values.yaml",
    "puma560": PUMA_FILE,
    "puma560_float": FLOAT_PUMA_FILE,
    "stanford": EXAMPLES / "stanford.yaml",
    "panda": EXAMPLES / "panda.yaml",
    "chain_9": chains.chain_file(9),
    "chain_12": chains.chain_file(12),
}
URDF_TIPS: dict[Path, str] = {}  # URDF file -> the tip link of its chain
if (_urdf := example_robot_file("panda_description/urdf/panda.urdf")) is not None:
    ROBOTS["panda_urdf"] = _urdf  # the same arm as panda.yaml, through the URDF loader
    URDF_TIPS[_urdf] = "panda_hand"
_TREE_FILES = {  # whole URDF trees on a fixed base (no tip); joint order = Pinocchio's
    "talos_reduced": "talos_data/robots/talos_reduced.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
}
for _name, _inside in _TREE_FILES.items():
    if (_urdf := example_robot_file(_inside)) is not None:
        ROBOTS[_name] = _urdf
QUICK_ROBOTS = ("roger_arm_values", "puma560", "panda")
ARMS = ("puma560", "stanford", "panda")  # the "6-7 joint arms with numeric parameters"
TREES = tuple(_TREE_FILES)  # the kinematic trees judged against Pinocchio (when installed)


def write_robot_files() -> dict[str, Path]:
    """(Re)write bench/chains/*.yaml and puma560_float.yaml if their text changed; {name: path}."""
    files = chains.write_robot_files()
    text = puma560_float_text()
    if not FLOAT_PUMA_FILE.exists() or FLOAT_PUMA_FILE.read_text(encoding="utf-8") != text:
        FLOAT_PUMA_FILE.write_text(text, encoding="utf-8")
    return {**files, "puma560_float": FLOAT_PUMA_FILE}


def load(path: Path) -> Robot:
    """The robot of a file of ROBOTS (or bench/chains/), through symdyn's loaders."""
    from symdyn.parsers import load as load_any

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # implausible-but-published inertia (PUMA link 1)
        return load_any(path, tip=URDF_TIPS.get(path))
