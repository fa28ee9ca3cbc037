"""The pybullet simulated robot cell: a UR5 with a parallel gripper and a suction tool.

Import ``capabilities.sim.cell.SimCell`` to use it; pybullet is only imported with it.
"""
