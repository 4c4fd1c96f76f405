"""The robot's variables and how the model's data flows in and out of them (guideline G7).

- A data object's literal parameters (``50``, ``0.0``, JSON) become variables when its process
  starts; ``name = ${name}`` declares ``name`` (None until set).
- A data input association sets its data object's parameters as variables before the activity
  (``${expr}`` evaluated then); camunda input parameters likewise; a skill gets them as inputs.
- Output parameters and data output associations are evaluated after the activity or catch,
  with the activity's outputs or the message's fields in scope.
- A caught message becomes the variable named after its signal. In FAME's dialect each of its
  fields also goes to the first variable whose name starts with the field's name (``x`` to
  ``x_target``), as FAME's engine stores a caught payload (``received``).
- A thrown signal's payload template is filled in from the variables.
- In a process written in FAME's JavaScript dialect, a ``${name}`` of a variable nobody set
  stays as written in a variable and is null in a payload, as FAME's engine leaves it
  (``keep_unset``); elsewhere it is a model error naming the data object.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from robotale.errors import ModelError
from robotale.fame_runtime.expressions import render_json, self_reference, substitute
from robotale.fame_runtime.model import DataObject
from robotale.fame_runtime.plan import NodePlan


class Data:
    """One robot's variables, shared by all its instances (FAME's ``environment``)."""

    def __init__(
        self,
        robot: str,
        variables: dict[str, Any],
        env: dict[str, Any],
        changed: Callable[[Iterable[str]], None],
    ) -> None:
        self.robot = robot
        self.variables = variables
        self.env = env  # the globals scripts and ${...} see (robot, BpmnError)
        self.changed = changed  # conditional events re-evaluate
        self.given = frozenset(variables)  # set by the caller: data objects do not override
        self.keep_unset = False  # FAME's dialect: see the module's docstring

    def declare(self, data_objects: Iterable[DataObject]) -> None:
        """A process starts: literal values become variables, ``${name}`` declares ``name``."""
        changed = []
        for data_object in data_objects:
            for name, value in data_object.parameters.items():
                if name in self.given:
                    continue
                if self_reference(value) == name:
                    self.variables.setdefault(name, None)
                elif "${" not in value:
                    self.variables[name] = substitute(value, self.variables, self.env)
                    changed.append(name)
        self.changed(changed)

    def inputs(self, node: NodePlan) -> dict[str, Any]:
        """Before an activity: its data inputs and input parameters, set as variables."""
        values = self._resolve(node.data_inputs, {}) if node.data_inputs else {}
        for name, value in node.node.inputs.items():
            values[name] = self._parameter(value, self.variables)
        self.set(values)
        return values

    def outputs(self, node: NodePlan, extra: Mapping[str, Any]) -> None:
        """After an activity or catch: output parameters and data outputs, ``extra`` (its
        outputs, or the message's fields) in scope."""
        if not node.node.outputs and not node.data_outputs:
            return
        names = {**self.variables, **extra}
        values = {n: self._parameter(v, names) for n, v in node.node.outputs.items() if v}
        values.update(self._resolve(node.data_outputs, extra))
        self.set(values)

    def received(self, topic: str, data: Any) -> dict[str, Any]:
        """A caught message: the variable named after the signal; its fields, for outputs."""
        fields = dict(data) if isinstance(data, Mapping) else {}
        if self.keep_unset:
            self.set(prefix_matches(fields, self.variables))
        variable = topic.strip("/").replace("/", "_")
        if variable.isidentifier():
            self.set({variable: data})
        return fields

    def payload(self, node: NodePlan) -> dict[str, Any]:
        """The data a signal throw publishes, its template filled in."""
        assert node.throw is not None  # only throwing nodes publish
        template = node.throw.payload
        try:
            if isinstance(template, dict):
                return _nest(
                    {
                        k: substitute(v, self.variables, self.env, keep_unset=self.keep_unset)
                        for k, v in template.items()
                    }
                )
            if not template or not template.strip():
                return {}
            value = render_json(template, self.variables, self.env, keep_unset=self.keep_unset)
        except Exception as error:
            raise ModelError(
                f"robot {self.robot}: the payload of signal event {node.node.describe()} "
                f"cannot be filled in: {type(error).__name__}: {error}"
            ) from error
        return value if isinstance(value, dict) else {"data": value}

    def set(self, values: Mapping[str, Any]) -> None:
        if values:
            self.variables.update(values)
            self.changed(values)

    def _resolve(
        self, data_objects: Iterable[DataObject], extra: Mapping[str, Any]
    ) -> dict[str, Any]:
        names = {**self.variables, **extra} if extra else self.variables
        values = {}
        for data_object in data_objects:
            for name, text in data_object.parameters.items():
                try:
                    values[name] = substitute(text, names, self.env, keep_unset=self.keep_unset)
                except Exception as error:
                    raise ModelError(
                        f"robot {self.robot}: data object {data_object.id} "
                        f"({data_object.name}) parameter {name} = {text}: "
                        f"{type(error).__name__}: {error}"
                    ) from error
        return values

    def _parameter(self, value: Any, names: Mapping[str, Any]) -> Any:
        if isinstance(value, str):
            return substitute(value, names, self.env, keep_unset=self.keep_unset)
        if isinstance(value, list):
            return [self._parameter(v, names) for v in value]
        if isinstance(value, dict):
            return {k: self._parameter(v, names) for k, v in value.items()}
        return value


def prefix_matches(fields: Mapping[str, Any], variables: Mapping[str, Any]) -> dict[str, Any]:
    """FAME's engine (fame-ros ``controller.js``, the catch callback of ``camundaExtProperties``)
    gives each field of a caught payload to the first existing variable, in the order they
    were set, whose name starts with the field's name; a field no variable matches is
    dropped. DINGO's ``x_target``/``y_target`` get the ``x``/``y`` of ``target_found`` so."""
    values = {}
    for field, value in fields.items():
        match = next((name for name in variables if name.startswith(str(field))), None)
        if match is not None:
            values[match] = value
    return values


def _nest(flat: Mapping[str, Any]) -> dict[str, Any]:
    """``{"linear.x": 1}`` -> ``{"linear": {"x": 1}}`` (ros:parameter names may be dotted)."""
    nested: dict[str, Any] = {}
    for key, value in flat.items():
        *path, last = key.split(".")
        target = nested
        for part in path:
            target = target.setdefault(part, {})
        target[last] = value
    return nested
