"""The live view: a mirror of the cell in a process per camera renders what the physics thread
would render for the same state (the arm moved, an object added and removed), ends with the
cell and with the cell's process, and a mirror that crashed fails its pictures, not the cell.

The mirror draws a light world (a finite floor and the table's top drawn by numpy, the arm with
its collision meshes): its pictures match the physics thread's pixel for pixel everywhere but
on the arm and the floor (the table top included), and the arm is where the physics thread
draws it (its depth, within a mesh's coarseness).
"""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from capabilities.bullet import pybullet as p
from capabilities.sim import live_view
from capabilities.sim.cameras import _CV_TO_GL, SimCamera
from capabilities.sim.live_view import LiveViewError
from capabilities.sim.scene import yaw_pose
from capabilities.sim.session import SimCameraDevice, SimCellSession
from capabilities.sim.transforms import pose_to_matrix

SIZE = (320, 240)


def _gone(pid: int) -> bool:
    """The process has ended (a zombie nobody reaped has ended too)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return True
    return state in ("Z", "X")


def _wait_gone(pid: int, timeout: float = 10.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if _gone(pid):
            return True
        time.sleep(0.05)
    return _gone(pid)


def _rendered(cell: SimCellSession, name: str) -> SimCameraDevice:
    """A camera of the cell rendered in simulation (the default cell's cameras are)."""
    device = cell.cameras[name]
    assert isinstance(device, SimCameraDevice)
    return device


def _body_ids(cell: SimCellSession, device: SimCameraDevice) -> np.ndarray:
    """Which body each pixel of the physics thread's picture shows (-1: none)."""
    config = dataclasses.replace(device.camera.config, width=SIZE[0], height=SIZE[1])
    camera = SimCamera(device.name, config, device.camera.mount)

    def render(client: int) -> np.ndarray:
        view = np.linalg.inv(pose_to_matrix(camera.pose(client)) @ _CV_TO_GL)
        projection = p.computeProjectionMatrixFOV(
            np.degrees(config.fov_y), SIZE[0] / SIZE[1], config.near, config.far
        )
        seg = p.getCameraImage(
            SIZE[0], SIZE[1], viewMatrix=view.T.ravel().tolist(), projectionMatrix=projection,
            renderer=p.ER_TINY_RENDERER, physicsClientId=client,
        )[4]  # fmt: skip
        return np.asarray(seg, dtype=np.int64).reshape(SIZE[1], SIZE[0])

    return cell.sim.call(render)


def _assert_same_picture(cell: SimCellSession, camera: str) -> None:
    device = _rendered(cell, camera)
    live, exact = device.preview(SIZE), device.capture(size=SIZE)
    assert live.rgb.shape == exact.rgb.shape == (240, 320, 3)
    world = cell.sim.world
    bodies = _body_ids(cell, device)
    robot = bodies == world.robot
    # The light arm's meshes are a few millimetres off the detailed ones: a 3-pixel margin
    # around the arm and the floor (and the background the floor's edge may show) is left out.
    lighter = robot | (bodies == world.floor) | (bodies < 0)
    lighter = cv2.dilate(lighter.astype(np.uint8), np.ones((7, 7), np.uint8)) > 0
    same = ~lighter
    assert same.mean() > 0.15, f"{camera}: too little of the picture to compare"
    rgb_difference = np.abs(live.rgb[same].astype(int) - exact.rgb[same].astype(int)).mean()
    assert rgb_difference < 1.0, f"{camera}: mean colour difference {rgb_difference:.2f}"
    both = same & np.isfinite(live.depth) & np.isfinite(exact.depth)
    assert both.mean() > 0.15
    assert np.median(np.abs(live.depth[both] - exact.depth[both])) < 1e-3
    arm = robot & np.isfinite(live.depth) & np.isfinite(exact.depth)
    if arm.sum() > 50:  # the arm, where it is seen, is where the physics thread has it
        assert np.median(np.abs(live.depth[arm] - exact.depth[arm])) < 0.01
    np.testing.assert_allclose(live.K, exact.K)
    assert live.T_world_camera == exact.T_world_camera  # what the cell believes, on both


@pytest.fixture(scope="module")
def cell() -> Iterator[SimCellSession]:
    with SimCellSession("cup_to_bin", seed=0) as session:
        session.sim.wait_sim(0.3)  # the objects settle
        yield session


def test_the_mirror_shows_what_the_physics_thread_renders_as_the_cell_changes(
    cell: SimCellSession,
) -> None:
    _assert_same_picture(cell, "shoulder")
    _assert_same_picture(cell, "wrist")
    before = _rendered(cell, "shoulder").preview(SIZE).rgb
    home = cell.sim.config.home_joints
    assert cell.sim.robot.move_joints([home[0] + 0.6, *home[1:]]).wait(30)
    after = _rendered(cell, "shoulder").preview(SIZE).rgb
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 0.5  # the arm moved
    _assert_same_picture(cell, "shoulder")
    _assert_same_picture(cell, "wrist")
    model = cell.scene.library.names()[0]
    pose = yaw_pose(0.45, 0.25, cell.sim.table_top_z, 0.3)
    cell.sim.call(lambda c: cell.scene.spawn(c, "handed_over", model, pose, fixed=True))
    _assert_same_picture(cell, "shoulder")  # an object added after the mirror was built
    cell.sim.call(lambda c: cell.scene.remove(c, "handed_over"))
    _assert_same_picture(cell, "shoulder")
    frame = _rendered(cell, "shoulder").preview(SIZE)
    assert 0.0 < frame.stamp <= cell.clock()  # stamped with the simulated time it shows


def test_a_live_feed_gets_the_frame_it_asked_for_ahead_but_never_a_stale_one(
    cell: SimCellSession, monkeypatch: pytest.MonkeyPatch
) -> None:
    device = _rendered(cell, "wrist")
    arm = cell.interfaces()["arm"]
    home = arm.joint_positions()
    # The arm turns slowly all along: a frame asked for ahead shows another view.
    moving = arm.move_joints((home[0] + 1.0, *home[1:]), speed=0.05)
    # A frame asked for ahead goes stale after STALE_AFTER wall seconds: on a loaded machine
    # the calls below may be that far apart, and the stale case is tried on purpose below.
    monkeypatch.setattr(live_view, "STALE_AFTER", 60.0)
    try:
        cell.sim.wait_sim(0.1)
        device.preview(SIZE, ahead=True)  # the mirror renders the next frame meanwhile
        asked = cell.clock()
        cell.sim.wait_sim(0.05)
        ahead = device.preview(SIZE, ahead=True)
        assert 0.0 < ahead.stamp <= asked  # the frame asked for at the previous call
        # the belief taken with it, at the previous call: the wrist has turned since
        assert ahead.T_world_camera != device.extrinsics()
        now = cell.clock()
        assert device.preview(SIZE).stamp >= now  # a call without ``ahead`` wants the cell now
        device.preview(SIZE, ahead=True)
        monkeypatch.setattr(live_view, "STALE_AFTER", 0.0)
        later = cell.clock()
        assert device.preview(SIZE, ahead=True).stamp >= later  # the one asked for is stale
    finally:
        moving.cancel()
        arm.stop().wait(30.0)
        arm.move_joints(home).wait(60.0)


def test_a_cell_that_did_not_move_is_not_rendered_again(cell: SimCellSession) -> None:
    device = _rendered(cell, "shoulder")
    device.preview(SIZE, ahead=True)  # may be a frame asked for ahead earlier
    first = device.preview(SIZE, ahead=True)  # the cell as it is
    assert cell.live_view is not None
    asked = cell.live_view.requests()["shoulder"]
    cell.sim.wait_sim(0.05)
    now = cell.clock()
    again = device.preview(SIZE, ahead=True)
    assert again.rgb is first.rgb and again.depth is first.depth  # the same pictures ...
    assert again.stamp >= now  # ... showing the cell now
    assert cell.live_view.requests()["shoulder"] == asked  # the mirror rendered nothing


def test_a_frame_at_most_320_wide_is_rendered_so_and_sees_what_the_full_one_does(
    cell: SimCellSession,
) -> None:
    """Occupancy's frames: the simulated camera renders only the pixels asked for."""
    device = _rendered(cell, "shoulder")
    full, small = device.capture(), device.capture(max_width=320)
    assert full.depth.shape == (480, 640) and small.depth.shape == (240, 320)
    assert small.T_world_camera == full.T_world_camera
    # The coarse pixels' centres lie between the fine ones': the two clouds agree to a
    # few millimetres where the surfaces are smooth.
    near = np.abs(small.depth - full.depth[::2, ::2])
    assert np.nanmedian(near) < 0.005
    assert abs(len(small.point_cloud()) - len(full.point_cloud(2))) < 0.02 * small.depth.size


def test_the_mirrors_end_with_the_cell() -> None:
    with SimCellSession("cup_to_bin", seed=0) as session:
        _rendered(session, "shoulder").preview(SIZE)
        _rendered(session, "wrist").preview(SIZE)
        pids = session.live_view.pids() if session.live_view else {}
        assert set(pids) == {"shoulder", "wrist"}
    assert all(_wait_gone(pid, 1.0) for pid in pids.values())
    with pytest.raises(LiveViewError, match="closed"):
        _rendered(session, "shoulder").preview(SIZE)


def test_a_mirror_ends_when_the_cells_process_is_killed(tmp_path: Path) -> None:
    script = textwrap.dedent(
        """
        import sys, time
        from capabilities.sim.session import SimCellSession
        session = SimCellSession("cup_to_bin", seed=0)
        session.cameras["shoulder"].preview((320, 240))
        print(session.live_view.pids()["shoulder"], flush=True)
        time.sleep(60)
        """
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    parent = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=env
    )
    try:
        assert parent.stdout is not None
        mirror = int(parent.stdout.readline())
        assert not _gone(mirror)
        parent.send_signal(signal.SIGKILL)  # no close(), no atexit: only the pipe tells it
        parent.wait(10)
        assert _wait_gone(mirror), "the mirror outlived the cell's process"
    finally:
        if parent.poll() is None:
            parent.kill()


def test_a_crashed_mirror_fails_its_pictures_and_the_cell_goes_on() -> None:
    with SimCellSession("cup_to_bin", seed=0) as session:
        camera = _rendered(session, "shoulder")
        camera.preview(SIZE)
        pid = session.live_view.pids()["shoulder"] if session.live_view else 0
        os.kill(pid, signal.SIGKILL)
        with pytest.raises(LiveViewError, match="stopped"):
            camera.preview(SIZE)
        with pytest.raises(LiveViewError, match="stopped"):  # and stays stopped
            camera.preview(SIZE)
        now = session.clock()
        session.sim.wait_sim(0.1)
        assert session.clock() > now
        assert camera.capture(size=SIZE).rgb.shape == (240, 320, 3)  # perception's frames go on


def test_closing_the_cell_while_a_mirror_starts_ends_it() -> None:
    session = SimCellSession("cup_to_bin", seed=0)
    errors: list[Exception] = []

    def watch() -> None:
        try:
            _rendered(session, "shoulder").preview(SIZE)
        except LiveViewError as exc:
            errors.append(exc)

    watcher = threading.Thread(target=watch)
    watcher.start()
    assert session.live_view is not None
    mirror = session.live_view._mirrors["shoulder"]
    end = time.monotonic() + 10.0
    while mirror.process is None and time.monotonic() < end:
        time.sleep(0.01)  # the watcher is starting the mirror process
    process = mirror.process
    assert process is not None
    session.close()  # does not wait for the start to finish
    watcher.join(30.0)
    assert not watcher.is_alive()
    assert process.poll() is not None  # ended and reaped
    assert len(errors) == 1 and "closed" in str(errors[0])
