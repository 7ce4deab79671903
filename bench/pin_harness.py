"""The Pinocchio side of bench/run.py: find its headers, compile the harness, check and time it.

bench/pinocchio_harness.cpp builds the robot as a pinocchio::Model from the numbers of
`pinocchio_model_text` (each joint's parent, placements, axes, body inertias about the centre
of mass in the body frame, armature = gear_ratio^2 J_m): a chain or a kinematic tree on a fixed
base, in symdyn's depth-first link order. Robots with mimic joints are not modelled (the
harness adds one independent joint per link; `check_pinocchio` leaves them out with a note).
It checks rnea, crba, computeGeneralizedGravity, computeCoriolisMatrix, aba and
computeJointTorqueRegressor (Y pi + armature qdd, pi from toDynamicParameters) against
symdyn.rnea's numbers, then times them. It is
compiled header-only with g++ against the `pin` wheel's headers (cmeel.prefix/include) and
Eigen's (the `cmeel-eigen` wheel, or the system's as `pkg-config eigen3` reports them);
the build is cached. Notes name the headers by package, never by absolute path.
"""

from __future__ import annotations

import hashlib
import sysconfig
import time
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import casadi_route
import numpy as np
from c_harness import parse_harness
from machine import BENCH, CXX_COMPILER, CXX_EXTRA, FLAGS, compiler_version, log, project_path, run
from row import Row
from states import CHECK_TOL, NCHECK, NSTATES

__all__ = [
    "prepare",
    "check_pinocchio",
    "pinocchio_model_text",
    "model_and_states_lines",
    "floating_model_lines",
    "MIMIC_NOTE",
]

MIMIC_NOTE = (
    "mimic joints: Pinocchio not run (bench/pinocchio_harness.cpp gives every link an independent "
    "joint; a mimic joint would need Pinocchio's JointModelMimic)"
)

PIN_DEFINES = (  # what pinocchio's CMake target pinocchio_headers adds
    "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
    "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
)


@dataclass(frozen=True)
class Headers:
    """Where pinocchio's and Eigen's headers are, and how a report names them."""

    include: Path  # cmeel.prefix/include of the `pin` wheel
    eigen: Path  # the folder holding Eigen/
    note: str


def _eigen(include: Path) -> tuple[Path | None, str]:
    """Eigen's headers: the cmeel-eigen wheel's (beside pinocchio's), else pkg-config's eigen3."""
    if (include / "eigen3" / "Eigen").is_dir():
        try:
            return include / "eigen3", f"Eigen of cmeel-eigen {version('cmeel-eigen')}"
        except PackageNotFoundError:
            return include / "eigen3", "Eigen in cmeel.prefix/include/eigen3"
    try:
        flags = run(["pkg-config", "--cflags-only-I", "eigen3"]).stdout.split()
    except (RuntimeError, OSError):
        return None, ""
    for flag in flags:
        if flag.startswith("-I") and (Path(flag[2:]) / "Eigen").is_dir():
            return Path(flag[2:]), "the system's Eigen (pkg-config eigen3)"
    return None, ""


def find_headers() -> tuple[Headers | None, str]:
    """Pinocchio's and Eigen's headers, or None and why not."""
    try:
        pin_version = version("pin")
    except PackageNotFoundError:
        return None, "the `pin` package is not installed (pip install 'symdyn[bench]')"
    prefixes = dict.fromkeys(Path(sysconfig.get_paths()[k]) / "cmeel.prefix" for k in ("purelib", "platlib"))
    for prefix in prefixes:
        include = prefix / "include"
        if (include / "pinocchio").is_dir():
            eigen, eigen_note = _eigen(include)
            if eigen is None:
                return None, f"pin {pin_version} found but no Eigen headers (pip install cmeel-eigen)"
            return Headers(include, eigen, f"pin {pin_version} (cmeel.prefix/include), {eigen_note}"), ""
    return None, f"pin {pin_version} installed but cmeel.prefix/include/pinocchio was not found"


def build_pinocchio(
    headers: Headers, build_dir: Path, source: str = "pinocchio_harness.cpp"
) -> tuple[Path, str]:
    """Compile bench/SOURCE with bench/pinocchio_model.hpp (cached by sources, flags, compiler, headers)."""
    src = BENCH / source
    inc = headers.include
    cmd_flags = [*FLAGS, *CXX_EXTRA, *PIN_DEFINES, "-I", str(inc), "-I", str(headers.eigen)]
    config = (inc / "pinocchio" / "config.hpp").read_bytes()
    key = hashlib.sha256(
        src.read_bytes()
        + (BENCH / "pinocchio_model.hpp").read_bytes()
        + config
        + " ".join(cmd_flags).encode()
        + compiler_version(CXX_COMPILER).encode()
    ).hexdigest()[:16]
    exe = build_dir / f"{src.stem}_{key}"
    if exe.exists():
        return exe, "cached build"
    build_dir.mkdir(parents=True, exist_ok=True)
    log(f"compiling {source} (several minutes, cached in {project_path(build_dir)}) ...")
    t0 = time.perf_counter()
    tmp = exe.with_suffix(".tmp")
    # -w: GCC 12 prints false -Wstringop-overread warnings from Eigen's AVX-512 code
    run([CXX_COMPILER, *cmd_flags, "-w", "-o", tmp, src])
    tmp.rename(exe)
    return exe, f"compiled in {time.perf_counter() - t0:.0f} s"


