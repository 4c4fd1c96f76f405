"""A bus on Cyclone DDS: signals are ROS 2 topics that real ROS 2 nodes can share.

A topic ``/weed_position`` is the DDS topic ``rt/weed_position`` typed
``geometry_msgs::msg::dds_::Vector3_`` (:mod:`robotale.fame_runtime.rostypes`), and every
publisher and subscriber gets the model's QoS, so DDS itself decides which pairs talk (the
rules ``fame check`` applies). A robotale bus makes one data writer per topic, sender, QoS
and type, and one data reader per topic, type and QoS, kept while the process lives: a catch
that is armed again finds its reader matched already, and, like the in-process bus, a
subscription sees what arrives while it is active (a transient-local one also the reader's
last ``depth`` samples, what a new DDS reader would be sent).

Samples arrive on Cyclone's threads and are handed to the clock's thread
(:class:`~robotale.fame_runtime.clock.WallClock`), so engines never run concurrently.

Who sent a message and its id travel without changing the ROS type: a robotale writer's
user data names its sender and id space, and a message's id is ``m_<space>_<n>`` where ``n``
is the sample's source timestamp in nanoseconds (unique and increasing per bus). Samples of
writers that are not robotale's get an id from their writer's handle and timestamp.
"""

from __future__ import annotations

import contextlib
import functools
import os
import threading
import time
import uuid
from collections import deque
from collections.abc import Callable
from typing import Any

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsParticipant
from cyclonedds.core import DDSException, Entity, Listener, Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from robotale.errors import InputError
from robotale.fame_runtime.bus import Envelope, Subscription
from robotale.fame_runtime.clock import RunningClock
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS
from robotale.fame_runtime.rostypes import dds_topic, dds_type_name, idl_type, to_data, to_sample

#: seconds a closing bus waits for reliable readers to acknowledge what it published
ACK_TIMEOUT = 2.0
_USERDATA = "robotale;sender={sender};ids={ids}"
#: the user data of a recorder's participant, so robots wait until it reads their topics
RECORDER_MARK = b"robotale;recorder"
#: DDS QoS policy ids (DDS 1.4, 2.2.3) of the policies a model can set
_POLICIES = {
    2: "durability",
    4: "deadline",
    8: "liveliness",
    11: "reliability",
    13: "history",
    23: "data representation",
}


def dds_qos(qos: QoS, *, userdata: str = "") -> Any:
    """Cyclone QoS with the model's reliability, durability, history, deadline, lifespan,
    liveliness and lease duration."""
    policies = [
        Policy.Reliability.Reliable(duration(seconds=1))
        if qos.reliability == "reliable"
        else Policy.Reliability.BestEffort,
        Policy.Durability.TransientLocal
        if qos.durability == "transient_local"
        else Policy.Durability.Volatile,
        Policy.History.KeepLast(qos.depth)
        if qos.history == "keep_last"
        else Policy.History.KeepAll,
        Policy.DataRepresentation(use_cdrv0_representation=True),  # plain CDR, as ROS 2 sends
    ]
    if qos.durability == "transient_local":  # what late joiners get: the same history
        policies.append(Policy.DurabilityService(0, policies[2], -1, -1, -1))
    if qos.deadline is not None:
        policies.append(Policy.Deadline(duration(seconds=qos.deadline)))
    if qos.lifespan is not None:
        policies.append(Policy.Lifespan(duration(seconds=qos.lifespan)))
    lease = duration(seconds=qos.lease_duration) if qos.lease_duration is not None else None
    if qos.liveliness == "manual_by_topic":
        policies.append(Policy.Liveliness.ManualByTopic(lease or duration(infinite=True)))
    elif lease is not None:
        policies.append(Policy.Liveliness.Automatic(lease))
    if userdata:
        policies.append(Policy.Userdata(userdata.encode()))
    return Qos(*policies)


def domain_id() -> int:
    """The DDS domain: ``ROS_DOMAIN_ID`` as ROS 2 reads it (0 when unset)."""
    text = os.environ.get("ROS_DOMAIN_ID", "0").strip() or "0"
    if not text.isdigit() or int(text) > 232:
        raise InputError(f"ROS_DOMAIN_ID {text!r} is not a DDS domain id from 0 to 232")
    return int(text)


