"""ROS 2 interface definitions: the files users give, and those robotale ships.

A definition file's types are named by where it lives, as in a ROS package:
``my_pkg/msg/Event.msg`` defines ``my_pkg/msg/Event``, ``my_pkg/srv/Plan.srv`` a service's
request, response and service-event message (``my_pkg/srv/Plan_Event``, what rosbag2 records
of a service with introspection on), ``my_pkg/action/Dock.action`` an action's goal, result,
feedback and feedback topic message (``my_pkg/action/Dock_FeedbackMessage``).

robotale ships the definitions robot bags most often hold without any (a Humble-era sqlite3
bag stores none, and rosbag2 stores none for action types): Nav2's behaviour-tree log, its
navigation action, std_srvs' services. They are data files under ``definitions/`` (the
README there names their sources and licences), laid out by distribution where they differ:
``definitions/all/`` for every distribution, ``definitions/<distro>/`` for that distribution
and those after it. rosbags' own store already has std_msgs,
geometry_msgs, nav_msgs, sensor_msgs, action_msgs, lifecycle_msgs and diagnostic_msgs.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rosbags.interfaces import Nodetype
from rosbags.typesys import TypesysError, get_types_from_idl, get_types_from_msg

from robotale.errors import InputError

if TYPE_CHECKING:
    from rosbags.interfaces.typing import FieldDesc, Typesdict

#: the shipped definitions
SHIPPED = Path(__file__).parent / "definitions"
#: the ROS 2 distributions in release order (those rosbags knows, and rolling last)
RELEASES = (
    "dashing",
    "eloquent",
    "foxy",
    "galactic",
    "humble",
    "iron",
    "jazzy",
    "kilted",
    "lyrical",
    "rolling",
)
EXTENSIONS = ("msg", "srv", "action", "idl")
_SEPARATOR = re.compile(r"^---[ \t]*$", flags=re.MULTILINE)


def message_types(paths: Sequence[Path]) -> Typesdict:
    """Type definitions from ``.msg`` / ``.srv`` / ``.action`` / ``.idl`` files, or folders
    holding them."""
    typs: Typesdict = {}
    for path in paths:
        files = (
            [f for ext in EXTENSIONS for f in sorted(path.rglob(f"*.{ext}"))]
            if path.is_dir()
            else [path]
        )
        if not files:
            raise InputError(f"{path} holds no .msg, .srv, .action or .idl files.")
        for file in files:
            typs.update(types_from_file(file))
    return typs


def types_from_file(file: Path) -> Typesdict:
    """The types one definition file defines (an error naming the file if it cannot)."""
    if not file.is_file():
        raise InputError(f"Message definition {file} does not exist.")
    try:
        text = file.read_text(encoding="utf-8")
        if file.suffix == ".idl":
            return get_types_from_idl(text)
        kind, package = file.parent.name, file.parent.parent.name
        if file.suffix == ".action" and kind == "action":
            return action_types(text, package, file.stem)
        if file.suffix == ".srv" and kind == "srv":
            return service_types(text, package, file.stem)
        if file.suffix == ".msg" and kind == "msg":
            return get_types_from_msg(text, f"{package}/msg/{file.stem}")
        raise InputError(
            f"Cannot tell the type name of {file}: put it at <package>/msg/<Type>.msg "
            "(or <package>/srv/<Service>.srv, <package>/action/<Action>.action)."
        )
    except (TypesysError, UnicodeDecodeError) as error:
        reason = " ".join(str(error).split())
        raise InputError(f"Message definition {file} cannot be parsed: {reason}") from None


def action_types(text: str, package: str, action: str) -> Typesdict:
    """The types of an action's ``.action`` file (goal, result and feedback, split by ``---``)
    and of the feedback topic's message, which wraps the feedback with the goal's id, as
    rosidl generates them: ``<package>/action/<action>_Goal`` ... ``_FeedbackMessage``.

    rosbag2 stores no definition for these (its search for them knows ``msg`` and ``srv``
    only), so a bag's action feedback is read with the action's own file.
    """
    parts = _SEPARATOR.split(text)
    if len(parts) != 3:
        raise TypesysError(f"an action has a goal, a result and a feedback, not {len(parts)} parts")
    prefix = f"{package}/action/{action}"
    typs: Typesdict = {}
    for suffix, part in zip(("_Goal", "_Result", "_Feedback"), parts, strict=True):
        typs.update(get_types_from_msg(part, prefix + suffix))
    wrapper = f"unique_identifier_msgs/UUID goal_id\n{prefix}_Feedback feedback\n"
    typs.update(get_types_from_msg(wrapper, f"{prefix}_FeedbackMessage"))
    return _in_msg_folder(typs, package, "action")


def service_types(text: str, package: str, service: str) -> Typesdict:
    """The types of a service's ``.srv`` file (request and response, split by ``---``) and
    of its service-event message, as rosidl generates them (ROS 2 Iron and later):
    ``<package>/srv/<service>_Request``, ``_Response`` and ``_Event``, which records one call
    or reply with ``service_msgs/msg/ServiceEventInfo`` and at most one of each."""
    parts = _SEPARATOR.split(text)
    if len(parts) != 2:
        raise TypesysError(f"a service has a request and a response, not {len(parts)} parts")
    prefix = f"{package}/srv/{service}"
    typs: Typesdict = {}
    for suffix, part in zip(("_Request", "_Response"), parts, strict=True):
        typs.update(get_types_from_msg(part, prefix + suffix))
    event = (
        f"service_msgs/ServiceEventInfo info\n{prefix}_Request[<=1] request\n"
        f"{prefix}_Response[<=1] response\n"
    )
    typs.update(get_types_from_msg(event, f"{prefix}_Event"))
    return _in_msg_folder(_srv_names(typs), package, "srv")


def _srv_names(typs: Typesdict) -> Typesdict:
    """``typs`` with the names rosbags' parser gives service types (it knows ``msg`` and
    ``action`` folders only: ``pkg/srv/msg/X``) made ``pkg/srv/X``."""

    def name(text: str) -> str:
        return text.replace("/srv/msg/", "/srv/", 1)

    return {
        name(key): (consts, [(field, _renamed(desc, name)) for field, desc in fields])
        for key, (consts, fields) in typs.items()
    }


def _in_msg_folder(typs: Typesdict, package: str, kind: str) -> Typesdict:
    """``typs`` with their references to types of the package that are not their own
    (written without a package in the file, read as ``<package>/<kind>/X``) made
    ``<package>/msg/X``, where ROS looks for them."""
    own = set(typs)

    def moved(name: str) -> str:
        if name.startswith(f"{package}/{kind}/") and name not in own:
            return name.replace(f"/{kind}/", "/msg/", 1)
        return name

    return {
        name: (consts, [(field, _renamed(desc, moved)) for field, desc in fields])
        for name, (consts, fields) in typs.items()
    }


def _renamed(desc: FieldDesc, rename: Callable[[str], str]) -> FieldDesc:
    """A field's descriptor with the message type it refers to (its own, or its elements')
    renamed."""
    if desc[0] == Nodetype.NAME:
        return (Nodetype.NAME, rename(desc[1]))
    if desc[0] == Nodetype.ARRAY or desc[0] == Nodetype.SEQUENCE:
        element, size = desc[1]
        if element[0] == Nodetype.NAME:
            element = (Nodetype.NAME, rename(element[1]))
        return (desc[0], (element, size))
    return desc


def stored_types(data: str, msgtype: str) -> Typesdict:
    """The types of a definition rosbag2 stored in ``.msg`` form: the type's text, then each
    type it uses after a line of ``=`` and ``MSG: <name>``; for a service-event type the
    service's ``.srv`` text after ``SRV: <name>`` (what rosbag2 stores for those)."""
    separator = "=" * 80 + "\n"
    parts = data.split(separator)
    typs: Typesdict = {}
    if parts[0].strip():
        typs.update(get_types_from_msg(parts[0], msgtype))
    for part in parts[1:]:
        head, _, body = part.partition("\n")
        kind, _, name = head.partition(": ")
        if kind == "MSG":
            typs.update(get_types_from_msg(body, name.strip()))
        elif kind == "SRV":
            package, _, service = name.strip().partition("/srv/")
            typs.update(service_types(body, package, service))
        else:
            raise TypesysError(f"a stored definition has a part headed {head!r}")
    return typs


