"""JavaScript scripts and conditions in an embedded QuickJS engine, with FAME's runtime API.

What a FAME script sees (thesis chapter 5, bpmn-engine's script context):

- ``this.environment.variables`` (also the global ``environment.variables``): the robot's
  process variables, shared with Python scripts, skills and data associations;
- ``next()`` / ``next(err, value)``: the script task completes when ``next`` is called (maybe
  later, from a subscription's callback); ``next(err)`` throws a BPMN error; a condition's
  value is the ``value`` it passes to ``next`` (or the value of a bare expression);
- ``console.log``: a line of the run's output, prefixed with the robot;
- ``this.environment.variables.node`` / ``.ros_node``: a shim of the rclnodejs node API onto
  robotale's bus: ``createPublisher(type, topic).publish(msg)``,
  ``createSubscription(type, topic, [options], callback)``, ``destroySubscription(s)``,
  ``createClient(type, service)`` with ``waitForService()`` (a promise) and
  ``sendRequest(request, callback)``, ``namespace()``, ``name()`` and ``getLogger()``.
  Topics without a leading ``/`` are in the robot's namespace. A service call is a request
  published on ``<service>/request`` and the first message on ``<service>/response`` after it.

Why effects go through an outbox: the embedding refuses calls from JavaScript into Python
while a time limit is set, and a script without a time limit could hang a robot. So the
JavaScript side only records what a script does (publish, subscribe, log, ``next``) and the
variables it wrote; Python applies that after each call. The bus is used only through its
public ``publish``/``subscribe``, so the same shim works on every bus.

Why most scripts run quick: keeping a JavaScript copy of all the variables in step with
Python's (a Proxy noting reads and writes, JSON both ways) cost more than a usual script
itself. A script that names each variable it touches (see :func:`touches`) gets just those
values as arguments and returns what it assigned as short text.

QuickJS (``quickjs-ng`` on PyPI) is the embedding: no file, network or process access exists
in it at all, and each runtime has a CPU-time and a memory limit.
"""

from __future__ import annotations

import json
import re
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from importlib import resources
from typing import Any

import quickjs

from robotale.errors import ModelError
from robotale.fame_runtime.bus import Bus, Envelope
from robotale.fame_runtime.rclnodejs import EFFECTS, RosNode

#: CPU seconds one call into JavaScript may take (a script, a condition, a callback)
TIME_LIMIT = 2.0
#: bytes one robot's JavaScript runtime may allocate
MEMORY_LIMIT = 64 * 1024 * 1024

#: variables that hold the rclnodejs shim, never copied to Python
NODE_NAMES = ("node", "ros_node")

#: the runtime every robot's context starts with, and the rclnodejs node shim it hands
#: scripts: package files, evaluated in this order
PRELUDE_FILES = ("rclnodejs.js", "javascript.js")


def read_prelude() -> str:
    """The JavaScript every robot's context starts with, read from the package."""
    package = resources.files("robotale.fame_runtime")
    return "".join(package.joinpath(name).read_text("utf-8") for name in PRELUDE_FILES)


_PRELUDE = read_prelude()


_FRAME = re.compile(r"at (?P<name>\S+) \(<input>:(?P<line>\d+)")
_NEXT_CALL = re.compile(r"\bnext\s*\(")
_MEMBER = re.compile(r"\.\s*([A-Za-z_$][\w$]*)|\[\s*[\"']([^\"']+)[\"']\s*\]")
_WRAP = "(function (next) {\n%s\n})"
#: what can leave promise jobs behind; a runtime that never compiled any skips running them
_PROMISES = re.compile(
    r"Promise|\bthen\b|\basync\b|\bawait\b|waitForService|\bimport\b"
)  # the body's line n is the wrapper's line n + 1


def function_source(text: str, *, condition: bool) -> str:
    """A script or condition as the source of ``function (next) {...}``.

    A condition written as a bare expression (``x > 1``, ``${x > 1}``) returns its value
    through ``next`` like FAME's ``next(null, x > 1)``."""
    body = text.strip()
    if condition and not _NEXT_CALL.search(body):
        if body.startswith("${") and body.endswith("}"):
            body = body[2:-1]
        body = f"next(null, ({body.strip().rstrip(';')}));"
    return _WRAP % body


