"""Uploads: the extension and the content must agree, names are ours, archives unpack safely."""

from __future__ import annotations

import io
import os
import shutil
import time
import zipfile

import pytest

from robotale.errors import InputError
from robotale.webapp import uploads


def test_a_csv_is_stored_under_a_generated_name(tmp_path, thesis_csv):
    with thesis_csv.open("rb") as stream:
        upload = uploads.save(stream, "../../etc/robotic data.csv", tmp_path)
    assert upload.kind == "csv" and upload.path.parent == tmp_path
    assert upload.path.name == f"{upload.token}.csv" and len(upload.token) == 32
    assert upload.path.read_bytes() == thesis_csv.read_bytes()
    assert upload.suggested_name == "robotic data"
    assert uploads.find(tmp_path, upload.token).path == upload.path
    uploads.discard(upload)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("filename", "content", "message"),
    [
        ("log.txt", b"a,b\n1,2\n", "is not an event log robotale reads"),
        ("log.exe", b"MZ", "is not an event log robotale reads"),
        ("log.csv", b"", "is empty"),
        ("log.csv", b"\x89PNG\r\n\x1a\n\0\0", "is not a text file"),
        ("log.csv", b"just one column\nvalue\n", "header line of comma-separated"),
        ("log.xes", b"time,activity\n", "is not an XES document"),
        ("bags.zip", b"PK not really", "is not a zip archive"),
    ],
)
def test_content_must_match_the_extension(tmp_path, filename, content, message):
    with pytest.raises(InputError, match=message):
        uploads.save(io.BytesIO(content), filename, tmp_path)
    assert list(tmp_path.iterdir()) == []  # nothing half-written


def test_an_xes_document_is_accepted(tmp_path):
    xes = b'\xef\xbb\xbf<?xml version="1.0"?>\n<log xes.version="1.0"></log>'
    assert uploads.save(io.BytesIO(xes), "Run.XES", tmp_path).kind == "xes"


def test_tokens_that_are_not_ours_find_nothing(tmp_path):
    (tmp_path / "secret.csv").write_text("a,b\n")
    for token in ("../secret", "secret", "", "0" * 31):
        with pytest.raises(InputError, match="upload the file again"):
            uploads.find(tmp_path, token)


def zipped(entries: dict[str, bytes], links: tuple[str, ...] = ()) -> io.BytesIO:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in entries.items():
            archive.writestr(name, data)
        for name in links:
            info = zipfile.ZipInfo(name)
            info.external_attr = 0o120777 << 16
            archive.writestr(info, "target")
    buffer.seek(0)
    return buffer


def test_a_bag_folder_unpacks_in_place(tmp_path):
    archive = zipped({"runs/run_0001/metadata.yaml": b"x", "runs/run_0001/run.mcap": b"y"})
    upload = uploads.save(archive, "runs.zip", tmp_path)
    folder = uploads.unpack(upload, limit_bytes=1000)
    assert (folder / "runs" / "run_0001" / "run.mcap").read_bytes() == b"y"
    assert folder.parent == tmp_path


@pytest.mark.parametrize(
    ("entries", "links", "message"),
    [
        ({"../evil.txt": b"x"}, (), "unsafe path"),
        ({"/etc/evil.txt": b"x"}, (), "unsafe path"),
        ({"ok.txt": b"x"}, ("run/link",), "holds a link"),
        ({"big.bin": b"0" * 5000}, (), "unpacks to 0 MB, more than the limit"),
    ],
)
def test_unsafe_or_oversized_archives_are_refused(tmp_path, entries, links, message):
    upload = uploads.save(zipped(entries, links), "bags.zip", tmp_path)
    with pytest.raises(InputError, match=message):
        uploads.unpack(upload, limit_bytes=1000)
    assert [p.name for p in tmp_path.iterdir()] == [upload.path.name]  # no folder left over


def test_stale_uploads_are_removed(tmp_path, thesis_csv):
    with thesis_csv.open("rb") as stream:
        old = uploads.save(stream, "old.csv", tmp_path)
    with thesis_csv.open("rb") as stream:
        fresh = uploads.save(stream, "fresh.csv", tmp_path)
    (tmp_path / "notes.txt").write_text("not an upload")
    day_ago = time.time() - 2 * uploads.STALE_AFTER
    os.utime(old.path, (day_ago, day_ago))
    os.utime(tmp_path / "notes.txt", (day_ago, day_ago))
    assert uploads.remove_stale(tmp_path) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([fresh.path.name, "notes.txt"])


def _zip_of_zeros(path, megabytes: int) -> None:
    # written in pieces: the archive's content is never in memory at once
    with (
        zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as archive,
        archive.open("run/zeros.bin", "w", force_zip64=True) as member,
    ):
        for _ in range(megabytes):
            member.write(bytes(2**20))


def test_a_zip_bomb_writes_nothing_past_the_limit(tmp_path, small_disk):
    bomb = tmp_path / "bomb.zip"
    _zip_of_zeros(bomb, 1024)  # 1 GB of zeros in about 1 MB
    assert bomb.stat().st_size < 2 * 2**20
    disk = small_disk("16m")  # far less than the bomb, more than the archive
    with bomb.open("rb") as stream:
        upload = uploads.save(stream, "bomb.zip", disk)
    with pytest.raises(InputError) as refused:
        uploads.unpack(upload, limit_bytes=10 * 2**30)
    assert str(refused.value) == "'bomb.zip' unpacks to 1024 MB, more than the limit of 64 MB."
    assert [p.name for p in disk.iterdir()] == [upload.path.name]


def test_an_archive_larger_than_the_free_disk_is_refused_before_unpacking(small_disk):
    disk = small_disk("8m")
    entries = {"run/noise.bin": os.urandom(5 * 2**20)}  # does not compress
    upload = uploads.save(zipped(entries), "noise.zip", disk)
    free = shutil.disk_usage(disk).free
    with pytest.raises(InputError) as refused:
        uploads.unpack(upload, limit_bytes=2**30)
    assert str(refused.value) == (
        f"Unpacking 'noise.zip' needs 5 MB, but the disk of {disk} has "
        f"{free / 2**20:.1f} MB free.".replace(".0 MB", " MB")
    )
    assert [p.name for p in disk.iterdir()] == [upload.path.name]
