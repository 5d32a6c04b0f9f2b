"""Simulation (§V): pybullet container piles, ground truth by removal, range sensor.

Not built yet (issue "Simulation"); nothing is exported.
"""

__all__: list[str] = []
