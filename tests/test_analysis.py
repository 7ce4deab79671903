"""Dynamic conditioning (lecture slides 21-24): inertia ellipsoid, dynamic manipulability,
acceleration polytope, the `analyze` command and the slide-24 picture.

Expected values are computed another way: Roger's arm from the lecture's closed-form
M, V, G (slide 18) and the hand-written Jacobian of a planar 2-link arm, with NumPy
(numpy.linalg.eig, det, inv), and the 2^n images of the torque cube written out.
"""

from __future__ import annotations

import importlib.util
import itertools
import json
from pathlib import Path

import numpy as np
import pytest
from timebound import refused

from symdyn import cli
from symdyn.algorithms.kinematics import numeric_jacobian, numeric_pose
from symdyn.apps.analysis import (
    acceleration_polytope,
    analyze,
    convex_hull_2d,
    default_axes,
    inertia_ellipsoid,
    parse_axes,
    plot_analysis,
    plot_workspace,
    task_jacobian,
    zonotope_vertex_signs,
)
from symdyn.errors import SymdynError
from symdyn.parsers import load_robot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ROGER = EXAMPLES / "roger_arm_values.yaml"
M1 = M2 = 0.2
L1 = L2 = 0.25
G0 = 9.81
STATES = [([-0.927, 1.855], [0.0, 0.0]), ([0.3, 1.1], [0.0, 0.0]), ([1.2, -0.7], [0.8, -1.5])]


@pytest.fixture(scope="module")
def roger():
    return load_robot(ROGER)


def run_cli(argv, monkeypatch=None) -> int:
    """The symdyn command in-process (symdyn.cli.main, which registers simulate/analyze/check)."""
    return cli.main([str(a) for a in argv])


def cross(a, b) -> float:
    """z component of the cross product of two plane vectors."""
    return float(a[0] * b[1] - a[1] * b[0])


def lecture(q, qd):
    """Slide 18's M, V, G and the planar 2-link Jacobian (rows x, y) and Jdot qd, by hand."""
    q1, q2 = q
    qd1, qd2 = qd
    c2, s2 = np.cos(q2), np.sin(q2)
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    M = np.array(
        [
            [M2 * L2**2 + 2 * M2 * L1 * L2 * c2 + (M1 + M2) * L1**2, M2 * L2**2 + M2 * L1 * L2 * c2],
            [M2 * L2**2 + M2 * L1 * L2 * c2, M2 * L2**2],
        ]
    )
    V = np.array([-M2 * L1 * L2 * s2 * (qd2**2 + 2 * qd1 * qd2), M2 * L1 * L2 * s2 * qd1**2])
    G = np.array([(M1 + M2) * G0 * L1 * s1 + M2 * G0 * L2 * s12, M2 * G0 * L2 * s12])
    J = np.array([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12]])
    w = qd1 + qd2
    Jdq = np.array([-L1 * c1 * qd1**2 - L2 * c12 * w**2, -L1 * s1 * qd1**2 - L2 * s12 * w**2])
    return M, V, G, J, Jdq


@pytest.mark.parametrize("q, qd", STATES)
def test_jacobian_and_its_derivative_match_the_planar_arm(roger, q, qd):
    M, V, G, J, Jdq = lecture(q, qd)
    J_got, Jdq_got = task_jacobian(roger, q, qd, "x,y")
    assert np.allclose(J_got, J, atol=1e-14) and np.allclose(Jdq_got, Jdq, atol=1e-13)
    assert default_axes(roger) == ("x", "y")


def test_jdot_qd_is_exact_on_a_spatial_arm():
    """Jdot qd against a central difference of J(q + qd t) qd (kinematics.numeric_jacobian)."""
    robot = load_robot(EXAMPLES / "planar_prismatic_modified.yaml")
    q, qd = np.array([0.3, 0.2, -0.5]), np.array([0.7, -0.4, 1.1])
    J, Jdq = task_jacobian(robot, q, qd, "x,y,z,rx,ry,rz")
    assert np.allclose(J, numeric_jacobian(robot, q, -1, list(robot.resolved().links[-1].frame.p)))
    h = 1e-5
    Jp = numeric_jacobian(robot, q + qd * h, -1, list(robot.resolved().links[-1].frame.p))
    Jm = numeric_jacobian(robot, q - qd * h, -1, list(robot.resolved().links[-1].frame.p))
    assert np.allclose(Jdq, (Jp - Jm) / (2 * h) @ qd, atol=1e-8)


