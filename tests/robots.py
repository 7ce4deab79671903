"""Shared helpers for the derivation tests: example robots, hand-built robots, random robots.

Nothing here calls the derivation code to produce an *expected* value: expected
values come from the lecture's closed forms (slides 17-18), from the raw YAML
read with `yaml.safe_load` (independent of the loader), from hand-written DH
matrices, or from the numeric oracle `symdyn.rnea`.

Derivations are cached (`derived`, `derived_robot`) so that each example robot
is derived once per method per test session, whichever test file asks first.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace
from fractions import Fraction
from functools import cache
from pathlib import Path

import numpy as np
import sympy as sp
import yaml
from hypothesis import strategies as st

from symdyn.codegen.functions import build_functions
from symdyn.codegen.render import RenderContext
from symdyn.dynamics import derive
from symdyn.errors import SymdynWarning
from symdyn.model.robot import Friction, Link, Motor, Robot
from symdyn.parsers import load_robot, load_urdf, robot_from_data
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import forward_kinematics as rnea_poses
from symdyn.spatial.transform import Transform

EXAMPLES_DIR = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE_NAMES = tuple(sorted(p.stem for p in EXAMPLES_DIR.glob("*.yaml")))
#: the examples written as DH tables (not `convention: poe`), for tests that rebuild DH products
DH_EXAMPLE_NAMES = tuple(
    n for n in EXAMPLE_NAMES if "convention: poe" not in (EXAMPLES_DIR / f"{n}.yaml").read_text()
)
QUANTITIES = ("M", "C", "V", "G", "tau")

Z = sp.ImmutableMatrix([0, 0, 1])
ZERO3 = sp.ImmutableMatrix(sp.zeros(3, 3))


def vec(v) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(3, 1, [sp.sympify(x) for x in v])


def mat(a) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(np.asarray(a, dtype=float).tolist())


# --------------------------------------------------------------------------- examples


@cache
def example(name: str) -> Robot:
    """examples/<name>.yaml through the loader (its published-data warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        return load_robot(EXAMPLES_DIR / f"{name}.yaml")


@cache
def _raw_example_text(name: str) -> str:
    return (EXAMPLES_DIR / f"{name}.yaml").read_text()


def raw_example(name: str) -> dict:
    """The example file as plain data (yaml.safe_load), independent of the loader: a fresh
    copy each call, so that a test may change it without changing another test's."""
    return yaml.safe_load(_raw_example_text(name))


def raw_value(value, parameters: dict | None = None) -> sp.Expr:
    """A number or expression string of a trusted example file, evaluated with SymPy."""
    expr = sp.sympify(value)
    subs = {sp.Symbol(k): sp.sympify(v) for k, v in (parameters or {}).items() if v is not None}
    for _ in range(5):  # parameter values may refer to other parameters
        expr = expr.subs(subs)
    return expr


@cache
def derived(name: str, method: str, simplify: bool | None = False):
    """derive(example(name), method) once per session (closed forms unsimplified by default)."""
    return derive(example(name), method=method, simplify=simplify)


@cache
def example_context(name: str) -> RenderContext:
    """What symdyn.codegen.context(example(name)) builds (double precision, Newton-Euler, the
    default function groups), over the session-wide cached derivation: once per test process
    for every test file that renders the example robots (a RenderContext is frozen; a test
    that wants another precision takes dataclasses.replace of it)."""
    dyn = derived(name, "newton-euler")
    return RenderContext(dyn.robot, dyn, tuple(build_functions(dyn)), "double")


@cache
def derived_robot(robot: Robot, method: str, simplify: bool | None = False):
    """derive(robot, method) once per session for a hand-built (hashable) robot."""
    return derive(robot, method=method, simplify=simplify)


def random_params(robot: Robot, rng: np.random.Generator) -> np.ndarray:
    """Random positive values for the robot's free parameters, in `robot.params` order."""
    return rng.uniform(0.5, 2.0, len(robot.params))


def random_state(robot: Robot, rng: np.random.Generator):
    """(q, qd, qdd): revolute angles over a full turn, prismatic offsets within +-0.5 m (one per
    independent joint: mimic joints follow)."""
    n = robot.n
    revolute = np.array([lk.joint == "revolute" for lk in robot.links if lk.mimic is None])
    q = np.where(revolute, rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.5, 0.5, n))
    qd = rng.uniform(-2, 2, n)
    qd[np.abs(qd) < 1e-3] = 0.5  # keep sign(qd) away from its jump
    qdd = rng.uniform(-2, 2, n)
    return q, qd, qdd


