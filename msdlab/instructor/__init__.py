"""What only instructors use: grading, the sandbox, the student release and the templates.

Not shipped to students (see `release_rules`):

- `templates`: make the student templates (``assignments/``) from the reference
  solutions (``solutions/``) by replacing each marked solution block.
- grading, one folder a stage, in the order a submission goes through them: `intake` (the
  one place that reads a hand-in: folder, zip, git repository or Gradescope upload, into a
  fresh folder of plain files, with whose it is and when it was handed in) → `judging`
  (each in its own workspace with a judge process and a sandbox for the submission's code)
  → `points` (the gradebook database) → `rules` (the term's rules: late work, manual
  changes, final points) → `outputs` (the grades file, feedback, summary, class report,
  similarity, exports, all rendered from the gradebook).
- `release_rules` and `release`: which files ship to students, and the bundle.
- `validate` and `trivial`: how strong the checks are: solutions, templates, answers
  without physics and mutants of the solutions (``msdlab validate``).
- `commands`: the ``msdlab templates``, ``grade``, ``export`` and ``release`` sub-commands.
"""
