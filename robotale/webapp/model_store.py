"""The BPMN collaborations the Model page can show, kept in ``$ROBOTALE_HOME/models``.

A model is stored as ``<id>.bpmn`` where the id is derived from its content (uploading the
same file twice keeps one copy), with ``<id>.json`` holding the name it was uploaded under.
Only files the FAME parser reads are stored, so every stored model can be drawn and checked,
and only as :func:`sanitised` writes them again: without web content (XHTML, SVG, scripts,
event-handler attributes, processing instructions, a DOCTYPE), which a browser could run if it
opened the file on the dashboard's origin. The file as uploaded is kept too, in
``originals/<id>.bpmn``, for the verification alone (it reads the scripts the sanitised copy
lacks); nothing serves it. Two uploads that differ only in what sanitising removes share an
id, and the later one's original is kept.
``links.json`` remembers which model drove which log.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from lxml import etree

from robotale.errors import InputError, ModelError
from robotale.fame_runtime.parser import parse, parse_bytes
from robotale.fame_runtime.splitter import split
from robotale.files import write_file
from robotale.sim import scenarios
from robotale.webapp.settings import WebSettings

_ID = re.compile(r"[0-9a-f]{16}")
_LINKS = "links.json"
_ORIGINALS = "originals"
#: namespaces whose elements a browser renders or runs; BPMN never needs them
_WEB_NAMESPACES = frozenset(
    {
        "http://www.w3.org/1999/xhtml",
        "http://www.w3.org/2000/svg",
        "http://www.w3.org/1998/Math/MathML",
        "http://www.w3.org/1999/XSL/Transform",
        "http://www.w3.org/1999/xlink",
        "http://www.w3.org/2001/XInclude",
        "http://www.w3.org/XML/1998/namespace/events",
        "http://www.w3.org/2001/xml-events",
    }
)
#: element names that embed or run content in any namespace a browser knows
_WEB_ELEMENTS = frozenset({"script", "iframe", "object", "embed", "foreignobject", "style"})


@dataclass(frozen=True)
class StoredModel:
    id: str
    name: str
    path: Path
    pools: list[str]
    #: the file as uploaded (with its scripts), never served; ``path`` for a model stored
    #: before originals were kept
    original: Path


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
        shown = sanitised(data)
        model_id = hashlib.sha256(shown).hexdigest()[:16]
        (self.folder / _ORIGINALS).mkdir(parents=True, exist_ok=True)
        write_file(self.folder / _ORIGINALS / f"{model_id}.bpmn", data)
        write_file(self.folder / f"{model_id}.bpmn", shown)
        meta = {"name": name, "pools": pools}
        write_file(self.folder / f"{model_id}.json", json.dumps(meta).encode())
        return self.get(model_id)

    def get(self, model_id: str) -> StoredModel:
        path = self.folder / f"{model_id}.bpmn"
        if not _ID.fullmatch(model_id or "") or not path.is_file():
            raise InputError(f"There is no stored model {model_id!r}: upload the .bpmn file.")
        meta = json.loads((self.folder / f"{model_id}.json").read_text())
        original = self.folder / _ORIGINALS / f"{model_id}.bpmn"
        original = original if original.is_file() else path
        return StoredModel(model_id, meta["name"], path, meta["pools"], original)

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


def sanitised(data: bytes) -> bytes:
    """BPMN XML (already read by the FAME parser) written again without what a browser could
    run: web elements, web and script-URL attributes, processing instructions, comments,
    entity references and the DOCTYPE."""
    parser = etree.XMLParser(
        resolve_entities=False, no_network=True, remove_comments=True, remove_pis=True
    )
    root = etree.fromstring(data, parser)
    for node in list(root.iter()):
        if node is not root and (_is_web_element(node) or not isinstance(node.tag, str)):
            _remove(node)
    for element in root.iter(tag=etree.Element):
        for attribute in list(element.attrib):
            if _is_web_attribute(attribute, element.attrib[attribute]):
                del element.attrib[attribute]
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8")


def _is_web_element(node: etree._Element) -> bool:
    if not isinstance(node.tag, str):
        return False
    name = etree.QName(node)
    return name.namespace in _WEB_NAMESPACES or name.localname.lower() in _WEB_ELEMENTS


def _is_web_attribute(attribute: str, value: str) -> bool:
    name = etree.QName(attribute)
    # Event handlers and script URLs only run on web elements, which are gone; these would
    # make a BPMN element one again.
    return name.namespace in _WEB_NAMESPACES or value.strip().lower().startswith("javascript:")


def _remove(node: etree._Element) -> None:
    # Keep the text that follows the node (it belongs to the parent's content).
    parent = node.getparent()
    if parent is None:
        return
    if node.tail:
        previous = node.getprevious()
        if previous is not None:
            previous.tail = (previous.tail or "") + node.tail
        else:
            parent.text = (parent.text or "") + node.tail
    parent.remove(node)
