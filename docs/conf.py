"""Sphinx configuration of msdlab's documentation (builds offline: no CDN, no web fonts)."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))

os.environ.setdefault("MPLBACKEND", "Agg")
# The gallery's scenes are small: the numpy kernel runs them without compiling the numba one.
os.environ.setdefault("MSDLAB_KERNEL", "numpy")

project = "msdlab"
author = "the msdlab authors"
copyright = "msdlab authors, MIT licence"
release = "0.1.0"

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "architecture",
    "docstrings",
    "public_names",
    "sidebar_names",
]

# scenes/ holds the gallery's sources; gallery/ its generated pages, whose .ipynb downloads
# are not pages of the site, nor are timing tables (they load their styles from a CDN).
exclude_patterns = [
    "_build",
    "**.ipynb_checkpoints",
    "scenes",
    "gallery/*.ipynb",
    "**sg_execution_times.rst",
]
default_role = "py:obj"  # `name` links to the API where it can, plain code otherwise

# MyST: $...$ maths, ::: fences, heading anchors for [text](page.md#anchor) links.
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# docs/notebooks/ holds the notebooks run with their text outputs (notebooks/build.py); the
# site shows them as they are instead of running them again (`pytest` runs them with nbval).
nb_execution_mode = "off"

# MathJax 2 from Debian's libjs-mathjax (.ci/run installs it), the few files a page uses
# copied beside the site, so that pages load nothing from the network. Without it the
# formulas show as their TeX source.
MATHJAX = Path("/usr/share/javascript/mathjax")
MATHJAX_FILES = [
    "MathJax.js",
    "config/TeX-AMS_CHTML.js",
    "extensions",
    "jax/element",
    "jax/input/TeX",
    "jax/output/CommonHTML",
    "fonts/HTML-CSS/TeX/woff",
]
LOCAL_MATHJAX = DOCS / "_mathjax"


def copy_mathjax() -> None:
    for name in MATHJAX_FILES:
        source, target = MATHJAX / name, LOCAL_MATHJAX / "mathjax" / name
        if target.exists() or not source.exists():
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        if source.is_dir():
            shutil.copytree(source, target)
        else:
            shutil.copyfile(source, target)


copy_mathjax()
html_static_path = ["_static", str(LOCAL_MATHJAX)]
mathjax_path = "mathjax/MathJax.js?config=TeX-AMS_CHTML"
# MathJax 2 reads these class names (myst-nb marks its pages for MathJax 3's names).
mathjax2_config = {
    "tex2jax": {
        "processClass": "tex2jax_process|mathjax_process|math|output_area",
        "ignoreClass": "tex2jax_ignore|mathjax_ignore",
    }
}

sphinx_gallery_conf = {
    "examples_dirs": "scenes",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/scene_",
    # pictures with a text alternative in numbers, animations folded until played
    "image_scrapers": ("gallery_scraper.picture_scraper", "gallery_scraper.animation_scraper"),
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "show_signature": False,
    "within_subsection_order": "FileNameSortKey",
    "write_computation_times": False,
    "capture_repr": (),
}

# The API reference: one page per module (docs/api/index.md lists them), made at build time.
autosummary_generate = True
templates_path = ["_templates"]
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_preserve_defaults = True

html_theme = "pydata_sphinx_theme"
html_title = "msdlab"
html_logo = "_static/jelly.png"
html_favicon = "_static/jelly.png"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "header_links_before_dropdown": 6,
    "footer_start": ["copyright"],
    "footer_end": [],
    "secondary_sidebar_items": ["page-toc"],
    "use_edit_page_button": False,
}
# accessibility.css: the gallery's thumbnail links keep their names for screen readers
html_css_files = ["accessibility.css"]
html_show_sourcelink = False
html_copy_source = False
