"""A sphinx-gallery scraper for the animations a gallery example writes.

An example saves its animation with `msdlab.viz.save_animation` to a GIF in the folder it
runs in; this scraper moves each new GIF next to the example's pictures and shows it on
the example's page, after the pictures of the same code block.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from sphinx_gallery.scrapers import figure_rst


def animation_scraper(block, block_vars, gallery_conf) -> str:
    """Move the GIFs the code block wrote into the gallery's images; return their reST."""
    moved = []
    for gif in sorted(Path.cwd().glob("*.gif")):
        target = Path(next(block_vars["image_path_iterator"])).with_suffix(".gif")
        shutil.move(gif, target)
        moved.append(str(target))
    return figure_rst(moved, gallery_conf["src_dir"])
