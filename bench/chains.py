"""Robot files for bench/run.py: generic n-joint chains and the PUMA 560 with symbolic inertia.

* `chain_data(n)`: an n-joint spatial revolute arm as a robot-file dict (the format
  of docs/robot-files.md): standard DH, twists cycling 0, +pi/2, -pi/2, nonzero a and d,
  numeric masses, centres of mass and FULL inertia tensors (non-zero products of
  inertia, positive definite, triangle inequality kept), gravity (0, 0, -9.81).
  The numbers follow a fixed formula (no randomness), so every run and every
  machine times the same robot.
* `puma560_symbolic_data()`: examples/puma560.yaml with every link's mass, centre of
  mass (cx, cy, cz) and inertia tensor (6 entries) replaced by free parameters
  (m1, cx1, ..., izz6: 60 in all). Motor inertia and friction are left out, as in
  bench/robots.py's `puma560_symbolic`, so tau is the rigid-body part only.
* `write_robot_files(directory)`: writes chain_2.yaml .. chain_12.yaml and
  puma560_symbolic.yaml there (default bench/chains/) and returns their paths.

    python bench/chains.py            # (re)writes bench/chains/*.yaml
"""

from __future__ import annotations

import sys
from pathlib import Path

import yaml

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CHAIN_DIR = HERE / "chains"
PUMA_FILE = ROOT / "examples" / "puma560.yaml"
TWISTS = ("0", "pi/2", "-pi/2")

__all__ = ["chain_data", "puma560_symbolic_data", "write_robot_files", "chain_file", "CHAIN_DIR"]


def _r(x: float) -> float:
    return round(x, 6)


def chain_data(n: int) -> dict:
    """The robot-file dict of the generic n-joint spatial revolute chain `chain_<n>`."""
    if n < 1:
        raise ValueError("a chain needs at least one joint")
    links = []
    for i in range(1, n + 1):
        a = 0.20 + 0.03 * (i % 4)
        d = 0.05 + 0.02 * (i % 3)
        mass = 3.0 - 1.5 * (i - 1) / max(n - 1, 1)  # 3.0 kg at the base down to 1.5 kg at the tip
        # Principal-ish moments (the triangle inequality holds: ixx + iyy > izz etc.) and small
        # products of inertia; the tensor stays strongly diagonally dominant, so positive definite.
        ixx = 0.020 + 0.002 * (i % 5)
        iyy = 0.030 + 0.001 * (i % 4)
        izz = 0.025 + 0.0015 * (i % 3)
        links.append(
            {
                "name": f"link{i}",
                "joint": "revolute",
                "a": _r(a),
                "alpha": TWISTS[(i - 1) % 3],
                "d": _r(d),
                "theta": 0,
                "mass": _r(mass),
                "com": [_r(-a / 2), _r(0.01 * (1 + i % 3)), _r(0.02 * (-1) ** i)],
                "inertia": {
                    "ixx": _r(ixx),
                    "iyy": _r(iyy),
                    "izz": _r(izz),
                    "ixy": _r(0.0010 * (-1) ** i),
                    "ixz": _r(-0.0005 - 0.0001 * (i % 3)),
                    "iyz": _r(0.0008),
                },
            }
        )
    return {
        "name": f"chain_{n}",
        "convention": "standard",
        "gravity": [0, 0, -9.81],
        "parameters": {},
        "links": links,
    }


def puma560_symbolic_data(path: Path = PUMA_FILE) -> dict:
    """examples/puma560.yaml with all 60 inertial parameters free (no motor, no friction)."""
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    links = []
    for i, link in enumerate(data["links"], 1):
        out = {k: link[k] for k in ("name", "joint", "a", "alpha", "d", "theta")}
        out["mass"] = f"m{i}"
        out["com"] = [f"cx{i}", f"cy{i}", f"cz{i}"]
        out["inertia"] = {k: f"{k}{i}" for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
        links.append(out)
    return {
        "name": "puma560_symbolic",
        "convention": data.get("convention", "standard"),
        "gravity": data.get("gravity", [0, 0, -9.81]),
        "parameters": {},
        "links": links,
    }


def chain_file(n: int, directory: Path = CHAIN_DIR) -> Path:
    return Path(directory) / f"chain_{n}.yaml"


def _dump(data: dict, path: Path, comment: str) -> Path:
    text = f"# {comment}\n# Written by bench/chains.py; do not edit by hand.\n"
    text += yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=100)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
    return path


def write_robot_files(directory: Path = CHAIN_DIR, sizes=range(2, 13)) -> dict[str, Path]:
    """Write the chain files and puma560_symbolic.yaml; return {robot name: path}."""
    directory = Path(directory)
    out = {}
    for n in sizes:
        out[f"chain_{n}"] = _dump(
            chain_data(n),
            chain_file(n, directory),
            f"Generic {n}-joint spatial revolute chain (standard DH, twists 0, +pi/2, -pi/2).",
        )
    out["puma560_symbolic"] = _dump(
        puma560_symbolic_data(),
        directory / "puma560_symbolic.yaml",
        "PUMA 560 geometry of examples/puma560.yaml, all 60 inertial parameters free "
        "(no motor inertia, no friction).",
    )
    return out


if __name__ == "__main__":
    for name, path in write_robot_files().items():
        print(f"{name}: {path}")
    sys.exit(0)
