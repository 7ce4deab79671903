"""The repository stands alone: no reference outside it, and the README's commands are CI's.

- No tracked file names the folder beside the checkout that the project was planned in, a design
  card kept outside the repository, or an absolute path of a machine (home folders, build and
  work folders, this checkout's own path). Everything a user relies on is in docs/.
- The README starts with the two set-up commands, and .ci/run runs exactly the second one.
- The development toolchain is pinned, so that generated/ is compared byte for byte everywhere.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
THIS = Path(__file__).resolve()

# Built from parts so that this file does not match itself.
OUTSIDE = ("../" + "shared", "design" + ".md")
ABSOLUTE = re.compile(r"(?<![\w.~-])/(?:home|root|work|Users|builds?|runner|opt/hostedtoolcache)/")


def _tracked() -> list[Path]:
    if not (ROOT / ".git").exists() or shutil.which("git") is None:
        pytest.skip("not a git checkout (e.g. an unpacked sdist)")
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True)
    return [ROOT / name for name in out.stdout.decode().split("\0") if name]


def _text(path: Path) -> str | None:
    try:
        data = path.read_bytes()
    except OSError:  # listed by git but deleted in the work tree
        return None
    if b"\0" in data[:8192]:
        return None
    return data.decode("utf-8", errors="replace")


def test_no_file_refers_outside_the_repository():
    here = str(ROOT) + "/"  # the checkout's own absolute path (its parent may be a shared /tmp)
    problems = []
    for path in _tracked():
        if path == THIS:
            continue
        text = _text(path)
        if text is None:
            continue
        rel = path.relative_to(ROOT)
        for lineno, line in enumerate(text.splitlines(), 1):
            if any(s in line for s in OUTSIDE) or here in line or ABSOLUTE.search(line):
                problems.append(f"{rel}:{lineno}: {line.strip()[:120]}")
    assert not problems, "references outside the repository:\n" + "\n".join(problems[:40])


def test_the_check_finds_what_it_looks_for():
    for line in ("see ../" + "shared/x", "python at /ho" + "me/me/venv/bin", "/wo" + "rk/venv/bin/python"):
        assert any(s in line for s in OUTSIDE) or ABSOLUTE.search(line), line
    for line in ("the payload touches /tmp/marker", "docs/robot-files.md", "https://example.org/home/x"):
        assert not (any(s in line for s in OUTSIDE) or ABSOLUTE.search(line)), line


def _readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```sh\n(.*?)```", text, re.S)
    assert block, "the README starts with a sh block of the two set-up commands"
    return [ln for ln in block.group(1).splitlines() if ln.strip() and not ln.startswith("#")]


def test_readme_starts_with_the_two_commands_and_ci_runs_the_second():
    commands = _readme_commands()
    assert len(commands) == 2, commands
    ci = [ln for ln in (ROOT / ".ci" / "run").read_text().splitlines() if ln.strip()]
    assert ci[-1] == commands[1], "the last line of .ci/run must be the README's test command"
    assert "-c constraints.txt" in commands[0] and "-c constraints.txt" in commands[1]


def test_the_toolchain_that_generated_files_depend_on_is_pinned():
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        if "==" in line and not line.startswith("#"):
            name, version = line.split("==")
            pins[name.strip().lower()] = version.strip()
    for tool in ("sympy", "casadi", "numpy", "jinja2", "pyyaml", "mkdocs", "pytest"):
        assert tool in pins, tool
    stamp = (ROOT / "generated" / "TOOLCHAIN").read_text()
    assert f"sympy {pins['sympy']}" in stamp and f"casadi {pins['casadi']}" in stamp