@pytest.mark.parametrize("q, qd", STATES)
def test_analysis_of_rogers_arm_by_hand(roger, q, qd):
    limits = np.array([2.0, 1.5])
    M, V, G, J, Jdq = lecture(q, qd)
    a = analyze(roger, q, qd, torque_limits=limits, axes="x,y")
    Minv = np.linalg.inv(M)
    L = np.diag(limits)
    # inertia ellipsoid: numpy.linalg.eig of M M^T
    w, U = np.linalg.eig(M @ M.T)
    order = np.argsort(w)[::-1]
    assert np.allclose(a.inertia.lengths, np.sqrt(w[order]), rtol=1e-10)
    assert np.allclose(np.abs(np.sum(a.inertia.axes * U[:, order].T, axis=1)), 1.0)
    assert np.allclose(a.inertia.lengths, np.linalg.svd(M, compute_uv=False))  # = singular values of M
    assert np.allclose(inertia_ellipsoid(M).axes, a.inertia.axes)
    # dynamic manipulability: measure with the square root, bias, matrix
    kappa = np.sqrt(np.linalg.det(J @ np.linalg.inv(M.T @ M) @ J.T))
    assert a.manipulability.measure == pytest.approx(kappa, rel=1e-10)
    assert a.manipulability.measure_squared == pytest.approx(kappa**2, rel=1e-10)
    assert kappa == pytest.approx(abs(np.linalg.det(J) / np.linalg.det(M)), rel=1e-10)
    bias = Jdq - J @ Minv @ (V + G)
    assert np.allclose(a.bias, bias, rtol=1e-10, atol=1e-12)
    assert np.allclose(a.v_grav, -J @ Minv @ G) and np.allclose(a.v_vel, Jdq - J @ Minv @ V)
    assert np.allclose(a.manipulability.matrix, J @ Minv @ L @ L @ Minv.T @ J.T, rtol=1e-10)
    # polytope: the four images J M^-1 L tau_hat + bias, all vertices of a parallelogram
    A = J @ Minv @ L
    images = {tuple(np.round(A @ np.array(s) + bias, 9)) for s in itertools.product((-1, 1), repeat=2)}
    got = a.polytope.vertices
    assert {tuple(np.round(v, 9)) for v in got} == images
    for v, s in zip(got, a.polytope.signs, strict=True):
        assert np.allclose(v, A @ s + bias)
    # counter-clockwise, starting at the lowest x; consecutive vertices differ in one torque sign
    area = 0.5 * sum(cross(got[k], got[(k + 1) % 4]) for k in range(4))
    assert area > 0 and area == pytest.approx(4 * abs(np.linalg.det(A)), rel=1e-10)
    assert np.argmin(got[:, 0]) == 0
    for k in range(4):
        assert np.sum(a.polytope.signs[k] != a.polytope.signs[(k + 1) % 4]) == 1


def test_json_has_exactly_the_keys(roger):
    doc = json.loads(analyze(roger, [0.3, 1.1], torque_limits=2).to_json())
    assert set(doc["inertia_ellipsoid"]) == {"axes", "lengths"}
    assert set(doc["dynamic_manipulability"]) == {"measure", "bias", "matrix"}
    assert set(doc["acceleration_polytope"]) == {"vertices"}
    assert "square root taken" in doc["notes"]["measure"]
    assert np.array(doc["acceleration_polytope"]["vertices"]).shape == (4, 2)


def test_three_axes_of_a_planar_arm_give_a_flat_polytope(roger):
    flat = analyze(roger, [0.3, 1.1], torque_limits=2, axes="x,y,z")
    plane = analyze(roger, [0.3, 1.1], torque_limits=2, axes="x,y")
    assert flat.manipulability.measure == 0.0  # J has a zero row: det = 0
    assert np.allclose(flat.polytope.vertices[:, 2], 0) and len(flat.polytope.vertices) == 4
    key = sorted(tuple(np.round(v[:2], 9)) for v in flat.polytope.vertices)
    assert key == sorted(tuple(np.round(v, 9)) for v in plane.polytope.vertices)
    rz = analyze(roger, [0.3, 1.1], torque_limits=2, axes=["x", "y", "rz"])
    assert len(rz.polytope.vertices) == 4  # two joints: always a parallelogram


