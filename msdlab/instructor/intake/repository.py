"""A submission handed in as a git repository (GitHub Classroom), read as data by dulwich.

No git program runs in a student's repository: a repository's configuration can name
programs git runs (``gpg.program``, ``core.fsmonitor``, ``diff.external``, hooks) and a
crafted tree can name files anywhere. Here git's objects are read as data, and only:

- the repository's own ``.git`` folder is read: a ``.git`` file (``gitdir: …``) pointing
  outside the submission, a ``.git`` holding a symbolic link, borrowed objects
  (``objects/info/alternates``) or a shared ``commondir`` refuse the submission; its
  configuration is never read;
- ``HEAD`` is followed to a branch by name (``refs/…``, loose or packed), nowhere else;
- the commits are walked newest first to the last one made no later than the cutoff
  (`take_commit`); its time is the committer date, which the student's machine set;
- of that commit's tree, the regular files directly in the graded folder are written
  into the fresh folder; a name that is absolute, ``..`` or ``.git`` refuses the
  submission, and so does a name the graded folder's tree holds twice; links (mode
  120000) and submodules (160000) are left out, with a note;
- every object's size is read from its header before it is read (`git_objects`): a file
  larger than `fresh.MAX_FILE_BYTES` is left out unread, a tree or commit larger than
  `fresh.MAX_TOTAL_BYTES` makes the repository unreadable;
- a commit time no calendar can hold (year 0, past 9999) is an unreadable hand-in time;
  the commit's files are graded.
"""

from __future__ import annotations

import collections
import os
import re
import stat
import zlib
from datetime import datetime, timedelta, timezone
from pathlib import Path

from dulwich.errors import ObjectFormatException
from dulwich.objects import Blob, Commit, Tree
from dulwich.walk import Walker

from .fresh import MAX_FILE_BYTES, MAX_TOTAL_BYTES, FreshFolder, Refused, graded_folder
from .git_objects import BoundedStore
from .names import readable, unsafe_name
from .times import NAMES, STUDENT, HandIn, shown, unreadable

MAX_COMMITS = 10_000
_SHA = re.compile(rb"^[0-9a-f]{40}$")
_REF = re.compile(rb"^refs/[A-Za-z0-9._/-]+$")


class Unreadable(ValueError):
    """A repository with nothing to read (no commit, an empty or broken ``.git``)."""


def is_repository(folder: Path) -> bool:
    """Whether ``folder`` holds a ``.git`` (folder, file or link: each is looked at)."""
    return os.path.lexists(folder / ".git")


def take_commit(
    repository: Path, inside: str, fresh: FreshFolder, cutoff: datetime | None
) -> HandIn:
    """Write the files of the last commit no later than ``cutoff`` (None: HEAD's) in the
    folder ``inside`` (``assignments/``, '' the top) into ``fresh``; return the commit's
    time. Raises `Refused` or `Unreadable`."""
    git = _git_folder(repository)
    store = BoundedStore(git / "objects", MAX_TOTAL_BYTES)
    try:
        head = _head(git)
        commit, newest = _last_commit(store, head, cutoff)
        tree = _subtree(store, store[commit.tree], inside)
        part = graded_folder(
            lambda p: _names(store, tree, p)[0], lambda p: _names(store, tree, p)[1]
        )
        graded = _subtree(store, tree, part)
        _refuse_twins(graded)
        for name, mode, sha in graded.items():
            _take(store, name, mode, sha, fresh)
    except (KeyError, ObjectFormatException, ValueError, OSError, AssertionError,
            zlib.error) as error:  # fmt: skip
        if isinstance(error, (Refused, Unreadable)):
            raise
        raise Unreadable(f"its .git could not be read ({type(error).__name__}: {error})") from None
    finally:
        store.close()
    try:
        when = datetime.fromtimestamp(
            commit.commit_time, timezone(timedelta(seconds=commit.commit_timezone))
        )
    except (ValueError, OverflowError, OSError):
        return unreadable("git", f"the commit's time ({commit.commit_time} s, offset "
                          f"{commit.commit_timezone} s) is no date a calendar holds")  # fmt: skip
    note = None
    if commit.id != newest:
        note = (f"commits after the cutoff ignored; graded commit {commit.id.decode()[:10]} "
                f"of {shown(when, cutoff)}")  # fmt: skip
    return HandIn(when, NAMES["git"], STUDENT, note)


def unreadable_repository(why: str) -> HandIn:
    """The hand-in time of a repository with nothing to read."""
    return unreadable("git", why)


def _git_folder(repository: Path) -> Path:
    """The repository's own ``.git`` folder, or `Refused` if it leads elsewhere."""
    dot_git = repository / ".git"
    if dot_git.is_symlink():
        raise Refused(
            f"not graded: its .git is a symbolic link (to {readable(os.readlink(dot_git))})"
        )
    if dot_git.is_file():
        dot_git = _pointed_to(dot_git, repository)
    if not dot_git.is_dir():
        raise Unreadable("its .git is not a folder")
    for place, folders, files in os.walk(dot_git):
        for name in folders + files:
            if os.path.islink(os.path.join(place, name)):
                raise Refused(f"not graded: its .git holds a symbolic link ({readable(name)})")
    for borrowed in ("objects/info/alternates", "commondir", "objects/info/http-alternates"):
        if (dot_git / borrowed).exists():
            raise Refused(
                f"not graded: its .git borrows from another repository ({borrowed}); hand in "
                "a repository of its own (git clone without --shared or --reference)"
            )
    return dot_git


