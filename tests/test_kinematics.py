"""Forward kinematics and Jacobians (symdyn.algorithms.kinematics) against hand-written DH matrices,
finite differences and the numeric oracle's poses (symdyn.rnea.forward_kinematics)."""

from __future__ import annotations

import zlib

import numpy as np
import pytest
import sympy as sp
from robots import (
    DH_EXAMPLE_NAMES,
    EXAMPLE_NAMES,
    RobotSpec,
    assert_close,
    assert_matrix_zero,
    example,
    fd_jacobian,
    random_general_robot,
    random_params,
    random_state,
    raw_example,
    raw_value,
    solo_robot,
    sym3_data,
    y_robot,
)

from symdyn.algorithms.kinematics import (
    body_point_jacobian,
    end_effector_jacobian,
    forward_kinematics,
    frame_poses,
    numeric_jacobian,
    numeric_pose,
    point_jacobian,
)
from symdyn.errors import SymdynError
from symdyn.parsers.robot_file import robot_from_data
from symdyn.rnea import forward_kinematics as rnea_poses

# --------------------------------------------------------------------------- DH by hand


def dh_standard(a, alpha, d, theta, lib=np):
    """Rz(theta) Tz(d) Tx(a) Rx(alpha), multiplied out."""
    ct, st, ca, sa = lib.cos(theta), lib.sin(theta), lib.cos(alpha), lib.sin(alpha)
    rows = [
        [ct, -st * ca, st * sa, a * ct],
        [st, ct * ca, -ct * sa, a * st],
        [0, sa, ca, d],
        [0, 0, 0, 1],
    ]
    return sp.Matrix(rows) if lib is sp else np.array(rows, dtype=float)


def dh_modified(a, alpha, d, theta, lib=np):
    """Rx(alpha) Tx(a) Rz(theta) Tz(d), multiplied out (Craig's row i)."""
    ct, st, ca, sa = lib.cos(theta), lib.sin(theta), lib.cos(alpha), lib.sin(alpha)
    rows = [
        [ct, -st, 0, a],
        [st * ca, ct * ca, -sa, -sa * d],
        [st * sa, ct * sa, ca, ca * d],
        [0, 0, 0, 1],
    ]
    return sp.Matrix(rows) if lib is sp else np.array(rows, dtype=float)


def rz_tz(theta, d, lib=np):
    """Rz(theta) Tz(d): the standard-DH joint frame (the body frame) within frame i-1."""
    ct, st = lib.cos(theta), lib.sin(theta)
    rows = [[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, d], [0, 0, 0, 1]]
    return sp.Matrix(rows) if lib is sp else np.array(rows, dtype=float)


def hand_poses(data: dict, q, values: dict | None = None, lib=np):
    """(convention frames, body frames) in the base frame from the raw description data."""
    params = dict(data.get("parameters") or {})
    params.update(values or {})
    T = sp.eye(4) if lib is sp else np.eye(4)
    frames, bodies = [], []
    for link, qi in zip(data["links"], q, strict=True):
        a, alpha, d, theta = (raw_value(link.get(k, 0), params) for k in ("a", "alpha", "d", "theta"))
        if lib is np:
            a, alpha, d, theta = float(a), float(alpha), float(d), float(theta)
        if link["joint"] == "revolute":
            theta = theta + qi
        else:
            d = d + qi
        if data.get("convention", "standard") == "standard":
            bodies.append(T @ rz_tz(theta, d, lib) if lib is np else T * rz_tz(theta, d, lib))
            T = (
                T @ dh_standard(a, alpha, d, theta, lib)
                if lib is np
                else T * dh_standard(a, alpha, d, theta, lib)
            )
        else:
            T = (
                T @ dh_modified(a, alpha, d, theta, lib)
                if lib is np
                else T * dh_modified(a, alpha, d, theta, lib)
            )
            bodies.append(T)
        frames.append(T)
    return frames, bodies


def _floats(T) -> np.ndarray:
    return np.array(T.matrix().tolist(), dtype=float)


