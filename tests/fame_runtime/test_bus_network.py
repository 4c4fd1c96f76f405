"""The network model of the in-process bus: latency drawn per message, loss per transmission
(growing with distance), reliable resends within a deadline, best effort lost for good."""

from __future__ import annotations

import statistics
from dataclasses import replace

import pytest

from robotale.fame_runtime.bus import InProcessBus, Link, Network
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.qos import DEFAULT_QOS

RELIABLE = DEFAULT_QOS
BEST_EFFORT = replace(DEFAULT_QOS, reliability="best_effort")
MESSAGES = 10_000


def send(network: Network, qos, count: int = MESSAGES, seed: int = 7):
    """Publish ``count`` messages from a to b; (publish time, arrival time) of those that
    arrived."""
    clock = SimClock(0.0)
    bus = InProcessBus(clock, network=network, seed=seed)
    arrived = []
    bus.subscribe("/t", lambda e: arrived.append((e.stamp, clock.now())), qos=qos, owner="b")
    for n in range(count):
        clock.call_at(n * 0.01, lambda: bus.publish("/t", {}, msgtype="x", sender="a", qos=qos))
    clock.run()
    return arrived


@pytest.mark.parametrize("rate", [0.05, 0.2, 0.5])
def test_best_effort_loses_the_configured_share_of_10k_messages(rate):
    arrived = send(Network(Link(loss=rate)), BEST_EFFORT)
    lost = 1 - len(arrived) / MESSAGES
    assert abs(lost - rate) < 0.02


def test_reliable_recovers_every_loss_within_its_deadline_best_effort_does_not():
    link = Link(latency=0.02, loss=0.3, retry=0.05, deadline=0.5)
    reliable = send(Network(link), RELIABLE)
    assert len(reliable) == MESSAGES  # 0.3 ** 11 per message: none lost in 10k
    delays = [arrival - sent for sent, arrival in reliable]
    assert max(delays) <= link.deadline + link.latency + 1e-9
    late = sum(d > link.latency + 1e-9 for d in delays) / MESSAGES
    assert abs(late - 0.3) < 0.02  # the share sent again is the loss rate
    assert 1 - len(send(Network(link), BEST_EFFORT)) / MESSAGES == pytest.approx(0.3, abs=0.02)
    # a deadline shorter than one resend leaves reliable delivery no better than best effort
    hurried = send(Network(replace(link, deadline=0.01)), RELIABLE)
    assert 1 - len(hurried) / MESSAGES == pytest.approx(0.3, abs=0.02)


def test_loss_grows_with_distance_between_the_robots():
    where = {"a": (0.0, 0.0), "b": (30.0, 40.0)}  # 50 m apart
    network = Network(Link(loss=0.05, loss_per_metre=0.004), locate=where.get)
    lost = 1 - len(send(network, BEST_EFFORT)) / MESSAGES
    assert lost == pytest.approx(0.05 + 0.004 * 50, abs=0.02)


def test_latency_is_drawn_per_message_and_links_can_differ():
    slow = Link(latency=0.2, jitter=0.05)
    network = Network(Link(latency=0.01), links={("a", "b"): slow})
    delays = [arrival - sent for sent, arrival in send(network, RELIABLE, count=2000)]
    assert statistics.mean(delays) == pytest.approx(0.2, abs=0.01)
    assert statistics.stdev(delays) == pytest.approx(0.05, abs=0.01)
    assert send(network, RELIABLE, count=2000, seed=3) == send(
        network, RELIABLE, count=2000, seed=3
    )


def test_a_robots_messages_to_itself_keep_their_order_others_may_overtake():
    """A skill's stop command must not arrive before the drive command published earlier (the
    robot would drive on); between two robots jitter may reorder messages."""
    network = Network(Link(latency=0.04, jitter=0.03))
    clock = SimClock(0.0)
    bus = InProcessBus(clock, network=network, seed=2)
    arrived: dict[str, list[int]] = {"a": [], "b": []}
    for owner in arrived:
        bus.subscribe(
            "/a/cmd", lambda e, o=owner: arrived[o].append(e.data["n"]), msgtype="x", owner=owner
        )
    for n in range(500):
        clock.call_at(
            n * 0.01, lambda n=n: bus.publish("/a/cmd", {"n": n}, msgtype="x", sender="a")
        )
    clock.run()
    assert arrived["a"] == list(range(500))
    assert sorted(arrived["b"]) == list(range(500)) and arrived["b"] != list(range(500))