class _Reader:
    """One DDS data reader and the bus subscriptions it feeds."""

    def __init__(self, bus: DdsBus, topic: str, msgtype: str, qos: QoS) -> None:
        self.bus, self.topic, self.msgtype, self.qos = bus, topic, msgtype, qos
        self.subscriptions: list[Subscription] = []
        self.kept: deque[Envelope] = deque(maxlen=qos.depth if qos.history == "keep_last" else None)
        listener = Listener(
            on_data_available=self._arrived,
            on_requested_incompatible_qos=self._incompatible,
        )
        # the listener is set once the reader exists: history that arrives while it is made
        # would reach a listener with no reader to take from; it is taken just after
        self.reader = DataReader(bus.participant, bus.topic(topic, msgtype), qos=dds_qos(qos))
        self.reader.set_listener(listener)
        self._arrived(self.reader)

    def detach(self) -> None:
        """No more callbacks from Cyclone's threads. The binding frees a listener's C callbacks
        with its Python object, so the old listener is kept until Cyclone has let go of it:
        a callback into freed code, or into a reader the garbage collector is finalising,
        crashes the process."""
        old = self.reader._listener
        with contextlib.suppress(Exception):
            self.reader.set_listener(None)
        del old

    def _arrived(self, _reader: Any = None) -> int:
        # a Cyclone thread (or a drain): take the samples, hand them to the clock's thread
        taken = 0
        for sample in self.reader.take(N=256):
            info = sample.sample_info
            if not info.valid_data:
                continue
            envelope = self.bus.envelope(self.reader, self.topic, self.msgtype, sample, info)
            self.bus.hand_over(functools.partial(self.dispatch, envelope))
            taken += 1
        return taken

    def dispatch(self, envelope: Envelope) -> None:
        if self.qos.durability == "transient_local":
            self.kept.append(envelope)
        for subscription in list(self.subscriptions):
            if subscription.active:
                subscription.callback(envelope)

    def _incompatible(self, reader: Any, status: Any) -> None:  # Cyclone's status
        self.bus.warn(
            f"{self.topic}: a publisher and {self.bus.node}'s subscriber cannot talk "
            f"({_POLICIES.get(status.last_policy_id, status.last_policy_id)} does not match; "
            "see robotale fame check)"
        )


