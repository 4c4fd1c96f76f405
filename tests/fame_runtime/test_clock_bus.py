from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock


def test_clock_runs_callbacks_in_time_then_schedule_order():
    clock, seen = SimClock(start=100.0), []
    clock.call_later(2.0, lambda: seen.append(("b", clock.now())))
    clock.call_at(101.0, lambda: seen.append(("a", clock.now())))
    clock.call_later(2.0, lambda: seen.append(("c", clock.now())))
    cancelled = clock.call_later(1.5, lambda: seen.append(("never", clock.now())))
    cancelled.cancel()
    assert clock.run() == 102.0
    assert seen == [("a", 101.0), ("b", 102.0), ("c", 102.0)]


def test_clock_run_until_stops_before_later_callbacks_and_sets_time():
    clock, seen = SimClock(), []
    clock.call_at(5.0, lambda: seen.append(5))
    clock.call_at(15.0, lambda: seen.append(15))
    assert clock.run(until=10.0) == 10.0
    assert seen == [5]
    assert clock.run(stop_when=lambda: bool(seen[1:])) == 15.0


def test_bus_delivers_through_the_clock_not_inside_publish():
    clock = SimClock()
    bus = InProcessBus(clock, latency=0.5)
    got, tapped = [], []
    bus.subscribe("/weed_position", got.append)
    bus.tap(tapped.append)
    envelope = bus.publish(
        "/weed_position",
        {"x": 1.0},
        msgtype="geometry_msgs/msg/Vector3",
        sender="drone",
        msg_id=bus.new_msg_id(),
    )
    assert got == [] and tapped == [envelope] and bus.pending == 1
    clock.run()
    assert got == [envelope] and clock.now() == 0.5 and bus.pending == 0
    assert envelope.msg_id == "m_1" and envelope.sender == "drone"


def test_unsubscribed_and_dropped_deliveries_never_arrive():
    clock = SimClock()
    bus = InProcessBus(clock, drop=lambda env, sub: sub.owner == "tractor_2")
    one, two, gone = [], [], []
    bus.subscribe("/t", one.append, owner="tractor_1")
    bus.subscribe("/t", two.append, owner="tractor_2")
    leaving = bus.subscribe("/t", gone.append)
    bus.publish("/t", {}, msgtype="std_msgs/msg/Empty")
    leaving.unsubscribe()
    clock.run()
    assert len(one) == 1 and two == [] and gone == []
    assert bus.topics() == ["/t"]
