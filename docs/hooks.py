"""MkDocs hooks: serve the pictures that live beside their sources, so docs/ holds no stale copies,
and make the docstrings' page paths links.

`examples/slide24.png` (drawn by examples/slide24.py) and `bench/results/scaling.png` (drawn by
bench/plot.py) are added to the site as `images/slide24.png` and `images/scaling.png`.

Docstrings name the page that explains a thing by its path in the repository (`docs/urdf.md`),
which a reader of the source can open; on the site (the API reference), every such path in prose
becomes a link to that page.
"""

from __future__ import annotations

import re
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


#: A page path in prose, and the parts of a page left alone: code, preformatted text, links.
PAGE_PATH = re.compile(r"\bdocs/((?:[\w-]+/)*[\w-]+\.md)\b")
LEFT_ALONE = re.compile(r"<(pre|code|a)\b.*?</\1>", re.S | re.I)


def on_page_content(html: str, page, config, files: Files) -> str:
    """Every `docs/PAGE.md` in the page's prose that names a page of the site, as a link to it."""

    def link(match: re.Match) -> str:
        target = files.get_file_from_path(match.group(1))
        if target is None:
            return match.group(0)
        return f'<a href="{target.url_relative_to(page.file)}">{match.group(0)}</a>'

    out, start = [], 0
    for kept in LEFT_ALONE.finditer(html):
        out += [PAGE_PATH.sub(link, html[start : kept.start()]), kept.group(0)]
        start = kept.end()
    out.append(PAGE_PATH.sub(link, html[start:]))
    return "".join(out)
