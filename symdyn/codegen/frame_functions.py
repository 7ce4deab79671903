"""The generated frame functions (docs/generated-code.md): kinematics and operational space.

For each chosen frame F (`FrameChoice`), with F's name made an identifier ID valid in every
target (`frame_identifiers`: symdyn.model.names.identifiers, distinct, never `com`):

    ID_pose(q, p, T)                            T = world_T_F, 4 x 4
    ID_jacobian(q, p, J)                        6 x n, world-aligned at F's origin
    ID_jacobian_local(q, p, J)                  6 x n, in F's own axes
    ID_jacobian_dot_qd(q, qd, p, a)             Jdot qd (6) at qdd = 0, world-aligned
    ID_operational_space_inertia(q, p, Lambda)  (J M^-1 J^T)^-1, k x k
    ID_operational_space_bias(q, qd, p, mu)     mu + p = Lambda (J M^-1 (V + G + F) - Jdot qd), k

and once per robot com(q, p, c), com_jacobian(q, p, Jc), com_jacobian_dot_qd(q, qd, p, a)
(world frame). Rows of J are v_x v_y v_z w_x w_y w_z; the operational-space functions use the
world-aligned rows the task axes choose (symdyn.algorithms.operational_space.TASK_AXES, all six
by default, k of them). The quantities are symdyn.algorithms.frame_kinematics' and
symdyn.algorithms.operational_space's, over named intermediates written into copies of
`dyn.program` (the derivation is not changed); both inverses are unrolled L D L^T
factorisations, without square roots. On a floating robot (symdyn.algorithms.floating_frames)
q has NQ entries and qd NV, J is 6 x NV with the base's columns first and M NV x NV, inverted
with the joints eliminated before the base (docs/floating-base.md).

The default frames are every leaf link of the tree (a link no other link hangs from) followed
by every frame of Robot.frames (a URDF's merged fixed links, a robot file's `frames:`, PoE's
end_effector), each once.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import sympy as sp

from ..algorithms.floating_frames import FloatingFrames
from ..algorithms.frame_kinematics import FrameKinematics
from ..algorithms.operational_space import operational_space, task_rows
from ..dynamics import Dynamics
from ..errors import SymdynError, SymdynWarning
from ..model.free_flyer import NQ_BASE, NV_BASE
from ..model.names import comment_text, identifier, identifiers
from ..model.robot import Robot
from .centroidal_functions import centroidal_of, com_row, floating_inputs
from .function_rows import FrameChoice, FunctionRow, Inputs, Output, with_steps

__all__ = [
    "FrameChoice",
    "choose_frames",
    "identifier",
    "frame_identifiers",
    "comment_text",
    "default_frames",
    "kinematics_rows",
    "operational_space_rows",
    "COM_FUNCTIONS",
    "FRAME_SUFFIXES",
    "frame_function_names",
]

#: The centre-of-mass functions of the kinematics group (an identifier must not shadow them).
COM_FUNCTIONS = ("com", "com_jacobian", "com_jacobian_dot_qd")


#: The functions of each frame, ID_<suffix> (module docstring).
FRAME_SUFFIXES = (
    "pose",
    "jacobian",
    "jacobian_local",
    "jacobian_dot_qd",
    "operational_space_inertia",
    "operational_space_bias",
)


def frame_function_names(frames: tuple[tuple[str, str, str], ...]) -> set[str]:
    """The names every frame function of FrameChoice.frames `frames` may have, and COM_FUNCTIONS."""
    return {f"{ident}_{s}" for _, ident, _ in frames for s in FRAME_SUFFIXES} | set(COM_FUNCTIONS)


def frame_identifiers(names: Sequence[str]) -> dict[str, str]:
    """{frame: identifier} of the chosen frames: distinct identifiers valid in every target
    (symdyn.model.names.identifiers), none of them `com`, whose functions would be the centre
    of mass's."""
    return identifiers(names, reserved=("com",))


def default_frames(robot: Robot) -> list[str]:
    """Every leaf link (no child), then every frame of Robot.frames (module docstring)."""
    parents = set(robot.parents)
    return [link.name for i, link in enumerate(robot.links) if i not in parents] + [
        f.name for f in robot.frames
    ]


def _link_text(robot: Robot, link: int) -> str:
    return "the base" if link < 0 else f"link {link + 1} ({comment_text(robot.links[link].name)})"


def choose_frames(robot: Robot, frames: Sequence[str] | str | None = None, task_axes=None) -> FrameChoice:
    """The FrameChoice of `frames` (names, or "F1,F2"; None: the default frames) and `task_axes`
    ("x,y,z", names of TASK_AXES, or None: all six).

    Each frame's identifier is frame_identifiers': two frames never share one.

    Raises:
        SymdynError: an unknown frame (naming the near matches), no frame, or an unknown task axis.
    """
    rows = task_rows(task_axes, "--task-axes")
    if isinstance(frames, str):
        frames = [a.strip() for a in frames.split(",") if a.strip()]
    names = list(dict.fromkeys(default_frames(robot) if frames is None else frames))
    if not names:
        raise SymdynError(f"--frames: robot '{robot.name}': no frame given")
    links = [robot.frame(name, "--frames").link for name in names]
    idents = frame_identifiers(names)
    table = [(name, idents[name], _link_text(robot, link)) for name, link in zip(names, links, strict=True)]
    return FrameChoice(tuple(table), rows)


def _entries(*matrices: sp.Matrix) -> tuple[sp.Expr, ...]:
    return tuple(m[i, j] for m in matrices for i in range(m.rows) for j in range(m.cols))


