"""The real UR cell: ur_rtde backends and a loopback UR controller (the emulator).

Nothing here is imported by the rest of the project at start-up: ``capabilities.ur.backends``
imports ur_rtde, ``capabilities.ur.emulator`` imports the simulated cell (pybullet); both are
imported only when a cell asks for them.
"""
