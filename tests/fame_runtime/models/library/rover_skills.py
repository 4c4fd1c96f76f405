"""A skills module for the command line tests: ``--skills rover_skills.py``."""


def navigate(robot, inputs, done):
    """Drive |x| + |y| - 2 metres at ``speed`` (simulated time only)."""
    distance = abs(inputs["x_goal"]) + abs(inputs["y_goal"]) - 2.0
    timer = robot.clock.call_later(
        distance / inputs["speed"], lambda: done({"arrival": robot.now(), "distance": distance})
    )
    return timer.cancel


SKILLS = {"navigate": navigate}
