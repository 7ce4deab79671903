"""MkDocs hook: serve the pictures that live beside their sources, so docs/ holds no stale copies.

`examples/slide24.png` (drawn by examples/slide24.py) and `bench/results/scaling.png` (drawn by
bench/plot.py) are added to the site as `images/slide24.png` and `images/scaling.png`.
"""

from __future__ import annotations

from pathlib import Path

from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parent.parent

#: site path -> source file, relative to the repository root
EXTERNAL = {
    "images/slide24.png": "examples/slide24.png",
    "images/scaling.png": "bench/results/scaling.png",
}


def on_files(files: Files, config) -> Files:
    """Add each external picture as a generated file of the site (mkdocs >= 1.6)."""
    for uri, source in EXTERNAL.items():
        files.append(File.generated(config, uri, abs_src_path=str(ROOT / source)))
    return files
