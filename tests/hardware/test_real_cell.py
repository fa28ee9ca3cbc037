"""A real UR and a real RealSense: what the emulator stands in for elsewhere."""

from __future__ import annotations

import math

import numpy as np


def test_the_real_arm_reports_running_and_moves_its_wrist_a_little(real_cell) -> None:
    assert real_cell.hold_reason() == "", real_cell.hold_reason()
    status = real_cell.status()
    assert status.connected and status.robot_mode == "RUNNING" and status.program == "PLAYING"
    arm = real_cell.interfaces()["arm"]
    start = arm.joint_positions()
    assert any(abs(q) > 1e-6 for q in start)  # a powered arm never reads all zeros
    target = list(start)
    target[5] += math.radians(5.0)
    handle = arm.move_joints(target, 0.2, 0.5)
    assert handle.wait(30) and handle.ok, handle.message
    back = arm.move_joints(start, 0.2, 0.5)
    assert back.wait(30) and back.ok, back.message
    assert np.allclose(arm.joint_positions(), start, atol=0.01)


def test_a_realsense_gives_rgbd_frames(realsense_serial: str) -> None:
    from capabilities.realsense import RealSenseCamera

    camera = RealSenseCamera("test", realsense_serial)
    try:
        frame = camera.capture()
    finally:
        camera.close()
    height, width = frame.depth.shape
    assert frame.rgb.shape == (height, width, 3) and frame.rgb.dtype == np.uint8
    assert frame.K[0, 0] > 0 and np.isfinite(frame.depth).mean() > 0.3
