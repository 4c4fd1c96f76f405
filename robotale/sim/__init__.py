"""Simulation: a pybullet world, robot models, skills and scenarios, run in batches and
recorded as rosbag2."""
