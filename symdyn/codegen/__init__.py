"""Code generation: the functions of docs/generated-code.md rendered for C, CasADi, NumPy, JAX,
PyTorch, LaTeX, MATLAB.

Each target is a backend package `symdyn.codegen.<backend>` (TARGETS maps target
names to them) shaped like a SymForce backend: a config of names and a printer
of SymPy expressions in the package, every statement of the target language in
templates/<target>/*.j2, and `render(ctx) -> {file name: text or bytes}` in
between, which passes the templates plain data. `TOOLS` in each backend says
which tools' versions (besides symdyn's) the bytes of each of its files depend
on. `generate` renders every requested target in memory first and writes
nothing unless all of them succeed (symdyn.codegen.output).
"""

from __future__ import annotations

import importlib
import os
import re
import warnings
from collections.abc import Sequence
from pathlib import Path

from ..destination import check_folder
from ..dynamics import SINGULAR_M, derive
from ..errors import SymdynError, SymdynWarning
from ..model.expressions import is_c_identifier
from ..model.robot import Robot
from ..progress import stage as progress_stage
from .frame_functions import choose_frames
from .functions import FRAME_GROUPS, FUNCTION_NAMES, GROUPS, build_functions
from .output import write_files
from .render import PRECISIONS, RenderContext

__all__ = ["generate", "render", "file_tools", "TARGETS", "FUNCTION_NAMES"]

TARGETS = {
    "c": "c",
    "casadi": "casadi",
    "python": "python",
    "jax": "jax",
    "torch": "pytorch",
    "latex": "latex",
    "matlab": "matlab",
}


def _target_module(name: str):
    if name not in TARGETS:
        raise SymdynError(f"unknown target '{name}' (one of {', '.join(TARGETS)})")
    return importlib.import_module(f"{__name__}.{TARGETS[name]}")


def file_tools(file_name: str) -> tuple[str, ...]:
    """The tools whose versions the bytes of a generated file depend on (sympy, casadi).

    Read from the backends' TOOLS tables, keyed by how the file name ends.
    """
    tools = {ending: deps for target in TARGETS for ending, deps in _target_module(target).TOOLS.items()}
    matches = sorted((e for e in tools if file_name.endswith(e)), key=len)
    if not matches:
        raise ValueError(f"{file_name}: not a file name any target generates")
    return tools[matches[-1]]


def context(
    robot: Robot,
    precision: str = "double",
    method: str = "newton-euler",
    prune: float | None = None,
    functions: Sequence[str] | None = None,
    frames: Sequence[str] | str | None = None,
    task_axes: Sequence[str] | str | None = None,
    freestanding: bool = False,
) -> RenderContext:
    """Derive the robot and build the target-independent function specs (from the pruned
    configuration-space form when `prune` is given, symdyn.codegen.pruned; only the groups of
    symdyn.codegen.functions.GROUPS named in `functions`, when given; None: every group but the
    frame groups; "all": every group). The frame groups (kinematics, operational_space) are built
    for `frames` (names or "F1,F2"; None: the default frames) and `task_axes`
    (symdyn.codegen.frame_functions.choose_frames), which are checked before anything is derived.
    `freestanding`: the C target without the C library (RenderContext.freestanding)."""
    if precision not in PRECISIONS:
        raise SymdynError(f"unknown precision '{precision}' (double or float)")
    if not is_c_identifier(robot.name):
        raise SymdynError(
            f"robot name {robot.name!r} is not a valid C identifier (letters, digits and underscores, "
            "not starting with a digit, not a C keyword): it names the generated files and functions"
        )
    bad = [str(p) for p in robot.params if not is_c_identifier(str(p))]
    if bad:
        raise SymdynError(
            f"robot '{robot.name}': parameter name(s) {', '.join(map(repr, bad))} are not valid C "
            "identifiers (letters, digits and underscores, not starting with a digit, not a C keyword): "
            "they name the generated code's parameters"
        )
    groups = _groups(functions)
    choice = None
    if groups is not None and set(groups) & set(FRAME_GROUPS):
        choice = choose_frames(robot, frames, task_axes)
    elif frames is not None or task_axes is not None:
        raise SymdynError(
            "--frames and --task-axes choose the frames of the kinematics and operational_space "
            "function groups: name them in --functions"
        )
    with (
        warnings.catch_warnings(),  # build_functions says it again, with the functions left out
        progress_stage(f"deriving '{robot.name}' ({robot.n} joints, {method})"),
    ):
        warnings.filterwarnings("ignore", f"robot '.*': {re.escape(SINGULAR_M)}", SymdynWarning)
        dyn = derive(robot, method=method, simplify=False)
    notes: tuple[str, ...] = ()
    if prune is not None:
        from .pruned import pruned_dynamics

        dyn, notes = pruned_dynamics(dyn, prune)
    specs = tuple(build_functions(dyn, groups, choice))
    frame_names = choice.frames if choice else ()
    return RenderContext(dyn.robot, dyn, specs, precision, notes, frame_names, freestanding)