def _setup(name, seed=0):
    robot = example(name)
    rng = np.random.default_rng(seed + zlib.crc32(name.encode()))
    p = random_params(robot, rng) if robot.params else None
    values = dict(zip((str(s) for s in robot.params), p, strict=True)) if robot.params else {}
    return robot, rng, p, values


# --------------------------------------------------------------------------- poses


@pytest.mark.parametrize("name", DH_EXAMPLE_NAMES)
def test_poses_equal_the_dh_product(name):
    robot, rng, p, values = _setup(name)
    numeric = robot.numeric(p)
    for _ in range(5):
        q, _, _ = random_state(robot, rng)
        frames, bodies = hand_poses(raw_example(name), q, values)
        got_frames = frame_poses(numeric, list(q))
        got_bodies = forward_kinematics(numeric, list(q))
        oracle = rnea_poses(robot, q, p)
        for i in range(robot.n):
            assert_close(_floats(got_frames[i]), frames[i], what=f"frame {i + 1}")
            assert_close(_floats(got_bodies[i]), bodies[i], what=f"body {i + 1}")
            assert_close(_floats(got_bodies[i]), oracle[i], what=f"body {i + 1} vs rnea")


@pytest.mark.parametrize(
    "data",
    [raw_example("roger_arm"), sym3_data("standard"), sym3_data("modified")],
    ids=["roger_arm", "sym3_standard", "sym3_modified"],
)
def test_poses_symbolic(data):
    robot = robot_from_data(data)
    q = sp.symbols(f"q1:{robot.n + 1}")
    frames, bodies = hand_poses(data, q, lib=sp)
    got_frames = frame_poses(robot.resolved())
    got_bodies = forward_kinematics(robot.resolved())
    for i in range(robot.n):
        assert_matrix_zero(got_frames[i].matrix() - frames[i], robot.n, f"frame {i + 1}")
        assert_matrix_zero(got_bodies[i].matrix() - bodies[i], robot.n, f"body {i + 1}")


# --------------------------------------------------------------------------- Jacobians


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_point_jacobian_by_finite_differences(name):
    robot, rng, p, values = _setup(name, 1)
    numeric = robot.numeric(p)
    points = rng.uniform(-0.3, 0.3, (robot.n, 3))  # one point per link: the compiled functions are cached
    for _ in range(2):
        q, _, _ = random_state(robot, rng)
        for k, point in enumerate(points):
            want = fd_jacobian(robot, q, k, point, p)
            J = numeric_jacobian(robot, q, link=k, point=tuple(point), params=p)
            assert_close(J, want, rtol=1e-6, what=f"link {k + 1}")
            sym = point_jacobian(numeric, k, tuple(point), q=list(q))
            assert_close(np.array(sym.tolist(), dtype=float), J, what=f"symbolic link {k + 1}")
            pose = numeric_pose(robot, q, link=k, point=tuple(point), params=p)
            T = rnea_poses(robot, q, p)[k]
            assert_close(pose[:3, :3], T[:3, :3])
            assert_close(pose[:3, 3], T[:3, :3] @ point + T[:3, 3])
            assert_close(pose[3], [0, 0, 0, 1])


@pytest.mark.parametrize("name", DH_EXAMPLE_NAMES)
def test_end_effector_jacobian(name):
    """The last DH frame's origin, differentiated from the hand-written DH product."""
    robot, rng, p, values = _setup(name, 2)
    numeric = robot.numeric(p)
    q, _, _ = random_state(robot, rng)
    h = 1e-6
    data = raw_example(name)
    Jv = np.array(
        [
            (
                hand_poses(data, q + h * e, values)[0][-1][:3, 3]
                - hand_poses(data, q - h * e, values)[0][-1][:3, 3]
            )
            / (2 * h)
            for e in np.eye(robot.n)
        ]
    ).T
    J = np.array(end_effector_jacobian(numeric, list(q)).tolist(), dtype=float)
    assert_close(J[:3], Jv, rtol=1e-6)
    tip = np.array(numeric.links[-1].frame.p.tolist(), dtype=float).ravel()
    assert_close(J, fd_jacobian(robot, q, robot.n - 1, tip, p), rtol=1e-6)