def frames_of(dyn: Dynamics, x: Inputs, prog) -> tuple:
    """(frame quantities, q, qd, columns of a Jacobian, their size name) over `prog`: on a
    floating robot FloatingFrames over q (NQ) and v (NV), else FrameKinematics over the joints."""
    robot = dyn.robot
    if robot.floating:
        q, qd = floating_inputs(dyn, x)
        joints, rates = q.symbols[NQ_BASE:], qd.symbols[NV_BASE:]
        fk = FloatingFrames(FrameKinematics(robot, joints, rates, prog), centroidal_of(dyn, x, prog))
        return fk, q, qd, robot.nv, "nv"
    return FrameKinematics(robot, list(dyn.q), list(dyn.qd), prog), x.q, x.qd, dyn.n, "n"


def kinematics_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """pose, jacobian, jacobian_local and jacobian_dot_qd of each chosen frame, then the centre
    of mass's three functions (module docstring); on a floating robot over q (NQ) and v (NV),
    with the base's columns (symdyn.algorithms.floating_frames)."""
    prog = dyn.program.copy("K")
    first = len(prog.assignments)
    fk, q, qd, n, cols = frames_of(dyn, x, prog)
    rows: list[tuple] = []
    for name, ident, link in x.frames.frames:
        on = f"of frame {comment_text(name)} on {link}"
        rows += [
            (
                f"{ident}_pose",
                f"world_T_F {on}, row-major 4 x 4",
                (q, x.p),
                (Output("T", 4, 4, "pose world_T_F: rotation and origin of F in the world", ("4", "4")),),
                _entries(fk.pose(name)),
            ),
            (
                f"{ident}_jacobian",
                f"Jacobian {on}, world-aligned at F's origin, rows v_x v_y v_z w_x w_y w_z",
                (q, x.p),
                (Output("J", 6, n, "world-aligned Jacobian", ("6", cols)),),
                _entries(fk.jacobian(name, "world")),
            ),
            (
                f"{ident}_jacobian_local",
                f"Jacobian {on}, in F's own axes, rows v_x v_y v_z w_x w_y w_z",
                (q, x.p),
                (Output("J", 6, n, "Jacobian in F's own axes", ("6", cols)),),
                _entries(fk.jacobian(name, "local")),
            ),
            (
                f"{ident}_jacobian_dot_qd",
                f"Jdot qd {on} at qdd = 0, world-aligned: classical acceleration of F's origin, "
                "then F's angular acceleration",
                (q, qd, x.p),
                (Output("a", 6, 1, "Jdot qd: linear then angular acceleration at qdd = 0", ("6", "1")),),
                _entries(fk.jacobian_dot_qd(name)),
            ),
        ]
    rows += [
        com_row(q, x.p, fk.com()),
        (
            "com_jacobian",
            "Jc(q) with dc/dt = Jc qd, world frame",
            (q, x.p),
            (Output("Jc", 3, n, "centre-of-mass Jacobian", ("3", cols)),),
            _entries(fk.com_jacobian()),
        ),
        (
            "com_jacobian_dot_qd",
            "Jc_dot qd: the centre of mass's acceleration at qdd = 0, world frame",
            (q, qd, x.p),
            (Output("a", 3, 1, "Jc_dot qd", ("3", "1")),),
            _entries(fk.com_jacobian_dot_qd()),
        ),
    ]
    return with_steps(rows, prog, first, "kinematics")


def operational_space_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """operational_space_inertia and operational_space_bias of each chosen frame over the task
    axes' rows of its world-aligned Jacobian (module docstring); on a floating robot J is k x NV
    with the base's columns (symdyn.algorithms.floating_frames) and M NV x NV, inverted with
    the joints eliminated before the base, as forward dynamics does."""
    c = dyn.compact
    prog = dyn.program.copy("O")
    first = len(prog.assignments)
    fk, _, _, n, _ = frames_of(dyn, x, prog)
    chain = dyn.robot.is_chain and not dyn.robot.floating
    keep = list(x.frames.rows)
    k = len(keep)
    axes = ", ".join(x.frames.axes)
    rows: list[tuple] = []
    if dyn.singular_joints:
        return []  # M is singular by construction (build_functions warns)
    for name, ident, link in x.frames.frames:
        J = fk.jacobian(name, "world").extract(keep, list(range(n)))
        drift = fk.jacobian_dot_qd(name).extract(keep, [0])
        mark = len(prog.assignments)
        os = operational_space(sp.Matrix(c["M"]), J, sp.Matrix(c["bias"]), drift, chain, prog)
        made = [e for _, e in prog.assignments[mark:]] + list(os.inertia) + list(os.bias)
        if any(sp.sympify(e).has(sp.zoo, sp.nan, sp.oo) for e in made):
            warnings.warn(
                f"robot '{dyn.robot.name}': the operational-space functions of frame {name!r} are not "
                f"generated: J M^-1 J^T over the task axes {axes} is singular at every q (the joints "
                "supporting the frame cannot move it along every axis); choose fewer --task-axes",
                SymdynWarning,
                stacklevel=4,
            )
            continue
        on = f"of frame {comment_text(name)} on {link}, task axes {axes}"
        rows += [
            (
                f"{ident}_operational_space_inertia",
                f"Lambda = (J M^-1 J^T)^-1 {on} (unrolled L D L^T, no square roots)",
                (x.q, x.p),
                (Output("Lambda", k, k, "operational-space inertia", ("k", "k")),),
                _entries(os.inertia),
            ),
            (
                f"{ident}_operational_space_bias",
                f"mu + p = Lambda (J M^-1 (V + G + F) - Jdot qd) {on}",
                (x.q, x.qd, x.p),
                (Output("mu", k, 1, "operational-space bias mu + p", ("k", "1")),),
                _entries(os.bias),
            ),
        ]
    return with_steps(rows, prog, first, "operational_space")