_LOOKS_LIKE_JAVASCRIPT = re.compile(
    r"\bnext\s*\(|\bthis\.environment\b|\benvironment\.variables\b"
    r"|\b(?:var|let|const)\s+[A-Za-z_$]|=>|===|!==|&&|\|\||;\s*$",
    re.MULTILINE,
)


#: a variable named in full; anything else that can reach the variables object is refused
_TOUCH = re.compile(
    r"(?:\bthis\s*\.\s*)?\benvironment\s*\.\s*variables\s*\.\s*(?P<name>[A-Za-z_$][\w$]*)"
)
#: what could reach the variables object other than by name, or run after the call: a
#: function (also a method like ``{f() {...}}``), a promise, eval, or ``next`` other than
#: called (kept, it could complete the run later)
_DYNAMIC = re.compile(
    r"\b(?:this|environment|variables|function|class|eval|Function|arguments|globalThis"
    r"|with|delete|import|async|await|yield|Promise|then|__fame\w*)\b|=>"
    r"|\bnext\b(?!\s*\()"
    r"|(?<![\w$.])(?!(?:if|for|while|switch|catch|return|typeof|void|new|in|of)\b)"
    r"[A-Za-z_$][\w$]*\s*\([^()]*\)\s*\{"
)
#: what a plain object inherits: its value is not the variable's
_INHERITED = frozenset(
    {"constructor", "hasOwnProperty", "isPrototypeOf", "propertyIsEnumerable"}
    | {"toLocaleString", "toString", "valueOf"}
)
#: a quick script touches at most this many variables (one bit each of a 32-bit integer)
QUICK_NAMES = 16


def touches(body: str) -> tuple[str, ...] | None:
    """The variables a script body touches, in order, when it names every one in full
    (``[this.]environment.variables.<name>``) and nothing else can reach them: then it may run
    on just those values. None when it may use the variables object any other way (kept in a
    variable, ``variables[name]``, passed to a function), defines a function or promise
    callback that could run after the call, keeps ``next``, or touches the node shim."""
    names = tuple(dict.fromkeys(match["name"] for match in _TOUCH.finditer(body)))
    if _DYNAMIC.search(_TOUCH.sub(" ", body)) or len(names) > QUICK_NAMES:
        return None
    if any(n in NODE_NAMES or n in _INHERITED or n.startswith("__") for n in names):
        return None
    return names


#: the prelude's functions a quick script's code uses, as locals of its closure
_QUICK_LOCALS = (
    "__fame_call = __fame.quick_call, __fame_flat = __fame.quick_flat, "
    "__fame_finish = __fame.quick_finish, __fame_merge = __fame.quick_merge"
)
#: a variable as a property whose setter notes it was written (bit ``bit`` of __fame_w), as
#: the Proxy's set trap does; its value lives in a local of the closure
_QUICK_PROPERTY = (
    "Object.defineProperty(__fame_v, {key}, {{get: function fame_get() {{ return __fame_{i}; "
    "}}, set: function fame_set(x) {{ __fame_{i} = x; __fame_w |= {bit}; }}, enumerable: true}});"
)
#: one field of the outbox: empty when not written, else the value flat (a 32-bit integer or
#: a string inline: three calls deep, fame_flat costs more than the script)
_QUICK_FIELD = (
    "if (__fame_w & {bit}) {{ __fame_k = __fame_{i}; __fame_f = typeof __fame_k === 'number' "
    "&& (__fame_k | 0) === __fame_k ? 'i' + __fame_k : typeof __fame_k === 'string' ? "
    "(__fame_k.indexOf('\\u001f') < 0 ? 's' + __fame_k : null) : __fame_flat(__fame_k); "
    "if (__fame_f === null) return __fame_merge(__fame_v, __fame_names, __fame_w); "
    "__fame_h += '\\u001f' + __fame_f; }} else __fame_h += '\\u001f';"
)
#: next() or next(null) and the one variable written: its value when a number or a boolean
_QUICK_DIRECT = (
    "if (__fame_h === 'z' && __fame_w === 1 && ((typeof __fame_0 === 'number' && "
    "isFinite(__fame_0)) || typeof __fame_0 === 'boolean')) return __fame_finish(__fame_0);\n"
)


