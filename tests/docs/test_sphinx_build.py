"""The built site as files: every page, every scene in the gallery, nothing from outside."""

from __future__ import annotations

import html
import inspect
import re
from pathlib import Path

import msdlab
from msdlab.scenes import SCENES

DOCS = Path(__file__).resolve().parents[2] / "docs"
# a script, style sheet, picture or frame loaded from another host, or a CSS url() to one
OUTSIDE = re.compile(
    r"<(?:script|link|img|iframe|source)\b[^>]*\b(?:src|href)=\"(?:https?:)?//[^\"]*\""
    r"|url\(\s*[\"']?(?:https?:)?//[^)]*\)"
)


def test_no_page_loads_anything_from_another_host(site):
    found = []
    for path in sorted(site.rglob("*")):
        if path.suffix in (".html", ".css", ".js") and "_sources" not in path.parts:
            text = path.read_text(encoding="utf-8", errors="replace")
            found += [f"{path.relative_to(site)}: {m}" for m in OUTSIDE.findall(text)]
    assert not found, "\n".join(found[:20])


def test_every_scene_has_a_gallery_example():
    names = {path.stem.removeprefix("scene_") for path in (DOCS / "scenes").glob("scene_*.py")}
    assert names == {name.replace("-", "_") for name in SCENES}


def test_gallery_pages_show_a_picture_and_an_animation(site):
    pages = sorted((site / "gallery").glob("scene_*.html"))
    assert len(pages) == len(SCENES)
    for page in pages:
        html = page.read_text(encoding="utf-8")
        assert re.search(r"<img [^>]*src=\"[^\"]+\.png\"", html), f"{page.name}: no picture"
        assert re.search(r"<img [^>]*src=\"[^\"]+\.gif\"", html), f"{page.name}: no animation"
        assert (page.parent / re.search(r"src=\"([^\"]+\.gif)\"", html)[1]).stat().st_size > 10_000


def test_the_api_reference_has_a_page_per_listed_module(site):
    listed = re.findall(r"^   (msdlab[\w.]*)$", (DOCS / "api" / "index.md").read_text(), re.M)
    assert "msdlab.engine.simulation.simulation" in listed
    for module in listed:
        assert (site / "api" / "generated" / f"{module}.html").exists(), module


def test_the_msdlab_page_links_every_public_name_with_its_summary(site):
    """``msd.Body``, ``msd.Simulation``, ...: each name of ``msdlab.__all__`` links to where
    its module documents it, beside the first words of its docstring."""
    page = (site / "api" / "generated" / "msdlab.html").read_text(encoding="utf-8")
    text = html.unescape(re.sub(r"<[^>]+>", "", page))
    for name in msdlab.__all__:
        target = f"{getattr(msdlab, name).__module__}.{name}"
        assert f'href="{target.rsplit(".", 1)[0]}.html#{target}"' in page, name
        words = " ".join(inspect.getdoc(getattr(msdlab, name)).split()[:3])
        assert words in " ".join(text.split()), f"{name}: no summary ({words} ...)"
