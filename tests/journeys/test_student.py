"""A student's week, walked as the student walks it, from the bundle the instructor releases.

``msdlab release`` → a fresh virtual environment → the release README's quick-start
commands as written → task 2: a wrong answer in ``assignments/task2.py`` is named by
``msdlab check 2`` and by the check cell of the task-2 notebook in JupyterLab (headless
Chromium); fixed, it gets full marks; an error raised in the student's code names their
file and line; a scene's live view opens in JupyterLab and a particle can be dragged.

One module-scoped walk (the environment and the bundle are made once) and one test per
step, in the order the student meets them. Slow, and run in CI with everything else:
14 min 44 s on 2 cores shared with a load average of 15 to 19 (most of it the first
compile of ``msdlab demo``, the checks and the notebook); a quiet machine takes a small
part of that.
"""

from __future__ import annotations

import re
from contextlib import contextmanager
from pathlib import Path

import pytest
from browser import jupyterlab_server, launch, needs, run_notebook, wait_until
from harness import ROOT, Terminal, quick_start, release

pytestmark = pytest.mark.timeout(900)

SOLUTION = ROOT / "solutions" / "task2.py"
TODO = re.compile(r"    raise NotImplementedError\(\n.*?\n    \)\n", re.S)
"""The template's to-do in ``spring_acceleration``, which the student replaces."""

WRONG = """\
    a = np.zeros_like(x)
    for axis in range(3):
        i = [slice(None)] * 3
        j = [slice(None)] * 3
        i[axis], j[axis] = slice(None, -1), slice(1, None)
        d = x[tuple(i)] - x[tuple(j)]
        length = np.linalg.norm(d, axis=-1, keepdims=True)
        f = stiffness * (1.0 - length) * d / length  # rest length 1
        a[tuple(i)] += f
        a[tuple(j)] -= f
    return a
"""
RIGHT = WRONG.replace("(1.0 - length)", "(spacing - length)").replace(
    "d / length", "np.divide(d, length, out=np.zeros_like(d), where=length > 0)"
)
RAISING = WRONG.replace("a[tuple(i)] += f\n", "a[tuple(i)] += f[..., :2]  # one short\n")
MISTAKE = "rest length 1 in world units"
"""What the checks call the wrong answer's mistake."""


@pytest.fixture(scope="module")
def course(tmp_path_factory) -> Path:
    """The student's copy of the released bundle."""
    return release(tmp_path_factory.mktemp("student") / "course")


@pytest.fixture(scope="module")
def terminal(tmp_path_factory) -> Terminal:
    return Terminal(tmp_path_factory.mktemp("terminal"))


@pytest.fixture(scope="module")
def template(course) -> str:
    """assignments/task2.py as released."""
    return (course / "assignments" / "task2.py").read_text()


def answer(course: Path, template: str, body: str) -> int:
    """Write ``body`` as the student's spring_acceleration; the line number of its first line."""
    (course / "assignments" / "task2.py").write_text(TODO.sub(body, template, count=1))
    return template[: TODO.search(template).start()].count("\n") + 1


def plain(text: str) -> str:
    """``text`` with its lines joined: a message wrapped to the terminal reads as one line."""
    return " ".join(text.split())


def needing(*packages: str):
    """Skip the test (saying why) without Chromium or ``packages``."""

    def decorate(test):
        for mark in needs(*packages):
            test = mark(test)
        return test

    return decorate


def test_the_release_readmes_quick_start_works_as_written(course, terminal):
    commands = quick_start(course / "README.md")
    assert commands, "the README has no quick-start commands"
    typed = [terminal.type(command, course) for command in commands]
    for done in typed[:-1]:
        assert done.status == 0, done
    demo = next(done for done in typed if "msdlab demo" in done.command)
    assert "animation:" in demo.output and "energy plot:" in demo.output, demo
    check = typed[-1]
    assert "msdlab check" in check.command
    # nothing written yet: every check is a to-do
    assert check.status == 1 and "to do in assignments/" in check.output, check
    assert "Traceback" not in check.output


def test_a_wrong_answer_is_named_by_msdlab_check(course, terminal, template):
    answer(course, template, WRONG)
    check = terminal.type("msdlab check 2", course)
    assert check.status == 1, check
    assert str(course / "assignments") in check.output  # the student's files, said so
    assert MISTAKE in plain(check.output), check


@needing("jupyterlab", "playwright")
def test_the_notebooks_check_cell_names_it_then_gives_full_marks(course, terminal, template):
    answer(course, template, WRONG)
    with notebook_page(course, terminal) as (page, url, token):
        run_notebook(page, url, token, "notebooks/task2.ipynb")
        # the check's total line: the plots' words above it have lines "- total: ..." too
        text = wait_for_output(page, "/13 points")  # (JupyterLab draws only cells in view)
        assert "checks of task 2 on assignments:" in text and "reference answers" not in text
        assert MISTAKE in plain(text)
        answer(course, template, RIGHT)
        page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
        text = wait_for_output(page, "total: 13/13 points")
        assert "Traceback" not in text


def test_fixed_it_gets_full_marks_from_msdlab_check(course, terminal, template):
    answer(course, template, RIGHT)
    check = terminal.type("msdlab check 2", course)
    assert check.status == 0, check
    assert "total: 13/13 points" in check.output


def test_an_error_in_the_students_code_names_their_file_and_line(course, terminal, template):
    first = answer(course, template, RAISING)
    line = first + RAISING.splitlines().index("        a[tuple(i)] += f[..., :2]  # one short")
    check = terminal.type("msdlab check 2", course)
    assert check.status == 1, check
    assert f"assignments/task2.py, line {line}, in spring_acceleration" in check.output, check
    assert "a[tuple(i)] += f[..., :2]  # one short" in check.output
    for hypothesis_words in ("Failing test case", "Falsifying example", "generated value"):
        assert hypothesis_words not in check.output


@needing("jupyterlab", "ipympl", "playwright")
def test_a_scenes_live_view_opens_and_a_particle_can_be_dragged(terminal, tmp_path):
    from viz.test_live_notebook import test_a_dragged_particle_follows_the_mouse_in_jupyterlab

    with jupyterlab_server(tmp_path, python=terminal.python) as server:
        test_a_dragged_particle_follows_the_mouse_in_jupyterlab(server, tmp_path)


# ----------------------------------------------------------------------------- the browser
@contextmanager
def notebook_page(course: Path, terminal: Terminal):
    """JupyterLab of the student's environment serving their course folder, and a page of
    headless Chromium on it: (page, url, token)."""
    from playwright.sync_api import sync_playwright

    home = terminal.home / "jupyter"
    home.mkdir(exist_ok=True)
    with (
        jupyterlab_server(home, python=terminal.python, root=course) as (url, token),
        sync_playwright() as playwright,
    ):
        browser = launch(playwright)
        page = browser.new_page(viewport={"width": 1400, "height": 1200})
        page.set_default_timeout(120_000)
        try:
            yield page, url, token
        except BaseException:
            page.screenshot(path=terminal.home / "notebook.png")
            raise
        finally:
            browser.close()


def wait_for_output(page, text: str, seconds: float = 300) -> str:
    """All the notebook's output text, once it shows ``text``; a cell's traceback (which
    stops "run all" before the check cell) fails at once, showing it."""

    def shown() -> str:
        outputs = "\n".join(page.locator(".jp-OutputArea-output").all_inner_texts())
        assert "Traceback (most recent call last)" not in outputs, outputs[-3000:]
        return outputs if text in outputs else ""

    return wait_until(shown, seconds, f"the notebook showing {text!r}")
