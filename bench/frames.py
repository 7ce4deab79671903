"""Speed of the generated frame functions against Pinocchio C++ (issue 22, item 6).

    python bench/frames.py            # about 3 minutes once Pinocchio's harness is compiled
    python bench/frames.py --quick    # fewer repetitions

For the Panda (its URDF cut at panda_hand, frame panda_hand) and the UR5 (cut at tool0, frame
tool0) of example-robot-data: `symdyn generate --target c --functions kinematics
operational_space --frames ...` timed in a fresh process (the Panda for two frames, panda_hand
and panda_link8), then symdyn's C (bench/frames_harness.py) and Pinocchio's C++
(bench/pinocchio_frames.cpp) checked against the numeric oracle (symdyn.oracle.frames and
symdyn.rnea's M) at NCHECK states and timed on the same NSTATES states in alternating rounds
(bench/c_harness.time_compiled; medians). Pinocchio's side of each row:

    pose + jacobian            forwardKinematics + updateFramePlacement + computeFrameJacobian
    jacobian_dot_qd            forwardKinematics(q, v, 0) + getFrameClassicalAcceleration
    operational_space_inertia  computeMinverse + computeFrameJacobian + J M^-1 J^T + 6x6 inverse()

all LOCAL_WORLD_ALIGNED. The table goes to stdout and bench/results/frames.txt, every number to
bench/results/frames.json.
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pin_harness  # noqa: E402
import robots  # noqa: E402
from c_harness import parse_harness, time_compiled  # noqa: E402
from frames_harness import build_frame_harness  # noqa: E402
from generation import symdyn_command  # noqa: E402
from machine import RESULTS, load_averages, log, machine, pin_to_one_core, run  # noqa: E402
from row import Row  # noqa: E402
from states import CHECK_TOL, NCHECK, SEED, make_states, rel_err, write_states  # noqa: E402

from symdyn import rnea  # noqa: E402
from symdyn.oracle.frames import frame_state  # noqa: E402

#: name -> (example-robot-data URDF, tip link, the frame timed, the frames generated)
ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", "panda_hand", "panda_hand", "panda_hand,panda_link8"),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "tool0", "tool0", "tool0"),
}
#: table row -> (symdyn harness label, Pinocchio label, target ratio symdyn / Pinocchio)
ROWS = {
    "pose + jacobian": ("pose_jacobian", "pose_jacobian", 0.25),
    "jacobian_dot_qd": ("jacobian_dot_qd", "jacobian_dot_qd", 0.25),
    "operational_space_inertia": ("operational_space_inertia", "operational_space_inertia", 0.5),
}
GENERATION_TARGET = 10.0  # s: the Panda, both groups, two frames


def generate(urdf: Path, tip: str, frames: str, out: Path, runs: int) -> tuple[float, float]:
    """Best (wall s, CPU s) of `symdyn generate` (both frame groups) in a fresh process."""
    cmd = [*symdyn_command(), "generate", urdf, "--tip", tip, "--target", "c", "--functions"]
    cmd += ["kinematics", "operational_space", "--frames", frames, "--out", out, "--force"]
    walls, cpus = [], []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        run(cmd)
        walls.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return min(walls), min(cpus)


def references(robot, frame: str, states, k: int) -> dict[str, np.ndarray]:
    """The oracle's pose, world-aligned J, Jdot*qd and Lambda = (J M^-1 J^T)^-1 at state k."""
    q, qd = states["q"][k], states["qd"][k]
    fs = frame_state(robot, frame, q, qd)
    J = fs.jacobian
    lam = np.linalg.inv(J @ np.linalg.solve(rnea.mass_matrix(robot, q), J.T))
    return {"pose": fs.pose, "jacobian": J, "jacobian_dot_qd": fs.drift, "operational_space_inertia": lam}


def check(what: str, text: str, refs: list[dict]) -> dict[str, float]:
    """Largest relative error per quantity of a harness's `check` lines; stops the run above CHECK_TOL."""
    checks, _ = parse_harness(text)
    worst = {key: max(rel_err(checks[key][k], refs[k][key]) for k in range(NCHECK)) for key in refs[0]}
    bad = {k: v for k, v in worst.items() if not v <= CHECK_TOL}
    if bad:
        raise SystemExit(f"{what} disagrees with the numeric oracle: {bad}")
    return worst


