"""The live view of the simulated cameras, rendered by a mirror of the cell in other processes.

pybullet's CPU renderer takes 40-90 ms for a 320x240 RGB-D frame; on the physics thread that
time stops the simulation and, through Python's GIL, the engine's ticks. A live picture does
not need to be rendered there: :class:`LiveView` keeps a mirror of the cell in a process of
its own per camera (a pybullet DIRECT client built with the cell's own ``build_world`` and
``load_scene``). For each frame the physics thread only takes a :class:`CellSnapshot` (a few
hundred bytes, some tens of microseconds); the mirror lays it onto its bodies, renders with
the same :class:`SimCamera` and sends the images back through a pipe. The mirror's world is
the light one (``build_world(light=True)``: the arm drawn with its collision meshes, the floor
and the table's top drawn into each picture by numpy, ``flat_surfaces.py``), which takes a
frame's CPU time from 45-55 ms to 12-14 ms; objects, markers and tools are the cell's.

Perception does not use this: its images are rendered on the physics thread, exact and
stamped with simulated time (``SimCameraDevice.capture``). A live frame is stamped with the
simulated time of the snapshot it shows.

A mirror process ends with the cell (``close``), when the cell's process ends (its pipe
reads end-of-file, even when it was killed). A mirror that
crashed makes ``capture`` raise :class:`LiveViewError`; the cell goes on.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

import numpy as np

from capabilities.robot.cell_file import CellConfig
from capabilities.sim.cameras import LinkMount, RGBDFrame, SimCamera
from capabilities.sim.errors import SimError
from capabilities.sim.mirror_state import CellSnapshot, apply_snapshot
from engine.types import Pose

__all__ = ["LiveView", "LiveViewError", "MirrorRecipe"]

START_TIMEOUT = 60.0  # s: a fresh interpreter imports numpy and pybullet, builds the scene
FRAME_TIMEOUT = 10.0  # s: one frame on a loaded machine
# s: a frame asked for ahead and read later than this (the feed slept) is dropped for a new one
STALE_AFTER = 0.5
# Priority of a mirror process (added niceness): below the app's, so that the live pictures
# take only spare CPU. Measured with bench/cell_views.py on the loaded 2-core VM (under Xvfb
# the 3D scene's OpenGL is drawn by the CPU too): at niceness 0 the cameras got ~1.5x the
# frames but the 3D scene fell from ~22 to ~13 frames a second (means over runs); the ticks
# and the simulation's speed did not measurably differ.
NICENESS = 5


class LiveViewError(SimError):
    """The live view's renderer cannot give a frame (it stopped, crashed or was closed)."""


@dataclass(frozen=True)
class MirrorRecipe:
    """How to build the mirror: the cell's configuration and how its scene was loaded."""

    config: CellConfig
    scene: Path
    seed: int | None
    table_top_z: float
    keep_out: tuple[tuple[float, float, float], ...] = ()


@dataclass(frozen=True)
class _Request:
    snapshot: CellSnapshot
    size: tuple[int, int]


# ---------------------------------------------------------------------- the mirror process


def _serve(conn: Connection) -> None:
    """The mirror process: build the cell, then answer frame requests until told to stop."""
    from capabilities.bullet import pybullet as p
    from capabilities.sim.flat_surfaces import FlatSurfaces
    from capabilities.sim.scene import load_scene
    from capabilities.sim.world import build_world, light_surfaces

    if NICENESS:
        os.nice(NICENESS)
    recipe, name, camera = conn.recv()
    client = p.connect(p.DIRECT)
    world = build_world(client, recipe.config, light=True)
    scene = load_scene(
        client,
        recipe.scene,
        recipe.seed,
        table_top_z=recipe.table_top_z,
        make_table=False,
        keep_out=recipe.keep_out,
    )
    if isinstance(camera.mount, LinkMount):  # the mirror's robot body, not the cell's id
        camera = SimCamera(
            name, camera.config, dataclasses.replace(camera.mount, body_id=world.robot)
        )
    sized: dict[tuple[int, int], SimCamera] = {}
    surfaces = FlatSurfaces(light_surfaces(recipe.config), camera.config.light_direction)
    conn.send("ready")
    while True:
        try:
            request = conn.recv()
        except (EOFError, OSError):  # the cell's process ended: end too
            break
        if request is None:
            break
        apply_snapshot(client, world, scene, request.snapshot)
        view = sized.setdefault(request.size, _resized(camera, request.size))
        frame = view.capture(client, stamp=request.snapshot.stamp, surfaces=surfaces)
        try:
            conn.send((frame.rgb, frame.depth, frame.T_world_camera, frame.stamp))
        except OSError:  # the cell closed while a frame asked for ahead was on its way: end
            break
    p.disconnect(client)


# A body that moved less than this since the last picture did not visibly move (a pixel is
# some millimetres where the cameras look): joints (rad) and positions (m) by VIEW_TOLERANCE,
# orientations (quaternion components; 1e-3 turns a 0.3 m object's end by some 0.3 mm) by
# ORIENTATION_TOLERANCE. The resting world's numerical creep (the suction tool in its holster
# turns some 2e-4 a second) then makes a picture every few seconds, not every frame.
VIEW_TOLERANCE = 2e-4
ORIENTATION_TOLERANCE = 1e-3


