"""The numeric oracle against Pinocchio's free flyer on every floating URDF of example-robot-data,
algorithm by algorithm (issue 23, item 4).

    python bench/floating_sweep.py            # 5 states per file
    python bench/floating_sweep.py --states 20
    python bench/floating_sweep.py --generated   # and generated code of Solo-12 and a humanoid

For every legged, humanoid and flying robot of example-robot-data (bench/pin_urdf.py's
floating_files), loaded with `symdyn.load_urdf(path, floating=True)` and built by Pinocchio with a
JointModelFreeFlyer root: at random states (random unit quaternions) the worst relative error
(the largest entry's difference over the largest entry, at least 1) of each of the oracle's
results against Pinocchio's: rnea, crba (and the M of computeRNEADerivatives), nonLinearEffects,
computeGeneralizedGravity, aba (the forward error, bounded by cond(M) eps; where mimic joints
leave no aba, Pinocchio's rnea at the oracle's acceleration; "-" where M is singular),
computeCentroidalMap (A_g), its drift dAg v, centerOfMass, computeTotalMass and
computeRNEADerivatives (dtau/dq in the tangent space by the oracle's five-point difference,
dtau/dv), then the worst of the file. tests/test_oracle_floating.py asserts the same comparisons
(bench/pin_urdf.py) at two states per file. With --generated, the NumPy functions of the
`centroidal` and `derivatives` groups of Solo-12 and a humanoid (GENERATED: minutes to derive,
too slow for the tests, which check Solo-12's centroidal code and derivation against Pinocchio)
against Pinocchio's computeCentroidalMap, its time variation, centerOfMass, computeTotalMass,
computeRNEADerivatives and computeABADerivatives. The tables go to stdout and
bench/results/floating_sweep.txt.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings
import zlib
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pin_urdf  # noqa: E402
from machine import RESULTS, log  # noqa: E402

import symdyn  # noqa: E402
from symdyn.codegen import render  # noqa: E402
from symdyn.generated_modules import load_module  # noqa: E402
from symdyn.regenerate import example_robot_data_folder  # noqa: E402

#: the robots whose generated NumPy functions (--generated) are compared with Pinocchio
GENERATED = ("solo_description/robots/solo12.urdf", "simple_humanoid_description/urdf/simple_humanoid.urdf")


def _cell(x: float) -> str:
    return "-" if np.isnan(x) else f"{x:.0e}"


def sweep(states: int) -> list[str]:
    """The table's lines: one row per file (a refused file says why), then the worst per column."""
    robots = example_robot_data_folder()
    if robots is None:
        raise SystemExit("example-robot-data is not installed")
    header = ["file", "n", "cond(M)", *pin_urdf.ALGORITHMS, "worst"]
    rows, columns = [], []
    for path in pin_urdf.floating_files(robots):
        rel = str(path.relative_to(robots))
        log(rel)
        try:
            robot = _load(path)
        except symdyn.SymdynError as exc:
            rows.append(f"{rel}: refused by symdyn ({str(exc).split(': ', 1)[1]})")
            continue
        theirs = pin_urdf.Projected.of(path, robot)
        rng = np.random.default_rng(zlib.crc32(rel.encode()))
        results = [
            pin_urdf.floating_errors(theirs, robot, *pin_urdf.random_state(robot, rng)) for _ in range(states)
        ]
        worst = pin_urdf.worst([errors for errors, _ in results])
        columns.append(worst)
        cond = f"{max(c for _, c in results):.0e}"
        cells = [rel, str(robot.n), cond, *map(_cell, worst.values()), _cell(np.nanmax(list(worst.values())))]
        rows.append(cells)
    overall = pin_urdf.worst(columns)
    rows.append(["worst", "", "", *map(_cell, overall.values()), _cell(np.nanmax(list(overall.values())))])
    widths = [max(len(r[k]) for r in [header, *rows] if isinstance(r, list)) for k in range(len(header))]

    def line(cells: list[str]) -> str:
        return "  ".join(
            c.ljust(w) if k == 0 else c.rjust(w) for k, (c, w) in enumerate(zip(cells, widths, strict=True))
        )

    return [
        "The numeric oracle against Pinocchio's free flyer on every floating URDF of example-robot-data",
        f"(Pinocchio {pin.__version__}): the worst relative error per algorithm, {states} states",
        "per file; n: joints besides the free flyer; cond(M): the largest at those states; aba: the",
        "forward error (cond(M) times the differences of M and tau at most), '-' where M is singular",
        "",
        line(header),
        *(line(r) if isinstance(r, list) else r for r in rows),
    ]


