"""Contact dynamics speed (issue 36, item 5): Pinocchio's C++ and symdyn's compiled functions.

    python bench/contacts.py [--quick] [--no-talos]

For Solo-12 on its four feet (point contacts) and Talos on both soles (6d contacts), loaded from
example-robot-data with `floating=True`: bench/pinocchio_contacts.cpp (compiled header-only by
bench/pin_harness.py, the model of bench/pinocchio_model.hpp under a free flyer, the contacts as
RigidConstraintModel at the frames' joints and placements) checks constraintDynamics,
impulseDynamics and the derivatives in q of both against symdyn's numeric oracle
(symdyn.oracle.contacts, .contact_derivatives; joint friction left out, as Pinocchio has none) at
NCHECK states, then times them on NSTATES random states (each call on the next state; the
derivatives after the dynamics they differentiate, as a user calls them; the thread's CPU time).

symdyn's column: the robot with `Robot.contacts` (symdyn.model.contacts.Contact) compiled by
`symdyn.compile(robot, functions=("contacts", "contact_derivatives"))` (its time is reported: with
SYMDYN_CACHE_DIR an empty folder, the derivation, generation and C compilation), its methods
contact_forward_dynamics, impulse_dynamics, contact_forward_dynamics_derivatives and
impulse_dynamics_derivatives (the restitution e = 0) called
on the same NSTATES states as one batch (one thread; the thread's CPU time of the call over
NSTATES: the generated C plus the batch call's share of Python's overhead), checked against the
oracle first. The table's calls write into the output arrays of that first call (`out=`, as
docs/python-api.md advises for repeated calls and as Pinocchio's harness reuses its Data); the
same calls allocating their outputs each time are timed too and printed below the table (a fresh
array costs the kernel's mapping and zeroing of its pages: Talos' derivatives write 30 to 46 kB a
state). Where symdyn has no such functions yet, or they fail, the column says "n/a" and the
next line says why. Pinocchio's harness and symdyn's batches run in alternating rounds; the
figures are medians. The targets (issue 36): forward and impulse dynamics <= 0.25 x Pinocchio,
the derivatives <= 0.35 x. The table goes to stdout and bench/results/contacts.txt.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pin_harness  # noqa: E402
from c_harness import parse_harness  # noqa: E402
from machine import RESULTS, load_averages, log, machine, pin_to_one_core, run  # noqa: E402
from states import CHECK_TOL, NCHECK, NSTATES, SEED, rel_err  # noqa: E402

import symdyn  # noqa: E402
from symdyn.model.friction import Friction  # noqa: E402
from symdyn.oracle.contacts import (  # noqa: E402
    contact_forward_dynamics,
    contact_forward_dynamics_derivatives,
    impulse_dynamics,
    impulse_dynamics_derivatives,
)
from symdyn.oracle.inputs import numeric_model  # noqa: E402
from symdyn.regenerate import example_robot_data_folder  # noqa: E402

#: name: (file, contacts as (frame, kind))
ROBOTS = {
    "solo12": (
        "solo_description/robots/solo12.urdf",
        tuple((f, "point") for f in ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")),
    ),
    "talos": ("talos_data/robots/talos_reduced.urdf", (("left_sole_link", "6d"), ("right_sole_link", "6d"))),
}
#: table row: (symdyn method, Pinocchio label, target ratio)
ROWS = {
    "forward dynamics": ("contact_forward_dynamics", "constraintDynamics", 0.25),
    "impulse dynamics": ("impulse_dynamics", "impulseDynamics", 0.25),
    "forward derivatives": ("contact_forward_dynamics_derivatives", "constraintDynamicsDerivatives", 0.35),
    "impulse derivatives": ("impulse_dynamics_derivatives", "impulseDynamicsDerivatives", 0.35),
}


def load(name: str):
    """The robot without joint friction (Pinocchio's model has none)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = symdyn.load_urdf(example_robot_data_folder() / ROBOTS[name][0], floating=True)
    links = tuple(dataclasses.replace(link, friction=Friction()) for link in robot.links)
    return dataclasses.replace(robot, links=links)


def make_states(robot, rng) -> dict[str, np.ndarray]:
    """NSTATES states: base position and joints in [-1, 1], unit quaternions, v in [-1, 1],
    tau in [-5, 5]."""
    q = rng.uniform(-1, 1, (NSTATES, robot.nq))
    quat = rng.normal(size=(NSTATES, 4))
    q[:, 3:7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    return {
        "q": q,
        "v": rng.uniform(-1, 1, (NSTATES, robot.nv)),
        "tau": rng.uniform(-5, 5, (NSTATES, robot.nv)),
    }


def oracle(robot, contacts, st, k: int) -> dict[str, np.ndarray]:
    """The oracle's answers at state k (restitution 0, every contact active)."""
    q, v, tau = st["q"][k], st["v"][k], st["tau"][k]
    out = dict(zip(("qdd", "lambda"), contact_forward_dynamics(robot, contacts, q, v, tau), strict=True))
    out |= dict(zip(("qd_plus", "impulse"), impulse_dynamics(robot, contacts, q, v), strict=True))
    out |= contact_forward_dynamics_derivatives(robot, contacts, q, v, tau)
    return out | impulse_dynamics_derivatives(robot, contacts, q, v)


def pinocchio_text(robot, contacts, st, refs: list[dict]) -> str:
    """MODEL.txt of bench/pinocchio_contacts.cpp (its header says the format)."""
    lines = pin_harness.floating_model_lines(robot)
    mdl = numeric_model(robot)
    lines.append(f"ncontact {len(contacts)}")
    for frame, kind in contacts:
        f = mdl.frame_names.index(frame)
        placement = np.r_[mdl.frame_R[f].ravel(), mdl.frame_p[f]]
        kind_rows = 3 if kind == "point" else 6
        lines.append(
            f"contact {kind_rows} {mdl.frame_link[f]} " + " ".join(repr(float(x)) for x in placement)
        )
    lines.append(f"nstates {NSTATES}")
    lines += [
        " ".join(repr(float(x)) for x in np.r_[st["q"][k], st["v"][k], st["tau"][k]]) for k in range(NSTATES)
    ]
    lines.append(f"ncheck {NCHECK}")
    keys = ("qdd", "lambda", "qd_plus", "impulse", "dqdd_dq", "dlambda_dq", "dqd_plus_dq", "dimpulse_dq")
    for k, ref in enumerate(refs):
        lines.append(f"{k} " + " ".join(repr(float(x)) for key in keys for x in np.ravel(ref[key])))
    return "\n".join(lines) + "\n"


def symdyn_methods(robot, contacts) -> tuple[dict, str]:
    """symdyn.compile's contact methods (name -> callable) and a note; {} and why not when absent."""
    try:
        from symdyn.model.contacts import Contact
    except ImportError:
        return {}, "symdyn has no contacts in its model yet (symdyn.model.contacts)"
    try:
        with_contacts = dataclasses.replace(
            robot, contacts=tuple(Contact(f, f, kind) for f, kind in contacts)
        )
        t0 = time.perf_counter()
        compiled = symdyn.compile(with_contacts, functions=("contacts", "contact_derivatives"))
        seconds = time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001 - whatever fails, the column says so and why
        return {}, f"symdyn.compile with contacts failed: {type(exc).__name__}: {exc}"
    methods = {m: getattr(compiled, m) for m, _, _ in ROWS.values() if hasattr(compiled, m)}
    missing = [m for m, _, _ in ROWS.values() if m not in methods]
    note = f"symdyn.compile (with contacts) {seconds:.1f} s" + (
        f"; missing: {', '.join(missing)}" if missing else ""
    )
    return methods, note


def symdyn_batches(
    methods: dict, robot, contacts, st, refs: list[dict]
) -> tuple[dict, dict, dict, list[str]]:
    """Per method: the batch call writing into the output arrays of the first call (out=, as
    Pinocchio's harness reuses its Data), the same call allocating its outputs (a closure each), the
    worst relative error against the oracle at the first NCHECK states, and notes for the methods
    that fail."""
    active = np.ones((NSTATES, len(contacts)))
    e = np.zeros((NSTATES, 1))  # the restitution, an input of its own (0: the contacts stick)
    args = {
        "contact_forward_dynamics": (st["q"], st["v"], st["tau"], active),
        "contact_forward_dynamics_derivatives": (st["q"], st["v"], st["tau"], active),
        "impulse_dynamics": (st["q"], st["v"], active, e),
        "impulse_dynamics_derivatives": (st["q"], st["v"], active, e),
    }
    outputs = {
        "contact_forward_dynamics": ("qdd", "lambda"),
        "impulse_dynamics": ("qd_plus", "impulse"),
        "contact_forward_dynamics_derivatives": (
            "dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dlambda_dq", "dlambda_dqd", "dlambda_dtau",
        ),
        "impulse_dynamics_derivatives": ("dqd_plus_dq", "dqd_plus_dqd", "dimpulse_dq", "dimpulse_dqd"),
    }  # fmt: skip
    calls, fresh, errors, notes = {}, {}, {}, []
    for name, method in methods.items():
        try:
            got = method(*args[name], threads=1)
            got = got if isinstance(got, tuple) else (got,)
            worst = 0.0
            for key, value in zip(outputs[name], got, strict=True):
                for k, ref in enumerate(refs):
                    want = ref[key]
                    worst = max(worst, rel_err(np.reshape(value[k], want.shape), want))
        except Exception as exc:  # noqa: BLE001
            notes.append(f"symdyn {name}: {type(exc).__name__}: {exc}")
            continue
        calls[name] = lambda method=method, a=args[name], out=got: method(*a, threads=1, out=out)
        fresh[name] = lambda method=method, a=args[name]: method(*a, threads=1)
        errors[name] = worst
    return calls, fresh, errors, notes


def bench_robot(name: str, work: Path, opts, pin_exe: Path | None) -> dict:
    robot = load(name)
    contacts = ROBOTS[name][1]
    st = make_states(robot, np.random.default_rng(SEED))
    log(f"{name}: the oracle at {NCHECK} states ...")
    refs = [oracle(robot, contacts, st, k) for k in range(NCHECK)]
    result = {"robot": name, "nv": robot.nv, "nlambda": sum(3 if k == "point" else 6 for _, k in contacts)}
    pin_cmd = None
    if pin_exe is not None:
        model = work / f"{name}_contacts.txt"
        model.write_text(pinocchio_text(robot, contacts, st, refs))
        checks = parse_harness(run([pin_exe, model, 1, 0.1]).stdout)[0]
        result["pin_checks"] = checks
        bad = {k: v for k, v in checks.items() if not v <= CHECK_TOL * 100}
        if bad:
            raise SystemExit(f"{name}: Pinocchio disagrees with the oracle: {bad}")
        pin_cmd = [pin_exe, model]
    log(f"{name}: symdyn.compile with contacts ...")
    methods, note = symdyn_methods(robot, contacts)
    calls, fresh, errors, notes = symdyn_batches(methods, robot, contacts, st, refs)
    result |= {"symdyn_note": note, "symdyn_errors": errors, "notes": notes}
    pin_samples: dict[str, list[float]] = {}
    ours: dict[str, list[float]] = {m: [] for m in calls}
    allocating: dict[str, list[float]] = {m: [] for m in fresh}
    per_round = max(1, -(-opts.reps // opts.rounds))
    for _ in range(opts.rounds):
        if pin_cmd is not None:
            for label, values in parse_harness(run([*pin_cmd, per_round, opts.target_ms]).stdout)[1].items():
                pin_samples.setdefault(label, []).extend(values)
        for samples, timed in ((ours, calls), (allocating, fresh)):
            for method, call in timed.items():
                for _ in range(per_round):
                    t0 = time.thread_time_ns()
                    call()
                    samples[method].append((time.thread_time_ns() - t0) / NSTATES)
    result["pinocchio_ns"] = {k: statistics.median(v) for k, v in pin_samples.items()}
    result["symdyn_ns"] = {k: statistics.median(v) for k, v in ours.items() if v}
    result["fresh_ns"] = {k: statistics.median(v) for k, v in allocating.items() if v}
    return result


def table(results: list[dict], note: str) -> list[str]:
    lines = [
        f"Contact dynamics, symdyn's compiled C vs Pinocchio C++ ({machine()})",
        f"Pinocchio: {note}; ns per call, medians of the thread's CPU time",
        "",
        f"{'robot':7} {'NV':>3} {'NL':>3} {'function':20} {'Pinocchio ns':>12} {'symdyn ns':>10} "
        f"{'ratio':>6} {'target':>7}",
    ]
    for r in results:
        for title, (method, label, target) in ROWS.items():
            theirs, mine = r["pinocchio_ns"].get(label), r["symdyn_ns"].get(method)
            pin = f"{theirs:12.0f}" if theirs else f"{'-':>12}"
            ours = f"{mine:10.0f}" if mine else f"{'n/a':>10}"
            ratio = f"{mine / theirs:6.2f}" if mine and theirs else f"{'-':>6}"
            verdict = ("PASS" if mine <= target * theirs else "FAIL") if mine and theirs else f"<={target}"
            lines.append(
                f"{r['robot']:7} {r['nv']:>3} {r['nlambda']:>3} {title:20} {pin} {ours} {ratio} {verdict:>7}"
            )
    lines.append("")
    for r in results:
        checks = ", ".join(f"{k} {v:.0e}" for k, v in r.get("pin_checks", {}).items())
        lines.append(f"{r['robot']}: Pinocchio against the oracle (relative): {checks or '-'}")
        lines.append(f"{r['robot']}: {r['symdyn_note']}")
        if r["symdyn_errors"]:
            errs = ", ".join(f"{k} {v:.0e}" for k, v in r["symdyn_errors"].items())
            lines.append(f"{r['robot']}: symdyn against the oracle (relative): {errs}")
        if r.get("fresh_ns"):
            fresh = ", ".join(
                f"{title} {r['fresh_ns'][m]:.0f}" for title, (m, _, _) in ROWS.items() if m in r["fresh_ns"]
            )
            lines.append(
                f"{r['robot']}: symdyn ns allocating its output arrays at every call (no out=): {fresh}"
            )
        lines += [f"{r['robot']}: {n}" for n in r["notes"]]
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--no-talos", action="store_true", help="Solo-12 only")
    opts = ap.parse_args(argv)
    opts.reps, opts.rounds, opts.target_ms = (6, 2, 5.0) if opts.quick else (30, 3, 20.0)
    if example_robot_data_folder() is None:
        print("example-robot-data is not installed", file=sys.stderr)
        return 1
    log(pin_to_one_core())
    build = Path(tempfile.gettempdir()) / "symdyn_bench_pinocchio"
    pin_exe, note = pin_harness.prepare(build, "pinocchio_contacts.cpp")
    names = ["solo12"] if opts.no_talos else ["solo12", "talos"]
    with tempfile.TemporaryDirectory() as tmp:
        results = [bench_robot(name, Path(tmp), opts, pin_exe) for name in names]
    lines = table(results, note)
    lines.append(f"load averages at the end: {', '.join(f'{x:.2f}' for x in load_averages())}")
    print("\n".join(lines))
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "contacts.txt").write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
