"""What the simulated and the real robot cell share, below both.

The cell file (``cell_file``, its ``robot`` block in ``cell_robot``), the default camera
mounts (``camera_mounts``), command handles (``commands``), UR5 kinematics (``kinematics``)
and the robot model (``robot_model``). ``capabilities.sim`` (the pybullet cell) and
``capabilities.ur`` (the real UR cell) build on this package and never import each other.
"""
