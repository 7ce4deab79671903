"""M(q) singular by construction (symdyn.algorithms.singular, and the oracle's symdyn.oracle.singular).

Two robots whose M is singular although no subtree is massless, so Robot.idle_joints() finds
nothing: a two-link arm whose second mass is a point on its own joint's axis, and the
Robotics Toolbox's UR5 (tests/data/good/toolbox_ur5.yaml: its link 6 is a point mass on joint
6's axis). That M is singular is checked numerically (the rank of the oracle's CRBA M at
random q); then `generate` must succeed for every target with one warning naming the joint and
the functions left out, leave out exactly the four functions that invert M, and the functions
it keeps must still agree with the oracle symdyn.rnea (finite differences of it for the
derivatives). The oracle's forward dynamics must say what it found.
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest
from robots import assert_close

import symdyn
from symdyn.codegen import TARGETS, context
from symdyn.codegen.derivative_functions import DERIVATIVE_FUNCTION_NAMES
from symdyn.codegen.functions import FUNCTION_NAMES
from symdyn.errors import SINGULAR_REASONS, SymdynError, SymdynWarning
from symdyn.model.parameters import numeric_parameters
from symdyn.oracle.regressor import regressor as oracle_regressor

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

DATA = Path(__file__).parent / "data" / "good"

#: The issue's reproduction (standard DH): link 2's point mass sits on z1, joint 2's axis.
TWO_LINK = """\
name: two_link
convention: standard
gravity: [0, 0, -9.81]
links:
  - {name: l1, joint: revolute, a: 0.5, alpha: 0, d: 0, theta: 0, mass: 1, com: [-0.25, 0, 0]}
  - {name: l2, joint: revolute, a: 0, alpha: 0, d: 0, theta: 0, mass: 0.5, com: [0, 0, -0.02]}
