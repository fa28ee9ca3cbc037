"""The real UR cell: ur_rtde backends.

Nothing here is imported by the rest of the project at start-up: ``capabilities.cells`` imports
``capabilities.ur.cell`` (and ur_rtde with it) only when a cell file asks for a UR. The loopback
UR controller that tests it without a robot is ``capabilities.ur_emulator``, which imports this
package and the simulated cell; this package imports neither.
"""