def bench_robot(name: str, work: Path, opts, pin_exe: Path | None) -> dict:
    inside, tip, frame, frames = ROBOTS[name]
    urdf = robots.example_robot_file(inside)
    if urdf is None:
        raise SystemExit("example-robot-data is not installed (pip install 'symdyn[test]')")
    from symdyn.parsers import load

    robot = load(urdf, tip=tip)
    out = work / f"gen_{name}"
    log(f"[{name}] symdyn generate --functions kinematics operational_space --frames {frames} ...")
    gen_s, gen_cpu = generate(urdf, tip, frames, out, opts.gen_runs)
    states = make_states(robot, np.random.default_rng(SEED + robot.n))
    states_file = work / f"states_{name}.bin"
    write_states(states, states_file)
    refs = [references(robot, frame, states, k) for k in range(NCHECK)]
    exe, build_s = build_frame_harness(robot.name, robot.n, frame, out, work)
    checks = {"symdyn C": check(f"{name}: symdyn's C", run([exe, states_file, "check", NCHECK]).stdout, refs)}
    pin_cmd = None
    if pin_exe is not None:
        model = work / f"pinocchio_frames_{name}.txt"
        f = robot.frame(frame)
        R, p = (np.array(m, dtype=float) for m in (f.placement.R, f.placement.p))
        lines = pin_harness.model_and_states_lines(robot, states)
        lines.append(f"frame {f.link} " + " ".join(repr(float(v)) for v in [*R.ravel(), *p.ravel()]))
        model.write_text("\n".join(lines) + "\n")
        text = run([pin_exe, model, "check", NCHECK]).stdout
        checks["Pinocchio"] = check(f"{name}: Pinocchio", text, refs)
        pin_cmd = [pin_exe, model, "time"]
    log(f"[{name}] time symdyn's C" + (" and Pinocchio" if pin_cmd else "") + " ...")
    row = Row(name=name, n=robot.n)
    time_compiled(row, [exe, states_file, "time"], pin_cmd, opts)
    return dict(
        robot=name, n=robot.n, frame=frame, frames_generated=frames, generate_s=gen_s, generate_cpu_s=gen_cpu,
        c_build_s=build_s, c_ns=row.c_ns, pin_ns=row.pin_ns, checks=checks,
    )  # fmt: skip


def table(results: list[dict], opts) -> list[str]:
    head = f"{'robot':<6} {'frame':<11} {'quantity':<26} {'symdyn C ns':>11} {'Pinocchio ns':>12}"
    head += f" {'ratio':>6} target"
    lines = [head]
    for r in results:
        for quantity, (c_label, pin_label, target) in ROWS.items():
            c, pin = r["c_ns"][c_label], r["pin_ns"].get(pin_label, float("nan"))
            ratio = c / pin
            verdict = "PASS" if ratio <= target else ("FAIL" if ratio == ratio else "-")
            lines.append(
                f"{r['robot']:<6} {r['frame']:<11} {quantity:<26} {c:11.1f} {pin:12.1f} {ratio:5.2f}x "
                f"<= {target}x {verdict}"
            )
    lines.append("")
    lines.append("other timings (ns, medians): " + "; ".join(
        f"{r['robot']}: symdyn pose {r['c_ns']['pose']:.1f}, jacobian {r['c_ns']['jacobian']:.1f}, "
        f"operational_space_bias {r['c_ns']['operational_space_bias']:.1f}, Pinocchio computeFrameJacobian "
        f"alone {r['pin_ns'].get('jacobian_only', float('nan')):.1f}"
        for r in results
    ))  # fmt: skip
    for r in results:
        ok = "PASS" if r["robot"] != "panda" or r["generate_s"] <= GENERATION_TARGET else "FAIL"
        target = f" (target <= {GENERATION_TARGET:g} s: {ok})" if r["robot"] == "panda" else ""
        lines.append(
            f"generate {r['robot']} --functions kinematics operational_space "
            f"--frames {r['frames_generated']}: "
            f"{r['generate_s']:.1f} s wall ({r['generate_cpu_s']:.1f} s CPU), fresh process, best of "
            f"{opts.gen_runs}{target}"
        )
    worst = {r["robot"]: max(v for c in r["checks"].values() for v in c.values()) for r in results}
    lines.append(f"checks against symdyn.oracle.frames (largest relative error): {worst}")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--robots", nargs="+", choices=list(ROBOTS), help="only these robots")
    ap.add_argument("--no-pinocchio", action="store_true", help="skip Pinocchio even if installed")
    ap.add_argument("--build-dir", type=Path, default=RESULTS / "build", help="the Pinocchio harness's cache")
    ap.add_argument("--reps", type=int, help="timing repetitions per function (default 400, quick 40)")
    ap.add_argument("--target-ms", type=float, default=0.25, help="length of one repetition in ms")
    opts = ap.parse_args(argv)
    opts.rounds = 2 if opts.quick else 4
    opts.reps = opts.reps or (40 if opts.quick else 400)
    opts.gen_runs = 1 if opts.quick else 2
    load_before = load_averages()
    pinned = pin_to_one_core()
    pin_exe, pin_note = None, "Pinocchio skipped (--no-pinocchio)"
    if not opts.no_pinocchio:
        pin_exe, pin_note = pin_harness.prepare(opts.build_dir, "pinocchio_frames.cpp")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="symdyn_frames_") as tmp:
        results = [bench_robot(name, Path(tmp), opts, pin_exe) for name in opts.robots or ROBOTS]
    lines = table(results, opts)
    lines += [
        f"machine: {machine()}; {pinned}; load average {load_before} -> {load_averages()}",
        f"Pinocchio: {pin_note}; {opts.reps} repetitions of {opts.target_ms:g} ms in {opts.rounds} "
        f"alternating rounds, medians; whole run {time.perf_counter() - t0:.0f} s",
    ]
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if not opts.quick and not opts.robots and opts.reps == 400 and opts.target_ms == 0.25:
        (RESULTS / "frames.txt").write_text(text)
        (RESULTS / "frames.json").write_text(json.dumps(results, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
