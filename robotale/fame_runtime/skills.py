"""Skills: robot capabilities written in Python that call activities invoke.

A skill takes simulated time. The engine calls it with the robot handle, the call activity's
inputs and a ``done`` callback, and goes on running the robot's other tokens (event
sub-processes, timers) meanwhile. The skill acts only through topics and the clock (publish
``cmd_vel``, subscribe to ``odom`` ...), never through the simulator, so the same skill drives
a real robot. When it finishes it calls ``done(outputs)``; the outputs become process
variables. If the engine interrupts the activity (an interrupting event, a terminate, a
process replaced at run time) it calls the cancel function the skill returned, which must
leave the robot safe (stop the wheels, close the blade).

Topic names: signals are global topics named after the signal (``/weed_position``); a robot's
own topics live in its namespace (``/tractor_1/odom``, ``/tractor_1/cmd_vel``), and so do error
events (``/tractor_1/low_battery``, ``std_msgs/msg/Empty``).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol

from robotale.errors import ModelError
from robotale.fame_runtime.bus import Bus, Envelope, Subscription
from robotale.fame_runtime.clock import Clock


class Robot(Protocol):
    """What a skill and a script see of the robot they run on."""

    name: str  # the robot's namespace: drone, tractor_1
    robot_type: str  # its pool: Drone, Tractor
    bus: Bus
    clock: Clock

    @property
    def variables(self) -> Mapping[str, Any]:
        """The process variables, read-only for skills."""
        ...

    def topic(self, name: str) -> str:
        """``name`` inside the robot's namespace (``odom`` -> ``/tractor_1/odom``)."""
        ...

    def publish(self, topic: str, data: Any, msgtype: str) -> Envelope: ...

    def subscribe(
        self, topic: str, callback: Callable[[Envelope], None], msgtype: str | None = None
    ) -> Subscription: ...


#: ``done(outputs)`` ends the activity; ``done(BpmnError(name))`` throws a BPMN error from it
Done = Callable[[Mapping[str, Any] | None], None]
Cancel = Callable[[], None]


class Skill(Protocol):
    def __call__(self, robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel | None: ...


def load_skills(module_name: str) -> dict[str, Skill]:
    """The skills a module offers: its ``SKILLS`` mapping of called-element name to skill.

    ``robotale fame run --skills mymodule`` uses this, so a user's own skills are a plain
    Python module on the path (or in the current folder), or a ``.py`` file given by its path.
    """
    module = _import(module_name)
    skills = getattr(module, "SKILLS", None)
    if not isinstance(skills, Mapping):
        raise ModelError(
            f"the skills module {module_name!r} has no SKILLS mapping of name to skill"
        )
    return dict(skills)


def _import(module_name: str) -> ModuleType:
    path = Path(module_name)
    try:
        if path.suffix == ".py" and path.is_file():
            spec = importlib.util.spec_from_file_location(path.stem, path)
            assert spec is not None and spec.loader is not None  # a .py file has both
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            return module
        if "" not in sys.path and str(Path.cwd()) not in sys.path:
            sys.path.insert(0, str(Path.cwd()))
        return importlib.import_module(module_name)
    except ImportError as error:
        raise ModelError(f"cannot import the skills module {module_name!r}: {error}") from error