def test_numeric_functions_take_parameters_by_order_or_name():
    robot = example("roger_arm")
    q = np.array([0.4, -1.1])
    p = np.array([9.81, 0.5, 1.2, 0.3, 0.8])  # g, l1, m1, l2, m2
    named = {"m2": 0.8, "l2": 0.3, "m1": 1.2, "l1": 0.5, "g": 9.81}
    tip = (1, (0.3, 0, 0))
    T_seq = numeric_pose(robot, q, *tip, params=p)
    T_map = numeric_pose(robot, q, *tip, params=named)
    assert_close(T_seq, T_map)
    want = [0.5 * np.cos(0.4) + 0.3 * np.cos(0.4 - 1.1), 0.5 * np.sin(0.4) + 0.3 * np.sin(0.4 - 1.1), 0]
    assert_close(T_seq[:3, 3], want)
    J = numeric_jacobian(robot, q, *tip, params=named)
    s1, s12, c1, c12 = np.sin(0.4), np.sin(-0.7), np.cos(0.4), np.cos(-0.7)
    want_J = [
        [-0.5 * s1 - 0.3 * s12, -0.3 * s12],
        [0.5 * c1 + 0.3 * c12, 0.3 * c12],
        [0, 0],
        [0, 0],
        [0, 0],
        [1, 1],
    ]
    assert_close(J, want_J)
    assert_close(numeric_jacobian(robot, q, *tip, params=p), want_J)


ARM_P = [9.81, 0.5, 1.2, 0.3, 0.8]  # g, l1, m1, l2, m2


@pytest.mark.parametrize("function", [numeric_pose, numeric_jacobian], ids=lambda f: f.__name__)
def test_numeric_functions_check_their_arguments(function):
    robot, name = example("roger_arm"), function.__name__
    free = "g, l1, m1, l2, m2"
    bad = {
        "q too long": (
            ([0, 0, 0],),
            {"params": ARM_P},
            f"{name}: q has 3 entries, expected 2 (one per joint)",
        ),
        "q a batch": (
            ([[0, 0]],),
            {"params": ARM_P},
            f"{name}: q has shape (1, 2), expected (2,) (one per joint)",
        ),
        "link out of range": (
            ([0, 0], 2),
            {"params": ARM_P},
            f"{name}: link 2 out of range: the robot has 2 links (0 .. 1)",
        ),
        "link not an index": (
            ([0, 0], 1.0),
            {"params": ARM_P},
            f"{name}: link must be an integer index, got 1.0",
        ),
        "point of two": (
            ([0, 0], 1, (1, 2)),
            {"params": ARM_P},
            f"{name}: point has 2 entries, expected 3 (x, y, z in the link's frame)",
        ),
        "point with an unknown symbol": (
            ([0, 0], 1, ("l9", 0, 0)),
            {"params": ARM_P},
            f"{name}: point names unknown symbol(s) l9",
        ),
        "no params": (
            ([0, 0],),
            {},
            f"{name}: robot 'roger_arm' has free parameters ({free}); give their values",
        ),
        "unknown param": (
            ([0, 0],),
            {"params": {"g": 1, "l1": 1, "m1": 1, "l2": 1, "m2": 1, "m9": 1}},
            f"{name}: unknown parameter(s) m9 (free parameters of robot 'roger_arm': {free})",
        ),
    }
    for case, (args, kwargs, message) in bad.items():
        with pytest.raises(SymdynError) as err:
            function(robot, *args, **kwargs)
        assert str(err.value) == message, case
    assert function(robot, [0, 0], -1, ("l2", 0, 0), params=ARM_P).shape == (
        (4, 4) if name == "numeric_pose" else (6, 2)
    )


def test_symbolic_jacobian_checks_the_link_and_q():
    robot = example("roger_arm")
    with pytest.raises(SymdynError, match=r"^point_jacobian: link -3 out of range: the robot has 2 links"):
        point_jacobian(robot, -3)
    with pytest.raises(SymdynError, match=r"^link_transforms: q has length 1, expected 2 \(one per joint\)$"):
        forward_kinematics(robot, [0])