def _view_key(snapshot: CellSnapshot, size: tuple[int, int]) -> Any:
    """What a picture of ``snapshot`` at ``size`` depends on (not its stamp); see
    :func:`_same_view`.
    """
    names = tuple(sorted(snapshot.objects))
    poses = [snapshot.tool, *(snapshot.objects[name] for name in names)]
    numbers = [*snapshot.robot_joints]
    tolerances = [VIEW_TOLERANCE] * len(numbers)
    for position, orientation in poses:
        numbers += [*position, *orientation]
        tolerances += [VIEW_TOLERANCE] * len(position)
        tolerances += [ORIENTATION_TOLERANCE] * len(orientation)
    meta = (tuple(size), names, tuple(sorted(snapshot.new_models)))
    return meta, np.array(numbers), np.array(tolerances)


def _same_view(a: Any, b: Any) -> bool:
    """Two view keys give the same picture: the same size, bodies and models, and no joint
    or body moved more than its tolerance.
    """
    return a[0] == b[0] and a[1].shape == b[1].shape and bool(np.all(np.abs(a[1] - b[1]) <= a[2]))


def _resized(camera: SimCamera, size: tuple[int, int]) -> SimCamera:
    config = dataclasses.replace(camera.config, width=int(size[0]), height=int(size[1]))
    return SimCamera(camera.name, config, camera.mount)


# ---------------------------------------------------------------------- the cell's side


