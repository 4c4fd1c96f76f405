"""Where a call activity's called element comes from (guideline G2.1.1, building blocks).

A called element is, in this order: a Python skill given to the engine, a process of the same
file, or a process of a library folder of .bpmn building blocks. In the folder, ``GoTo`` is
looked up first as the file ``GoTo.bpmn`` (its process with that id or name, else its only
process), then as a process id, process name or pool name in any file of the folder.
"""

from __future__ import annotations

from pathlib import Path

from robotale.errors import ModelError
from robotale.fame_runtime.model import Definitions, Process
from robotale.fame_runtime.parser import parse


class Library:
    """A folder of .bpmn building blocks, parsed on first use."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise ModelError(f"the building-block library {self.folder} is not a folder")
        self._files: dict[Path, Definitions] = {}

    def __repr__(self) -> str:
        return f"Library({str(self.folder)!r})"

    def definitions(self, path: Path) -> Definitions:
        if path not in self._files:
            self._files[path] = parse(path)
        return self._files[path]

    def find(self, name: str) -> Process | None:
        """The building block called ``name``, or None."""
        own_file = self.folder / f"{name}.bpmn"
        if own_file.is_file():
            found = find_process(self.definitions(own_file), name)
            processes = list(self.definitions(own_file).processes.values())
            return found or (processes[0] if len(processes) == 1 else None)
        for path in sorted(self.folder.glob("*.bpmn")):
            found = find_process(self.definitions(path), name)
            if found is not None:
                return found
        return None


def resolve_call(name: str, caller: Process, library: Library | None) -> Process | None:
    """The process a call activity of ``caller`` calls by ``name``: one of the caller's file,
    else a building block of the library (skills are matched before, by the caller)."""
    if not name:
        return None
    found = find_process(caller.definitions, name) if caller.definitions else None
    if found is None and library is not None:
        found = library.find(name)
    return found


def find_process(definitions: Definitions, name: str) -> Process | None:
    """The process of a file whose id, name or pool name is ``name``."""
    if name in definitions.processes:
        return definitions.processes[name]
    for process in definitions.processes.values():
        if process.name == name:
            return process
    for pool, process in definitions.pools():
        if pool.name == name:
            return process
    return None
