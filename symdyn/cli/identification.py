"""The `symdyn` subcommands identify and excite (their parsers in `COMMANDS`).

    symdyn identify ROBOT DATA.csv [--params NAME=VALUE ...] [--format text|json] [--plot fig.png]
    symdyn excite ROBOT --out excite.csv [--q0 ...] [--q-range ...] [--qd-max ...] [--qdd-max ...]
           [--period T] [--harmonics L] [--samples S] [--evaluations E] [--dt H] [--seed K]
           [--params NAME=VALUE ...]

identify estimates the base parameters (symdyn.apps.identification.identify) from a CSV of t, q,
[qd, qdd,] tau; excite writes an exciting trajectory (symdyn.apps.identification.excite) as a CSV
identify reads and prints the --track expressions `symdyn simulate` follows. Warnings go to stderr
as `symdyn: warning: ...`.
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from ..errors import SymdynError
from .apps import whole_number
from .common import add_robot_argument, load_robot_argument

__all__ = ["COMMANDS", "cmd_identify", "cmd_excite"]


def _values(items, what: str) -> list[float]:
    """Numbers or constant expressions, space- or comma-separated."""
    from ..model.expressions import parse_expression  # SymPy: only when these options are given

    words = [w.strip() for item in items for w in str(item).split(",")]
    out = []
    for w in words:
        e = parse_expression(w, field=what) if w else None
        if e is None or e.free_symbols or not np.isfinite(float(e)):
            raise SymdynError(f"{what}: '{w}' is not a finite number")
        out.append(float(e))
    return out


def _robot(args: argparse.Namespace):
    """The robot with --params applied; every free parameter must have a value."""
    from ..apps.compilation.compiled import with_parameters

    params = {}
    for w in [w.strip() for item in args.params or [] for w in str(item).split(",")]:
        name, sep, value = w.partition("=")
        if not sep or not name.strip():
            raise SymdynError(f"--params: expected NAME=VALUE, got '{w}'")
        params[name.strip()] = _values([value], f"--params {name.strip()}")[0]
    robot = with_parameters(load_robot_argument(args), params)
    if robot.params:
        names = ", ".join(map(str, robot.params))
        raise SymdynError(
            f"robot '{robot.name}' has free parameters ({names}); give them with --params NAME=VALUE"
        )
    return robot


def _per_joint(items, n: int, what: str):
    if items is None:
        return None
    values = _values(items, what)
    if len(values) not in (1, n):
        raise SymdynError(f"{what}: expected 1 or {n} values, got {len(values)}")
    return np.array(values)


def cmd_identify(args: argparse.Namespace) -> int:
    from ..apps.identification.identify import identify, plot_identification
    from ..apps.identification.measurements import read_measurements
    from ..apps.output import check_output
    from ..dynamics import derive

    check_output(args.plot, "--plot")
    robot = _robot(args)
    data = read_measurements(args.data, robot.n, floating=robot.floating)
    result = identify(robot, data, derive(robot, simplify=False).base_parameters, predict=bool(args.plot))
    image = plot_identification(result, data) if args.plot else None
    print(json.dumps(result.as_dict(), indent=2) if args.format == "json" else result.text(), end="")
    if args.format == "json":
        print()
    for line in result.warnings():
        print(f"symdyn: warning: {line}", file=sys.stderr)
    if data.differentiated:
        what = "qdd estimated from qd" if robot.floating else "qd and qdd estimated from q"
        print(f"symdyn: note: {what} (Savitzky-Golay filter)", file=sys.stderr)
    if image is not None:
        from ..apps.output import write_atomic

        write_atomic(args.plot, image)
    return 0


def cmd_excite(args: argparse.Namespace) -> int:
    from ..apps.identification.excite import excite
    from ..apps.output import check_output

    check_output(args.out, "--out")
    robot = _robot(args)
    n = robot.n
    _check_excite_options(args)
    traj = excite(
        robot,
        q0=_per_joint(args.q0, n, "--q0"),
        q_range=_per_joint(args.q_range, n, "--q-range"),
        qd_max=_per_joint(args.qd_max, n, "--qd-max"),
        qdd_max=_per_joint(args.qdd_max, n, "--qdd-max"),
        period=args.period,
        harmonics=args.harmonics,
        samples=args.samples,
        evaluations=args.evaluations,
        seed=args.seed,
    )
    traj.write_csv(robot, args.out, args.dt)
    print(f"{args.out}: one period T = {traj.period:g} s every {args.dt:g} s, {args.harmonics} harmonics")
    print(f"condition number of the base regressor over {args.samples} samples: {traj.condition_number:.4g}")
    print(
        f"follow it with: symdyn simulate ROBOT --track {args.out} --duration T --dt H (T <= {traj.period:g})"
    )
    print("or, exactly: symdyn simulate ROBOT --track " + ",".join(traj.expressions()))
    return 0


def _check_excite_options(args: argparse.Namespace) -> None:
    """The options of `excite` in range, before the optimisation runs (excite checks them again)."""
    from ..apps.identification.excite import MAX_HARMONICS, MAX_SAMPLES, PERIOD_RANGE, csv_samples

    for option, value, low, high in (
        ("--harmonics", args.harmonics, 1, MAX_HARMONICS),
        ("--samples", args.samples, 2, MAX_SAMPLES),
        ("--evaluations", args.evaluations, 1, None),
        ("--seed", args.seed, 0, None),
    ):
        if value < low or (high is not None and value > high):
            bound = f"from {low} to {high:,}" if high is not None else f"at least {low}"
            raise SymdynError(f"{option} {value}: must be {bound}")
    low, high = PERIOD_RANGE
    if not low <= args.period <= high:
        raise SymdynError(f"--period {args.period:g}: must be from {low:g} to {high:g} s")
    if not (np.isfinite(args.dt) and 0 < args.dt <= args.period):
        raise SymdynError(f"--dt {args.dt:g}: must be positive and at most the period ({args.period:g} s)")
    csv_samples(args.period, args.dt)


def _identify_arguments(i: argparse.ArgumentParser) -> None:
    add_robot_argument(i)
    i.add_argument(
        "data",
        help="CSV with columns t, q1..qn, [qd1..qdn, qdd1..qddn,] tau1..taun (a floating robot: its free "
        "flyer's columns too, as symdyn simulate writes them), or a .npz/.npy of the same values",
    )
    i.add_argument("--params", nargs="+", help="values of free parameters (NAME=VALUE)")
    i.add_argument("--format", choices=("text", "json"), default="text")
    i.add_argument("--plot", help="draw measured and predicted torques to this PNG (or .pdf, .svg)")
    i.set_defaults(func=cmd_identify)


def _excite_arguments(e: argparse.ArgumentParser) -> None:
    add_robot_argument(e)
    vec = {"nargs": "+", "default": None}
    e.add_argument("--out", required=True, help="CSV file to write: t, q, qd, qdd and the file's tau")
    e.add_argument("--q0", **vec, help="centre of each joint's motion (default 0)")
    e.add_argument("--q-range", **vec, help="largest |q - q0| per joint (default 1 rad, 0.1 m)")
    e.add_argument("--qd-max", **vec, help="largest |qd| per joint (default 1.5 rad/s, 0.3 m/s)")
    e.add_argument("--qdd-max", **vec, help="largest |qdd| per joint (default 3 rad/s^2, 1 m/s^2)")
    e.add_argument("--period", type=float, default=10.0, help="period T in s (default 10)")
    e.add_argument("--harmonics", type=whole_number, default=5, help="harmonics per joint (default 5)")
    e.add_argument(
        "--samples", type=whole_number, default=100, help="samples per period for the condition number"
    )
    e.add_argument(
        "--evaluations", type=whole_number, default=1000, help="optimiser evaluations (default 1000)"
    )
    e.add_argument("--dt", type=float, default=0.01, help="CSV sample spacing in s (default 0.01)")
    e.add_argument("--seed", type=whole_number, default=0, help="random starts (default 0)")
    e.add_argument("--params", nargs="+", help="values of free parameters (NAME=VALUE)")
    e.set_defaults(func=cmd_excite)


#: The subcommands of this module (symdyn.cli.main.COMMANDS): name -> (help, adds its arguments).
COMMANDS = {
    "identify": ("estimate the base parameters from measured torques (CSV)", _identify_arguments),
    "excite": ("an exciting trajectory (Fourier series) for identification", _excite_arguments),
}
