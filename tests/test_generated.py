"""generated/ is exactly what the code generates now: regenerate in memory and compare file by file.

Byte-identical output is defined per toolchain, and generated/TOOLCHAIN records
the one that wrote generated/. Each file depends on a known set of tools
(symdyn.codegen.file_tools: every file on SymPy, which derives, orders and
simplifies every expression; the serialised .casadi functions also on CasADi's
format). A file is skipped only when one of its tools has another version here
than in the stamp, and the skip names the tool and both versions; every other
file is compared byte for byte. symdyn's own version is no such tool: a stamp
from another symdyn version means generated/ is stale.
"""

from __future__ import annotations

import difflib
import sys
from pathlib import Path

import pytest

from symdyn.codegen import file_tools
from symdyn.parsers import load_robot
from symdyn.regenerate import (
    EXAMPLES,
    TOOLCHAIN_FILE,
    changed_tools,
    read_toolchain,
    render_all,
    toolchain,
    versions,
)

ROOT = Path(__file__).resolve().parents[1]
GENERATED = ROOT / "generated"
STAMP = GENERATED / TOOLCHAIN_FILE


def _recorded() -> dict[str, str]:
    return read_toolchain(STAMP.read_text()) if STAMP.is_file() else {}


def _committed() -> list[tuple[str, str]]:
    """(robot, file name) of every file in generated/<robot>/, for parametrising at collection."""
    return [
        (robot, path.name)
        for robot in EXAMPLES
        if (GENERATED / robot).is_dir()
        for path in sorted((GENERATED / robot).iterdir())
    ]


@pytest.fixture(scope="module")
def fresh() -> dict[str, dict[str, bytes]]:
    return {
        robot: {name: c.encode() if isinstance(c, str) else c for name, c in files.items()}
        for robot, files in render_all(ROOT).items()
    }


def test_toolchain_is_recorded_by_this_symdyn():
    assert STAMP.is_file(), "run: python -m symdyn.regenerate"
    recorded, current = _recorded(), versions()
    assert list(recorded) == list(current), f"{STAMP} records {list(recorded)}, expected {list(current)}"
    assert recorded["symdyn"] == current["symdyn"], (
        f"generated/ was written by symdyn {recorded['symdyn']}, this is {current['symdyn']}: "
        "run python -m symdyn.regenerate"
    )


@pytest.mark.parametrize("robot", EXAMPLES)
def test_file_list(robot, fresh):
    committed = sorted(p.name for p in (GENERATED / robot).iterdir())
    assert committed == sorted(fresh[robot]), "file list differs: run python -m symdyn.regenerate"


@pytest.mark.parametrize(("robot", "fname"), _committed())
def test_generated_file_is_up_to_date(robot, fname, fresh):
    changed = changed_tools(fname, _recorded(), versions())
    if changed:
        pytest.skip(
            f"generated/{robot}/{fname} depends on "
            + ", ".join(
                f"{tool} (generated/ has {old}, this environment {new})" for tool, old, new in changed
            )
        )
    if fname not in fresh[robot]:
        pytest.fail(f"generated/{robot}/{fname} is no longer generated: run python -m symdyn.regenerate")
    new = fresh[robot][fname]
    old = (GENERATED / robot / fname).read_bytes()
    if new == old:
        return
    if fname.endswith(".casadi"):
        pytest.fail(f"{robot}/{fname}: serialised function differs (python -m symdyn.regenerate)")
    diff = difflib.unified_diff(
        old.decode().splitlines(),
        new.decode().splitlines(),
        f"generated/{robot}/{fname}",
        f"regenerated/{robot}/{fname}",
        lineterm="",
        n=1,
    )
    pytest.fail("generated/ is stale (python -m symdyn.regenerate):\n" + "\n".join(list(diff)[:60]))


def test_every_file_is_compared_unless_its_own_tool_changed():
    """A changed CasADi skips only the .casadi files; a changed SymPy skips all; symdyn none."""
    names = [name for _, name in _committed()]
    assert {n.rsplit(".", 1)[-1] for n in names} == {"c", "h", "py", "tex", "casadi", "m", "txt"}
    current = versions()
    for tool, skipped in (
        ("casadi", {n for n in names if n.endswith(".casadi")}),
        ("sympy", set(names)),
        ("symdyn", set()),
    ):
        recorded = dict(current, **{tool: "0.0.0"})
        got = {n for n in names if changed_tools(n, recorded, current)}
        assert got == skipped, tool
        for n in got:
            assert changed_tools(n, recorded, current) == [(tool, "0.0.0", current[tool])]


def test_files_without_casadi_among_their_tools_render_without_casadi(fresh, monkeypatch):
    """The dependency table follows the code: with casadi unimportable, every file whose tools
    exclude casadi (the C, NumPy, JAX, PyTorch, LaTeX and MATLAB files and the casadi module's
    text) renders to the same bytes, and the .casadi files cannot be made at all.

    Rendering is also deterministic within a process: Roger's arm rendered a second time here
    (as render_all renders it: symdyn.codegen.render, its groups) gives `fresh`'s bytes, the
    serialised .casadi files too once casadi is importable again."""
    import symdyn.codegen
    from symdyn.codegen import casadi as casadi_backend

    robot = load_robot(ROOT / "examples" / "roger_arm.yaml")
    ctx = symdyn.codegen.context(robot)
    with monkeypatch.context() as mp:
        mp.setitem(sys.modules, "casadi", None)  # `import casadi` raises ImportError
        files = symdyn.codegen.render(robot, targets=("c", "python", "jax", "torch", "latex", "matlab"))
        files["roger_arm_casadi.py"] = casadi_backend.render_module(ctx)
        want = {name for name in fresh["roger_arm"] if "casadi" not in file_tools(name)}
        assert set(files) == want
        for name, text in files.items():
            assert text.encode() == fresh["roger_arm"][name], name
        with pytest.raises(ImportError):
            casadi_backend.serialise(files["roger_arm_casadi.py"], ctx)
    serialised = casadi_backend.serialise(files["roger_arm_casadi.py"], ctx)
    assert set(serialised) == {name for name in fresh["roger_arm"] if name.endswith(".casadi")}
    for name, data in serialised.items():
        assert data == fresh["roger_arm"][name], name


def test_file_tools_lookup_by_ending():
    """Robot names that end like another target's file do not confuse the lookup."""
    assert file_tools("my_numpy_casadi.py") == file_tools("roger_arm_casadi.py")
    assert file_tools("my_casadi_numpy.py") == file_tools("roger_arm_numpy.py")
    assert "casadi" in file_tools("my_dynamics_friction.casadi")
    with pytest.raises(ValueError, match="not a file name"):
        file_tools("notes.txt")


def test_stamp_is_deterministic_and_round_trips():
    assert toolchain() == toolchain()
    assert read_toolchain(toolchain()) == versions()
    assert toolchain() == "".join(f"{tool} {version}\n" for tool, version in versions().items())