def quick_source(body: str, names: tuple[str, ...]) -> str:
    """A script body as ``fame_quick(run, present, value...)``: the variables' values (a bit
    of ``present`` set for each the robot has) on an object of just those, the body run on
    it, the outbox made (see the prelude's ``fame_quick_*``). The body stays on lines 2 and
    on, as in :func:`function_source`, so errors name its own lines."""
    keys = [json.dumps(name) for name in names]
    slots = "".join(f", __fame_{i}" for i in range(len(names)))
    properties = "".join(
        _QUICK_PROPERTY.format(key=key, i=i, bit=1 << i) for i, key in enumerate(keys)
    )
    values = "".join(
        f"__fame_{i} = __fame_present & {1 << i} ? __fame_a{i} : undefined; "
        for i in range(len(names))
    )
    fields = "\n".join(_QUICK_FIELD.format(i=i, bit=1 << i) for i in range(len(names)))
    parameters = "".join(f", __fame_a{i}" for i in range(len(names)))
    return (
        "(function () { var __fame_v = {}, __fame_ctx = {environment: {variables: __fame_v}}, "
        f"environment = __fame_ctx.environment, {_QUICK_LOCALS}, __fame_w = 0{slots}, "
        f"__fame_names = {json.dumps(names)}; {properties} "
        f"__fame_ctx.fame_body = function (next) {{\n{body}\n}};\n"
        f"return function fame_quick(__fame_run, __fame_present{parameters}) {{ {values}"
        "__fame_w = 0;\nvar __fame_h = __fame_call(__fame_ctx, __fame_run), __fame_k, __fame_f;\n"
        f"{_QUICK_DIRECT if len(names) == 1 else ''}"
        "if (__fame_h === null) return __fame_merge(__fame_v, __fame_names, __fame_w);\n"
        f"__fame_h = 'Q' + __fame_h;\n{fields}\nreturn __fame_finish(__fame_h); }}; }})()"
    )


def looks_like_javascript(text: str) -> bool:
    """A script or condition without a language is JavaScript when it uses what Python
    cannot (``next(``, ``this.environment``, ``var``/``let``/``const``, ``=>``, ``===``,
    ``&&``, a statement ending in ``;``), as FAME's models do; otherwise it is Python."""
    return bool(_LOOKS_LIKE_JAVASCRIPT.search(text))


def member_names(text: str) -> frozenset[str]:
    """Every ``.name`` and ``["name"]`` in ``text``: a superset of the variables a condition
    reads, so a conditional event is re-evaluated when one of them changes."""
    return frozenset(a or b for a, b in _MEMBER.findall(text))


_WRAP_HEAD, _WRAP_TAIL = _WRAP.split("%s")


def _is_wrapped(source: str) -> bool:
    return source.startswith(_WRAP_HEAD) and source.endswith(_WRAP_TAIL)


@dataclass(slots=True)
class _Script:
    """A script's source compiled: ``quick`` when :func:`touches` found its variables,
    ``full`` (on the whole of the variables) when first needed."""

    source: str
    names: tuple[str, ...] | None
    quick: Any = None
    full: Any = None


_ABSENT = object()
#: what goes into JavaScript as an argument as it is (an int only within 32 bits)
_PLAIN = frozenset({str, float, bool, type(None)})
_INT32 = 1 << 31
#: integers a double holds exactly
_EXACT = 1 << 53
#: from this magnitude on, JSON writes a whole number with an exponent: Python reads a float
_JSON_INT = 1e21

_checker_lock = threading.Lock()
_checker: list[quickjs.Context] = []


def syntax_error(source: str) -> str | None:
    """Why ``source`` (from :func:`function_source`) is not valid JavaScript, or None."""
    with _checker_lock:
        if not _checker:
            _checker.append(quickjs.Context())
        try:
            _checker[0].eval(f"(function () {{ return {source}; }})")
        except quickjs.JSException as error:
            message, line = _first_line(str(error)), _script_line(str(error))
            return f"JavaScript syntax error on line {line}: {message}" if line else message
    return None


