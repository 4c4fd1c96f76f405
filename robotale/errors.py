"""The one exception type a user can cause.

Every error a user can provoke (a bad file, a bad model, a server that is down) is raised as a
:class:`RobotaleError` whose message is one clear sentence naming the file, row or element id.
The command line prints that sentence and exits with status 1; nothing is half-written.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol


class RobotaleError(Exception):
    """A problem with the user's input or environment, explained in one sentence."""


class InputError(RobotaleError):
    """A file or value the user gave cannot be used (missing, malformed, wrong column ...)."""


class Located(Protocol):
    """Where one problem of a model is: its file, line, column (0: unknown) and element id,
    and the sentence saying what is wrong there."""

    @property
    def file(self) -> str: ...

    @property
    def line(self) -> int: ...

    @property
    def column(self) -> int: ...

    @property
    def element(self) -> str: ...

    @property
    def sentence(self) -> str: ...

    def as_dict(self) -> dict[str, object]:
        """The fields by name, as JSON reports give them."""
        ...


class ModelError(RobotaleError):
    """A BPMN model cannot be parsed, checked or run; the message names the element id.

    ``problems`` are the same problems with their fields, for those who point at them (the
    dashboard, ``robotale fame check --json``); empty when the model was read and a running
    engine found the problem."""

    def __init__(self, sentence: str, *, problems: Sequence[Located] = ()) -> None:
        super().__init__(sentence)
        self.problems: tuple[Located, ...] = tuple(problems)


class ServerError(RobotaleError):
    """Neo4j (or another server robotale needs) cannot be reached or started."""


class LogNotFound(InputError):
    """No event log of that name is stored in Neo4j; ``hint`` says where to find or get one."""

    def __init__(self, name: str, hint: str | None = None) -> None:
        self.name, self.hint = name, hint or "see `robotale logs list`"
        super().__init__(f"There is no log named {name!r} in Neo4j ({self.hint}).")


def require_range(
    value: float, option: str, low: float, high: float = float("inf"), unit: str = ""
) -> float:
    """``value`` of the command-line ``option`` if it is a number from ``low`` to ``high``;
    otherwise an :class:`InputError` naming the option (argparse takes ``nan`` and ``-5``)."""
    if not low <= value <= high:  # also false for nan
        wanted = f"of at least {low:g}" if high == float("inf") else f"from {low:g} to {high:g}"
        raise InputError(f"{option} {value:g} is not usable: give a number {wanted}{unit}.")
    return value
