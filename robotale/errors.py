"""The one exception type a user can cause.

Every error a user can provoke (a bad file, a bad model, a server that is down) is raised as a
:class:`RobotaleError` whose message is one clear sentence naming the file, row or element id.
The command line prints that sentence and exits with status 1; nothing is half-written.
"""


class RobotaleError(Exception):
    """A problem with the user's input or environment, explained in one sentence."""


class InputError(RobotaleError):
    """A file or value the user gave cannot be used (missing, malformed, wrong column ...)."""


class ModelError(RobotaleError):
    """A BPMN model cannot be parsed, checked or run; the message names the element id."""


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
