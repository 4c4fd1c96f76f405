"""One robot's conditions and expressions -- a sequence flow's condition, a loop's
cardinality or completion condition, a conditional event's -- evaluated on its variables, in
Python or in its JavaScript runtime, with their errors explained."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import Any

from robotale.errors import ModelError
from robotale.fame_runtime.expressions import BpmnError, Compiled
from robotale.fame_runtime.javascript import JavaScript, ScriptFailure

#: a ``with`` block of work of a kind (``condition``) charged to the robot's clock
Charged = Callable[[str], contextlib.AbstractContextManager[None]]


class Conditions:
    """Evaluates ``robot``'s conditions on ``variables`` (Python sees ``env`` as its
    globals); ``javascript`` gives the robot's JavaScript runtime, made when first needed."""

    def __init__(
        self,
        robot: str,
        env: dict[str, Any],
        variables: dict[str, Any],
        *,
        javascript: Callable[[], JavaScript],
        charged: Charged,
    ) -> None:
        self.robot, self.env, self.variables = robot, env, variables
        self.javascript, self.charged = javascript, charged

    def holds(self, condition: Compiled, where: str) -> bool:
        """Whether ``condition`` (of ``where``, for the messages) holds."""
        return bool(self.value(condition, where))

    def value(self, condition: Compiled, where: str) -> Any:
        """The value of a condition or expression (a loop's cardinality), errors explained."""
        try:
            with self.charged("condition"):
                if condition.code is None:  # JavaScript: its own engine compiled it
                    return self.javascript().condition(condition.source)
                return eval(condition.code, self.env, self.variables)
        except BpmnError:
            raise
        except ScriptFailure as failure:
            raise ModelError(
                f"robot {self.robot}: the JavaScript condition of {where} failed: {failure.text}"
            ) from None
        except Exception as error:
            raise ModelError(
                f"robot {self.robot}: the condition of {where} ({condition.source}) "
                f"failed: {type(error).__name__}: {error}"
            ) from error

    def event(self, condition: Compiled) -> Any:
        """A conditional event's condition; one reading a variable nobody set yet is false
        (it cannot have become true), unlike a gateway's, where that is a model error."""
        try:
            if condition.code is None:  # JavaScript: its own engine compiled it
                return self.holds(condition, "a conditional event")
            with self.charged("condition"):
                return eval(condition.code, self.env, self.variables)
        except NameError:
            return False
        except Exception:
            return self.holds(condition, "a conditional event")