"""

LEFT_OUT = (
    "forward_dynamics",
    "forward_dynamics_derivatives",
    "mass_matrix_inverse",
    "linearize",
    "operational_space_inertia",
    "operational_space_bias",
)
KEPT = tuple(n for n in (*FUNCTION_NAMES, *DERIVATIVE_FUNCTION_NAMES) if n not in LEFT_OUT)
ON_AXIS = (
    "moves only mass that lies on its own axis, with no rotational inertia about that axis "
    "(M has a zero on its diagonal for it)"
)


def two_link(tmp_path: Path) -> symdyn.Robot:
    path = tmp_path / "two_link.yaml"
    path.write_text(TWO_LINK)
    return symdyn.load_robot(path)


def ur5(tmp_path: Path) -> symdyn.Robot:
    return symdyn.load_robot(DATA / "toolbox_ur5.yaml")


#: robot loader, its name, the link whose joint is singular (name, number)
CASES = {"two_link": (two_link, "l2", 2), "toolbox_ur5": (ur5, "link6", 6)}


def expected_warning(robot: str, link: str, k: int) -> str:
    return (
        f"robot '{robot}': M(q) is singular: the joint of link '{link}' (link {k}) {ON_AXIS}; so "
        "forward_dynamics, forward_dynamics_derivatives, mass_matrix_inverse, linearize, "
        "operational_space_inertia and operational_space_bias are not generated (the other functions are)"
    )


def symdyn_warnings(record) -> list[str]:
    return [str(w.message) for w in record if issubclass(w.category, SymdynWarning)]


@pytest.mark.parametrize("case", CASES)
def test_the_mass_matrix_is_singular_without_a_massless_subtree(case, tmp_path):
    load, _, k = CASES[case]
    robot = load(tmp_path)
    assert robot.idle_joints() == ()  # every subtree has mass: the old check saw nothing
    rng = np.random.default_rng(7)
    for q in rng.uniform(-np.pi, np.pi, (5, robot.n)):
        M = rn.mass_matrix(robot, q)
        assert np.linalg.matrix_rank(M) == robot.n - 1
        assert M[k - 1, k - 1] == 0.0 and np.all(M[k - 1] == 0.0)  # the point mass is on the axis
    with pytest.warns(SymdynWarning) as record:
        dyn = symdyn.derive(robot, simplify=False)
    assert [(j.coordinate, j.link, j.reason) for j in dyn.singular_joints] == [(k - 1, k - 1, "on_axis")]
    message = f"robot '{case}': M(q) is singular: the joint of link '{CASES[case][1]}' (link {k}) {ON_AXIS}"
    assert symdyn_warnings(record) == [f"{message}; forward dynamics is undefined"]


@pytest.fixture(scope="module", params=list(CASES))
def generated(request, tmp_path_factory):
    """(case, robot, output folder, the SymdynWarnings) of one `generate` of every target."""
    case = request.param
    tmp = tmp_path_factory.mktemp(case)
    robot = CASES[case][0](tmp)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        written = symdyn.generate(robot, targets=tuple(TARGETS), out_dir=tmp / "out", functions=("all",))
    assert written
    return case, robot, tmp / "out", symdyn_warnings(record)


def test_generate_leaves_out_the_functions_that_invert_M_with_one_warning(generated):
    case, robot, out, said = generated
    _, link, k = CASES[case]
    assert said == [expected_warning(case, link, k)]
    for path in out.iterdir():
        if path.suffix in (".c", ".h", ".py", ".tex", ".m", ".casadi"):
            text = path.read_text()
            assert not any(name in text for name in LEFT_OUT), path.name
    numpy_text = (out / f"{case}_numpy.py").read_text()
    assert all(f"def {name}(" in numpy_text for name in KEPT)
    c_header = (out / f"{case}_dynamics.h").read_text()
    assert all(f"{case}_{name}(" in c_header for name in KEPT)


def test_the_function_specs_are_the_kept_ones(tmp_path):
    robot = two_link(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        assert [spec.name for spec in context(robot).functions] == list(KEPT)


def test_the_functions_kept_agree_with_the_oracle(generated):
    case, robot, out, _ = generated
    path = out / f"{case}_numpy.py"
    spec = importlib.util.spec_from_file_location(path.stem, path)
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    assert not any(hasattr(gen, name) for name in LEFT_OUT)
    pi = numeric_parameters(robot)
    rng = np.random.default_rng(3)
    n, h = robot.n, 1e-6
    for _ in range(3):
        q, qd, qdd = rng.uniform(-1.5, 1.5, (3, n))
        tau = symdyn.rnea(robot, q, qd, qdd)
        assert_close(gen.inverse_dynamics(q, qd, qdd), tau, what="tau")
        M = np.reshape(gen.mass_matrix(q), (n, n))
        assert_close(M, rn.mass_matrix(robot, q), what="M")
        assert np.linalg.matrix_rank(M) == n - 1
        V = rn.bias_torque(robot, q, qd)
        assert_close(gen.coriolis(q, qd), V, what="V")
        assert_close(np.reshape(gen.coriolis_matrix(q, qd), (n, n)) @ qd, V, what="C qd")
        assert_close(gen.gravity(q), rn.gravity_torque(robot, q), what="G")
        assert_close(gen.friction(qd), rn.friction_torque(robot, qd), what="F")
        Y = np.reshape(gen.regressor(q, qd, qdd), (n, -1))
        assert_close(Y, oracle_regressor(robot, q, qd, qdd), what="Y")
        assert_close(Y @ pi, tau, what="Y pi")
        dq, dqd = (np.reshape(d, (n, n)) for d in gen.inverse_dynamics_derivatives(q, qd, qdd))
        E = np.eye(n) * h
        fd_q = np.stack(
            [symdyn.rnea(robot, q + e, qd, qdd) - symdyn.rnea(robot, q - e, qd, qdd) for e in E], 1
        )
        fd_qd = np.stack(
            [symdyn.rnea(robot, q, qd + e, qdd) - symdyn.rnea(robot, q, qd - e, qdd) for e in E], 1
        )
        assert_close(dq, fd_q / (2 * h), 1e-6, "dtau/dq")
        assert_close(dqd, fd_qd / (2 * h), 1e-6, "dtau/dqd")


def test_compiled_c_of_the_two_link_arm(tmp_path):
    """The C target compiles (no division by zero left in it) and agrees with the oracle."""
    robot = two_link(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        fast = symdyn.compile(robot)
    assert "forward_dynamics" not in fast.functions
    q, qd, qdd = np.array([0.3, -1.1]), np.array([0.4, 0.9]), np.array([-0.7, 0.2])
    assert_close(fast.inverse_dynamics(q, qd, qdd), symdyn.rnea(robot, q, qd, qdd))
    assert_close(fast.mass_matrix(q), rn.mass_matrix(robot, q))
    assert not hasattr(fast, "linearize")  # left out: an AttributeError, and a SymdynError saying why
    with pytest.raises(SymdynError, match=r"forward_dynamics was not generated: M\(q\) is singular"):
        fast.forward_dynamics(q, qd, qdd)


@pytest.mark.parametrize("case", CASES)
def test_oracle_forward_dynamics_says_what_it_found(case, tmp_path):
    load, link, k = CASES[case]
    robot = load(tmp_path)
    q = np.full(robot.n, 0.3)
    message = (
        f"forward_dynamics: robot '{case}': M(q) is singular: the joint of link '{link}' (link {k}) {ON_AXIS}"
    )
    with pytest.raises(SymdynError) as info:
        rn.forward_dynamics(robot, q, q, q)
    assert str(info.value) == message
    batch = np.stack([q, q + 1])
    with pytest.raises(SymdynError, match="M\\(q\\) is singular at state 0 of the batch: the joint of link"):
        rn.forward_dynamics(robot, batch, batch, batch)


COAXIAL = """\
name: coaxial
convention: standard
links:
  - {name: hub, joint: revolute, a: 0, alpha: 0, d: 0, theta: 0, mass: 0, com: [0, 0, 0]}
  - {name: arm, joint: revolute, a: 0.4, alpha: 0, d: 0, theta: 0, mass: 1.5, com: [-0.2, 0, 0],
     inertia: {ixx: 0.01, iyy: 0.02, izz: 0.03}}
