"""The robot pictures of the documentation, written by `symdyn draw` (docs/images/robots/*.svg).

    python docs/pictures.py            # rewrite them (run from the repository's root)

tests/test_docs.py draws them again and compares the bytes, as tests/test_generated.py does for
generated/: a picture that no longer matches what `symdyn draw` writes fails the suite. Solo-12
comes from example-robot-data (the test extra), in the SRDF's "standing" configuration.
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = Path("docs/images/robots")

#: alpha_3 of the PUMA with the wrong sign, the mistake of docs/tutorials/dh-check.md: the file's
#: first line `alpha: -pi/2` (link 3's; link 5 has the second) written `alpha: pi/2`.
WRONG_ALPHA = ("    alpha: -pi/2\n", "    alpha: pi/2\n")


def fourbar_closed(q1: float, a=0.1, b=0.35, c=0.3, d=0.4) -> list[float]:
    """The four-bar's closed configuration at crank angle q1 (examples/closed_loops/fourbar.yaml):
    A = a (cos q1, sin q1), B the intersection of |B - A| = b and |B - O4| = c above the ground,
    q2 = angle(B - A) - q1, q3 = angle(B - O4)."""
    ax, ay = a * math.cos(q1), a * math.sin(q1)
    dx, dy = d - ax, -ay
    r = math.hypot(dx, dy)
    along = (b * b - c * c + r * r) / (2 * r)
    h = math.sqrt(b * b - along * along)
    bx, by = ax + (along * dx - h * dy) / r, ay + (along * dy + h * dx) / r
    if by < 0:
        bx, by = ax + (along * dx + h * dy) / r, ay + (along * dy - h * dx) / r
    return [q1, math.atan2(by - ay, bx - ax) - q1, math.atan2(by, bx - d)]


def _solo12() -> tuple[str, list[float]]:
    sys.path.insert(0, str(ROOT))
    from symdyn.parsers import load_urdf
    from symdyn.regenerate import example_robot_data_folder

    folder = example_robot_data_folder()
    if folder is None:
        raise SystemExit("Solo-12's picture needs example-robot-data (pip install -e '.[test]')")
    path = folder / "solo_description/robots/solo12.urdf"
    standing = {"HAA": 0.1, "HFE": 0.8, "KFE": -1.6}
    robot = load_urdf(path, floating=True)
    joints = []
    for link in robot.links:
        leg, part = link.joint_name.split("_")
        sign = (1 if leg[0] == "F" else -1) if part != "HAA" else (1 if leg[1] == "L" else -1)
        joints.append(sign * standing[part])
    return str(path), [0.0, 0.0, 0.235, 0.0, 0.0, 0.0, 1.0, *joints]


def pictures(work: Path) -> dict[str, list[str]]:
    """picture file name -> the `symdyn draw` arguments that write it (the robot's path first);
    `work` holds the robot files made on the way (the PUMA with the wrong alpha)."""
    puma = (ROOT / "examples/puma560.yaml").read_text()
    assert puma.count(WRONG_ALPHA[0]) == 2
    wrong = work / "puma560_wrong_alpha.yaml"
    wrong.write_text(puma.replace(*WRONG_ALPHA, 1))
    solo, standing = _solo12()
    ready = ["0", "0.5", "-0.8", "0", "0.6", "0"]
    q = lambda values: ["--q", *(repr(float(v)) for v in values)]  # noqa: E731
    return {
        "puma560.svg": ["examples/puma560.yaml", *q(map(float, ready))],
        "puma560_zero.svg": ["examples/puma560.yaml", "--view", "front"],
        "puma560_wrong_alpha.svg": [str(wrong), "--view", "front"],
        "panda.svg": ["examples/panda.yaml", *q([0, -0.3, 0, -2.2, 0, 2.0, 0.8])],
        "solo12.svg": [solo, "--floating", *q(standing), "--view", "iso"],
        "fourbar.svg": ["examples/closed_loops/fourbar.yaml", *q(fourbar_closed(1.0)), "--view", "top"],
        "roger_arm.svg": [
            "examples/roger_arm.yaml",
            *q([0.5, 0.9]),
            "--params",
            "l1=1",
            "l2=0.8",
            "m1=1",
            "m2=1",
            "g=9.81",
            "--view",
            "top",
        ],
    }


def write(out: Path = OUT) -> list[Path]:
    """Draw every picture into `out` with `symdyn draw` (run from the repository's root)."""
    import warnings

    from symdyn.cli import main

    written = []
    with tempfile.TemporaryDirectory() as work, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, args in pictures(Path(work)).items():
            status = main(["draw", *args, "--out", str(out / name)])
            assert status == 0, name
            written.append(out / name)
    return written


if __name__ == "__main__":
    for path in write():
        print(path)