def _load(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the published files' own oddities
        return symdyn.load_urdf(path, floating=True)


def _pinocchio_generated(theirs: pin_urdf.Projected, q, v, a, tau) -> dict[str, np.ndarray]:
    """Pinocchio's values of the generated functions' outputs on symdyn's coordinates (no mimic
    joints: S is a permutation, S^T its inverse)."""
    m, d, S = theirs.model, theirs.data, theirs.S
    qp, vp, ap = theirs.state(q, v, a)
    pin.computeCentroidalMapTimeVariation(m, d, qp, vp)
    out = {
        "centroidal_momentum_matrix": d.Ag @ S,
        "centroidal_momentum_drift": d.dAg @ vp,
        "com": pin.centerOfMass(m, d, qp),
        "total_mass": np.array([pin.computeTotalMass(m)]),
    }
    dq, dv, _ = pin.computeRNEADerivatives(m, d, qp, vp, ap)
    out["inverse_dynamics_derivatives"] = (theirs.back(dq), theirs.back(dv))
    dq, dv, Minv = pin.computeABADerivatives(m, d, qp, vp, S @ tau)
    out["forward_dynamics_derivatives"] = tuple(S.T @ x @ S for x in (dq, dv, pin_urdf.symmetric(Minv)))
    out["mass_matrix_inverse"] = out["forward_dynamics_derivatives"][2]
    return out


def generated(states: int) -> list[str]:
    """The generated NumPy functions of the centroidal and derivatives groups of GENERATED against
    Pinocchio (computeCentroidalMap, computeCentroidalMapTimeVariation, centerOfMass,
    computeTotalMass, computeRNEADerivatives, computeABADerivatives): the worst relative error of
    each function's outputs over `states` states."""
    robots = example_robot_data_folder()
    lines = []
    for rel in GENERATED:
        robot = _load(robots / rel)
        log(f"{rel}: deriving and generating the centroidal and derivatives groups (minutes) ...")
        start = time.perf_counter()
        files = render(robot, targets=("python",), functions=["centroidal", "derivatives"])
        seconds = time.perf_counter() - start
        with tempfile.TemporaryDirectory() as work:
            ((name, text),) = files.items()
            (Path(work) / name).write_text(text)
            module = load_module(Path(work) / name, f"floating_sweep_{robot.name}")
        theirs = pin_urdf.Projected.of(robots / rel, robot)
        rng = np.random.default_rng(zlib.crc32(rel.encode()))
        worst: dict[str, float] = {}
        for _ in range(states):
            q, v, a = pin_urdf.random_state(robot, rng)
            tau = symdyn.rnea(robot, q, v, a)
            want = _pinocchio_generated(theirs, q, v, a, tau)
            args = {
                "centroidal_momentum_matrix": (q,),
                "centroidal_momentum_drift": (q, v),
                "com": (q,),
                "total_mass": (),
                "inverse_dynamics_derivatives": (q, v, a),
                "forward_dynamics_derivatives": (q, v, tau),
                "mass_matrix_inverse": (q,),
            }
            for fname, expected in want.items():
                got = getattr(module, fname)(*args[fname])
                got, expected = (got, expected) if isinstance(expected, tuple) else ((got,), (expected,))
                err = max(
                    pin_urdf.rel_error(np.reshape(g, np.shape(e)), e)
                    for g, e in zip(got, expected, strict=True)
                )
                worst[fname] = max(worst.get(fname, 0.0), err)
        lines.append(f"{rel} ({robot.n} joints + free flyer; generated in {seconds:.0f} s):")
        lines += [f"  {fname:30s} {err:.0e}" for fname, err in worst.items()]
    return [
        "",
        f"Generated NumPy functions (--functions centroidal derivatives) against Pinocchio, {states} states:",
        *lines,
    ]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--states", type=int, default=5, help="random states per file (default 5)")
    parser.add_argument(
        "--generated",
        action="store_true",
        help="also the generated centroidal and derivatives functions of Solo-12 and a humanoid (minutes)",
    )
    args = parser.parse_args(argv)
    lines = sweep(args.states) + (generated(args.states) if args.generated else [])
    text = "\n".join(lines) + "\n"
    print(text, end="")
    RESULTS.mkdir(exist_ok=True)
    with tempfile.NamedTemporaryFile("w", dir=RESULTS, delete=False, suffix=".tmp") as tmp:
        tmp.write(text)
    os.replace(tmp.name, RESULTS / "floating_sweep.txt")
    return 0


if __name__ == "__main__":
    sys.exit(main())
