"""The BPMN collaborations the Model page can show, kept in ``$ROBOTALE_HOME/models``.

A model is stored as ``<id>.bpmn`` where the id is derived from its content (uploading the
same file twice keeps one copy), with ``<id>.json`` holding the name it was uploaded under.
Only files the FAME parser reads are stored, so every stored model can be drawn and checked.
``links.json`` remembers which model drove which log.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from robotale.errors import InputError, ModelError
from robotale.fame_runtime.parser import parse, parse_bytes
from robotale.fame_runtime.splitter import split
from robotale.files import write_file
from robotale.sim import scenarios
from robotale.webapp.settings import WebSettings

_ID = re.compile(r"[0-9a-f]{16}")
_LINKS = "links.json"


@dataclass(frozen=True)
class StoredModel:
    id: str
    name: str
    path: Path
    pools: list[str]


class ModelStore:
    def __init__(self, folder: Path) -> None:
        self.folder = folder

    def add(self, data: bytes, filename: str) -> StoredModel:
        """Check ``data`` with the FAME parser and store it; a ``ModelError`` if it is no model."""
        name = PurePosixPath(filename.replace("\\", "/")).name or "model.bpmn"
        if not name.lower().endswith(".bpmn"):
            raise InputError(f"{name!r} is not a .bpmn file.")
        try:
            definitions = parse_bytes(data, name)
        except ModelError as error:
            raise InputError(str(error)) from None
        pools = [pool.name for pool, _ in definitions.pools()]
        if not pools:
            raise InputError(f"{name!r} holds no process to show.")
        model_id = hashlib.sha256(data).hexdigest()[:16]
        self.folder.mkdir(parents=True, exist_ok=True)
        write_file(self.folder / f"{model_id}.bpmn", data)
        meta = {"name": name, "pools": pools}
        write_file(self.folder / f"{model_id}.json", json.dumps(meta).encode())
        return StoredModel(model_id, name, self.folder / f"{model_id}.bpmn", pools)

    def get(self, model_id: str) -> StoredModel:
        path = self.folder / f"{model_id}.bpmn"
        if not _ID.fullmatch(model_id or "") or not path.is_file():
            raise InputError(f"There is no stored model {model_id!r}: upload the .bpmn file.")
        meta = json.loads((self.folder / f"{model_id}.json").read_text())
        return StoredModel(model_id, meta["name"], path, meta["pools"])

    def all(self) -> list[StoredModel]:
        if not self.folder.is_dir():
            return []
        found = [self.get(p.stem) for p in self.folder.glob("*.bpmn") if _ID.fullmatch(p.stem)]
        return sorted(found, key=lambda model: model.name.lower())

    def add_shipped(self) -> list[StoredModel]:
        """Store the mission models of the scenarios robotale ships (agri, rexdingo)."""
        return [self.add(p.read_bytes(), p.name) for p in sorted(scenarios.FOLDER.glob("*.bpmn"))]

    def matching(self, robots: list[str]) -> StoredModel | None:
        """The first stored model whose pools bind all of ``robots`` (as the splitter would)."""
        for model in self.all():
            try:
                split(parse(model.path), robots)
            except ModelError:
                continue
            return model
        return None

    def link(self, log: str, model_id: str) -> None:
        """Remember that ``model_id`` drove ``log``."""
        self.get(model_id)
        links = self._links()
        links[log] = model_id
        self.folder.mkdir(parents=True, exist_ok=True)
        write_file(self.folder / _LINKS, json.dumps(links, indent=1).encode())

    def linked(self, log: str) -> StoredModel | None:
        model_id = self._links().get(log)
        try:
            return self.get(model_id) if model_id else None
        except InputError:
            return None

    def _links(self) -> dict[str, str]:
        path = self.folder / _LINKS
        return json.loads(path.read_text()) if path.is_file() else {}


def attach_model(log: str, model: Path, folder: Path | None = None) -> StoredModel:
    """Remember that the BPMN file ``model`` drove ``log``, for the Model page (scripts and
    ``robotale demo`` call it after storing a log; ``folder`` defaults to the dashboard's)."""
    if folder is None:
        folder = WebSettings.from_env().model_dir
    store = ModelStore(folder)
    stored = store.add(Path(model).read_bytes(), Path(model).name)
    store.link(log, stored.id)
    return stored
