"""The `symdyn` subcommands simulate, analyze, check and cache (their parsers in `COMMANDS`).

    symdyn simulate ROBOT [--q0 Q ...] [--qd0 QD ...] [--tau TAU ...]
           [--track QREF ... [--kp KP ...] [--kd KD ...] [--model-params NAME=VALUE ...]]
           --duration T --dt H [--integrator rk4|euler|lecture|semi-implicit|rk45|dop853]
           [--rtol R --atol A]
           [--params NAME=VALUE ...] --out traj.csv [--plot traj.png] [--progress]
           [--animate run.html|run.gif [--frames N] [--view iso|front|side|top]]
    symdyn analyze ROBOT --q Q ... [--qd QD ...] --torque-limits L ... [--frame F] [--axes x,y]
           [--params NAME=VALUE ...] [--format text|json] [--plot fig.png]
    symdyn check ROBOT ANSWERS.yaml [--method newton-euler|lagrange] [--samples N] [--verbose]

Vectors are given as separate words or comma-separated ("--q0 0.1 0.2" or
"--q0 0.1,0.2"; write "--q0=-pi/4,0" when the first value starts with a minus
sign and is not a plain number). Every value may be an expression (pi/4); torques
and references may use the time t ("0.5*sin(2*t)"). Expressions go through the
safe parser, never eval. Bad input raises SymdynError, which `symdyn.cli.main`
prints as one line with exit status 1; `check` exits 1 when an answer differs.
"""

from __future__ import annotations

import argparse
import re
import sys

import numpy as np

from ..errors import SymdynError
from .cache import CACHE_HELP, cache_arguments, cached_plant
from .common import METHODS, add_robot_argument, load_robot_argument, whole_number

#: A plain decimal number, read with float() instead of the expression parser (no SymPy needed).
_PLAIN = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")

__all__ = [
    "COMMANDS",
    "cmd_simulate",
    "cmd_analyze",
    "cmd_check",
    "whole_number",
    "vector_option",
    "assignments_option",
    "with_params",
]


# --------------------------------------------------------------------------- argument helpers


def _words(items, what: str) -> list[str]:
    """The comma- or space-separated values of a vector option, as strings."""
    out: list[str] = []
    for item in items or []:
        out += [w.strip() for w in str(item).split(",")]
    if any(not w for w in out):
        raise SymdynError(f"{what}: empty value in '{','.join(map(str, items))}'")
    return out


def _numbers(items, what: str) -> list[float]:
    """Numbers or constant expressions ("pi/4") of a vector option."""
    values = []
    words = _words(items, what)
    if all(_PLAIN.fullmatch(w) for w in words):
        return [float(w) for w in words]
    from ..model.expressions import parse_expression

    for k, w in enumerate(words, 1):
        e = parse_expression(w, field=f"{what}[{k}]" if len(words) > 1 else what)
        if e.free_symbols:
            names = ", ".join(sorted(str(s) for s in e.free_symbols))
            raise SymdynError(f"{what}: '{w}' is not a number (unknown name {names})")
        v = float(e)
        if not np.isfinite(v):
            raise SymdynError(f"{what}: '{w}' is not finite")
        values.append(v)
    return values


def _vector(items, n: int, what: str, default=None) -> np.ndarray:
    if items is None:
        if default is None:
            raise SymdynError(f"{what} is required ({n} values, one per joint)")
        return np.asarray(default, dtype=float)
    values = _numbers(items, what)
    if len(values) != n:
        raise SymdynError(f"{what}: expected {n} values (one per joint), got {len(values)}")
    return np.array(values)


def _assignments(items, what: str) -> dict[str, float]:
    """NAME=VALUE pairs (space- or comma-separated) of --params / --model-params."""
    out: dict[str, float] = {}
    for w in _words(items, what):
        name, sep, value = w.partition("=")
        name = name.strip()
        if not sep or not name or not value.strip():
            raise SymdynError(f"{what}: expected NAME=VALUE, got '{w}'")
        if name in out:
            raise SymdynError(f"{what}: {name} given twice")
        out[name] = _numbers([value], f"{what} {name}")[0]
    return out


