"""axe-core, the accessibility engine, run on a page open in headless Chromium.

Tests import it (``from accessibility import ...``, as `browser`). axe-core comes with
the ``axe-playwright-python`` package (its file ``axe.min.js``): nothing is fetched from
the network. The rules run are those of WCAG 2.1 levels A and AA.
"""

from __future__ import annotations

from browser import needs

WCAG_21_AA = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa"]
"""axe-core's tags of the success criteria of WCAG 2.0 and 2.1, levels A and AA."""
COLOUR_RULES = ("color-contrast", "link-in-text-block")
"""The rules that work out the colours of text (most of axe-core's time on a page): the
contrast of text, links told from the text around them."""

needs_axe = needs("playwright", "axe_playwright_python")
"""Marks skipping a test without Chromium, Playwright or axe-core."""


def axe_violations(
    page, colours: bool = True, context: object = None, best_practice: bool = False
) -> list[str]:
    """The WCAG 2.1 A and AA rules ``page`` breaks, one line per rule with the elements
    that break it (none: the page passes every rule axe-core can check). ``colours``:
    the `COLOUR_RULES` too (the slowest by far); ``context``: the part of the
    page to check (a CSS selector, or axe-core's include/exclude object; None: all);
    ``best_practice``: axe-core's rules of good practice too (landmarks, one h1, named
    table headers)."""
    from axe_playwright_python.base import AXE_SCRIPT

    page.evaluate(AXE_SCRIPT)
    options = {
        "runOnly": {"type": "tag", "values": WCAG_21_AA + ["best-practice"] * best_practice},
        "resultTypes": ["violations"],
        "rules": {rule: {"enabled": colours} for rule in COLOUR_RULES},
    }
    found = page.evaluate(
        "([context, options]) => axe.run(context ?? document, options)"
        ".then((results) => results.violations)",
        [context, options],
    )
    return [describe(violation) for violation in found]


def describe(violation: dict) -> str:
    """One rule's violation as a line: the rule, its impact, what it asks, the elements."""
    nodes = violation["nodes"]
    where = "; ".join(node["html"][:160] for node in nodes[:3])
    more = f" and {len(nodes) - 3} more" if len(nodes) > 3 else ""
    return (
        f"{violation['id']} ({violation['impact']}): {violation['help']}, "
        f"{len(nodes)} element(s): {where}{more}"
    )
