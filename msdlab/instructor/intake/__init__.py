"""The intake: the one place that reads what students hand in, outside the sandbox.

A hand-in (a folder, a zip file, a git repository, Gradescope's upload) becomes a fresh
folder of plain files and the evidence about it: whose it is (from the roster) and when
it was handed in, with who controls that record. Nothing of a hand-in is executed or
followed: no link, no name leading out of its folder, no git program in a student's
repository (git's objects are read as data). The grader, ``msdlab similarity`` and the
gradebook read the fresh folders only.

- `submissions`: `Entry`, `Intake`, `from_paths`, `from_roster`: the class taken in;
- `roster`: the roster file, the source of every student's id;
- `folder`, `archive`, `repository`: each form of hand-in, read without trusting it;
- `fresh`: the fresh folder and its bounds;
- `times`: hand-in times and who controls them;
- `names`: ids and file names checked, escaped, made into file stems.
"""

from .fresh import BUNDLE_FOLDER, LEFT_OUT, MAX_FILE_BYTES
from .names import MAX_POINTS_ID, MAX_STEM, escaped, file_stem, readable, unescaped
from .submissions import (
    NOT_ON_ROSTER,
    NOTHING_HANDED_IN,
    Entry,
    Intake,
    Rules,
    from_paths,
    from_roster,
    taken_in,
    task_files,
)
from .times import SOURCES, UNVERIFIED_POLICIES, HandIn

__all__ = [
    "BUNDLE_FOLDER", "LEFT_OUT", "MAX_FILE_BYTES", "MAX_POINTS_ID", "MAX_STEM",
    "NOTHING_HANDED_IN", "NOT_ON_ROSTER", "SOURCES",
    "UNVERIFIED_POLICIES", "Entry", "HandIn", "Intake", "Rules", "escaped", "file_stem",
    "from_paths", "from_roster", "readable", "taken_in", "task_files", "unescaped",
]  # fmt: skip