def test_convex_hull_2d():
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    extra = [(0.5, 0.5), (0.5, 0), (1, 0.5), (0, 0), (0.2, 0.9)]
    pts = np.array(square + extra, dtype=float)
    hull = convex_hull_2d(pts)
    assert [tuple(pts[i]) for i in hull] == [(0, 0), (1, 0), (1, 1), (0, 1)]
    assert convex_hull_2d([(1, 2)]) == [0]
    assert len(convex_hull_2d([(0, 0), (1, 1), (2, 2)])) == 2  # collinear: the two ends


def test_zonotope_vertices_in_3d_by_support_directions():
    """Every sign pattern sign(A^T c) for random directions c is returned, and only those."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(3, 5))
    signs = zonotope_vertex_signs(A)
    sampled = {tuple(np.sign(A.T @ c)) for c in rng.normal(size=(20000, 3))}
    assert {tuple(s) for s in signs} == sampled
    assert len(signs) == 2 * (1 + 4 + 6)  # regions of 5 generic planes through 0 in R^3
    # and their hull is the image of the whole cube: same support in every direction
    cube = np.array(list(itertools.product((-1, 1), repeat=5))) @ A.T
    poly = acceleration_polytope(A, np.zeros(3)).vertices
    for c in rng.normal(size=(200, 3)):
        assert np.max(poly @ c) == pytest.approx(np.max(cube @ c), rel=1e-12)


def test_zonotope_with_parallel_and_zero_generators():
    A = np.array([[1.0, 2.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])  # two parallel, one zero
    poly = acceleration_polytope(A, np.array([1.0, 0.0]))
    assert sorted(map(tuple, poly.vertices)) == [(-2, -1), (-2, 1), (4, -1), (4, 1)]


def test_parse_axes_and_bad_input(roger):
    assert parse_axes("x, y,rz") == ("x", "y", "rz")
    with pytest.raises(SymdynError, match="unknown axis"):
        parse_axes("x,w")
    with pytest.raises(SymdynError, match="repeated"):
        parse_axes("x,x")
    with pytest.raises(SymdynError, match="torque limits"):
        analyze(roger, [0, 1], torque_limits=[1, 2, 3])
    with pytest.raises(SymdynError, match="q must have 2"):
        analyze(roger, [0, 1, 2], torque_limits=1)


def test_cli_analyze_json_text_and_plot(tmp_path, monkeypatch, capsys):
    png = tmp_path / "fig.png"
    argv = [
        "analyze",
        ROGER,
        "--q",
        "-0.927",
        "1.855",
        "--torque-limits",
        "2",
        "--format",
        "json",
        "--plot",
        png,
    ]
    assert run_cli(argv, monkeypatch) == 0
    doc = json.loads(capsys.readouterr().out)
    M, V, G, J, _ = lecture([-0.927, 1.855], [0, 0])
    assert np.allclose(doc["dynamic_manipulability"]["bias"], -J @ np.linalg.solve(M, G))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    argv = [
        "analyze",
        EXAMPLES / "roger_arm.yaml",
        "--q=-0.927,1.855",
        "--torque-limits",
        "2",
        "1",
        "--params",
        "g=9.81,m1=0.2,m2=0.2,l1=0.25,l2=0.25",
    ]
    assert run_cli(argv, monkeypatch) == 0
    text = capsys.readouterr().out
    assert "square root taken" in text and "singular values of M" in text and "4 vertices" in text


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--axes", "x,y,z", "--plot", "fig.png"], "two --axes"),
        (["--axes", "x,q"], "unknown axis"),
        (["--params", "m1=-"], "--params"),
    ],
)
def test_cli_analyze_bad_input(extra, message, tmp_path, monkeypatch, capsys):
    argv = ["analyze", ROGER, "--q", "0", "1", "--torque-limits", "2", *extra]
    monkeypatch.chdir(tmp_path)
    assert run_cli(argv, monkeypatch) == 1
    err = capsys.readouterr().err
    assert err.startswith("symdyn: error: ") and message in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_slide24_script(roger, tmp_path):
    """examples/slide24.py draws the picture; its stated choices hold (see its docstring)."""
    spec = importlib.util.spec_from_file_location("slide24", EXAMPLES / "slide24.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = mod.main(tmp_path / "slide24.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert mod.TORQUE_LIMIT == 2.0
    holding = (M1 + M2) * G0 * L1 + M2 * G0 * L2  # largest gravity torque: 1.47 N m < 2 N m
    assert holding < mod.TORQUE_LIMIT
    for x, y in mod.HAND_POSITIONS:
        q = mod.inverse_kinematics(x, y)
        assert np.allclose(numeric_pose(roger, q, -1, [L2, 0, 0])[:2, 3], [x, y])
        a = analyze(roger, q, torque_limits=mod.TORQUE_LIMIT, axes="x,y")
        v = a.polytope.vertices
        # zero acceleration is inside every gravity-biased polytope (the arm can hold itself)
        assert all(cross(v[(k + 1) % len(v)] - v[k], -v[k]) > 0 for k in range(len(v)))
        # the gravity bias is visible but smaller than the ellipse's smaller semi-axis
        assert 5 < np.linalg.norm(a.bias) < a.manipulability.lengths[-1]


def test_plots_return_the_image_they_write(roger, tmp_path):
    """plot_analysis and plot_workspace give back the very bytes they write, in each format."""
    analyses = [analyze(roger, q, torque_limits=2.0, axes="x,y") for q, _ in STATES[:2]]
    draws = {
        "analysis": lambda path: plot_analysis(analyses[0], path, robot=roger),
        "workspace": lambda path: plot_workspace(roger, analyses, path),
    }
    for name, draw in draws.items():
        for suffix, magic in ((".png", b"\x89PNG\r\n\x1a\n"), (".pdf", b"%PDF"), (".svg", b"<?xml")):
            path = tmp_path / f"{name}{suffix}"
            data = draw(path)
            assert isinstance(data, bytes) and data.startswith(magic), (name, suffix)
            assert path.read_bytes() == data, (name, suffix)


def test_frame_option_uses_that_frames_jacobian(tmp_path, monkeypatch, capsys):
    """--frame F: J and Jdot qd of F (the generated functions) equal the numeric oracle's, and
    the analysis follows from them; an unknown frame is one line naming the near match."""
    from symdyn.oracle.frames import frame_state

    path = tmp_path / "roger_tool.yaml"
    path.write_text(
        ROGER.read_text()
        + "frames:\n  - {name: tool, link: forearm, xyz: [0.1, 0.05, 0], rpy: [0, 0, 0.3]}\n"
    )
    robot = load_robot(path)
    q, qd = np.array([0.3, 1.1]), np.array([0.8, -1.5])
    result = analyze(robot, q, qd, torque_limits=2, frame="tool")
    fs = frame_state(robot, "tool", q, qd)
    assert result.axes == ("x", "y")
    assert np.allclose(result.J, fs.jacobian[:2], atol=1e-14) and np.allclose(
        result.Jdot_qd, fs.drift[:2], atol=1e-13
    )
    M, V, G, _, _ = lecture(q, qd)
    assert np.allclose(result.v_grav, -fs.jacobian[:2] @ np.linalg.solve(M, G), atol=1e-12)
    argv = [
        "analyze",
        path,
        "--q",
        "0.3",
        "1.1",
        "--torque-limits",
        "2",
        "--frame",
        "tool",
        "--format",
        "json",
    ]
    assert run_cli(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert np.allclose(doc["dynamic_manipulability"]["bias"], -fs.jacobian[:2] @ np.linalg.solve(M, G))
    monkeypatch.chdir(tmp_path)
    assert run_cli(["analyze", path, "--q", "0", "1", "--torque-limits", "2", "--frame", "tol"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("symdyn: error: ") and "unknown frame 'tol'" in err and "'tool'" in err
    assert err.count("\n") == 1


def test_overflowing_options_are_one_line(capsys):
    """Before: `analyze --torque-limits 1e308` and `--qd 1e200,0,0` printed a polytope of NaN
    vertices and exited 0; now one line saying the products overflow."""
    robot = str(EXAMPLES / "planar_3r.yaml")
    for options in (["--torque-limits", "1e308"], ["--qd", "1e200,0,0", "--torque-limits", "1"]):
        line = refused(capsys, "analyze", robot, "--q", "0,0,0", *options, seconds=60)
        assert line.startswith(
            "symdyn: error: analyze: the velocity terms, the ellipsoid or the polytope are not"
        )
