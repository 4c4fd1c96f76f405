"""Whole-file writes: complete or unchanged, never a temporary file left, normal permissions."""

from __future__ import annotations

import os
import stat

import pytest

from robotale.errors import InputError
from robotale.files import atomic_file, write_file, write_files


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_text_and_bytes_arrive_whole_and_nothing_else_is_left(tmp_path):
    write_file(tmp_path / "a.txt", "grüße\n")
    write_file(tmp_path / "b.bin", b"\x00\x01")
    assert (tmp_path / "a.txt").read_text(encoding="utf-8") == "grüße\n"
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.bin"]


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_permissions_are_those_of_a_normally_created_file(tmp_path, mask):
    previous = os.umask(mask)
    try:
        with open(tmp_path / "plain", "w") as stream:  # what any program would create
            stream.write("x")
        write_file(tmp_path / "atomic", "x")
        with atomic_file(tmp_path / "streamed") as stream:
            stream.write("x")
        write_files([(tmp_path / "several", "x")])
    finally:
        os.umask(previous)
    expected = mode(tmp_path / "plain")
    assert [mode(tmp_path / n) for n in ("atomic", "streamed", "several")] == [expected] * 3


def test_a_failing_writer_leaves_the_old_file_untouched(tmp_path):
    target = tmp_path / "log.csv"
    target.write_text("old\n")
    with pytest.raises(RuntimeError), atomic_file(target) as stream:
        stream.write("half a ")
        raise RuntimeError("the writer failed")
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["log.csv"]


def test_several_files_change_together_or_not_at_all(tmp_path):
    first = tmp_path / "graph.dot"
    first.write_text("old\n")
    missing = tmp_path / "no such folder" / "graph.svg"
    with pytest.raises(InputError, match=r"no such folder/graph\.svg"):
        write_files([(first, "new\n"), (missing, "<svg/>")])
    assert first.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["graph.dot"]
    write_files([(first, "new\n"), (tmp_path / "graph.svg", "<svg/>")])
    assert first.read_text() == "new\n" and (tmp_path / "graph.svg").read_text() == "<svg/>"


def test_a_target_that_is_a_folder_fails_without_leftovers(tmp_path):
    (tmp_path / "out").mkdir()
    with pytest.raises(OSError):
        write_file(tmp_path / "out", "x")
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