def _first_line(text: str) -> str:
    return text.strip().splitlines()[0] if text.strip() else "unknown error"


def _script_line(stack: str) -> int:
    """The line, counted in the script's own text, of the innermost frame that is the
    script's (the runtime's own functions are ``fame_*``); 0 when there is none."""
    for match in _FRAME.finditer(stack):
        if not match.group("name").startswith("fame_"):
            return max(int(match.group("line")) - 1, 1)
    line = re.search(r"<input>:(\d+)", stack)
    return max(int(line.group(1)) - 1, 1) if line else 0


class ScriptFailure(Exception):
    """A script threw, called ``next(err)`` or ran out of time: ``text`` says what and
    where; the engine throws it as a BPMN error of the script's activity."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self.text = text


class ScriptLimit(ModelError):
    """A script ran out of its CPU time or memory: a model error (no BPMN error a boundary
    event could catch); ``what`` says which limit, as "ran out of its 64 MiB of memory"."""

    def __init__(self, robot: str, what: str) -> None:
        super().__init__(f"robot {robot}: JavaScript {what}")
        self.what = what


#: called when a script calls ``next(err, value)``: err is None or the error's text
Completion = Callable[[str | None, Any], None]
#: what a script passed to ``next``: (err, value)
Outcome = tuple[str | None, Any]
_NEXT: Outcome = (None, None)


class _Now:
    """The completion of a run while it is called: it keeps what the run passed to
    ``next``, for the caller to act on once the call has returned."""

    __slots__ = ("outcome",)

    def __init__(self) -> None:
        self.outcome: Outcome | None = None

    def __call__(self, error: str | None, value: Any) -> None:
        self.outcome = (error, value)


class JavaScript:
    """One robot's JavaScript runtime: its variables mirror the robot's, its node shim
    publishes and subscribes on the robot's bus.

    ``schedule`` queues work on the robot's engine (deliveries run there, never inside the
    bus); ``changed`` tells the engine which variables a callback wrote; ``output`` prints a
    ``console.log`` line.
    """

    def __init__(
        self,
        robot: str,
        bus: Bus,
        variables: dict[str, Any],
        *,
        schedule: Callable[[Callable[[], Any]], None],
        changed: Callable[[Iterable[str]], None],
        output: Callable[[str], None],
        time_limit: float = TIME_LIMIT,
        memory_limit: int = MEMORY_LIMIT,
    ) -> None:
        self.robot, self.bus, self.variables = robot, bus, variables
        self.schedule, self.changed, self.output = schedule, changed, output
        self.time_limit, self.memory_limit = time_limit, memory_limit
        self.context = quickjs.Context()
        self.context.set_memory_limit(memory_limit)
        self.context.eval(_PRELUDE)
        js = self.context.eval
        self._run, self._message, self._response = (
            js("__fame.run"),
            js("__fame.message"),
            js("__fame.response"),
        )
        self._drain = js("__fame.drain")
        node, hide = js("__fame.node")(robot), js("__fame.hide")
        for name in NODE_NAMES:
            hide(name, node)
        self.context.set_time_limit(time_limit)
        self._scripts: dict[str, _Script] = {}
        self._source = ""  # the script running (what a failure is read against)
        self._opaque: set[str] = set()  # variables JavaScript holds that JSON cannot carry
        self._promises = False  # a script that may queue promise jobs was compiled
        self._mirror: dict[str, Any] = {}  # what the JavaScript side holds, by identity
        self._runs: dict[int, Completion] = {}
        self._run_ids = 0
        self.node = RosNode(
            robot,
            bus,
            schedule=schedule,
            on_message=lambda sub_id, envelope: self._deliver(self._message, sub_id, envelope),
            on_response=lambda call_id, envelope: self._deliver(self._response, call_id, envelope),
        )

    # -- running ---------------------------------------------------------------------------

    def run_script(self, source: str, done: Completion) -> None:
        """Run a script's body; ``done`` is called when it calls ``next`` (maybe now).
        ScriptFailure when it throws."""
        now = self.run_task(source, lambda: done)
        if now is not None:
            done(*now)

    def run_task(self, source: str, later: Callable[[], Completion]) -> Outcome | None:
        """Run a script task's body: ``(error, value)`` when it called ``next(error, value)``
        while it ran; else None, and ``later()`` gives what its ``next`` calls when it does.
        ScriptFailure when it throws."""
        self._run_ids += 1
        run = self._run_ids
        self._source = source
        script = self._scripts.get(source) or self._compile(source)
        if script.names is not None:
            values = self._quick_values(script.names)
            if values is not None:
                return self._run_quick(script, run, values, later)
        outboxes = self._call(self._run, self._full(script), run, self._push())
        return self._settle(run, later, outboxes)

    def _settle(
        self, run: int, later: Callable[[], Completion], outboxes: tuple[str, ...]
    ) -> Outcome | None:
        """Apply a run's outboxes: what it passed to ``next`` if it called it, else None and
        its later completion is waiting."""
        now = _Now()
        self._runs[run] = now
        try:
            self._apply(outboxes, run)
        except ScriptFailure:
            self._runs.pop(run, None)
            raise
        if run in self._runs:
            self._runs[run] = later()
        return now.outcome

    def _run_quick(
        self, script: _Script, run: int, values: list[Any], later: Callable[[], Completion]
    ) -> Outcome | None:
        """Run a script on the values of the variables it names (see ``fame_quick``)."""
        names = script.names
        assert names is not None  # only a script whose variables are known runs quick
        try:
            outbox = script.quick(run, *values)
            jobs = self._jobs() if self._promises else None
        except quickjs.JSException as error:
            raise self._failure(error) from None
        kind = type(outbox)
        if kind is str and outbox[:1] == "Q":
            now = self._apply_quick(outbox, names)
            if now is None:  # it may call next later (from a callback a former script set up)
                self._runs[run] = later()
        elif kind is str:  # what it did could not go flat: the usual outbox
            now = self._settle(run, later, (outbox,))
        else:  # next() and one variable set to a number or a boolean (see _QUICK_DIRECT)
            if kind is float and outbox.is_integer() and -_JSON_INT < outbox < _JSON_INT:
                outbox = int(outbox)  # what JSON would have made of it
            self.variables[names[0]] = outbox
            self.changed(names)
            now = _NEXT
        if jobs:
            self._apply((jobs,))
        return now

    def _quick_values(self, names: tuple[str, ...]) -> list[Any] | None:
        """A bit mask of the ``names`` the robot has, then their values; None when one of
        them holds what only JSON carries (a list, an object, a huge integer) or a value
        JavaScript holds that Python lacks."""
        if self._opaque and not self._opaque.isdisjoint(names):
            return None
        variables = self.variables
        values: list[Any] = [0]
        present, bit = 0, 1
        for name in names:
            value = variables.get(name, _ABSENT)
            if value is not _ABSENT:
                kind = type(value)
                if kind is int and not -_INT32 <= value < _INT32:
                    if not -_EXACT <= value <= _EXACT:
                        return None
                    value = float(value)  # the embedding would cut an integer to 32 bits
                elif kind is not int and kind not in _PLAIN:
                    return None
                present |= bit
            values.append(None if value is _ABSENT else value)
            bit <<= 1
        values[0] = present
        return values

    def condition(self, source: str) -> Any:
        """The value a condition passes to ``next`` (None when it never calls it)."""
        values: list[Any] = []

        def done(error: str | None, value: Any) -> None:
            if error is not None:
                raise ScriptFailure(f"the condition called next with the error {error!r}")
            values.append(value)

        self.run_script(source, done)
        self._runs.pop(self._run_ids, None)  # a condition that never called next is false
        return values[0] if values else None

    def close(self) -> None:
        """Drop the subscriptions scripts made (the engine stops or restarts)."""
        self.node.close()
        self._runs.clear()

    def _compile(self, source: str) -> _Script:
        body = source[len(_WRAP_HEAD) : -len(_WRAP_TAIL)] if _is_wrapped(source) else None
        names = None if body is None else touches(body)
        script = _Script(source, names)
        if body is not None and names is not None:
            script.quick = self.context.eval(quick_source(body, names))
        self._scripts[source] = script
        return script

    def _full(self, script: _Script) -> Any:
        """The script as ``function (next)`` on the whole of the variables."""
        if script.full is None:
            script.full = self.context.eval(script.source)
            self._promises = self._promises or bool(_PROMISES.search(script.source))
        return script.full

    def _call(self, function: Any, *args: Any) -> tuple[str, ...]:
        """Call into JavaScript: its drained outbox, and a second one when it left promise
        jobs (they run before anything is applied)."""
        try:
            result = function(*args)
            later = self._jobs() if self._promises else None
        except quickjs.JSException as error:
            raise self._failure(error) from None
        return (result, later) if later else (result,)

    def _jobs(self) -> str | None:
        """Run the promise jobs calls left; the outbox of what they did (None: no job)."""
        if not self.context.execute_pending_job():
            return None
        while self.context.execute_pending_job():
            pass
        outbox: str = self._drain()
        return outbox

    def _failure(self, error: quickjs.JSException) -> Exception:
        """What a call that JavaScript stopped raises."""
        text = str(error)
        if "interrupted" in text:
            return ScriptLimit(
                self.robot,
                f"ran longer than its time limit of {self.time_limit:g} s of CPU time",
            )
        if _out_of_memory(text):
            return self._memory_limit()
        return ScriptFailure(f"{_first_line(text)} (line {_script_line(text)})")

    def _memory_limit(self) -> ScriptLimit:
        return ScriptLimit(self.robot, f"ran out of its {self.memory_limit >> 20} MiB of memory")

    def _exhausted(self, text: str | None) -> bool:
        """Whether a script's caught failure is running out of memory: QuickJS throws null
        when it cannot even make the error object, so a null that the script itself does not
        throw is that."""
        if text is not None and text != "null":
            return _out_of_memory(text)
        return "throw null" not in self._source

    def _push(self) -> str:
        """The variables that changed in Python since JavaScript last saw them, as JSON."""
        mirror, variables = self._mirror, self.variables
        try:
            if variables == mirror:  # the usual case, compared in C (identical values first)
                return ""
        except (TypeError, ValueError):
            pass  # a value that cannot be compared (an array): look at each one
        changed = {
            k: v
            for k, v in variables.items()
            if k not in NODE_NAMES and (k not in mirror or mirror[k] is not v)
        }
        gone = [k for k in mirror if k not in variables]
        if not changed and not gone:
            return ""
        for name in gone:
            del mirror[name]
        sendable = {}
        for name, value in changed.items():
            try:
                json.dumps(value)
            except (TypeError, ValueError):
                continue  # a Python-only value (an object a skill left): JavaScript lacks it
            sendable[name] = value
            mirror[name] = value
        return json.dumps({"set": sendable, "del": gone})

    # -- effects -------------------------------------------------------------------------------

    def _apply(self, outboxes: tuple[str, ...], run: int = 0) -> None:
        for outbox in outboxes:
            if not outbox:
                continue
            if outbox[0] == "F":
                self._apply_fast(outbox, run)
                continue
            if outbox[0] == "C":
                self._apply_flat(outbox)
                continue
            outcome = json.loads(outbox)
            written = self._take_writes(outcome)
            for effect in outcome["e"]:
                self._effect(effect, run)
            if written:
                self.changed(written)

    def _apply_fast(self, outbox: str, run: int) -> None:
        """The usual outbox (see the prelude's ``fame_fast``): the value the run passed to
        ``next`` (empty: not called), then the variables it wrote."""
        fields = outbox.split("\x1f")
        if len(fields) > 1:
            mirror, variables = self._mirror, self.variables
            names = fields[1::2]
            for name, value in zip(names, fields[2::2], strict=True):
                variables[name] = mirror[name] = _flat(value)
            self.changed(names)
        if len(fields[0]) > 1:
            done = self._runs.pop(run, None)
            if done is not None:
                done(None, _flat(fields[0][1:]))

    def _apply_flat(self, outbox: str) -> None:
        """The flat outbox (see the prelude's ``fame_drain``): writes, then ``next`` calls."""
        mirror, variables = self._mirror, self.variables
        fields = iter(outbox.split("\x1f"))
        next(fields)  # "C"
        written = []
        # the writes come first, then the next() calls: they complete after every write
        for kind, name, value in zip(fields, fields, fields, strict=True):
            if kind == "w":
                variables[name] = mirror[name] = _flat(value)
                written.append(name)
            elif kind == "d":
                variables.pop(name, None)
                mirror.pop(name, None)
                written.append(name)
            else:  # "n": next(null, value) called by run ``name``
                done = self._runs.pop(int(name), None)
                if done is not None:
                    done(None, _flat(value))
        if written:
            self.changed(written)

    def _apply_quick(self, outbox: str, names: tuple[str, ...]) -> Outcome | None:
        """A quick script's outbox (see :func:`quick_source`): what it passed to
        ``next``, None when it did not call it. The values go to Python only: JavaScript's
        store did not see them, so its mirror keeps the old ones and the next call on the
        whole of the variables pushes them."""
        fields = outbox.split("\x1f")
        if len(fields) > 1:
            values = fields[1:]
            variables = self.variables
            for name, field in zip(names, values, strict=True):
                tag = field[:1]  # the usual tags inline: a call per value costs as much
                if tag == "i":
                    variables[name] = int(field[1:])
                elif tag == "s":
                    variables[name] = field[1:]
                elif tag == "-":
                    variables.pop(name, None)
                elif tag:  # empty: not written
                    variables[name] = _flat(field)
            if "" in values:
                names = tuple(n for n, f in zip(names, values, strict=True) if f)
            if names:
                self.changed(names)
        head = fields[0]
        if head == "Qz":  # next() or next(null)
            return _NEXT
        return (None, _flat(head[1:])) if len(head) > 1 else None

    def _take_writes(self, outcome: dict[str, Any]) -> list[str]:
        self._opaque.update(outcome.get("o", ()))
        mirror, variables = self._mirror, self.variables
        for name, value in outcome["w"].items():
            variables[name] = mirror[name] = value
        for name in outcome["d"]:
            variables.pop(name, None)
            mirror.pop(name, None)
        return [*outcome["w"], *outcome["d"]]

    def _effect(self, effect: list[Any], run: int) -> None:
        kind = effect[0]
        if kind == "log":
            self.output(effect[1])
        elif kind == "next":
            done = self._runs.pop(effect[1], None)
            if done is not None:
                done(effect[2], effect[3])
        elif kind == "throw":
            self._runs.pop(effect[1], None)
            if self._exhausted(effect[2]):
                raise self._memory_limit()
            raise ScriptFailure(f"{_first_line(effect[2])} (line {_script_line(effect[3])})")
        elif kind in EFFECTS:
            self.node.apply(effect)

    def _deliver(self, function: Any, callback_id: int, envelope: Envelope) -> None:
        try:
            message = json.dumps(envelope.data)
        except (TypeError, ValueError):
            return  # not a ROS message (a tag): nothing a rclnodejs callback could read
        try:
            self._apply(self._call(function, callback_id, message, self._push()))
        except ScriptFailure as failure:
            raise ModelError(
                f"robot {self.robot}: a JavaScript callback on {envelope.topic} failed: "
                f"{failure.text}"
            ) from None


def _out_of_memory(text: str) -> bool:
    return "out of memory" in text or "string too long" in text


_FLAT_CONSTANTS = {"t": True, "f": False, "z": None}


def _flat(text: str) -> Any:
    """One flat value: i<integer>, n<number> (a float, as JSON reads a number with a fraction
    or an exponent), s<string>, t, f, z (null)."""
    tag = text[0]
    if tag == "i":
        return int(text[1:])
    if tag == "s":
        return text[1:]
    if tag == "n":
        return float(text[1:])
    return _FLAT_CONSTANTS[tag]