"""


def test_a_joint_that_moves_what_the_joint_before_it_moves(tmp_path):
    """Two joints on one axis with nothing between them: M = [[a, a], [a, a]], a non-zero
    diagonal and a zero second pivot ("dependent"), in the derivation and in the oracle."""
    path = tmp_path / "coaxial.yaml"
    path.write_text(COAXIAL)
    robot = symdyn.load_robot(path)
    M = rn.mass_matrix(robot, [0.2, -0.5])
    assert np.linalg.matrix_rank(M) == 1 and M[1, 1] > 0
    clause = f"the joint of link 'arm' (link 2) {SINGULAR_REASONS['dependent']}"
    with pytest.warns(SymdynWarning, match="M\\(q\\) is singular: ") as record:
        dyn = symdyn.derive(robot, simplify=False)
    assert symdyn_warnings(record) == [
        f"robot 'coaxial': M(q) is singular: {clause}; forward dynamics is undefined"
    ]
    assert [(j.coordinate, j.reason) for j in dyn.singular_joints] == [(1, "dependent")]
    with pytest.raises(SymdynError) as info:
        rn.forward_dynamics(robot, [0.2, -0.5], [0, 0], [0, 0])
    assert str(info.value) == f"forward_dynamics: robot 'coaxial': M(q) is singular: {clause}"


def test_a_symbolic_mass_on_the_axis_is_still_singular(tmp_path):
    """A pivot that is identically zero counts whatever the free parameters are (a free mass
    m2 on joint 2's axis); one that depends on a free parameter does not (an offset r off the
    axis: r may take any value, and M[2,2] = m2 r^2)."""
    path = tmp_path / "two_link_m2.yaml"
    path.write_text(TWO_LINK.replace("mass: 0.5", "mass: m2"))
    with pytest.warns(SymdynWarning, match="the joint of link 'l2' \\(link 2\\) moves only mass"):
        dyn = symdyn.derive(symdyn.load_robot(path), simplify=False)
    assert [str(p) for p in dyn.params] == ["m2"]
    assert [(j.coordinate, j.reason) for j in dyn.singular_joints] == [(1, "on_axis")]
    path.write_text(TWO_LINK.replace("mass: 0.5, com: [0, 0, -0.02]", "mass: m2, com: [r, 0, -0.02]"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", SymdynWarning)
        assert symdyn.derive(symdyn.load_robot(path), simplify=False).singular_joints == ()


URDF_ON_AXIS = """<robot name="urdf_arm">
  <link name="base"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="upper"><inertial><origin xyz="0.25 0 0"/><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="fore"><inertial><origin xyz="0 0 -0.02"/><mass value="0.5"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
