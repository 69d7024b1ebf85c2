"""Names for the theme's fold buttons in the side navigation.

pydata-sphinx-theme folds a page's subpages in the left sidebar under a ``<summary>`` that
holds only a chevron icon: a screen reader announces a button without a name (WCAG 2.1
success criterion 4.1.2). Each such summary is named after the page whose subpages it
folds: "Pages under Blob".
"""

from __future__ import annotations

from bs4 import BeautifulSoup


def name_fold_buttons(soup: BeautifulSoup) -> None:
    """Name every summary without text in ``soup`` (the sidebar's HTML, parsed) after the
    link beside its ``<details>``."""
    for summary in soup.select("details > summary"):
        if summary.get_text(strip=True) or summary.has_attr("aria-label"):
            continue
        link = summary.parent.find_previous_sibling("a")
        title = link.get_text(" ", strip=True) if link else "this page"
        summary["aria-label"] = f"Pages under {title}"


def wrap_sidebar(app, pagename, templatename, context, doctree) -> None:
    """Wrap the theme's ``generate_toctree_html`` so the sidebar it gives names its fold
    buttons (it gives HTML, or the parsed tree it keeps for the next pages, named in
    place)."""
    generate = context.get("generate_toctree_html")
    if generate is None:
        return

    def named(kind: str, *args, **kwargs):
        sidebar = generate(kind, *args, **kwargs)
        if isinstance(sidebar, str):
            parsed = BeautifulSoup(sidebar, "html.parser")
            name_fold_buttons(parsed)
            return str(parsed)
        name_fold_buttons(sidebar)
        return sidebar

    context["generate_toctree_html"] = named


def setup(app) -> dict:
    # after the theme's own handler (priority 500) has put the function in the context
    app.connect("html-page-context", wrap_sidebar, priority=900)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
