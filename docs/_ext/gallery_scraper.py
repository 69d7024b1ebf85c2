"""sphinx-gallery scrapers: the pictures of a gallery example, with words a reader without
the picture gets, and the animations it writes, playing only when the reader asks.

An example saves its animation with `msdlab.viz.save_animation` to a GIF in the folder it
runs in; `animation_scraper` moves each new GIF next to the example's pictures and shows it
on the example's page, after the pictures of the same code block, folded in a
``<details>`` element: it plays when opened and stops when closed (an animation longer
than 5 s must be one a reader can stop, WCAG 2.1 success criterion 2.2.2).

`picture_scraper` is sphinx-gallery's matplotlib scraper with a text alternative saying what
the picture shows: the scene, its particles and springs, the time, and the strains its
colours stand for, in numbers.
"""

from __future__ import annotations

import html
import re
import shutil
from pathlib import Path

from sphinx_gallery.scrapers import matplotlib_scraper

ANIMATION_RST = """
.. raw:: html

   <details class="msdlab-animation"><summary>{summary}</summary>

.. image:: {path}
   :alt: {alt}

.. raw:: html

   </details>
"""


def picture_scraper(block, block_vars, gallery_conf) -> str:
    """The example's matplotlib pictures (sphinx-gallery's scraper), each with the text
    alternative `described` gives where the example has a scene and its simulation."""
    rst = matplotlib_scraper(block, block_vars, gallery_conf)
    words = described(block_vars["example_globals"])
    return re.sub(r":alt: .*", lambda _: f":alt: {words}", rst) if words else rst


def described(example: dict) -> str | None:
    """What a picture of the example's ``scene`` and ``sim`` shows, in words and numbers;
    None where the example has neither."""
    from msdlab.viz.view import strains

    scene, sim = example.get("scene"), example.get("sim")
    if scene is None or sim is None:
        return None
    body = sim.body
    words = (
        f"{scene.name} after {sim.time:.4g} {scene.unit}: {_count(body.n_particles, 'particle')}"
        f", {_count(body.n_springs, 'spring')}"
    )
    if scene.colour == "strain" and body.n_springs:
        strain = strains(body.edges(), body.positions)
        words += (
            " drawn by strain (thick orange stretched, dashed blue squeezed),"
            f" from {strain.min():+.2%} to {strain.max():+.2%}"
        )
    elif body.n_springs:
        words += " coloured by their depth below the rim"
    return words


def _count(number: int, thing: str) -> str:
    return f"{number} {thing}{'s' if number != 1 else ''}"


def animation_scraper(block, block_vars, gallery_conf) -> str:
    """Move the GIFs the code block wrote into the gallery's images; return their reST,
    each folded behind a button-like summary naming its frames and length."""
    rst = []
    for gif in sorted(Path.cwd().glob("*.gif")):
        target = Path(next(block_vars["image_path_iterator"])).with_suffix(".gif")
        shutil.move(gif, target)
        frames, seconds = _length(target)
        scene = block_vars["example_globals"].get("scene")
        about = f"the run of {scene.name}: {scene.description}" if scene else "the run"
        path = "/" + target.relative_to(gallery_conf["src_dir"]).as_posix()
        summary = f"Play the animation ({frames} frames, {seconds:.0f} s, repeating)"
        alt = f"Animation of {about}".replace("\n", " ")
        rst.append(ANIMATION_RST.format(summary=html.escape(summary), path=path, alt=alt))
    return "".join(rst)


def _length(gif: Path) -> tuple[int, float]:
    """The frames of ``gif`` and how long one pass through them takes (s)."""
    from PIL import Image

    with Image.open(gif) as image:
        durations = []
        for frame in range(image.n_frames):
            image.seek(frame)
            durations.append(image.info.get("duration", 0))
    return len(durations), sum(durations) / 1000
