"""What only instructors use: grading, the sandbox, the student release and the templates.

Not shipped to students (see `release_rules`):

- `templates`: make the student templates (``assignments/``) from the reference
  solutions (``solutions/``) by replacing each marked solution block.
- grading, in the order a submission goes through it: `intake` (the one place that reads
  a hand-in: folder, zip, git repository or Gradescope upload, into a fresh folder of
  plain files, with whose it is and when it was handed in) → `grading` (each in its own
  workspace with a judge process and a `sandbox` for the submission's code; `wire` is
  their data format, `pytest_sandbox` the judge's pytest plugin) → the points
  (`gradebook_db`, `gradebook`) → the term's rules (`late`, `adjustments`,
  `final_points`) → the outputs (`render`, `feedback`, `class_report`, `similarity`,
  `export`).
- `release_rules` and `release`: which files ship to students, and the bundle.
- `validate` and `trivial`: how strong the checks are: solutions, templates, answers
  without physics and mutants of the solutions (``msdlab validate``).
- `late`, `adjustments` and `final_points`: due dates and late penalties, manual changes
  that last, and each row's final points; `export`: the grades for Canvas, Moodle or a
  spreadsheet.
- `commands`: the ``msdlab templates``, ``grade``, ``export`` and ``release`` sub-commands.
"""