def normalized(msgtype: str) -> str:
    """A type name as ROS 2 writes it: ``pkg/Type`` (the old style some bags record, and ROS
    1's) is ``pkg/msg/Type``."""
    parts = msgtype.split("/")
    return f"{parts[0]}/msg/{parts[1]}" if len(parts) == 2 and all(parts) else msgtype


def definition_file(msgtype: str) -> str:
    """The file that defines ``msgtype``, where a ROS package keeps it: an action's types
    come from its ``.action`` file, a service's from its ``.srv`` file."""
    package, _, rest = msgtype.partition("/") if "/" in msgtype else ("my_pkg", "", msgtype)
    kind, _, name = rest.rpartition("/")
    if kind == "action":
        stem = re.sub(r"_(Goal|Result|Feedback|FeedbackMessage)$", "", name)
        return f"{package}/action/{stem}.action"
    if kind == "srv":
        stem = re.sub(r"_(Request|Response|Event)$", "", name)
        return f"{package}/srv/{stem}.srv"
    return f"{package}/msg/{name}.msg"


@functools.lru_cache(maxsize=16)
def shipped(distro: str) -> Typesdict:
    """The definitions robotale ships for a distribution: ``all/``, then the latest
    distribution folder at or before ``distro`` overriding it."""
    rank = RELEASES.index(distro) if distro in RELEASES else RELEASES.index("humble")
    layers = [SHIPPED / "all"]
    for release in RELEASES[: rank + 1]:
        if (SHIPPED / release).is_dir():
            layers.append(SHIPPED / release)
    typs: Typesdict = {}
    for layer in layers:
        typs.update(message_types([layer]))
    return typs