def _groups(functions: Sequence[str] | None) -> Sequence[str] | None:
    """The groups of GROUPS that `functions` names (None, or a name "all" among them: every group)."""
    if functions is None:
        return None
    if "all" in functions:
        return list(GROUPS)
    unknown = sorted(set(functions) - set(GROUPS))
    if unknown or not functions:
        raise SymdynError(
            f"unknown function group(s) {', '.join(unknown) or '(none given)'} (one or more of "
            f"{', '.join(GROUPS)}, or all)"
        )
    return functions


def render(
    robot: Robot,
    targets: Sequence[str] = ("c", "casadi"),
    precision: str = "double",
    method: str = "newton-euler",
    prune: float | None = None,
    functions: Sequence[str] | None = None,
    frames: Sequence[str] | str | None = None,
    task_axes: Sequence[str] | str | None = None,
    freestanding: bool = False,
) -> dict[str, str | bytes]:
    """All files of the requested targets, in memory (name -> content)."""
    modules = [_target_module(t) for t in dict.fromkeys(targets)]
    if freestanding and "c" not in targets:
        raise SymdynError("--freestanding is an option of the C target: add --target c")
    both = precision == "both"  # symdyn.codegen.c.both
    if both and set(targets) != {"c"}:
        raise SymdynError(
            "--precision both is the C target's (files that compile in float or double): "
            "generate with --target c alone"
        )
    ctx = context(
        robot, "double" if both else precision, method, prune, functions, frames, task_axes, freestanding
    )
    files: dict[str, str | bytes] = {}
    for target, module in zip(dict.fromkeys(targets), modules, strict=True):
        with progress_stage(f"rendering {target} ({len(ctx.functions)} functions)"):
            files.update(module.render_both(ctx) if both else module.render(ctx))
    return files


def generate(
    robot: Robot | str | os.PathLike,
    targets: Sequence[str] = ("c", "casadi"),
    out_dir: str | os.PathLike = ".",
    precision: str = "double",
    force: bool = False,
    method: str = "newton-euler",
    prune: float | None = None,
    functions: Sequence[str] = ("dynamics",),
    frames: Sequence[str] | str | None = None,
    task_axes: Sequence[str] | str | None = None,
    freestanding: bool = False,
) -> list[Path]:
    """Render the targets for `robot` (a Robot, a robot file or a URDF file) into out_dir.

    `functions` names the groups of symdyn.codegen.functions.GROUPS to build: by default
    ("dynamics",), the seven functions of tau = M(q) qdd + V(q, qd) + G(q) + F(qd) and forward
    dynamics; ("all",) builds every group (the regressors, the derivatives, tip_wrench_torque,
    and the frame groups kinematics and operational_space). The frame groups are built for
    `frames` (frame names, or "F1,F2"; None: every leaf link and every frame of Robot.frames) and,
    for operational_space, the rows `task_axes` ("x,y,z"; None: all six), docs/generated-code.md.
    `prune`: from the significance-pruned model, symdyn.codegen.pruned. `freestanding`: the C
    target without the C library (no <math.h>; symdyn's own sines and cosines; docs/embedded.md).
    """
    check_folder(out_dir)  # before the work: '', a file, a path through a missing folder
    if not isinstance(robot, Robot):
        from ..parsers import load

        robot = load(robot)
    files = render(robot, targets, precision, method, prune, functions, frames, task_axes, freestanding)
    return write_files(out_dir, files, force=force)
