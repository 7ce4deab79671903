"""Run calls of generated MATLAB functions in one GNU Octave process and read their outputs back.

    results = octave_values(folder, {"a": "robot_integrate([1 2 3], ...)", ...})

Each call's output is printed with 17 significant digits on a line of its own, marked by its
label; the values come back as flat NumPy arrays (row-major, as the generated functions store
matrices). A call that prints nothing fails the assertion with Octave's output."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Mapping
from pathlib import Path

import numpy as np

__all__ = ["OCTAVE", "octave_numbers", "octave_values"]

OCTAVE = shutil.which("octave-cli")


def octave_numbers(values) -> str:
    """A vector as an Octave literal that round-trips every double."""
    return "[" + " ".join(f"{float(v):.17g}" for v in np.ravel(values)) + "]"


def octave_values(folder: Path, calls: Mapping[str, str], timeout: float = 120) -> dict[str, np.ndarray]:
    """label -> the output of the Octave expression `calls[label]`, run in `folder`."""
    lines = ["1;", f"addpath('{folder}');"]
    for k, call in enumerate(calls.values()):
        lines.append(f"o = {call}; fprintf('@ {k}'); fprintf(' %.17g', o.'); fprintf('\\n');")
    (folder / "run_calls.m").write_text("\n".join(lines) + "\n")
    done = subprocess.run(
        [OCTAVE, "--no-gui", "--quiet", "--norc", "--no-history", "run_calls.m"],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=folder,
    )
    labels = list(calls)
    got = {}
    for line in done.stdout.splitlines():
        if line.startswith("@ "):
            k, *nums = line.split()[1:]
            got[labels[int(k)]] = np.array([float(x) for x in nums])
    assert len(got) == len(calls), done.stdout[-2000:] + done.stderr[-2000:]
    return got