def prepare(build_dir: Path, source: str = "pinocchio_harness.cpp") -> tuple[Path | None, str]:
    """The compiled harness bench/SOURCE (None if Pinocchio is missing or does not compile) and
    the report's note."""
    headers, why = find_headers()
    if headers is None:
        return None, why + "; Pinocchio columns skipped"
    try:
        exe, how = build_pinocchio(headers, build_dir, source)
    except (RuntimeError, OSError) as exc:
        log(f"the Pinocchio harness did not compile:\n{exc}")
        why = "the harness did not compile (the compiler's messages are on stderr)"
        return None, f"{headers.note}: {why}, Pinocchio columns skipped"
    return exe, f"{headers.note}; harness {how}"


def pinocchio_model_text(robot, states, refs: list[dict]) -> str:
    """The MODEL.txt of bench/pinocchio_harness.cpp, with symdyn.rnea's reference numbers `refs`."""
    lines = model_and_states_lines(robot, states)
    lines.append(f"ncheck {NCHECK}")
    for k in range(NCHECK):
        ref = refs[k]
        vec = np.concatenate(
            [
                ref["rnea_nofriction"],
                ref["mass_matrix"].ravel(),
                ref["gravity"],
                ref["coriolis"],
                ref["aba_nofriction"],
            ]
        )
        lines.append(f"{k} " + " ".join(repr(float(v)) for v in vec))
    return "\n".join(lines) + "\n"


def model_and_states_lines(robot, states) -> list[str]:
    """The model and the states of MODEL.txt (bench/pinocchio_model.hpp reads them)."""
    m = casadi_route.robot_arrays(robot)
    assert not m.has_mimic, "the Pinocchio harness models independent joints only"
    lines = [f"n {m.n}", "gravity " + " ".join(repr(float(x)) for x in m.gravity)]
    for i in range(m.n):
        I = m.inertia[i]
        vals = [
            *m.axis[i],
            *m.R0[i].ravel(),
            *m.p0[i],
            m.mass[i],
            *m.com[i],
            I[0, 0],
            I[0, 1],
            I[0, 2],
            I[1, 1],
            I[1, 2],
            I[2, 2],
            m.reflected[i],
        ]
        kind = "R" if m.revolute[i] else "P"
        lines.append(f"joint {kind} {m.parent[i]} " + " ".join(repr(float(v)) for v in vals))
    lines.append(f"nstates {NSTATES}")
    for k in range(NSTATES):
        vec = np.concatenate([states[x][k] for x in ("q", "qd", "qdd", "tau")])
        lines.append(" ".join(repr(float(v)) for v in vec))
    return lines


def floating_model_lines(robot) -> list[str]:
    """The model lines of MODEL.txt for a floating robot: the joints (model_and_states_lines) and
    the `floating MASS CX CY CZ IXX IXY IXZ IYY IYZ IZZ` line of the base body after `gravity`
    (bench/pinocchio_model.hpp puts a free flyer ahead of the joints); no states."""
    zeros = {x: np.zeros((NSTATES, robot.n)) for x in ("q", "qd", "qdd", "tau")}
    lines = model_and_states_lines(robot, zeros)[: 2 + robot.n]
    b = robot.numeric().base_body
    inertia = np.array(b.inertia, dtype=float)
    base = [float(b.mass), *np.array(b.com, dtype=float).ravel(), *inertia[np.triu_indices(3)]]
    lines.insert(2, "floating " + " ".join(repr(float(x)) for x in base))
    return lines


def check_pinocchio(row: Row, robot, exe: Path, work: Path, states, refs: list[dict]) -> list | None:
    """Write MODEL.txt, run the harness once (it checks, then times briefly); the command to time.

    None (and MIMIC_NOTE in the row's notes) for a robot with mimic joints.
    """
    if robot.n != robot.nb:
        row.notes.append(MIMIC_NOTE)
        return None
    model = work / f"pinocchio_{row.name}.txt"
    model.write_text(pinocchio_model_text(robot, states, refs))
    checks, _ = parse_harness(run([exe, model, 1, 0.1]).stdout)
    row.checks.update({f"Pinocchio {k}": v for k, v in checks.items() if isinstance(v, float)})
    bad = {k: v for k, v in checks.items() if isinstance(v, float) and not v <= CHECK_TOL}
    if bad or not checks:
        raise SystemExit(f"{row.name}: Pinocchio's model disagrees with symdyn.rnea: {bad or 'no output'}")
    return [exe, model]
