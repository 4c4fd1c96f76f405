"""Checking a YAML file that people write by hand: each value of the type it must have, and
each mistake one :class:`~robotale.errors.InputError` naming the file and the key.

Nothing here knows what the file describes: :mod:`robotale.sim.worldspec` checks a world
with it, another file kind can too.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import yaml

from robotale.errors import InputError

Range = tuple[float, float]


def load_yaml(path: Path, what: str) -> Any:
    """The YAML document of ``path`` (``what`` names it in an error: "the world file")."""
    try:
        return yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(f"{path}: cannot read {what} ({error.strerror})") from None
    except yaml.YAMLError as error:
        raise InputError(f"{path}: not valid YAML ({_yaml_problem(error)})") from None


def _yaml_problem(error: yaml.YAMLError) -> str:
    mark = getattr(error, "problem_mark", None)
    problem = getattr(error, "problem", None) or "syntax error"
    return f"{problem} at line {mark.line + 1}" if mark else problem


class YamlChecker:
    """The checks of one file's values; every error names the file and where in it."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, where: str, message: str) -> InputError:
        return InputError(f"{self.path}: {where} {message}")

    def known(self, data: Mapping[str, Any], where: str, keys: Iterable[str]) -> None:
        unknown = sorted(set(data) - set(keys))
        if unknown:
            raise self.fail(
                where,
                f"has unknown key {', '.join(map(repr, unknown))} "
                f"(known: {', '.join(sorted(keys))})",
            )

    def flag(self, value: Any, where: str) -> bool:
        if not isinstance(value, bool):
            raise self.fail(where, f"is {value!r}; it must be true or false")
        return value

    def mapping(self, value: Any, where: str) -> Mapping[str, Any]:
        if value is None:
            return {}
        if not isinstance(value, Mapping):
            raise self.fail(where, f"must be a mapping of names to values, not {value!r}")
        return value

    def signals(self, value: Any, where: str) -> tuple[str, ...]:
        names = self.sequence(value, where)
        for name in names:
            if not isinstance(name, str) or not name.strip("/"):
                raise self.fail(where, f"holds {name!r}; it must list signal names")
        return tuple(name.strip("/") for name in names)

    def sequence(self, value: Any, where: str) -> list[Any]:
        if not isinstance(value, list):
            raise self.fail(where, f"must be a list, not {value!r}")
        return value

    def number(self, value: Any, where: str, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(where, f"is {value!r}, not a number")
        if positive and value <= 0:
            raise self.fail(where, f"is {value!r}; it must be positive")
        if value < 0:
            raise self.fail(where, f"is {value!r}; it must not be negative")
        return float(value)

    def numbers(self, value: Any, where: str, length: int) -> tuple[float, ...]:
        if not isinstance(value, list | tuple) or len(value) != length:
            raise self.fail(where, f"is {value!r}; it must be a list of {length} numbers")
        out = []
        for item in value:
            if isinstance(item, bool) or not isinstance(item, int | float):
                raise self.fail(where, f"is {value!r}; it must be a list of {length} numbers")
            out.append(float(item))
        return tuple(out)

    def pair(self, value: Any, where: str, positive: bool = False) -> tuple[float, float]:
        pair = self.numbers(value, where, 2)
        if positive and min(pair) <= 0:
            raise self.fail(where, f"is {value!r}; both numbers must be positive")
        return pair  # type: ignore[return-value]

    def triple(self, value: Any, where: str) -> tuple[float, float, float]:
        return self.numbers(value, where, 3)  # type: ignore[return-value]

    def color(self, value: Any, where: str) -> tuple[float, float, float, float]:
        if isinstance(value, list | tuple) and len(value) == 3:
            value = [*value, 1.0]
        return self.numbers(value, where, 4)  # type: ignore[return-value]

    def range(self, value: Any, where: str) -> Range:
        """``x`` or ``[low, high]``."""
        if isinstance(value, list | tuple):
            low, high = self.numbers(value, where, 2)
        else:
            low = high = self.number(value, where)
        if low > high or low < 0:
            raise self.fail(where, f"is {value!r}; it must be [low, high] with 0 <= low <= high")
        return (low, high)

    def probability(self, value: Any, where: str) -> float:
        number = self.number(value, where)
        if number > 1:
            raise self.fail(where, f"is {value!r}; a probability is at most 1")
        return number
