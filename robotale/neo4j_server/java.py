"""The Java a Neo4j release runs on, found on this machine when the server starts.

Each release runs on a range of Java feature versions (5.26 on 17 to 21, the 2025 and later
releases on 21 to 25). :func:`find_java` looks, in this order, at ``JAVA_HOME``, the ``java``
on the ``PATH`` and the JDKs installed where systems put them (:data:`JVM_ROOTS`), and takes
the first whose version the release runs on. A Java home's version is read from its
``release`` file, or asked of the executable where there is none.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from robotale.errors import ServerError

#: folders whose subfolders are Java homes (Debian and Red Hat, Oracle's RPMs, SDKMAN, macOS)
JVM_ROOTS = (
    Path("/usr/lib/jvm"),
    Path("/usr/java"),
    Path("/opt/java"),
    Path("~/.sdkman/candidates/java").expanduser(),
    Path("/Library/Java/JavaVirtualMachines"),
)
_RELEASE_VERSION = re.compile(r'^JAVA_VERSION="(\d+)', re.MULTILINE)
_SAID_VERSION = re.compile(r'version "(\d+)(?:\.(\d+))?')


@dataclass(frozen=True)
class Java:
    executable: Path
    #: the feature version: 17, 21, 25 ...
    version: int


def find_java(lowest: int, highest: int, what: str) -> Java:
    """The first Java found whose feature version is ``lowest`` to ``highest``; ``what``
    names the release in the sentence that says none was."""
    seen: list[Java] = []
    for executable in _candidates():
        version = java_version(executable)
        if version is None:
            continue
        java = Java(executable, version)
        if lowest <= version <= highest:
            return java
        if java not in seen:
            seen.append(java)
    found = ", ".join(f"Java {java.version} ({java.executable})" for java in seen) or "none"
    raise ServerError(
        f"{what} needs Java {lowest} to {highest} and none was found (found: {found}); install "
        f"one (Debian: openjdk-{lowest}-jre-headless) or point JAVA_HOME at it, or set "
        "NEO4J_URI to use another server."
    )


def java_version(executable: Path) -> int | None:
    """The feature version of the Java ``executable`` (None when it is none)."""
    if not executable.is_file():
        return None
    home = executable.resolve().parent.parent
    release = home / "release"
    if release.is_file():
        match = _RELEASE_VERSION.search(release.read_text(errors="replace"))
        if match:
            return _feature(int(match.group(1)), None)
    try:
        said = subprocess.run(
            [str(executable), "-version"], capture_output=True, text=True, timeout=60, check=False
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    match = _SAID_VERSION.search(said.stderr + said.stdout)
    if match is None:
        return None
    return _feature(int(match.group(1)), match.group(2))


def _feature(major: int, minor: str | None) -> int:
    # Java 8 and older call themselves 1.8
    return int(minor) if major == 1 and minor else major


def _candidates() -> Iterator[Path]:
    java_home = os.environ.get("JAVA_HOME")
    if java_home:
        yield Path(java_home) / "bin" / "java"
    on_path = shutil.which("java")
    if on_path:
        yield Path(on_path)
    for root in JVM_ROOTS:
        if not root.is_dir():
            continue
        for home in sorted(root.iterdir(), reverse=True):
            yield home / "bin" / "java"
            yield home / "Contents" / "Home" / "bin" / "java"  # macOS bundles