def ev(dyn, name: str, q=None, qd=None, qdd=None, params=None) -> np.ndarray:
    """dyn.evaluate with M and C always shaped (n, n).

    Dynamics.evaluate squeezes every (k, 1) result to (k,), which turns the 1 x 1 M and C
    of a one-joint robot into vectors; test_dynamics.py::test_evaluate_shapes_one_joint
    records that, the other tests compare values.
    """
    out = dyn.evaluate(name, q, qd, qdd, params)
    return out.reshape(dyn.n, dyn.n) if name in ("M", "C") else out


def _vee(W: np.ndarray) -> np.ndarray:
    return np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / 2


def fd_jacobian(robot, q, k, point, p, h=1e-6) -> np.ndarray:
    """Jv by central differences of the point's position, Jw from dR/dq_j R^T (rnea poses),
    over the robot's n independent coordinates."""
    n = robot.n
    R = rnea_poses(robot, q, p)[k][:3, :3]
    J = np.zeros((6, n))
    for j in range(n):
        e = np.eye(n)[j] * h
        Tp, Tm = rnea_poses(robot, q + e, p)[k], rnea_poses(robot, q - e, p)[k]
        J[:3, j] = ((Tp[:3, :3] @ point + Tp[:3, 3]) - (Tm[:3, :3] @ point + Tm[:3, 3])) / (2 * h)
        J[3:, j] = _vee((Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ R.T)
    return J


def assert_close(got, want, rtol: float = 1e-9, what: str = "") -> None:
    """Equal up to `rtol` relative to the largest entry of `want` (entries near zero included)."""
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    scale = max(float(np.max(np.abs(want), initial=0.0)), 1e-3)
    np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol * scale, err_msg=what)


# --------------------------------------------------------------------------- the lecture's robots

m, l, g = sp.symbols("m l g")
m1, m2, l1, l2 = sp.symbols("m1 m2 l1 l2")
q1, q2, qd1, qd2 = sp.symbols("q1 q2 qd1 qd2")


def roger_eye_lecture() -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """Slide 17: a point mass m at distance l, M = m l^2, V = 0, G = m g l sin q."""
    return sp.Matrix([[m * l**2]]), sp.Matrix([0]), sp.Matrix([m * g * l * sp.sin(q1)])


def roger_arm_lecture() -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """Slide 18 (restated in the seed README): M, V, G of the two-link arm."""
    c2, s2 = sp.cos(q2), sp.sin(q2)
    s1, s12 = sp.sin(q1), sp.sin(q1 + q2)
    M = sp.Matrix(
        [
            [m2 * l2**2 + 2 * m2 * l1 * l2 * c2 + (m1 + m2) * l1**2, m2 * l2**2 + m2 * l1 * l2 * c2],
            [m2 * l2**2 + m2 * l1 * l2 * c2, m2 * l2**2],
        ]
    )
    V = sp.Matrix([-m2 * l1 * l2 * s2 * (qd2**2 + 2 * qd1 * qd2), m2 * l1 * l2 * s2 * qd1**2])
    G = sp.Matrix([(m1 + m2) * g * l1 * s1 + m2 * g * l2 * s12, m2 * g * l2 * s12])
    return M, V, G


def roger_eye_robot() -> Robot:
    """Slide 17 built directly: one revolute z joint, the mass l along the body x axis."""
    eye = Link("eye", "revolute", Transform.identity(), Z, m, vec([l, 0, 0]), ZERO3)
    return Robot("roger_eye", (eye,), vec([g, 0, 0]), params=(m, l, g))


def roger_arm_robot(motors: tuple[Motor, Motor] | None = None) -> Robot:
    """Slide 18 built directly: point masses at the distal ends, hanging along +x."""
    mo = motors or (Motor(), Motor())
    upper = Link("upper", "revolute", Transform.identity(), Z, m1, vec([l1, 0, 0]), ZERO3, motor=mo[0])
    fore = Link("fore", "revolute", Transform.tx(l1), Z, m2, vec([l2, 0, 0]), ZERO3, motor=mo[1])
    params = [m1, m2, l1, l2, g]
    for mot in mo:
        params += [s for s in (mot.inertia, mot.gear_ratio) if isinstance(s, sp.Symbol)]
    return Robot("roger_arm", (upper, fore), vec([g, 0, 0]), params=tuple(params))


