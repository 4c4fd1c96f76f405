"""Stand-in skills for the agri mission without a simulated world: each takes a tenth of a
second; Explore reports one weed at (3, 4) on /weed_found, as the drone's camera would, and
the next Explore (the drone explores anew after each weed) finds the field clean."""

VECTOR3 = "geometry_msgs/msg/Vector3"


def _after(seconds, outputs=None):
    def skill(robot, inputs, done):
        timer = robot.clock.call_later(seconds, lambda: done(outputs or {}))
        return timer.cancel

    return skill


def explore(robot, inputs, done):
    if inputs.get("explored") or robot.variables.get("explored"):  # the weed was reported
        finished = robot.clock.call_later(0.1, lambda: done({"found": 0}))
        return finished.cancel
    spotted = robot.clock.call_later(
        0.1, lambda: robot.publish("/weed_found", {"x": 3.0, "y": 4.0, "z": 0.0}, VECTOR3)
    )
    finished = robot.clock.call_later(1.5, lambda: done({"found": 1, "explored": 1}))

    def cancel():
        spotted.cancel()
        finished.cancel()

    return cancel


SKILLS = {
    "TakeOff": _after(0.1),
    "Land": _after(0.1),
    "ReturnToBase": _after(0.1),
    "GoTo": _after(0.1),
    "CutGrass": _after(0.1),
    "GetPosition": _after(0.1, {"my_x": 1.0, "my_y": 1.0, "my_z": 0.0}),
    "Explore": explore,
}