@pytest.mark.parametrize("seed", range(3))
def test_general_joint_axes(seed):
    """Random placements and joint axes (not z): poses and Jacobians against the oracle."""
    spec = RobotSpec("general", ("revolute", "prismatic", "revolute", "prismatic"), ("0",) * 4, seed)
    robot = random_general_robot(spec)
    rng = np.random.default_rng(seed)
    q, _, _ = random_state(robot, rng)
    oracle = rnea_poses(robot, q)
    for k, T in enumerate(forward_kinematics(robot, list(q))):
        assert_close(_floats(T), oracle[k])
    point = tuple(rng.uniform(-0.3, 0.3, 3))
    J = numeric_jacobian(robot, q, link=-1, point=point)
    assert_close(J, fd_jacobian(robot, q, robot.n - 1, np.array(point), None), rtol=1e-6)
    assert_close(J, numeric_jacobian(robot, q, link=robot.n - 1, point=point))
    assert_close(numeric_pose(robot, q, point=point), numeric_pose(robot, q, link=robot.n - 1, point=point))


# --------------------------------------------------------------------------- trees


@pytest.mark.parametrize("make", [y_robot, solo_robot], ids=["ytree", "solo"])
def test_tree_poses_and_jacobians(make):
    """Poses against the oracle's; Jacobians against differences of the oracle's poses, with
    exact zeros in the columns of the joints off the link's path to the base."""
    robot = make()
    rng = np.random.default_rng(8)
    q, _, _ = random_state(robot, rng)
    oracle = rnea_poses(robot, q)
    for k, T in enumerate(forward_kinematics(robot, list(q))):
        assert_close(_floats(T), oracle[k])
    symbolic = point_jacobian(robot, robot.nb - 1, (0.1, 0, -0.05))
    path = {robot.nb - 1}
    while robot.parents[min(path)] >= 0:
        path.add(robot.parents[min(path)])
    assert all((symbolic[:, j] == sp.zeros(6, 1)) == (j not in path) for j in range(robot.n))
    for k in range(robot.nb):
        point = rng.uniform(-0.3, 0.3, 3)
        J = numeric_jacobian(robot, q, link=k, point=tuple(point))
        assert_close(J, fd_jacobian(robot, q, k, point, None), rtol=1e-6)


@pytest.mark.parametrize("case", ["puma560", "stanford", "ytree", "solo", "mimic"])
def test_body_jacobian_is_the_base_jacobian_rotated_into_the_link(case):
    """J_body = blockdiag(R_k^T, R_k^T) J_base (Murray, Li, Sastry (1994), sec. 4.2), by the
    base-frame Jacobian's finite differences of the oracle's poses; no column of a link's body
    Jacobian involves the first joint's angle (of a chain without mimic joints)."""
    from test_mimic import CASES as MIMIC_CASES

    robot = {"ytree": y_robot, "solo": solo_robot, "mimic": lambda: next(iter(MIMIC_CASES.values()))[0]}.get(
        case, lambda: example(case)
    )()
    rng = np.random.default_rng(21)
    q, _, _ = random_state(robot, rng)
    poses = rnea_poses(robot, q)
    symbols = list(sp.symbols(f"q1:{robot.n + 1}"))
    for k in range(robot.nb):
        point = tuple(rng.uniform(-0.3, 0.3, 3))
        body = body_point_jacobian(robot, k, point, symbols)
        got = np.array(body.xreplace(dict(zip(symbols, q, strict=True))).tolist(), dtype=float)
        R = poses[k][:3, :3]
        want = np.vstack(
            [R.T @ fd_jacobian(robot, q, k, point, None)[:3], R.T @ fd_jacobian(robot, q, k, point, None)[3:]]
        )
        assert_close(got, want, rtol=1e-6, what=f"{case} link {k + 1}")
        chain = all(p == i - 1 for i, p in enumerate(robot.parents))
        if chain and all(link.mimic is None for link in robot.links):
            assert symbols[0] not in body.free_symbols, (case, k)