# --------------------------------------------------------------------------- symbolic small arms


def sym3_data(convention: str = "standard") -> dict:
    """A 3-joint RPR arm with pi/2 twists, every length, mass and inertia a free symbol."""
    return {
        "name": f"sym3_{convention}",
        "convention": convention,
        "gravity": [0, 0, "-g"],
        "links": [
            {
                "name": "base",
                "joint": "revolute",
                "a": 0,
                "alpha": "pi/2",
                "d": "d1",
                "theta": 0,
                "mass": "m1",
                "com": [0, "-c1", 0],
                "inertia": {"ixx": "I1x", "iyy": "I1y", "izz": "I1z"},
            },
            {
                "name": "slide",
                "joint": "prismatic",
                "a": 0,
                "alpha": "-pi/2",
                "d": "d2",
                "theta": "pi/2",
                "mass": "m2",
                "com": [0, 0, "-c2"],
                "inertia": {"ixx": "I2x", "iyy": "I2y", "izz": "I2z"},
                "friction": {"viscous": "b2", "coulomb": "k2"},
            },
            {
                "name": "wrist",
                "joint": "revolute",
                "a": "a3",
                "alpha": "pi/2",
                "d": 0,
                "theta": 0,
                "mass": "m3",
                "com": ["-c3", 0, 0],
                "inertia": {"ixx": "I3x", "iyy": "I3y", "izz": "I3z", "ixy": "I3xy"},
                "motor": {"inertia": "J3", "gear_ratio": "n3"},
            },
        ],
    }


def _rational(x):
    """Floats of a data tree as exact fraction strings ("0.05024" -> "157/3125")."""
    if isinstance(x, float):
        return str(Fraction(str(x)))
    if isinstance(x, list):
        return [_rational(y) for y in x]
    if isinstance(x, dict):
        return {k: _rational(v) for k, v in x.items()}
    return x


def rational_example(name: str) -> Robot:
    """An example file with every decimal number read as the exact rational it denotes (its
    published-data warnings silenced, as in `example`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        return robot_from_data(_rational(raw_example(name)), source=f"{name} (rational)")


@cache
def derived_rational(name: str, method: str):
    """derive(rational_example(name), method), unsimplified, once per session (the exact-data
    tests of the configuration and product forms share it, and its cached forms)."""
    return derive(rational_example(name), method=method, simplify=False)


def trig_zero(expr: sp.Expr, n: int) -> bool:
    """Exact test that a polynomial in sin(q_i), cos(q_i) (and other symbols) vanishes.

    Multiple angles are expanded (expand_trig), sin q_i, cos q_i become S_i, C_i, and the
    polynomial is reduced modulo S_i**2 + C_i**2 - 1 (a Groebner basis: leading terms are
    coprime), so a zero remainder means the expression is identically zero.
    """
    q = sp.symbols(f"q1:{n + 1}")
    S = sp.symbols(f"S1:{n + 1}")
    C = sp.symbols(f"C1:{n + 1}")
    e = sp.expand(sp.expand_trig(sp.sympify(expr)))
    rep = {}
    for qi, si, ci in zip(q, S, C, strict=True):
        rep[sp.sin(qi)] = si
        rep[sp.cos(qi)] = ci
    e = sp.expand(e.xreplace(rep))
    if e.has(sp.sin, sp.cos):
        raise AssertionError(f"unexpected trigonometric terms left in {e}")
    if e == 0:
        return True
    gens = [*S, *C, *sorted(e.free_symbols - set(S) - set(C), key=str)]
    _, rem = sp.reduced(e, [si**2 + ci**2 - 1 for si, ci in zip(S, C, strict=True)], *gens)
    return rem == 0


def assert_matrix_zero(A: sp.Matrix, n: int, what: str = "") -> None:
    bad = [(i, x) for i, x in enumerate(A) if not trig_zero(x, n)]
    assert not bad, f"{what}: non-zero entries {bad[:2]}"


# --------------------------------------------------------------------------- random robots


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rpy(r, p, y):
    """URDF's fixed-axis roll, pitch, yaw, written out with NumPy."""
    return rz(y) @ ry(p) @ rx(r)


def rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random rotation matrix (from a random unit quaternion)."""
    w, x, y, z = (qu := rng.normal(size=4)) / np.linalg.norm(qu)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def random_inertia(rng: np.random.Generator, mass: float) -> np.ndarray:
    """I = R diag(a, b, c) R^T of a random body: a = m(y2+z2), b = m(x2+z2), c = m(x2+y2).

    Principal moments of that form always satisfy the triangle inequality.
    """
    x2, y2, z2 = rng.uniform(0.001, 0.05, 3)
    R = rotation(rng)
    inertia = R @ np.diag(mass * np.array([y2 + z2, x2 + z2, x2 + y2])) @ R.T
    return (inertia + inertia.T) / 2


TWISTS = ("0", "pi/2", "-pi/2", "pi", "random")


@dataclass(frozen=True)
class RobotSpec:
    """What hypothesis draws: the structure explicitly, the real numbers from a seed."""

    kind: str  # "standard" | "modified" (DH, through robot_from_data) | "general" (Link)
    joints: tuple[str, ...]
    twists: tuple[str, ...]
    seed: int

    @property
    def n(self) -> int:
        return len(self.joints)


@st.composite
def robot_specs(draw, min_joints: int = 1, max_joints: int = 7) -> RobotSpec:
    n = draw(st.integers(min_joints, max_joints))
    kind = draw(st.sampled_from(("standard", "modified", "general")))
    joints = draw(st.lists(st.sampled_from(("revolute", "prismatic")), min_size=n, max_size=n))
    twists = draw(st.lists(st.sampled_from(TWISTS), min_size=n, max_size=n))
    seed = draw(st.integers(0, 2**32 - 1))
    return RobotSpec(kind, tuple(joints), tuple(twists), seed)


def _maybe_zero(rng, lo, hi) -> float:
    return 0.0 if rng.random() < 0.3 else float(rng.uniform(lo, hi))


def random_dh_data(spec: RobotSpec) -> dict:
    """A DH robot description (as loaded YAML) with random, physically valid links."""
    rng = np.random.default_rng(spec.seed)
    links = []
    for i, (joint, twist) in enumerate(zip(spec.joints, spec.twists, strict=True)):
        mass = float(rng.uniform(0.2, 3.0))
        inertia = random_inertia(rng, mass)
        alpha = float(rng.uniform(-math.pi, math.pi)) if twist == "random" else twist
        link = {
            "name": f"link{i + 1}",
            "joint": joint,
            "a": _maybe_zero(rng, -0.5, 0.5),
            "alpha": alpha,
            "d": _maybe_zero(rng, -0.5, 0.5),
            "theta": _maybe_zero(rng, -math.pi, math.pi),
            "mass": mass,
            "com": [float(x) for x in rng.uniform(-0.3, 0.3, 3)],
            "inertia": {
                "ixx": float(inertia[0, 0]),
                "iyy": float(inertia[1, 1]),
                "izz": float(inertia[2, 2]),
                "ixy": float(inertia[0, 1]),
                "ixz": float(inertia[0, 2]),
                "iyz": float(inertia[1, 2]),
            },
        }
        if rng.random() < 0.5:
            link["friction"] = {"viscous": float(rng.uniform(0, 2)), "coulomb": float(rng.uniform(0, 2))}
        if rng.random() < 0.5:
            link["motor"] = {"inertia": float(rng.uniform(0, 1e-3)), "gear_ratio": float(rng.uniform(1, 50))}
        links.append(link)
    gravity = rng.normal(size=3) * 5
    return {
        "name": f"random_{spec.kind}",
        "convention": spec.kind,
        "gravity": [float(x) for x in gravity],
        "links": links,
    }


def random_axis(rng: np.random.Generator) -> np.ndarray:
    """A unit joint axis: a signed coordinate axis 30% of the time, else a random direction."""
    if rng.random() < 0.3:
        axis = np.zeros(3)
        axis[rng.integers(3)] = rng.choice([-1.0, 1.0])
        return axis
    axis = rng.normal(size=3)
    return axis / np.linalg.norm(axis)


def random_link(rng: np.random.Generator, name: str, joint: str, parent: int | None = None, **extra) -> Link:
    """A link with a random rotated placement, unit axis, mass, centre of mass, full inertia
    tensor, friction and motor (`extra` overrides fields, e.g. mimic=...)."""
    axis = random_axis(rng)
    mass = float(rng.uniform(0.2, 3.0))
    link = Link(
        name=name,
        joint=joint,
        placement=Transform(mat(rotation(rng)), mat(rng.uniform(-0.5, 0.5, (3, 1)))),
        axis=mat(axis.reshape(3, 1)),
        mass=sp.Float(mass),
        com=mat(rng.uniform(-0.3, 0.3, (3, 1))),
        inertia=mat(random_inertia(rng, mass)),
        friction=Friction(*(sp.Float(v) for v in rng.uniform(0, 2, 2))),
        motor=Motor(sp.Float(rng.uniform(0, 1e-3)), sp.Float(rng.uniform(1, 50))),
        parent=parent,
    )
    return replace(link, **extra)


def random_general_robot(spec: RobotSpec) -> Robot:
    """A chain of Link objects with random rotated placements and random unit joint axes."""
    rng = np.random.default_rng(spec.seed)
    links = [random_link(rng, f"link{i + 1}", joint) for i, joint in enumerate(spec.joints)]
    return Robot(f"random_general{spec.seed}", tuple(links), mat((rng.normal(size=3) * 5).reshape(3, 1)))


def build_robot(spec: RobotSpec) -> Robot:
    """The random robot of `spec`. A random twist may land near a multiple of pi/2, where the
    loader warns that it keeps it as written (the subject of test_angles): silenced here."""
    if spec.kind == "general":
        return random_general_robot(spec)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", r".* so it is kept as written", SymdynWarning)
        return robot_from_data(random_dh_data(spec), source="hypothesis")


def without_motors(robot: Robot) -> Robot:
    return replace(robot, links=tuple(replace(lk, motor=Motor()) for lk in robot.links))


# --------------------------------------------------------------------------- trees and mimic joints


def tree_robot(name: str, parents, joints, seed: int, mimic: dict | None = None) -> Robot:
    """Random links (random_link) joined as the tree `parents` (lambda(i), -1: the base).

    mimic: {link index: Mimic(...)} for the links whose joint follows another.
    """
    rng = np.random.default_rng(seed)
    mimic = mimic or {}
    links = []
    for i, (p, joint) in enumerate(zip(parents, joints, strict=True)):
        links.append(random_link(rng, f"{name}{i + 1}", joint, parent=p, mimic=mimic.get(i)))
    return Robot(name, tuple(links), mat((rng.normal(size=3) * 5).reshape(3, 1)))


#: the Y-shaped robot: a torso on the base carrying two 2-joint arms
Y_PARENTS = (-1, 0, 1, 0, 3)
Y_JOINTS = ("revolute", "revolute", "prismatic", "prismatic", "revolute")


def y_robot() -> Robot:
    """A torso (revolute) with a left arm (revolute, prismatic) and a right arm (prismatic,
    revolute): general axes and placements, full inertia tensors, friction and motors."""
    return tree_robot("ytree", Y_PARENTS, Y_JOINTS, seed=2015)


#: four legs of three joints each on a fixed base, depth first: leg k is links 3k, 3k+1, 3k+2
SOLO_PARENTS = tuple(p for k in range(4) for p in (-1, 3 * k, 3 * k + 1))


def solo_robot() -> Robot:
    """A quadruped on a fixed base (a "solo"-like test robot): per leg a hip abduction about x,
    a hip flexion and a knee about y, thigh and shank of 0.16 m along -z, full inertia tensors."""
    rng = np.random.default_rng(12)
    links = []
    x_axis, y_axis = mat([[1], [0], [0]]), mat([[0], [1], [0]])
    for k, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        hip = Transform(mat(np.eye(3)), mat([[0.2 * sx], [0.08 * sy], [0]]))
        flexion = Transform(mat(np.eye(3)), mat([[0], [0.06 * sy], [0]]))
        knee = Transform(mat(np.eye(3)), mat([[0], [0], [-0.16]]))
        for j, (placement, axis, mass, com) in enumerate(
            (
                (hip, x_axis, 0.15, [0.02 * sx, 0.01 * sy, 0]),
                (flexion, y_axis, 0.15, [0, 0.01 * sy, -0.08]),
                (knee, y_axis, 0.03, [0, 0, -0.08]),
            )
        ):
            links.append(
                Link(
                    name=f"leg{k + 1}_{('abduction', 'flexion', 'knee')[j]}",
                    joint="revolute",
                    placement=placement,
                    axis=axis,
                    mass=sp.Float(mass),
                    com=mat(np.reshape(com, (3, 1))),
                    inertia=mat(random_inertia(rng, mass)),
                    motor=Motor(sp.Float(5e-6), sp.Float(9)),
                    parent=SOLO_PARENTS[3 * k + j],
                )
            )
    return Robot("solo", tuple(links), mat([[0], [0], [-9.81]]))


@st.composite
def tree_parents(draw, min_bodies: int = 2, max_bodies: int = 7) -> tuple[int, ...]:
    """A random parent array in depth-first order: each link hangs from the base or from a link
    on the path from the base to the previous link (so every subtree is numbered contiguously)."""
    nb = draw(st.integers(min_bodies, max_bodies))
    parents: list[int] = []
    for i in range(nb):
        path = [-1]
        k = i - 1
        while k >= 0:
            path.append(k)
            k = parents[k]
        parents.append(draw(st.sampled_from(sorted(path))))
    return tuple(parents)


def branch_pairs(parents) -> list[tuple[int, int]]:
    """The pairs (i, j), i < j, of links on different branches: neither lies on the other's
    path to the base (computed from the parent array here, not by symdyn.model.topology)."""

    def path(i):
        out = set()
        while i >= 0:
            out.add(i)
            i = parents[i]
        return out

    return [(i, j) for j in range(len(parents)) for i in range(j) if i not in path(j)]


def regressor_oracle(dyn, q, qd, qdd, params=None) -> dict[str, np.ndarray]:
    """The generated regressor functions' expected values from the oracle's numeric regressor
    (symdyn.oracle.regressor): Y, and its columns of the base parameters for Y_b (one state or a batch)."""
    from symdyn.oracle.regressor import regressor

    Y = regressor(dyn.robot, q, qd, qdd, params)
    return {"regressor": Y, "base_regressor": Y[..., list(dyn.linear_compact()[1].columns)]}


# --------------------------------------------------------------------------- processes


def dead_pid() -> int:
    """The id of a process that has exited (for the tests of leftovers of killed runs)."""
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    return int(done.stdout)


# --------------------------------------------------------------------------- direction-dependent friction

#: a 3-link arm with direction-dependent Coulomb friction on links 1 (the Robotics Toolbox's PUMA 560
#: joint 1: B = 1.48e-3, Tc+ = 0.395, Tc- = -0.435) and 3 (free parameters), symmetric on link 2
ASYMMETRIC_FRICTION = Path(__file__).resolve().parent / "data" / "good" / "asymmetric_friction.yaml"
#: values of its free parameters, in `robot.params` order (m3, b3, cp3, cm3)
ASYMMETRIC_PARAMS = {"m3": 0.8, "b3": 0.05, "cp3": 0.2, "cm3": 0.25}


@cache
def asymmetric_friction() -> Robot:
    """tests/data/good/asymmetric_friction.yaml through the loader."""
    return load_robot(ASYMMETRIC_FRICTION)


def friction_closed_form(qd) -> np.ndarray:
    """F(qd) of `asymmetric_friction` at ASYMMETRIC_PARAMS written out by hand from its file:
    b qd + c+ for qd > 0, b qd - c- for qd < 0, 0 at rest (link 2: 0.2 qd + 0.3 sign(qd))."""
    qd = np.asarray(qd, dtype=float)

    def one(b, cp, cm, x):
        return b * x + np.where(x > 0, cp, 0.0) - np.where(x < 0, cm, 0.0)

    return np.stack(
        [
            one(1.48e-3, 0.395, 0.435, qd[..., 0]),
            one(0.2, 0.3, 0.3, qd[..., 1]),
            one(0.05, 0.2, 0.25, qd[..., 2]),
        ],
        axis=-1,
    )


def friction_states(seed: int = 7):
    """(q, qd, qdd, tau), 9 states of the 3-joint arm whose rates take every sign on every joint,
    exactly 0 included (both branches of the Coulomb term and its value at rest)."""
    rng = np.random.default_rng(seed)
    signs = np.array([[1, 1, 1], [-1, -1, -1], [0, 0, 0], [1, -1, 0], [-1, 0, 1], [0, 1, -1],
                      [1, 0, -1], [-1, 1, 0], [0, -1, 1]], dtype=float)  # fmt: skip
    qd = signs * rng.uniform(0.2, 2.0, signs.shape)
    q = rng.uniform(-np.pi, np.pi, signs.shape)
    qdd = rng.uniform(-2, 2, signs.shape)
    tau = rng.uniform(-3, 3, signs.shape)
    return q, qd, qdd, tau


def pinocchio_model(pin, robot):
    """A Pinocchio model built joint by joint from a numeric symdyn Robot without mimic joints:
    each joint's placement, axis and inertia, the base placement, and every frame."""
    r = robot.numeric()
    model = pin.Model()
    model.gravity.linear = np.array(r.gravity, dtype=float).reshape(3)
    base = pin.SE3(np.array(r.base.R, dtype=float), np.array(r.base.p, dtype=float).reshape(3))
    ids = []
    for i, lk in enumerate(r.links):
        parent = r.parents[i]
        placement = pin.SE3(
            np.array(lk.placement.R, dtype=float), np.array(lk.placement.p, dtype=float).reshape(3)
        )
        axis = np.array(lk.axis, dtype=float).reshape(3)
        joint = (
            pin.JointModelRevoluteUnaligned(axis)
            if lk.joint == "revolute"
            else pin.JointModelPrismaticUnaligned(axis)
        )
        jid = model.addJoint(
            0 if parent < 0 else ids[parent], joint, base * placement if parent < 0 else placement, lk.name
        )
        inertia = pin.Inertia(
            float(lk.mass), np.array(lk.com, dtype=float).reshape(3), np.array(lk.inertia, dtype=float)
        )
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        ids.append(jid)
    placed = [(lk.name, i, lk.frame) for i, lk in enumerate(r.links)] + [
        (f.name, f.link, f.placement) for f in r.frames
    ]
    for name, k, T in placed:
        se3 = pin.SE3(np.array(T.R, dtype=float), np.array(T.p, dtype=float).reshape(3))
        model.addFrame(
            pin.Frame(name, 0 if k < 0 else ids[k], base * se3 if k < 0 else se3, pin.FrameType.OP_FRAME)
        )
    return model


