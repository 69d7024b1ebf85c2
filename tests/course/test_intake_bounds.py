"""The intake's bounds and rules as an attacker or an unlucky student meets them: a small
repository of a huge object, a commit of a time no calendar holds, a zip of thousands of
entries, duplicate, encrypted and broken entries, a library raising on one hand-in. Each
hand-in's row says what could not be read; the rest of the class is taken in."""

from __future__ import annotations

import hashlib
import stat
import struct
import subprocess
import tracemalloc
import zipfile
import zlib
from datetime import datetime, timezone
from pathlib import Path

import pytest
from dulwich.objects import Blob, Commit, Tree
from dulwich.pack import write_pack_index
from dulwich.repo import Repo

from msdlab.course import PROJECT_ROOT
from msdlab.instructor import intake
from msdlab.instructor.intake import archive, fresh, git_objects, submissions

TASK1 = (PROJECT_ROOT / "solutions" / "task1.py").read_bytes()
HUGE = 30_000_000  # inflated bytes of zeros: a few tens of kB in a pack or a loose object


def commit_of(folder: Path, files: dict[bytes, bytes] | list[tuple[bytes, bytes]], time: int,
              packed: bool) -> None:  # fmt: skip
    """A repository at ``folder`` of one commit of ``files`` (a list may name one twice)
    in ``assignments/`` made at ``time`` (seconds since 1970), its objects loose or in one
    pack."""
    folder.mkdir(parents=True)
    repo = Repo.init(str(folder))
    pairs = files if isinstance(files, list) else list(files.items())
    named = [(name, Blob.from_string(content)) for name, content in pairs]
    raw = b"".join(b"100644 " + name + b"\0" + blob.sha().digest() for name, blob in named)
    inner = Tree.from_raw_string(Tree.type_num, raw)
    top = Tree()
    top.add(b"assignments", stat.S_IFDIR, inner.id)
    commit = Commit()
    commit.tree, commit.parents, commit.message = top.id, [], b"work\n"
    commit.author = commit.committer = b"Student <student@example.org>"
    commit.author_time = commit.commit_time = time
    commit.author_timezone = commit.commit_timezone = 0
    objects = [*(blob for _, blob in named), inner, top, commit]
    if packed:
        repo.object_store.add_objects([(obj, None) for obj in objects])
    else:
        for obj in objects:
            repo.object_store.add_object(obj)
    repo.refs[b"refs/heads/master"] = commit.id


def taken_alone(path: Path, identifier: str = "alice") -> tuple[intake.Entry, list[str]]:
    """The entry of ``path`` taken in alone, and the names of the files it took."""
    with intake.Intake() as found:
        entry = found.add(identifier, path)
        files = sorted(p.name for p in entry.folder.iterdir()) if not entry.problem else []
    return entry, files


@pytest.mark.parametrize("packed", [True, False], ids=["packed", "loose"])
def test_a_huge_git_object_is_left_out_by_its_header_before_it_is_read(tmp_path, packed):
    now = int(datetime(2027, 3, 1, tzinfo=timezone.utc).timestamp())
    commit_of(tmp_path / "mallory", {b"task1.py": TASK1, b"task2.py": bytes(HUGE)}, now, packed)
    tracemalloc.start()
    try:
        entry, files = taken_alone(tmp_path / "mallory" / "assignments", "mallory")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert entry.problem is None and files == ["task1.py"]
    assert any("task2.py was left out: larger than" in note for note in entry.notes)
    assert peak < HUGE / 10, f"the intake allocated {peak} bytes for a {HUGE}-byte object"


def test_a_repository_git_packed_into_deltas_is_read_by_its_headers(tmp_path):
    clone = tmp_path / "alice"
    (clone / "assignments").mkdir(parents=True)
    git = ["git", "-C", str(clone), "-c", "user.name=A", "-c", "user.email=a@b"]
    subprocess.run([*git[:3], "init", "-q"], check=True)
    text = TASK1 * 40
    for version in range(4):  # versions of one file: git stores them as deltas
        text += f"# version {version}\n".encode()
        (clone / "assignments" / "task1.py").write_bytes(text)
        subprocess.run([*git, "add", "."], check=True)
        subprocess.run([*git, "commit", "-qm", f"v{version}"], check=True)
    subprocess.run([*git, "gc", "-q", "--aggressive"], check=True)
    store = git_objects.BoundedStore(clone / ".git" / "objects", fresh.MAX_TOTAL_BYTES)
    for sha in store:
        assert store.size(sha) >= len(store[sha].as_raw_string())
    entry, files = taken_alone(clone)
    assert entry.problem is None and files == ["task1.py"] and not entry.notes


def test_a_delta_naming_itself_as_its_base_is_refused_not_followed_forever(tmp_path):
    itself = bytes(range(20))
    delta = zlib.compress(b"\x05\x05\x90\x05")  # base 5 bytes, result 5: copy them
    pack = b"PACK" + struct.pack(">II", 2, 1) + bytes([0x70 | 4]) + itself + delta
    pack += hashlib.sha1(pack).digest()
    (tmp_path / "pack").mkdir()
    (tmp_path / "pack" / "pack-x.pack").write_bytes(pack)
    with (tmp_path / "pack" / "pack-x.idx").open("wb") as index:
        write_pack_index(index, [(itself, 12, 0)], hashlib.sha1(pack[:-20]).digest())
    store = git_objects.BoundedStore(tmp_path, fresh.MAX_TOTAL_BYTES)
    with pytest.raises(git_objects.TooLarge, match="a delta chain longer than"):
        store[itself]