def _pointed_to(dot_git: Path, repository: Path) -> Path:
    """The folder a ``.git`` file names (``gitdir: …``), if it lies in the submission."""
    text = dot_git.read_bytes()[:4096].decode("utf-8", errors="replace").strip()
    target = text.removeprefix("gitdir:").strip()
    place = (repository / target).resolve()
    if not text.startswith("gitdir:") or not place.is_relative_to(repository.resolve()):
        raise Refused(
            f"not graded: its .git is a file naming another repository ({readable(text[:200])}), "
            "outside the submission; hand in the repository itself (git clone)"
        )
    return place


def _head(git: Path) -> bytes:
    """The commit HEAD names: directly, or through a branch ``refs/…`` (loose or packed)."""
    text = _small(git / "HEAD").strip()
    if _SHA.match(text):
        return text
    name = text.removeprefix(b"ref:").strip()
    if not text.startswith(b"ref:") or not _REF.match(name) or b".." in name:
        raise Unreadable("its HEAD names no branch")
    loose = git / os.fsdecode(name)
    if loose.is_file():
        sha = _small(loose).strip()
    else:
        packed = git / "packed-refs"
        lines = _small(packed).splitlines() if packed.is_file() else []
        sha = next((line.split()[0] for line in lines if line.split()[1:] == [name]), b"")
    if not _SHA.match(sha):
        raise Unreadable(f"its branch {name.decode()} has no commit")
    return sha


def _small(path: Path) -> bytes:
    """The first 64 KiB of ``path`` (a ref, HEAD, packed-refs), opened without a link."""
    handle = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    with os.fdopen(handle, "rb") as file:
        return file.read(65536)


def _last_commit(store: BoundedStore, head: bytes, cutoff: datetime | None) -> tuple[Commit, bytes]:
    """The commit graded (HEAD's, or the newest no later than ``cutoff``) and HEAD's id."""
    if cutoff is None:
        commit = store[head]
        if not isinstance(commit, Commit):
            raise Unreadable("its HEAD is not a commit")
        return commit, head
    bound = cutoff.timestamp()
    for entry in Walker(store, [head], order="date", max_entries=MAX_COMMITS):
        if entry.commit.commit_time <= bound:
            return entry.commit, head
    raise Unreadable(f"no commit made before the cutoff {cutoff.isoformat(timespec='minutes')}")


def _subtree(store: BoundedStore, tree: Tree, part: str) -> Tree:
    """The tree of the folder ``part`` (parts ending in ``/``) below ``tree``."""
    for name in filter(None, part.split("/")):
        entries = {os.fsdecode(e.path): e for e in tree.items()}
        entry = entries.get(name)
        if entry is None or not stat.S_ISDIR(entry.mode):
            raise Unreadable(f"the commit has no folder {part}")
        tree = store[entry.sha]
        if not isinstance(tree, Tree):
            raise Unreadable(f"{part} is not a folder in the commit")
    return tree


def _names(store: BoundedStore, tree: Tree, part: str) -> tuple[set[str], list[str]]:
    """The files and the folders directly in the folder ``part`` of ``tree``."""
    try:
        entries = _subtree(store, tree, part).items()
    except Unreadable:
        return set(), []
    files = {os.fsdecode(e.path) for e in entries if stat.S_ISREG(e.mode)}
    return files, sorted(os.fsdecode(e.path) for e in entries if stat.S_ISDIR(e.mode))


def _refuse_twins(tree: Tree) -> None:
    """Refuse a graded folder whose tree names one file twice (git itself never writes one;
    a parsed tree keeps only the last, so its raw entries are counted)."""
    raw, names, at = tree.as_raw_string(), [], 0
    while at < len(raw):
        space, end = raw.index(b" ", at), raw.index(b"\0", at)
        names.append(raw[space + 1 : end])
        at = end + 1 + 20
    counts = collections.Counter(names)
    twins = sorted(name for name, count in counts.items() if count > 1)
    if twins:
        name = readable(os.fsdecode(twins[0]))
        raise Refused(f"not graded: the commit's tree holds {name} {counts[twins[0]]} "
                      "times (which one was meant cannot be told)")  # fmt: skip


def _take(store: BoundedStore, path: bytes, mode: int, sha: bytes, fresh: FreshFolder) -> None:
    name = os.fsdecode(path)
    why = unsafe_name(name)
    if why is not None or "/" in name:
        raise Refused(f"not graded: the commit's tree holds {readable(name)!r}: {why or 'a path'}")
    if stat.S_ISLNK(mode):
        fresh.leave_out(name, "a symbolic link in the commit (links are not followed)")
    elif mode == 0o160000:
        fresh.leave_out(name, "a submodule (another repository) in the commit")
    elif stat.S_ISREG(mode) and store.size(sha) > MAX_FILE_BYTES:
        fresh.leave_out(name, f"larger than {MAX_FILE_BYTES} bytes, or stored in the "
                        "repository as a change to such an object (not read)")  # fmt: skip
    elif stat.S_ISREG(mode):
        blob = store[sha]
        if not isinstance(blob, Blob):
            raise Unreadable(f"{name} in the commit is not a file")
        fresh.add(name, blob.as_raw_string())