# --------------------------------------------------------------------------- generated functions


def spec_arguments(spec, rng: np.random.Generator, batch: tuple[int, ...] = ()) -> dict[str, np.ndarray]:
    """Random inputs of a generated function (symdyn.codegen.functions.FunctionSpec) by name,
    p excepted, each of shape batch + (its size,): angles over a full turn, rates and torques
    of a few units, joint rates kept away from the jump of sign(qd)."""
    args = {}
    for inp in spec.inputs:
        if inp.name == "p":
            continue
        shape = (*batch, len(inp.symbols))
        value = rng.uniform(-np.pi, np.pi, shape) if inp.name == "q" else rng.normal(0.0, 1.5, shape)
        if inp.name == "qd":
            value = np.where(np.abs(value) < 1e-3, 0.5, value)
        args[inp.name] = value
    return args


@cache
def floating_solo12():
    """(path, derive(load_urdf(path, floating=True), simplify=False)) of example-robot-data's
    Solo-12 on a free flyer, once per session; None without example-robot-data."""
    folder = example_robot_data_folder()
    if folder is None:
        return None
    path = folder / "solo_description/robots/solo12.urdf"
    return path, derive(load_urdf(path, floating=True), simplify=False)


#: a floating base body with one link (small: its libraries compile in a second or two)
FLYER = """name: flyer1
base: {floating: true, mass: 3, com: [0.02, -0.01, 0.05],
       inertia: {ixx: 0.05, iyy: 0.06, izz: 0.07, ixy: 0.004}}
links:
  - {joint: revolute, a: 0.4, alpha: 0.7, d: 0.1, theta: 0, mass: 1, com: [-0.2, 0.01, 0.02],
     inertia: {ixx: 0.002, iyy: 0.01, izz: 0.01}}
"""
