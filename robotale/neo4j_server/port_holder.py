"""Which process holds a TCP port, from Linux's /proc (nothing to install, no root needed for
one's own processes); elsewhere the answer is simply unknown."""

from __future__ import annotations

import os
from pathlib import Path

_PROC = Path("/proc")
_LISTEN = "0A"  # the state column of /proc/net/tcp
_BOUND_STATES = {_LISTEN, "07"}  # listening, or bound and closed (a socket not yet listening)


def port_holder(port: int) -> str | None:
    """``"<command> (pid N)"`` of the process whose socket holds ``port``, ``"a process of
    another user"`` when the socket is there but its owner cannot be seen, None when unknown."""
    inodes = _socket_inodes(port)
    if not inodes:
        return None
    for pid in _pids():
        if _holds_any(pid, inodes):
            return f"{_command(pid)} (pid {pid})"
    return "a process of another user"


def _socket_inodes(port: int) -> set[str]:
    inodes = set()
    for table in ("tcp", "tcp6"):
        try:
            lines = (_PROC / "net" / table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            local_port = int(fields[1].rsplit(":", 1)[1], 16)
            # Sockets of ended connections (TIME_WAIT) have inode 0 and block nobody who binds
            # with SO_REUSEADDR, as Neo4j does.
            if local_port == port and fields[3] in _BOUND_STATES and fields[9] != "0":
                inodes.add(fields[9])
    return inodes


def _pids() -> list[int]:
    try:
        return [int(entry.name) for entry in _PROC.iterdir() if entry.name.isdigit()]
    except OSError:
        return []


def _holds_any(pid: int, inodes: set[str]) -> bool:
    wanted = {f"socket:[{inode}]" for inode in inodes}
    try:
        descriptors = os.listdir(_PROC / str(pid) / "fd")
    except OSError:  # another user's process, or it just ended
        return False
    for descriptor in descriptors:
        try:
            if os.readlink(_PROC / str(pid) / "fd" / descriptor) in wanted:
                return True
        except OSError:
            continue
    return False


def _command(pid: int) -> str:
    try:
        return (_PROC / str(pid) / "comm").read_text().strip() or "a process"
    except OSError:
        return "a process"
