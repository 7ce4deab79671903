"""generated/ is exactly what the code generates now: regenerate into a temporary folder and diff."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest

from symdyn.regenerate import EXAMPLES, TOOLCHAIN_FILE, render_all, toolchain

ROOT = Path(__file__).resolve().parents[1]
GENERATED = ROOT / "generated"


@pytest.fixture(scope="module")
def fresh(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("generated")
    for name, files in render_all(ROOT).items():
        (out / name).mkdir()
        for fname, content in files.items():
            data = content.encode() if isinstance(content, str) else content
            (out / name / fname).write_bytes(data)
    return out


def _same_toolchain() -> bool:
    stamp = GENERATED / TOOLCHAIN_FILE
    return stamp.is_file() and stamp.read_text() == toolchain()


def test_toolchain_is_recorded():
    assert (GENERATED / TOOLCHAIN_FILE).is_file(), "run: python -m symdyn.regenerate"


@pytest.mark.parametrize("robot", EXAMPLES)
def test_generated_is_up_to_date(robot, fresh):
    if not _same_toolchain():
        pytest.skip(
            f"generated/ was written with\n{(GENERATED / TOOLCHAIN_FILE).read_text()}"
            f"this environment has\n{toolchain()}byte-identical output is defined per toolchain"
        )
    committed = sorted(p.name for p in (GENERATED / robot).iterdir())
    expected = sorted(p.name for p in (fresh / robot).iterdir())
    assert committed == expected, "file list differs: run python -m symdyn.regenerate"
    problems = []
    for fname in expected:
        new = (fresh / robot / fname).read_bytes()
        old = (GENERATED / robot / fname).read_bytes()
        if new == old:
            continue
        if fname.endswith(".casadi"):
            problems.append(f"{robot}/{fname}: serialised function differs")
            continue
        diff = difflib.unified_diff(
            old.decode().splitlines(),
            new.decode().splitlines(),
            f"generated/{robot}/{fname}",
            f"regenerated/{robot}/{fname}",
            lineterm="",
            n=1,
        )
        problems.append("\n".join(list(diff)[:60]))
    assert not problems, "generated/ is stale (python -m symdyn.regenerate):\n" + "\n".join(problems)


def test_regeneration_is_deterministic(fresh, tmp_path):
    again = render_all(ROOT)["roger_arm"]
    for fname, content in again.items():
        data = content.encode() if isinstance(content, str) else content
        assert (fresh / "roger_arm" / fname).read_bytes() == data, fname