def test_a_commit_time_no_calendar_holds_is_unreadable_and_the_class_taken_in(tmp_path):
    commit_of(tmp_path / "class" / "mallory", {b"task1.py": TASK1}, 2**40, packed=False)
    (tmp_path / "class" / "bob").mkdir()
    (tmp_path / "class" / "bob" / "task1.py").write_bytes(TASK1)
    paths = [tmp_path / "class" / "mallory", tmp_path / "class" / "bob"]
    with intake.from_paths(paths) as found:
        mallory, bob = found.entries
        assert mallory.problem is None and (mallory.folder / "task1.py").read_bytes() == TASK1
        assert mallory.handed_in.time is None and mallory.handed_in.control == "unreadable"
        assert "no date a calendar holds" in mallory.handed_in.note
        assert bob.problem is None and bob.handed_in.time is not None


def test_a_commit_naming_one_file_twice_is_refused_with_the_name(tmp_path):
    twice = [(b"task1.py", TASK1), (b"task1.py", b"raise SystemExit\n")]
    commit_of(tmp_path / "mallory", twice, 1_800_000_000, packed=False)
    entry, _ = taken_alone(tmp_path / "mallory", "mallory")
    assert "the commit's tree holds task1.py 2 times" in entry.problem


def test_whatever_a_library_raises_on_one_hand_in_is_its_row_only(tmp_path, monkeypatch):
    def broken(*args: object) -> None:
        raise KeyError("a library's own failure")

    monkeypatch.setattr(submissions, "take_zip", broken)
    with zipfile.ZipFile(tmp_path / "mallory.zip", "w") as bundle:
        bundle.writestr("task1.py", TASK1)
    (tmp_path / "bob").mkdir()
    (tmp_path / "bob" / "task1.py").write_bytes(TASK1)
    with intake.from_paths([tmp_path / "mallory.zip", tmp_path / "bob"]) as found:
        mallory, bob = found.entries
        assert mallory.problem.startswith("not graded: mallory.zip could not be read (KeyError")
        assert bob.problem is None


def test_a_zip_of_thousands_of_entries_is_refused_from_its_end_record(tmp_path):
    with zipfile.ZipFile(tmp_path / "bomb.zip", "w") as bundle:
        bundle.writestr("task1.py", TASK1)
        for number in range(archive.MAX_ENTRIES + 1):
            bundle.writestr(f"{'x' * 600}{number}.py", b"")  # a directory of 3.3 MB
    entry, _ = taken_alone(tmp_path / "bomb.zip")
    assert f"holds {archive.MAX_ENTRIES + 2} entries" in entry.problem
    data = (tmp_path / "bomb.zip").read_bytes()  # its end record made to say 1 entry
    end = data.rindex(b"PK\x05\x06")
    (tmp_path / "liar.zip").write_bytes(data[: end + 8] + b"\x01\x00\x01\x00" + data[end + 12 :])
    entry, _ = taken_alone(tmp_path / "liar.zip")
    assert "holds 1 entries in a directory of" in entry.problem


def test_files_left_out_are_counted_in_a_few_notes_not_one_each(tmp_path):
    with zipfile.ZipFile(tmp_path / "many.zip", "w") as bundle:
        bundle.writestr("task1.py", TASK1)
        for number in range(fresh.MAX_FILES + 100):
            bundle.writestr(f"helper{number:03}.py", b"x = 1\n")
    entry, files = taken_alone(tmp_path / "many.zip")
    assert entry.problem is None and len(files) == fresh.MAX_FILES
    assert len(entry.notes) == fresh.MAX_NOTES + 1
    assert entry.notes[-1].startswith(f"and {101 - fresh.MAX_NOTES} more files left out (")


def test_a_zip_naming_one_file_twice_is_refused_with_the_name(tmp_path):
    with zipfile.ZipFile(tmp_path / "twice.zip", "w") as bundle, pytest.warns(UserWarning):
        bundle.writestr("task1.py", TASK1)
        bundle.writestr("task1.py", b"raise SystemExit\n")
    entry, _ = taken_alone(tmp_path / "twice.zip")
    assert "holds task1.py 2 times" in entry.problem


def encrypted(data: bytes, name: bytes) -> bytes:
    """The zip ``data`` with the entry ``name`` marked encrypted (its flag's bit 0), in its
    local header and its central directory record."""
    out = bytearray(data)
    for signature, flags, name_at in ((b"PK\x03\x04", 6, 30), (b"PK\x01\x02", 8, 46)):
        at = out.find(signature)
        while at >= 0:
            if out[at + name_at : at + name_at + len(name)] == name:
                out[at + flags] |= 0x1
            at = out.find(signature, at + 1)
    return bytes(out)


def test_encrypted_and_broken_entries_are_left_out_and_the_rest_taken(tmp_path):
    with zipfile.ZipFile(tmp_path / "odd.zip", "w") as bundle:
        bundle.writestr("task1.py", TASK1)
        bundle.writestr("task2.py", b"encrypted, says its header")
        bundle.writestr("task3.py", b"# a stored entry whose bytes change\n")
    data = encrypted((tmp_path / "odd.zip").read_bytes(), b"task2.py")
    (tmp_path / "odd.zip").write_bytes(data.replace(b"whose bytes change", b"whose BYTES CHANGE"))
    entry, files = taken_alone(tmp_path / "odd.zip")
    assert entry.problem is None and files == ["task1.py"]
    assert any(n.startswith("task2.py was left out: encrypted") for n in entry.notes)
    assert any(n.startswith("task3.py was left out: could not be read") for n in entry.notes)