</robot>
"""


def test_a_urdf_joint_is_named_as_the_file_names_it(tmp_path):
    """A URDF names its joints: the warning gives the joint's own name beside its link's."""
    path = tmp_path / "urdf_arm.urdf"
    path.write_text(URDF_ON_AXIS)
    robot = symdyn.load_urdf(path)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        symdyn.generate(robot, targets=("python",), out_dir=tmp_path / "out")
    assert symdyn_warnings(record) == [
        f"robot 'urdf_arm': M(q) is singular: the joint of link 'fore' (joint 'elbow', link 2) {ON_AXIS}; "
        "so forward_dynamics is not generated (the other functions are)"
    ]


#: A floating robot whose base body is massless: the base turns about joint 1's axis while the
#: links stand still (M singular for every q); the same robot on a base with mass is not singular.
FLOATING_ARM = """\
name: {name}
base: {base}
links:
  - {{name: l1, joint: revolute, a: 0.5, alpha: 0.3, d: 0.1, theta: 0, mass: 1, com: [-0.25, 0.1, 0.02],
     inertia: {{ixx: 0.01, iyy: 0.02, izz: 0.03}}}}
  - {{name: l2, joint: revolute, a: 0.4, alpha: 0, d: 0, theta: 0.3, mass: 1, com: [-0.2, 0.01, 0],
     inertia: {{ixx: 0.01, iyy: 0.02, izz: 0.02}}}}
"""
FLOATING_BASES = {
    "massless_base": "floating",
    "massive_base": (
        "{floating: true, mass: 2, com: [0.05, -0.02, 0.1], inertia: {ixx: 0.1, iyy: 0.12, izz: 0.2}}"
    ),
}


def floating_arm(tmp_path: Path, name: str) -> symdyn.Robot:
    path = tmp_path / f"{name}.yaml"
    path.write_text(FLOATING_ARM.format(name=name, base=FLOATING_BASES[name]))
    return symdyn.load_robot(path)


def test_a_massless_floating_base_on_a_revolute_joint_is_singular(tmp_path):
    """The base's pivot wz_b (joint 1's axis is the base's z) is zero: reported with the cause
    "base", and the oracle's M has rank NV - 1 at random q; forward dynamics is left out with one
    warning, the rest generated."""
    robot = floating_arm(tmp_path, "massless_base")
    rng = np.random.default_rng(5)
    for joints in rng.uniform(-np.pi, np.pi, (3, robot.n)):
        quat = rng.normal(size=4)
        q = np.concatenate([rng.normal(size=3), quat / np.linalg.norm(quat), joints])
        assert np.linalg.matrix_rank(rn.mass_matrix(robot, q)) == robot.nv - 1
    clause = f"the base's coordinate wz_b (entry 6 of qd) {SINGULAR_REASONS['base']}"
    with pytest.warns(SymdynWarning) as record:
        dyn = symdyn.derive(robot, simplify=False)
    assert symdyn_warnings(record) == [
        f"robot 'massless_base': M(q) is singular: {clause}; forward dynamics is undefined"
    ]
    assert [(j.coordinate, j.link, j.reason) for j in dyn.singular_joints] == [(5, None, "base")]
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        names = [spec.name for spec in context(robot, functions=("dynamics",)).functions]
    assert symdyn_warnings(record) == [
        f"robot 'massless_base': M(q) is singular: {clause}; so forward_dynamics is not generated "
        "(the other functions are)"
    ]  # (the other families that invert M ask Dynamics.singular_joints as on a fixed base)
    assert names == [n for n in FUNCTION_NAMES[:7] if n != "forward_dynamics"]


def test_a_floating_base_with_mass_is_not_singular(tmp_path):
    robot = floating_arm(tmp_path, "massive_base")
    q = np.array([0.1, 0.2, 0.3, 0.0, 0.0, np.sin(0.2), np.cos(0.2), 0.4, -0.9])
    assert np.linalg.matrix_rank(rn.mass_matrix(robot, q)) == robot.nv
    with warnings.catch_warnings():
        warnings.simplefilter("error", SymdynWarning)
        assert symdyn.derive(robot, simplify=False).singular_joints == ()
