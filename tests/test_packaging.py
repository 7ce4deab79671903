"""The wheel is self-contained: templates ship inside it, and an installed copy generates code."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    pytest.importorskip("hatchling", reason="the test extra installs hatchling to build the wheel")
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "--no-build-isolation",
            "-q",
            "-w",
            str(out),
            str(ROOT),
        ],
        check=True,
        capture_output=True,
        timeout=600,
    )
    (found,) = out.glob("symdyn-*.whl")
    return found


def test_wheel_contains_every_target_template(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    for target in ("c", "casadi", "python", "jax", "torch", "latex", "matlab"):
        assert any(n.startswith(f"symdyn/templates/{target}/") and n.endswith(".j2") for n in names), target
    assert "symdyn/cli/main.py" in names
    for page in ("page.js", "vendor/three/three.module.min.js", "vendor/three/LICENSE"):  # symdyn draw's HTML
        assert f"symdyn/apps/drawing/{page}" in names, page
    assert not any(n.startswith("tests/") or n.startswith("generated/") for n in names)


def test_installed_wheel_generates_code_outside_the_source_tree(wheel, tmp_path):
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    work = tmp_path / "elsewhere"
    work.mkdir()
    robot = ROOT / "examples" / "roger_arm.yaml"
    script = (
        "import symdyn, pathlib;"
        f"assert pathlib.Path(symdyn.__file__).parent.parent == pathlib.Path(r'{site}');"
        f"paths = symdyn.generate(r'{robot}', targets=('c', 'python', 'latex'), out_dir='out');"
        "print(len(paths))"
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    out = subprocess.run(
        [sys.executable, "-c", script], cwd=work, env=env, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "5"  # .h, .c, CMakeLists.txt, NumPy, LaTeX
    assert (work / "out" / "roger_arm_dynamics.c").read_text().startswith("/*")


def test_build_requires_only_the_backend():
    """Building the package downloads nothing it does not use (no robot data, no test tools)."""
    tomllib = pytest.importorskip("tomllib", reason="Python 3.11 reads TOML")
    requires = tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"]
    assert [r.split(">")[0].split("=")[0].strip() for r in requires] == ["hatchling"]


def test_sdist_carries_the_docs_and_the_pinned_toolchain(tmp_path):
    import tarfile

    pytest.importorskip("hatchling", reason="the test extra installs hatchling to build the sdist")
    subprocess.run(
        [sys.executable, "-m", "hatchling", "build", "-t", "sdist", "-d", str(tmp_path)],
        cwd=ROOT,
        check=True,
        capture_output=True,
        timeout=600,
    )
    (sdist,) = tmp_path.glob("symdyn-*.tar.gz")
    with tarfile.open(sdist) as archive:
        names = {n.split("/", 1)[1] for n in archive.getnames() if "/" in n}
    needed_files = ("mkdocs.yml", "constraints.txt", "docs/index.md", "templates/c/dynamics.h.j2")
    for needed in needed_files:
        assert needed in names, needed
