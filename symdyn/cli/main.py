"""The `symdyn` command line: the parser, derive and generate, and the one error policy.

Bad input prints one line, `symdyn: error: <file>: link <i> (<name>): field '<f>': <why>`,
and exits with status 1; warnings print as `symdyn: warning: ...`. No
traceback reaches the user and no partial output is written.
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from collections.abc import Callable, Sequence

from .. import __version__
from ..errors import SymdynError, SymdynWarning, one_line
from ..model.names import comment_text
from ..progress import finish as progress_finish
from ..progress import note as progress_note
from ..progress import quiet as progress_quiet
from ..progress import restart as progress_restart
from ..progress import stage as progress_stage
from .apps import COMMANDS as APPLICATIONS
from .common import METHODS, add_contacts_argument, add_robot_argument, load_robot_argument
from .draw import COMMANDS as DRAWING
from .identification import COMMANDS as IDENTIFICATION

__all__ = ["main", "build_parser", "COMMANDS"]

EXIT_BAD_INPUT = 1
EXIT_INTERNAL = 3
PRINTED = ("M", "C", "V", "G", "F")
#: generate notes the size of its C, and how long a build takes, from this many bytes
BIG_C = 200_000


def _entry_name(name: str, shape: tuple[int, int], k: int) -> str:
    """1-based entry names: M[1,2] for the matrices M and C, G[2] for the vectors."""
    cols = shape[1]
    return f"{name}[{k // cols + 1},{k % cols + 1}]" if name in ("M", "C") else f"{name}[{k + 1}]"


def _derive_text(dyn) -> str:
    import sympy as sp

    from .derive_output import floating_note as _floating_note

    lines = [
        f"# {comment_text(dyn.robot.name)}: {dyn.robot.n} joints{_floating_note(dyn)}, method {dyn.method}",
        f"# joints: q = ({', '.join(map(str, dyn.q))}); free parameters: "
        + (", ".join(map(str, dyn.params)) or "none"),
        "# tau = M(q) qdd + V(q, qd) + G(q) + F(qd),  V = C(q, qd) qd",
    ]
    for name in PRINTED:
        m = dyn.closed_form(name)
        lines.append("")
        for k, e in enumerate(m):
            lines.append(f"{_entry_name(name, m.shape, k)} = {sp.sstr(e)}")
    return "\n".join(lines) + "\n"


def _derive_json(dyn) -> str:
    import sympy as sp

    doc: dict = {
        "robot": dyn.robot.name,
        "method": dyn.method,
        "joints": dyn.n,
        "q": [str(s) for s in dyn.q],
        "qd": [str(s) for s in dyn.qd],
        "qdd": [str(s) for s in dyn.qdd],
        "params": [str(s) for s in dyn.params],
    }
    for name in PRINTED:
        m = dyn.closed_form(name)
        if name not in ("M", "C"):
            doc[name] = [sp.sstr(e) for e in m]
        else:
            doc[name] = [[sp.sstr(m[i, j]) for j in range(m.cols)] for i in range(m.rows)]
    return json.dumps(doc, indent=2) + "\n"


def _derive_latex(dyn) -> str:
    """--form compact/expanded in LaTeX: the target's closed form up to three joints, beyond
    that its eliminated form (named intermediates; the product form is --form product)."""
    from ..codegen.latex import dynamics_latex
    from ..dynamics import AUTO_SIMPLIFY_MAX_JOINTS

    return dynamics_latex(dyn, "auto" if dyn.n <= AUTO_SIMPLIFY_MAX_JOINTS else "eliminated")


def cmd_derive(args: argparse.Namespace) -> int:
    if args.frames is not None and (args.steps or args.at):
        raise SymdynError(
            "derive: --frames prints the frames after the equations of motion, not with --steps"
        )
    if args.steps or args.at:
        from .steps import cmd_derive_steps

        return cmd_derive_steps(args)
    from ..algorithms.configuration_space import READABLE_TERMS
    from ..dynamics import derive
    from . import derive_output as out
    from .derive_loops import loop_report, with_loops

    robot = load_robot_argument(args)
    loops = loop_report(robot)  # generate's check of the loops, before any derivation
    if args.form == "product" and not robot.floating:
        from ..algorithms.product_form import check_product_size

        check_product_size(robot)  # a chain beyond the bound is refused before it is derived
    simplify = None if args.simplify == "auto" else args.simplify == "yes"
    with progress_stage(f"deriving '{robot.name}' ({robot.n} joints, {args.method})"):
        dyn = derive(robot, method=args.method, simplify=simplify)
    frames = out.frame_names(dyn, args.frames)
    if robot.floating:  # trigonometric polynomials in the joint angles: not with a quaternion
        if args.form not in (None, "compact") or args.lumped or args.prune is not None:
            raise SymdynError(
                "derive: a floating robot prints --form compact (no configuration or product form, "
                "--lumped or --prune)"
            )
        args.form = "compact"
    if args.form is None:
        args.form = "configuration"
        with progress_stage("the configuration-space form (M, Christoffel symbols, G)"):
            readable = dyn.readable_configuration_space()
        if readable is None:
            args.form = "compact"
            print(
                f"symdyn: note: the configuration-space form of '{comment_text(robot.name)}' has more "
                f"than {READABLE_TERMS:,} terms; printing --form compact (ask for --form configuration "
                "to print it all the same)",
                file=sys.stderr,
            )
    with progress_stage(f"the {args.form} form as {args.format}"):
        text = _derive_output(args, dyn, robot)
    text = with_loops(loops, text, args.format)
    if frames and args.format == "json":
        doc = json.loads(text)
        doc["frames"] = out.frames_json(dyn, frames)
        text = json.dumps(doc, indent=2) + "\n"
    elif frames:
        with progress_stage(f"the frames {', '.join(frames)}"):
            text += (out.frames_latex if args.format == "latex" else out.frames_text)(dyn, frames)
    sys.stdout.write(text)
    return 0


def _derive_output(args: argparse.Namespace, dyn, robot) -> str:
    """The text of `symdyn derive` in the form and format asked for."""
    from . import derive_output as out

    if args.form == "product":
        from . import derive_product as prod

        if args.prune is not None:
            raise SymdynError("derive: --prune applies to --form configuration, not --form product")
        writer = {"text": prod.product_text, "json": prod.product_json_text, "latex": prod.product_latex}
        return writer[args.format](dyn, lumped=args.lumped)
    if args.format == "latex":
        configuration = args.form == "configuration"
        return out.derive_latex_configuration(dyn, args.lumped) if configuration else _derive_latex(dyn)
    if args.prune is not None:
        from ..algorithms.pruning import prune_robot

        if args.format != "text" or args.form != "configuration":
            raise SymdynError("derive: --prune prints the configuration form as text only")
        pruned = prune_robot(dyn.configuration_space, robot, args.prune)
        return out.derive_text(dyn, args.form, args.lumped, pruned)
    return {"text": out.derive_text, "json": out.derive_json}[args.format](dyn, args.form, args.lumped)


def cmd_generate(args: argparse.Namespace) -> int:
    from ..codegen import generate

    robot = load_robot_argument(args)
    targets = args.target or ["c", "casadi"]
    paths = generate(
        robot,
        targets=targets,
        out_dir=args.out,
        precision=args.precision,
        force=args.force,
        method=args.method,
        prune=args.prune,
        functions=args.functions,
        frames=args.frames,
        task_axes=args.task_axes,
        freestanding=args.freestanding,
    )
    for p in paths:
        print(p)
    c_files = [p for p in paths if p.suffix == ".c"]
    size = sum(p.stat().st_size for p in c_files if p.is_file())
    if size >= BIG_C:
        from ..apps.compilation.build import compile_estimate

        progress_note(
            f"{size / 1000:.0f} KB of C in {len(c_files)} file{'s' * (len(c_files) != 1)}: a build takes "
            f"{compile_estimate(size)} (more on a smaller or busy machine; each .c file compiles on "
            "its own core)"
        )
    return 0


def _derive_arguments(d: argparse.ArgumentParser) -> None:
    add_robot_argument(d)
    add_contacts_argument(d)
    d.add_argument("--method", choices=METHODS, default="newton-euler")
    d.add_argument("--format", choices=("text", "latex", "json"), default="text")
    d.add_argument(
        "--simplify",
        choices=("auto", "yes", "no"),
        default="auto",
        help="trigonometric simplification of the closed forms (auto: up to 3 joints)",
    )
    d.add_argument(
        "--form",
        choices=("configuration", "product", "compact", "expanded"),
        default=None,
        help="configuration: M, B [qd qd], Csq [qd^2], G, F (default, unless larger than "
        "100,000 terms: then compact); product: the same over c_i, s_i, c_23, ..., factored "
        "and shared; compact: named intermediates; expanded: the full expansion",
    )
    d.add_argument(
        "--lumped",
        action="store_true",
        help="name each distinct coefficient once (I1, I2, ..., g1, ...; over the base parameters "
        "when the inertial data is symbolic)",
    )
    d.add_argument(
        "--prune",
        type=float,
        metavar="REL",
        help="drop terms below REL of their entry's largest value over the joint ranges (AKB's 1%% model)",
    )
    d.add_argument(
        "--frames",
        metavar="F1,F2",
        help="also print each frame's pose world_T_F and world-aligned Jacobian (a link's name or "
        "one of the robot's frames; docs/frames.md)",
    )
    d.add_argument(
        "--steps", action="store_true", help="print the derivation link by link (symdyn.apps.checking.steps)"
    )
    d.add_argument("--at", nargs="+", metavar="NAME=VALUES", help="with --steps: numbers, q=.. qd=.. qdd=..")
    d.set_defaults(func=cmd_derive)


def _generate_arguments(g: argparse.ArgumentParser) -> None:
    add_robot_argument(g)
    add_contacts_argument(g)
    g.add_argument(
        "--target",
        action="append",
        choices=("c", "casadi", "python", "jax", "torch", "latex", "matlab"),
        help="target language; repeat for several (default: c and casadi)",
    )
    g.add_argument("--out", required=True, help="output folder")
    g.add_argument(
        "--precision",
        choices=("double", "float", "both"),
        default="double",
        help="the C type of the code (both: C target only, files that compile in float or double, "
        "chosen by NAME_USE_FLOAT / CMake's NAME_PRECISION; docs/embedded.md)",
    )
    g.add_argument(
        "--freestanding",
        action="store_true",
        help="C target: no C library (no <math.h>; symdyn's own sine and cosine), for bare-metal builds "
        "linked with -nostdlib (docs/embedded.md)",
    )
    g.add_argument("--method", choices=METHODS, default="newton-euler")
    g.add_argument(
        "--functions",
        nargs="+",
        choices=(
            "dynamics",
            "regressor",
            "tip_wrench",
            "derivatives",
            "kinematics",
            "operational_space",
            "configuration",
            "centroidal",
            "contacts",
            "contact_derivatives",
            "contact_baumgarte",
            "all",
        ),
        default=["dynamics"],
        help="the groups of functions to build (default: dynamics, the seven of tau = M qdd + V + G + F "
        "and forward dynamics); regressor, tip_wrench (product-of-exponentials robots), derivatives, "
        "kinematics and operational_space (per frame, see --frames); configuration (a floating robot's "
        "integrate and difference), centroidal (momentum matrix, its drift, com, total mass), contacts "
        "(a robot with contacts: Jc, drift, constrained and impulse dynamics; docs/contacts.md), "
        "contact_derivatives (their derivatives), contact_baumgarte (the contacts' position errors and "
        "the Baumgarte-stabilised constrained dynamics, named only); all: every group",
    )
    g.add_argument(
        "--frames",
        metavar="F1,F2,...",
        help="the frames of the kinematics and operational_space groups (default: every leaf link "
        "and every frame the robot file names or the URDF keeps; docs/generated-code.md)",
    )
    g.add_argument(
        "--task-axes",
        metavar="AXES",
        help="the rows of operational_space, any of x,y,z,rx,ry,rz (default: all six)",
    )
    g.add_argument("--force", action="store_true", help="overwrite files symdyn did not generate")
    g.add_argument(
        "--prune",
        type=float,
        metavar="REL",
        help="generate from the model without the terms below REL of their entry's largest value "
        "(the bound goes into the headers)",
    )
    g.set_defaults(func=cmd_generate)


#: Every subcommand, in the order `symdyn --help` lists them: name -> (help, adds its arguments).
COMMANDS: dict[str, tuple[str, Callable[[argparse.ArgumentParser], None]]] = {
    "derive": ("print M, C, V, G, F of a robot", _derive_arguments),
    "generate": ("generate code (C, CasADi, NumPy, JAX, LaTeX, MATLAB)", _generate_arguments),
    **APPLICATIONS,  # simulate, analyze, check, cache (the lecture's applications)
    **IDENTIFICATION,  # identify, excite
    **DRAWING,  # draw
}


def _named_command(argv: Sequence[str]) -> str | None:
    """The subcommand the command line names (its first word that is not an option), if it is one."""
    word = next((w for w in argv if not w.startswith("-")), None)
    return word if word in COMMANDS else None


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of `symdyn`; given a subcommand's name, the parser of that subcommand alone.

    Building every subcommand's options costs start-up time a run does not need, so `main`
    builds only the one named; the list of commands (usage, errors) is the same either way.
    """
    parser = argparse.ArgumentParser(
        prog="symdyn",
        description="Symbolic equations of motion of robot manipulators, and code generated from them.",
    )
    parser.add_argument("--version", action="version", version=f"symdyn {__version__}")
    # with one subcommand built, the metavar keeps the usage naming them all (as argparse spells it)
    metavar = None if command is None else "{" + ",".join(COMMANDS) + "}"
    sub = parser.add_subparsers(dest="command", required=True, metavar=metavar)
    for name, (help_text, add_arguments) in COMMANDS.items():
        if command is None or name == command:
            add_arguments(sub.add_parser(name, help=help_text))
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    prefix = "symdyn: warning: " if issubclass(category, SymdynWarning) else "warning: "
    print(f"{prefix}{one_line(message)}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `symdyn` command; returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(_named_command(argv)).parse_args(argv)
    progress_restart()
    progress_quiet(bool(getattr(args, "quiet", False)))
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = _show_warning
        try:
            status = args.func(args)
            progress_finish()
            return status
        except SymdynError as exc:
            print(f"symdyn: error: {one_line(exc)}", file=sys.stderr)
            return EXIT_BAD_INPUT
        except OSError as exc:
            print(
                f"symdyn: error: {one_line(exc.filename or '')}: {one_line(exc.strerror or exc)}",
                file=sys.stderr,
            )
            return EXIT_BAD_INPUT
        except KeyboardInterrupt:
            print("symdyn: interrupted", file=sys.stderr)
            return 130
        except Exception as exc:  # a bug in symdyn: say so in one line, not a traceback
            print(
                f"symdyn: internal error: {type(exc).__name__}: {one_line(exc)} (please report it with the "
                "robot file)",
                file=sys.stderr,
            )
            return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