class _Mirror:
    """One mirror process rendering one camera; its methods are safe from any thread."""

    def __init__(self, recipe: MirrorRecipe, camera: SimCamera) -> None:
        self.recipe, self.camera = recipe, camera
        self.known: set[str] = set()  # objects whose model the mirror has been sent
        self._lock = threading.Lock()
        self._conn: Connection | None = None
        self.process: Any = None
        self._closed = False
        self._failure = ""
        # (when, size, believed pose, view key) of the frame asked for ahead and not yet read
        self._pending: tuple[float, tuple[int, int], Any, Any] | None = None
        self._last: tuple[Any, Any] | None = None  # (view key, reply) of the last frame given
        self.requests = 0  # frames asked of the mirror process (each one it renders)

    def render(
        self,
        snapshot: Callable[[set[str]], CellSnapshot],
        size: tuple[int, int],
        pose: Callable[[], Any],
        ahead: bool = False,
    ) -> tuple[Any, Any]:
        """(the mirror's reply, ``pose()`` taken with its snapshot); ``ahead``: ask for the
        next frame before returning, so that the mirror renders it while this one is shown.

        A cell that did not visibly move since the last reply (:func:`_same_view`)
        is not rendered again: that reply's pictures are returned, the very same arrays (so
        that a caller can tell that nothing changed), stamped with the time now; an idle
        cell costs its mirror nothing.
        """
        with self._lock:
            conn = self._connection()
            try:
                pending = self._pending_reply(conn, size, ahead)
                if pending is None:
                    now = snapshot(self.known)
                    key = _view_key(now, size)
                    if self._last is not None and _same_view(self._last[0], key):
                        # the same pictures, stamped now: they show the cell as it is now
                        return (*self._last[1][:3], now.stamp), pose()
                    conn.send(_Request(now, size))
                    self.requests += 1
                    reply, key = (self._receive(conn), pose()), key
                else:
                    reply, key = pending
                self._last = (key, reply[0])
                if ahead:
                    now = snapshot(self.known)
                    if not _same_view(_view_key(now, size), key):  # ahead only while it moves
                        conn.send(_Request(now, size))
                        self.requests += 1
                        self._pending = (time.perf_counter(), size, pose(), _view_key(now, size))
                return reply
            except (EOFError, OSError, TimeoutError) as exc:
                raise self._stopped(str(exc) or type(exc).__name__) from exc

    def _pending_reply(
        self, conn: Connection, size: tuple[int, int], ahead: bool
    ) -> tuple[tuple[Any, Any], Any] | None:
        """The frame asked for ahead and its view key, if this call wants one (``ahead``: a
        call without it wants the cell now) and it has this size and is not stale.
        """
        pending, self._pending = self._pending, None
        if pending is None:
            return None
        asked, asked_size, pose, key = pending
        reply = self._receive(conn)  # always read: the pipe holds one reply per request
        fresh = ahead and asked_size == tuple(size) and time.perf_counter() - asked <= STALE_AFTER
        return ((reply, pose), key) if fresh else None

    @staticmethod
    def _receive(conn: Connection) -> Any:
        if not conn.poll(FRAME_TIMEOUT):
            raise TimeoutError(f"no frame within {FRAME_TIMEOUT:.0f} s")
        return conn.recv()

    def _connection(self) -> Connection:
        if self._closed:
            raise LiveViewError("the live view was closed with the cell")
        if self._failure:
            raise LiveViewError(self._failure)
        if self._conn is None:
            self._conn = ours = self._start()
            try:
                ours.send((self.recipe, self.camera.name, self.camera))
                if not ours.poll(START_TIMEOUT) or ours.recv() != "ready":
                    raise TimeoutError(f"the renderer did not start within {START_TIMEOUT:.0f} s")
            except (EOFError, OSError, TimeoutError) as exc:
                raise self._stopped(str(exc) or "it ended while starting") from exc
            if self._closed:  # closed while it started, before it could be killed
                raise self._stopped("closed")
        return self._conn

    def _start(self) -> Connection:
        """Start the mirror process: a fresh interpreter (the caller's ``__main__`` is never
        imported again, unlike multiprocessing's spawn) talking over a socket pair.
        """
        ours, theirs = socket.socketpair()
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
        self.process = subprocess.Popen(
            [sys.executable, "-m", __name__, str(theirs.fileno())],
            pass_fds=(theirs.fileno(),),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            env=env,
        )
        theirs.close()  # only the child holds its end: its death reads as end-of-file here
        return Connection(ours.detach())

    def _stopped(self, why: str) -> LiveViewError:
        code = None
        if self.process is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                code = self.process.wait(0.5)
        ended = f" (exit code {code})" if code is not None else ""
        if self._closed:
            why = "the live view was closed with the cell"
        self._failure = f"the live view of camera {self.camera.name!r} stopped{ended}: {why}"
        self._shutdown()
        return LiveViewError(self._failure)

    def close(self) -> None:
        self._closed = True
        if self._lock.acquire(timeout=1.0):
            try:
                self._shutdown()
            finally:
                self._lock.release()
            return
        # A frame or the start is in flight (a start may take seconds): end the process; the
        # thread waiting for it reads end-of-file and shuts the rest down.
        process = self.process
        if process is not None and process.poll() is None:
            process.kill()
            process.wait(2.0)

    def _shutdown(self) -> None:
        conn, process, self._conn = self._conn, self.process, None
        self._pending = self._last = None
        if conn is not None:
            with contextlib.suppress(OSError):
                conn.send(None)
            conn.close()
        if process is not None:
            try:
                process.wait(2.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(2.0)


class LiveView:
    """Live frames of the cell's cameras, each rendered by a mirror process of its own.

    A mirror starts on the first frame asked of its camera (a cell nobody watches starts no
    process) and ends with :meth:`close`.

    Args:
        recipe: how the cell and its scene were built.
        cameras: name -> the cell's SimCamera (its optics and mount).
        snapshot: takes the cell's visible state on the physics thread; called with the
            names of the objects a mirror already has.
    """

    def __init__(
        self,
        recipe: MirrorRecipe,
        cameras: dict[str, SimCamera],
        snapshot: Callable[[set[str]], CellSnapshot],
    ) -> None:
        self._snapshot = snapshot
        self._mirrors = {name: _Mirror(recipe, camera) for name, camera in cameras.items()}

    def capture(
        self,
        name: str,
        size: tuple[int, int],
        T_world_camera: Callable[[], Pose] | None = None,
        ahead: bool = False,
    ) -> RGBDFrame:
        """A frame of camera ``name`` at ``size`` (width, height) showing the cell now.

        Args:
            name: the camera.
            size: image width and height.
            T_world_camera: gives the pose to put on the frame (the cell's belief), taken
                with the frame's snapshot; default the mirror's true camera pose.
            ahead: for a live feed: ask for the next frame before returning, so that the
                mirror renders it while this one is shown and the next call gets it at once.
                The frame then shows the cell as it was at the previous call (its stamp
                says when), unless that was more than ``STALE_AFTER`` seconds ago.

        Raises:
            LiveViewError: the mirror stopped or was closed (the message says why).
        """
        mirror = self._mirrors[name]
        believed: Callable[[], Pose | None] = T_world_camera or (lambda: None)
        (rgb, depth, true_pose, stamp), pose = mirror.render(self._snapshot, size, believed, ahead)
        config = dataclasses.replace(mirror.camera.config, width=size[0], height=size[1])
        return RGBDFrame(
            rgb=rgb,
            depth=depth,
            K=config.intrinsics(),
            T_world_camera=pose or true_pose,
            stamp=stamp,
            camera=name,
        )

    def pids(self) -> dict[str, int]:
        """Process id of each running mirror (for tests and diagnostics)."""
        return {
            name: m.process.pid
            for name, m in self._mirrors.items()
            if m.process is not None and m.process.poll() is None
        }

    def requests(self) -> dict[str, int]:
        """Frames asked of each camera's mirror so far (each one it renders)."""
        return {name: m.requests for name, m in self._mirrors.items()}

    def close(self) -> None:
        """End every mirror process (waits for each; kills one that does not end)."""
        for mirror in self._mirrors.values():
            mirror.close()


if __name__ == "__main__":  # the mirror process (started by _Mirror._start)
    _serve(Connection(int(sys.argv[1])))