class DdsBus:
    """Topics on a DDS domain (``ROS_DOMAIN_ID``, or ``domain``), delivered on ``clock``.

    ``node`` names the process (a robot's name) in warnings and message ids. Call
    :meth:`close` when done: it waits for reliable readers to acknowledge, then leaves.
    """

    def __init__(
        self,
        clock: RunningClock,
        *,
        node: str = "",
        domain: int | None = None,
        on_warning: Callable[[str], None] | None = None,
        recorder: bool = False,
    ) -> None:
        self.clock = clock
        self.node = node or uuid.uuid4().hex[:8]
        self.recorder = recorder
        mark = Qos(Policy.Userdata(RECORDER_MARK)) if recorder else None
        self.participant = DomainParticipant(domain_id() if domain is None else domain, qos=mark)
        self.on_warning = on_warning or (lambda text: None)
        self.warnings: list[str] = []
        self._topics: dict[tuple[str, str], Any] = {}
        self._writers: dict[tuple[str, str, QoS, str], Any] = {}
        self._readers: dict[tuple[str, str | None, QoS], _Reader] = {}
        self._taps: list[Subscription] = []
        self._senders: dict[int, tuple[str, str]] = {}
        self._lock = threading.Lock()
        self._last_stamp = 0
        self.pending = 0  # samples handed to the clock's thread but not dispatched yet

    # -- declaring endpoints -------------------------------------------------------------------

    def topic(self, topic: str, msgtype: str) -> Any:
        key = (topic, msgtype)
        if key not in self._topics:
            self._topics[key] = Topic(self.participant, dds_topic(topic), idl_type(msgtype))
        return self._topics[key]

    def writer(self, topic: str, msgtype: str, qos: QoS | None = None, sender: str = "") -> Any:
        """The data writer for ``topic`` in ``sender``'s name (made on first use)."""
        qos = qos or DEFAULT_QOS
        key = (topic, msgtype, qos, sender)
        if key not in self._writers:
            userdata = _USERDATA.format(sender=sender, ids=self.node)
            self._writers[key] = DataWriter(
                self.participant, self.topic(topic, msgtype), qos=dds_qos(qos, userdata=userdata)
            )
        return self._writers[key]

    def reader(self, topic: str, msgtype: str, qos: QoS | None = None) -> _Reader:
        """The data reader for ``topic`` with ``qos`` (made on first use)."""
        qos = qos or DEFAULT_QOS
        key = (topic, msgtype, qos)
        if key not in self._readers:
            self._readers[key] = _Reader(self, topic, msgtype, qos)
        return self._readers[key]

    def raw_reader(self, topic: str, msgtype: str, qos: QoS) -> Any:
        """A plain DDS reader (no listener) for what the caller polls itself."""
        return DataReader(self.participant, self.topic(topic, msgtype), qos=dds_qos(qos))

    def matched(self) -> list[tuple[str, int]]:
        """(topic, matched remote endpoints) of every writer and reader made so far."""
        counts = [
            (topic, w.get_publication_matched_status().current_count)
            for (topic, *_), w in self._writers.items()
        ]
        counts += [
            (r.topic, r.reader.get_subscription_matched_status().current_count)
            for r in self._readers.values()
        ]
        return counts

    def unrecorded(self, recorders: set[Any]) -> list[str]:
        """The topics this bus writes that a recorder (by participant key) does not read yet."""
        missing = set()
        for (topic, *_), writer in self._writers.items():
            readers = set()
            for handle in writer.get_matched_subscriptions():
                found = writer.get_matched_subscription_data(handle)
                if found is not None:
                    readers.add(found.participant_key)
            if not recorders <= readers:
                missing.add(topic)
        return sorted(missing)

    # -- the Bus interface ---------------------------------------------------------------------

    def new_msg_id(self) -> str:
        """An id whose number is the source timestamp the message will carry."""
        return f"m_{self.node}_{self._stamp()}"

    def _stamp(self) -> int:
        with self._lock:
            self._last_stamp = max(time.time_ns(), self._last_stamp + 1)
            return self._last_stamp

    def publish(
        self,
        topic: str,
        data: Any,
        *,
        msgtype: str,
        sender: str = "",
        msg_id: str = "",
        qos: QoS | None = None,
    ) -> Envelope:
        qos = qos or DEFAULT_QOS
        prefix = f"m_{self.node}_"
        own = msg_id.startswith(prefix) and msg_id[len(prefix) :].isdigit()
        stamp = int(msg_id[len(prefix) :]) if own else self._stamp()
        envelope = Envelope(topic, data, msgtype, self.clock.now(), sender, msg_id, qos)
        for tap in list(self._taps):
            tap.callback(envelope)
        sample = to_sample(msgtype, data, topic)
        self.writer(topic, msgtype, qos, sender).write(sample, timestamp=stamp)
        return envelope

    def subscribe(
        self,
        topic: str,
        callback: Callable[[Envelope], None],
        *,
        msgtype: str | None = None,
        qos: QoS | None = None,
        owner: str = "",
    ) -> Subscription:
        if not msgtype:
            raise ValueError(f"{topic}: a DDS subscription needs the message type")
        reader = self.reader(topic, msgtype, qos)
        subscription = Subscription(topic, callback, msgtype, reader.qos, owner, _bus=self)
        reader.subscriptions.append(subscription)
        for envelope in list(reader.kept):  # transient local: what the reader holds
            self.hand_over(functools.partial(_kept, subscription, envelope))
        return subscription

    def tap(self, callback: Callable[[Envelope], None]) -> Subscription:
        """See every envelope this process publishes, when it publishes it."""
        subscription = Subscription(None, callback, _bus=self)
        self._taps.append(subscription)
        return subscription

    def _remove(self, subscription: Subscription) -> None:
        if subscription.topic is None:
            self._taps.remove(subscription)
            return
        key = (subscription.topic, subscription.msgtype, subscription.qos)
        reader = self._readers.get(key)
        if reader is not None and subscription in reader.subscriptions:
            reader.subscriptions.remove(subscription)

    # -- receiving -----------------------------------------------------------------------------

    def hand_over(self, work: Callable[[], Any]) -> None:
        """Run ``work`` on the clock's thread (from any thread)."""
        with self._lock:
            self.pending += 1

        def run() -> None:
            with self._lock:
                self.pending -= 1
            work()

        self.clock.call_soon(run)

    def envelope(self, reader: Any, topic: str, msgtype: str, sample: Any, info: Any) -> Envelope:
        """A received sample with its sender and message id, stamped on arrival."""
        sender, ids = self._sender(reader, info.publication_handle)
        stamp = info.source_timestamp
        msg_id = f"m_{ids}_{stamp}" if ids else f"m_{info.publication_handle:x}_{stamp}"
        qos = DEFAULT_QOS
        return Envelope(
            topic, to_data(sample, msgtype), msgtype, self.clock.now(), sender, msg_id, qos
        )

    def _sender(self, reader: Any, handle: int) -> tuple[str, str]:
        """(sender, id space) from a robotale writer's user data; ("", "") for others."""
        if handle not in self._senders:
            found = reader.get_matched_publication_data(handle)
            if found is None:
                return "", ""  # not matched (any more): ask again next time
            self._senders[handle] = _parse_userdata(found.qos)
        return self._senders[handle]

    def drain(self) -> int:
        """Hand over what the readers hold now, not waiting for Cyclone to call their listeners
        (a recording that closes); returns how many samples that was."""
        return sum(reader._arrived() for reader in list(self._readers.values()))

    def warn(self, text: str) -> None:
        if text not in self.warnings:
            self.warnings.append(text)
            self.on_warning(text)

    def close(self) -> None:
        """Wait (a little) for reliable readers to acknowledge, then leave the domain."""
        for writer in self._writers.values():
            # a reader that left does not acknowledge: there is nothing to wait for then
            with contextlib.suppress(Exception):
                writer.wait_for_acks(duration(seconds=ACK_TIMEOUT))
        for reader in self._readers.values():
            reader.detach()
        self._taps.clear()
        if self.recorder:  # robots must not wait for it any more, even while this process lives
            with contextlib.suppress(Exception):
                self.participant.set_qos(Qos(Policy.Userdata(b"")))
        participant, self.participant = self.participant, None
        self._writers.clear()
        self._topics.clear()
        if participant is not None:
            leave(participant)