def _gains(items, n: int, what: str, default: float) -> np.ndarray:
    if items is None:
        return np.full(n, default)
    values = _numbers(items, what)
    if len(values) == 1:
        values = values * n
    if len(values) != n:
        raise SymdynError(f"{what}: expected 1 or {n} values, got {len(values)}")
    return np.array(values)


def _with_params(robot, params: dict[str, float], option: str = "--params"):
    """The robot with parameter values applied; every free parameter must then have one."""
    from ..apps.compilation.compiled import with_parameters

    robot = with_parameters(robot, params)
    if robot.params:
        names = ", ".join(str(p) for p in robot.params)
        raise SymdynError(
            f"robot '{robot.name}' has free parameters ({names}); give their values with "
            f"{option} NAME=VALUE (e.g. {option} {str(robot.params[0])}=1)"
        )
    return robot


def _check_plot_path(path: str | None) -> None:
    if path is None:
        return
    from ..apps.output import check_output, plot_format

    check_output(path, "--plot")
    plot_format(path)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise SymdynError("--plot needs matplotlib (pip install 'symdyn[plot]')") from None


# --------------------------------------------------------------------------- simulate


def _plant(args: argparse.Namespace, params: dict, model_params: dict | None = None):
    """The compiled robot (cached by file content and options), with the parameter values applied."""

    def make_robot():
        robot = _with_params(load_robot_argument(args), params)
        return robot if model_params is None else _with_params(robot, model_params, "--model-params")

    return cached_plant(args, make_robot, params=params, model_params=model_params)


def _torques(items, n: int):
    """--tau: plain numbers as floats (no parsing), else numbers or expressions of t."""
    from ..apps.simulation.simulate import time_expressions

    words = _words(items, "--tau")
    if all(_PLAIN.fullmatch(w) for w in words) and len(words) in (1, n):
        return [float(w) for w in words]
    return time_expressions(words, n, "--tau")


