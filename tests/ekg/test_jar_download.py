"""A Neo4j jar is downloaded whole (through robotale/files.py) or not at all, from a
repository reached by urllib (here a file:// Maven layout)."""

from __future__ import annotations

import hashlib
import os
import stat

import pytest
from tqdm import tqdm

from robotale.errors import ServerError
from robotale.neo4j_server.jars import Jar, _download

CONTENT = b"PK\x03\x04 not really a jar, but bytes with a checksum" * 100


@pytest.fixture
def repository(tmp_path):
    folder = tmp_path / "repo" / "org" / "example" / "tool" / "1.0"
    folder.mkdir(parents=True)
    (folder / "tool-1.0.jar").write_bytes(CONTENT)
    return (tmp_path / "repo").as_uri()


def jar(sha1: str) -> Jar:
    return Jar("org.example", "tool", "1.0", "", sha1, len(CONTENT))


def test_a_jar_with_the_pinned_checksum_arrives_whole_with_normal_permissions(tmp_path, repository):
    lib = tmp_path / "lib"
    lib.mkdir()
    with tqdm(disable=True) as progress:
        _download(jar(hashlib.sha1(CONTENT).hexdigest()), lib, repository, progress)
    assert (lib / "tool-1.0.jar").read_bytes() == CONTENT
    assert [p.name for p in lib.iterdir()] == ["tool-1.0.jar"]
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE((lib / "tool-1.0.jar").stat().st_mode) == 0o666 & ~umask


def test_a_wrong_checksum_leaves_the_folder_as_it_was(tmp_path, repository):
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "tool-1.0.jar").write_bytes(b"the copy already there")
    wrong = r"tool-1\.0\.jar has sha1 [0-9a-f]{40}, not the pinned"
    with pytest.raises(ServerError, match=wrong), tqdm(disable=True) as progress:
        _download(jar("0" * 40), lib, repository, progress)
    assert (lib / "tool-1.0.jar").read_bytes() == b"the copy already there"
    assert [p.name for p in lib.iterdir()] == ["tool-1.0.jar"]


def test_a_jar_the_repository_lacks_is_one_sentence_and_nothing_written(tmp_path, repository):
    lib = tmp_path / "lib"
    lib.mkdir()
    missing = Jar("org.example", "other", "2.0", "", "0" * 40, 1)
    failed = r"Could not download the Neo4j jar .*other-2\.0\.jar"
    with pytest.raises(ServerError, match=failed), tqdm(disable=True) as progress:
        _download(missing, lib, repository, progress)
    assert list(lib.iterdir()) == []