def leave(participant: DomainParticipant) -> None:
    """Delete ``participant`` and every reader, writer and topic in it now. Dropping the last
    reference would do it too, but only once the garbage collector finds the cycles around a
    bus (or never, while a caller or a traceback holds a writer): until then it stays on the
    domain, and its transient-local writers hand their old samples to every new reader."""
    # the binding deletes an entity in its finaliser and nowhere else, once: each of ours is
    # finalised now (so no finaliser deletes its handle later, when Cyclone may have given the
    # number to another entity), and deleting the participant deletes the rest with it
    for entity in list(Entity._entities.values()):
        if entity is not participant and _participant_of(entity) is participant:
            entity.__del__()
    participant.__del__()


def _participant_of(entity: Entity) -> Any:
    try:
        return entity.get_participant()
    except DDSException:  # a domain, or an entity Cyclone deleted already
        return None


class Recorders:
    """The recorders on the domain (participants with :data:`RECORDER_MARK`), as they come
    and go."""

    def __init__(self, bus: DdsBus) -> None:
        self.keys: set[Any] = set()
        self._reader = BuiltinDataReader(bus.participant, BuiltinTopicDcpsParticipant)

    def update(self) -> set[Any]:
        for sample in self._reader.take(N=256):
            if not sample.sample_info.valid_data:  # a participant that left
                self.keys.discard(sample.key)
                continue
            try:
                mark = sample.qos[Policy.Userdata].data
            except (KeyError, AttributeError):
                mark = b""
            if mark == RECORDER_MARK:
                self.keys.add(sample.key)
            else:  # a recording that was closed
                self.keys.discard(sample.key)
        return self.keys


def _kept(subscription: Subscription, envelope: Envelope) -> None:
    """Hand a sample a transient-local reader kept to a subscription still listening."""
    if subscription.active:
        subscription.callback(envelope)


def _parse_userdata(qos: Any) -> tuple[str, str]:
    try:
        data = qos[Policy.Userdata].data.decode()
    except (KeyError, AttributeError, UnicodeDecodeError):
        return "", ""
    if not data.startswith("robotale;"):
        return "", ""
    fields = dict(part.split("=", 1) for part in data.split(";")[1:] if "=" in part)
    return fields.get("sender", ""), fields.get("ids", "")


def type_of(dds_type: str) -> str | None:
    """``std_msgs::msg::dds_::String_`` -> ``std_msgs/msg/String`` (None: not a ROS type)."""
    parts = dds_type.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_"):
        return None
    msgtype = f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"
    return msgtype if dds_type_name(msgtype) == dds_type else None