def cmd_simulate(args: argparse.Namespace) -> int:
    from ..apps.output import check_output, write_atomic
    from ..apps.simulation.floating_stepping import floating_sizes, initial_configuration
    from ..apps.simulation.simulate import simulate
    from ..apps.simulation.trajectory import plot_trajectory
    from .animation import check_animation, write_animation
    from .contact_options import check_contact_options

    check_output(args.out, "--out")
    _check_plot_path(args.plot)
    check_animation(args)
    params = _assignments(args.params, "--params")
    check_contact_options(args)
    if args.contacts is not None:
        return _simulate_contacts(args, params)
    if args.track is not None and args.tau is not None:
        raise SymdynError("--tau and --track exclude each other (--track computes the torque)")
    if args.track is None:
        for opt in ("kp", "kd", "model_params"):
            if getattr(args, opt) is not None:
                raise SymdynError(f"--{opt.replace('_', '-')} applies with --track only")
    plant = _plant(args, params)
    n = plant.n
    tolerances = {"rtol": args.rtol, "atol": args.atol}
    sizes = floating_sizes(plant)
    if sizes is not None and (args.track is not None or args.plot):
        flag = "--track" if args.track is not None else "--plot"
        raise SymdynError(f"{flag} does not apply to a floating robot (docs/centroidal.md)")
    if sizes is not None:
        nq, nv = sizes
        traj = simulate(
            plant,
            _vector(args.q0, nq, "--q0", default=initial_configuration(nq)),
            _vector(args.qd0, nv, "--qd0", default=np.zeros(nv)),
            duration=args.duration,
            dt=args.dt,
            tau=None if args.tau is None else _torques(args.tau, nv),
            integrator=args.integrator,
            **tolerances,
        )
    elif args.track is not None:
        from ..apps.simulation.control import ComputedTorque, Reference, SampledReference, track

        words = _words(args.track, "--track")
        if len(words) == 1 and words[0].lower().endswith(".csv"):
            reference = SampledReference.from_csv(words[0], n)
            start, end = reference.span
            if start > 0.0 or end < args.duration:
                raise SymdynError(
                    f"{words[0]}: the reference covers t in [{start:g}, {end:g}] s, "
                    f"the simulation [0, {args.duration:g}] s"
                )
        else:
            reference = Reference(words, n)
        r0, rd0, _ = reference(0.0)
        q0 = _vector(args.q0, n, "--q0", default=r0)
        qd0 = _vector(args.qd0, n, "--qd0", default=rd0)
        model = plant
        if args.model_params is not None:
            model = _plant(args, params, _assignments(args.model_params, "--model-params"))
        kp = _gains(args.kp, n, "--kp", 100.0)
        kd = _gains(args.kd, n, "--kd", 20.0)
        controller = ComputedTorque(model, kp, kd)
        traj = track(
            plant,
            reference,
            controller,
            q0,
            qd0,
            duration=args.duration,
            dt=args.dt,
            integrator=args.integrator,
            progress=True if args.progress else None,
            **tolerances,
        )
    elif "actuated_forward_dynamics" in plant.functions:
        return _simulate_loops(args, plant)
    else:
        q0 = _vector(args.q0, n, "--q0", default=np.zeros(n))
        qd0 = _vector(args.qd0, n, "--qd0", default=np.zeros(n))
        tau = None if args.tau is None else _torques(args.tau, n)
        traj = simulate(
            plant,
            q0,
            qd0,
            duration=args.duration,
            dt=args.dt,
            tau=tau,
            integrator=args.integrator,
            progress=True if args.progress else None,
            **tolerances,
        )
    image = plot_trajectory(traj) if args.plot else None  # rendered before anything is written
    write_atomic(args.out, traj.csv_bytes())  # in C with the compiled plant: the same bytes as csv_text
    if image is not None:
        write_atomic(args.plot, image)
    if args.animate:
        write_animation(args, plant.robot, traj, lambda: _with_params(load_robot_argument(args), params))
    print(
        f"{args.out}: {len(traj.t)} samples, t = 0 .. {traj.t[-1]:g} s, dt = {args.dt:g} s, "
        f"integrator {traj.integrator}"
    )
    if traj.q_ref is not None:
        err = np.abs(traj.q_ref - traj.q)
        print(
            "tracking error |q_ref - q|: final "
            + ", ".join(f"{x:.3g}" for x in err[-1])
            + "; maximum over the last half "
            + ", ".join(f"{x:.3g}" for x in err[len(err) // 2 :].max(axis=0))
        )
    if args.plot:
        print(args.plot)
    return 0


def _simulate_contacts(args: argparse.Namespace, params: dict) -> int:
    """simulate --contacts: the constrained dynamics (symdyn.apps.simulation.contact_simulate), the
    contact forces in the CSV, --plot drawing them, --animate their arrows."""
    from ..apps.compilation.compile import compile as compile_robot
    from ..apps.compilation.compiled import compiled_dynamics
    from ..apps.output import write_atomic
    from ..apps.simulation.contact_simulate import plot_contact_forces, simulate_contacts
    from ..apps.simulation.floating_stepping import floating_sizes, initial_configuration
    from ..apps.simulation.stance import stance_schedule
    from ..apps.simulation.stepping import sample_times
    from .animation import write_animation
    from .contact_options import pd_torque

    robot = _with_params(load_robot_argument(args), params)
    if args.stance is not None:  # checked against the contacts before the compile
        stance_schedule(robot, sample_times(args.duration, args.dt)[0], args.duration, args.stance)
    if any(args.baumgarte or ()):  # the stabilised dynamics are generated only when named
        groups = ("dynamics", "configuration") if robot.floating else ("dynamics",)
        plant = compile_robot(robot, functions=(*groups, "contacts", "contact_baumgarte"))
    else:
        plant = compiled_dynamics(robot)  # cached by the robot's content (loaded anyway: its contacts)
    sizes = floating_sizes(plant)
    nq, nv = sizes if sizes is not None else (plant.n, plant.n)
    q0 = _vector(args.q0, nq, "--q0", default=initial_configuration(nq) if sizes else np.zeros(nq))
    qd0 = _vector(args.qd0, nv, "--qd0", default=np.zeros(nv))
    tau = pd_torque(args, q0, nv) or (None if args.tau is None else _torques(args.tau, nv))
    traj = simulate_contacts(
        plant,
        robot,
        q0,
        qd0,
        duration=args.duration,
        dt=args.dt,
        tau=tau,
        integrator=args.integrator,
        impulse_at=args.impulse_at,
        restitution=args.restitution or 0.0,
        baumgarte=tuple(args.baumgarte or (0.0, 0.0)),
        stance=args.stance,
    )
    image = plot_contact_forces(traj) if args.plot else None
    write_atomic(args.out, traj.csv_bytes())
    if image is not None:
        write_atomic(args.plot, image)
    if args.animate:
        write_animation(args, robot, traj, lambda: robot)
    total = traj.contact_forces[-1].sum(axis=0)
    print(
        f"{args.out}: {len(traj.t)} samples, t = 0 .. {traj.t[-1]:g} s, dt = {args.dt:g} s, "
        f"integrator {traj.integrator}, contacts {', '.join(c.name for c in robot.contacts)}"
    )
    print(
        f"contact forces at t = {traj.t[-1]:g} s: sum {' '.join(f'{x:.6g}' for x in total)} N (world axes)"
        + ("; touchdown at t = " if traj.touchdowns else "")
        + ", ".join(f"{time:g}" for time, _, _ in traj.touchdowns)
        + (" s" if traj.touchdowns else "")
    )
    if args.plot:
        print(args.plot)
    return 0


def _simulate_loops(args: argparse.Namespace, plant) -> int:
    """simulate for a robot with closed loops (symdyn.apps.simulation.loop_simulate): --q0 every joint (a
    closed configuration or a guess near one), --qd0 every joint (its actuated entries used),
    --tau the actuated joints' efforts."""
    from ..apps.output import write_atomic
    from ..apps.simulation.loop_simulate import simulate_loops
    from ..apps.simulation.trajectory import plot_trajectory

    n, nact = plant.n, len(plant.module.ACTUATED)
    q0 = _vector(args.q0, n, "--q0", default=np.zeros(n))
    qd0 = _vector(args.qd0, n, "--qd0", default=np.zeros(n))
    tau = None if args.tau is None else _torques(args.tau, nact)
    traj, residual = simulate_loops(
        plant, q0, qd0, duration=args.duration, dt=args.dt, tau=tau, integrator=args.integrator
    )
    image = plot_trajectory(traj) if args.plot else None
    write_atomic(args.out, traj.csv_bytes())
    if image is not None:
        write_atomic(args.plot, image)
    if args.animate:
        from .animation import write_animation

        params = _assignments(args.params, "--params")
        write_animation(args, plant.robot, traj, lambda: _with_params(load_robot_argument(args), params))
    print(
        f"{args.out}: {len(traj.t)} samples, t = 0 .. {traj.t[-1]:g} s, dt = {args.dt:g} s, "
        f"integrator {traj.integrator}, {nact} actuated joints"
    )
    print(f"largest closure residual max |phi|: {residual:.3g}")
    if args.plot:
        print(args.plot)
    return 0


# --------------------------------------------------------------------------- analyze


def cmd_analyze(args: argparse.Namespace) -> int:
    from ..apps.analysis import analyze, parse_axes, plot_analysis

    _check_plot_path(args.plot)
    axes = parse_axes(args.axes)
    if args.plot and axes is not None and len(axes) != 2:
        raise SymdynError(f"--plot draws a 2-D task space: give two --axes (got {args.axes})")
    params = _assignments(args.params, "--params")
    plant = _plant(args, params)
    n = plant.n
    q = _vector(args.q, n, "--q")
    qd = _vector(args.qd, n, "--qd", default=np.zeros(n))
    limits = _numbers(args.torque_limits, "--torque-limits")
    with np.errstate(all="ignore"):  # an overflow is reported below, in one line
        result = analyze(plant, q, qd, torque_limits=limits, axes=axes, frame=args.frame)
    computed = (result.V, result.G, result.F, result.v_vel, result.v_grav, result.manipulability.matrix)
    if not all(np.isfinite(x).all() for x in (*computed, result.polytope.vertices)):
        raise SymdynError(
            "analyze: the velocity terms, the ellipsoid or the polytope are not finite at this state: "
            "--qd or --torque-limits so large that their products overflow double precision"
        )
    image = None
    if args.plot:
        if len(result.axes) != 2:
            raise SymdynError(
                "--plot draws a 2-D task space: give two --axes "
                f"(the default here is {','.join(result.axes)})"
            )
        from ..apps.compilation.compile import RobotInfo

        robot = plant.robot
        if isinstance(robot, RobotInfo):  # the plant came from the cache: the picture needs the Robot
            robot = _with_params(load_robot_argument(args), params)
        image = plot_analysis(result, robot=robot)
    sys.stdout.write(result.to_json() if args.format == "json" else result.to_text())
    if image is not None:
        from ..apps.output import write_atomic

        write_atomic(args.plot, image)
    return 0


# --------------------------------------------------------------------------- check


def cmd_check(args: argparse.Namespace) -> int:
    from ..apps.checking.check import MAX_SAMPLES, check_answers

    if not 1 <= args.samples <= MAX_SAMPLES:
        raise SymdynError(f"--samples {args.samples}: must be from 1 to {MAX_SAMPLES:,}")
    robot = load_robot_argument(args)
    report = check_answers(robot, args.answers, method=args.method, samples=args.samples)
    sys.stdout.write(report.text(verbose=args.verbose))
    return 0 if report.ok else 1


# --------------------------------------------------------------------------- the parser


def _positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number, got '{text}'") from None
    if not np.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got '{text}'")
    return v


#: The options of a vector: values separated by spaces (or commas, split by _words).
_VECTOR = {"nargs": "+", "metavar": "V"}


def _simulate_arguments(s: argparse.ArgumentParser) -> None:
    from ..apps.simulation.stepping import INTEGRATORS
    from .animation import animation_arguments
    from .contact_options import contact_arguments

    vec = _VECTOR
    s.description = (
        "Integrate qdd = M^-1 (tau - V - G - F) from q0, qd0 and write t, q1..qn, qd1..qdn "
        "as CSV. Vectors: values separated by spaces or commas; expressions allowed (pi/4), "
        "torques and references may use t."
    )
    add_robot_argument(s)
    s.add_argument("--q0", **vec, help="initial joint positions (default 0, or q_ref(0) with --track)")
    s.add_argument("--qd0", **vec, help="initial joint velocities (default 0, or qd_ref(0) with --track)")
    s.add_argument(
        "--tau",
        **vec,
        help="joint torques: numbers or expressions of t, one per joint (one value: every joint; default 0)",
    )
    s.add_argument(
        "--track",
        **vec,
        help="computed-torque control tracking q_ref(t): one expression of t per joint "
        "(qd_ref, qdd_ref by symbolic differentiation), or a CSV file with columns t, q1..qn and "
        "optionally qd1..qdn, qdd1..qddn (e.g. from symdyn excite), interpolated between samples",
    )
    s.add_argument("--kp", **vec, help="position gain(s) Kp, one or one per joint (default 100)")
    s.add_argument("--kd", **vec, help="velocity gain(s) Kd, one or one per joint (default 20)")
    s.add_argument(
        "--model-params",
        nargs="+",
        metavar="NAME=VALUE",
        help="the controller model's parameter values where they differ from the plant's",
    )
    s.add_argument("--duration", type=_positive, required=True, help="simulated time T (s)")
    s.add_argument("--dt", type=_positive, required=True, help="time step H (s)")
    s.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        default="rk4",
        help="rk4 (default); euler = lecture: the scheme of slide 19, q += qd dt + qdd dt^2/2, "
        "qd += qdd dt; semi-implicit: qd += qdd dt, then q += qd dt; rk45, dop853: adaptive steps "
        "(scipy) under --rtol/--atol, the state written every dt",
    )
    s.add_argument(
        "--rtol", type=_positive, default=1e-6, help="rk45/dop853: relative tolerance (default 1e-6)"
    )
    s.add_argument(
        "--atol", type=_positive, default=1e-9, help="rk45/dop853: absolute tolerance (default 1e-9)"
    )
    s.add_argument("--params", nargs="+", metavar="NAME=VALUE", help="parameter values (free or overriding)")
    s.add_argument("--out", required=True, help="CSV file to write (atomically)")
    s.add_argument("--plot", help="also draw q, qd (and the reference and tracking error) to this PNG")
    s.add_argument(
        "--progress", action="store_true", help="show a progress bar even when stderr is not a terminal"
    )
    animation_arguments(s)
    contact_arguments(s)
    s.set_defaults(func=cmd_simulate)


def _analyze_arguments(a: argparse.ArgumentParser) -> None:
    vec = _VECTOR
    a.description = (
        "Lecture slides 21-23 at (q, qd): the generalized inertia ellipsoid (eigenvectors and "
        "sqrt of eigenvalues of M M^T), the dynamic manipulability ellipsoid with its bias and "
        "kappa_d = sqrt(det(J (M^T M)^-1 J^T)), and the acceleration polytope."
    )
    add_robot_argument(a)
    a.add_argument("--q", **vec, required=True, help="joint positions")
    a.add_argument("--qd", **vec, help="joint velocities (default 0)")
    a.add_argument(
        "--torque-limits", **vec, required=True, help="|tau_i| bounds: one for all, or one per joint"
    )
    a.add_argument(
        "--frame",
        help="the frame whose Jacobian and Jdot qd are used: a link or a frame of the robot "
        "(default: the last link)",
    )
    a.add_argument(
        "--axes",
        help="task axes of the frame's world-aligned Jacobian, comma-separated among "
        "x,y,z,rx,ry,rz (default: the linear axes that move, e.g. x,y for a planar arm)",
    )
    a.add_argument("--params", nargs="+", metavar="NAME=VALUE", help="parameter values (free or overriding)")
    a.add_argument("--format", choices=("text", "json"), default="text")
    a.add_argument("--plot", help="draw the ellipses and the polytope (two axes) to this PNG")
    a.set_defaults(func=cmd_analyze)


def _check_arguments(c: argparse.ArgumentParser) -> None:
    c.description = (
        "Compare an answers file (YAML: any of M, C, V, G, F, tau as expressions in the "
        "robot's symbols and q1.., qd1.., qdd1..) with symdyn's derivation, symbolically and, when "
        "inconclusive, numerically. Exit status 0 when every entry matches, 1 otherwise."
    )
    add_robot_argument(c)
    c.add_argument("answers", help="answers file (YAML)")
    c.add_argument("--method", choices=METHODS, default="newton-euler")
    c.add_argument(
        "--samples", type=whole_number, default=16, help="random points for the numeric comparison"
    )
    c.add_argument("--verbose", action="store_true", help="also list the entries that match")
    c.set_defaults(func=cmd_check)


#: The option readers `symdyn draw` shares (symdyn.cli.draw).
vector_option, assignments_option, with_params = _vector, _assignments, _with_params

#: The subcommands of this module (symdyn.cli.main.COMMANDS): name -> (help, adds its arguments).
COMMANDS = {
    "simulate": (
        "simulate the robot (optionally under computed-torque control); write a CSV",
        _simulate_arguments,
    ),
    "analyze": (
        "inertia ellipsoid, dynamic manipulability and acceleration polytope at a state",
        _analyze_arguments,
    ),
    "check": ("check answers (M, C, V, G, F, tau as expressions) against the derivation", _check_arguments),
    "cache": (CACHE_HELP, cache_arguments),
}
