"""The simulated cell as capabilities see it: a SimCell, a scene, cameras, interfaces.

``interfaces()`` maps interface names to backends: ``arm``, ``gripper``, ``suction``,
``freedrive`` (the devices of the SimCell), ``rgbd:shoulder`` and ``rgbd:wrist`` (cameras
whose ``capture()`` renders on the physics thread), ``world`` (the cell's world model),
``workers`` (a thread pool for blocking work such as perception) and ``operator`` (the
OperatorConsole: prompts and buttons). The clock is simulated time. A scene file with a
``worker`` block gets a simulated person (``session.worker``, see ``sim/worker.py``), one with
a ``bender`` block a working 2D wire bender (``session.bender``, see ``sim/bender.py``).
Ground truth stays on ``ground_truth`` and ``scene`` for tests and scores.

A collision is a protective stop (``sim/safety.py``), reported as the UR cell reports one:
:meth:`SimCellSession.hold_reason` names it in the same words, :meth:`SimCellSession.status`
shows it in the status bar, whose button calls :meth:`SimCellSession.clear` once the unlock
delay has passed, and :meth:`SimCellSession.clear_protective_stop` unlocks it as the UR
cell's does (refused earlier than the delay).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from capabilities.camera_source import CameraSource, stride_for
from capabilities.camera_sources import open_source
from capabilities.cell_features import CellStatus, ClosesOnExit
from capabilities.collaboration.console import OperatorConsole
from capabilities.faults import PROTECTIVE_STOP
from capabilities.jobs import WorkerPool
from capabilities.robot.cell_file import CameraSettings, CellConfig
from capabilities.sim.bender import WireBender, install_scene_bender
from capabilities.sim.bender_spec import FaultModel
from capabilities.sim.cameras import (
    CameraConfig,
    FixedMount,
    LinkMount,
    RGBDFrame,
    SimCamera,
)
from capabilities.sim.cell import SimCell
from capabilities.sim.live_view import LiveView, MirrorRecipe
from capabilities.sim.mirror_state import take_snapshot
from capabilities.sim.scene import SceneState, default_scene_path, load_scene, yaw_pose
from capabilities.sim.worker import SimWorker, install_scene_worker
from capabilities.world_model import WorldModel
from engine.executor import Lockstep
from engine.types import Pose

__all__ = ["PERCEPTION_S", "SimCameraDevice", "SimCellSession"]

PERCEPTION_S = 0.1
"""Simulated seconds a perception job (a frame and its cloud) takes in lockstep: what a run
as fast as possible charges for each look, whatever the machine's load."""


class SimCameraDevice:
    """A camera interface: ``capture()`` blocks the calling thread (never the engine's)
    while the physics thread renders a frame stamped with simulated time.

    The frame carries the extrinsics the cell *believes* (its configuration, or the result of
    a calibration), not the simulator's true camera pose: a displaced camera stays wrong
    until it is calibrated, as on a real cell. A wrist camera's believed pose is the robot's
    flange pose composed with the believed hand-eye transform.
    """

    def __init__(self, cell: SimCell, camera: SimCamera) -> None:
        self._cell = cell
        self.camera = camera
        self.name = camera.name
        mount = camera.mount
        self.on_wrist = isinstance(mount, LinkMount)
        self._smaller: dict[tuple[int, int], SimCamera] = {}  # by (width, height)
        self.live: LiveView | None = None  # the session's mirror renderer, if it has one
        self._believed: Pose = (
            mount.T_link_camera if isinstance(mount, LinkMount) else mount.T_world_camera
        )

    @property
    def intrinsics(self) -> np.ndarray:
        return self.camera.intrinsics()

    def extrinsics(self) -> Pose:
        """The camera (OpenCV frame) in the world, as the cell believes it is now."""
        if self.on_wrist:
            return self._cell.robot.flange_pose().compose(self._believed)
        return self._believed

    def set_extrinsics(self, pose: Pose) -> None:
        """Store a calibration: the world pose (fixed camera) or the flange pose (wrist)."""
        self._believed = pose

    def capture(
        self, max_width: int | None = None, size: tuple[int, int] | None = None
    ) -> RGBDFrame:
        """Render a frame; ``size`` (width, height) renders a smaller view of the same
        camera (a live preview: the CPU renderer's cost grows with the pixels), as does
        ``max_width`` (the size of every n-th pixel, as a real camera's frame subsampled by
        ``RGBDFrame.at_most``).
        """
        if size is None and max_width is not None:
            config = self.camera.config
            stride = stride_for(config.width, max_width)
            size = (config.width // stride, config.height // stride)
        camera = self.camera if size is None else self._resized(size)

        def render(client: int) -> RGBDFrame:
            frame = camera.capture(client, stamp=self._cell.time())
            return dataclasses.replace(frame, T_world_camera=self.extrinsics())

        return self._cell.call(render)

    def preview(self, size: tuple[int, int], ahead: bool = False) -> RGBDFrame:
        """A live picture at ``size`` (width, height) for a view of the cell, rendered by the
        session's mirror in another process: the physics thread only takes a snapshot.
        ``ahead`` (a live feed): the mirror renders the next picture while this one is shown
        (a picture then shows the cell as at the previous call; see ``LiveView.capture``).

        Not for perception: use :meth:`capture` (exact, rendered on the physics thread).

        Raises:
            LiveViewError: the mirror stopped (the message says why).
        """
        if self.live is None:
            return self.capture(size=size)
        return self.live.capture(self.name, size, self.extrinsics, ahead)

    def _resized(self, size: tuple[int, int]) -> SimCamera:
        config = self.camera.config
        if (config.width, config.height) == tuple(size):
            return self.camera
        if size not in self._smaller:  # one each: each keeps its own noise going
            small = dataclasses.replace(config, width=int(size[0]), height=int(size[1]))
            self._smaller[size] = SimCamera(self.camera.name, small, self.camera.mount)
        return self._smaller[size]

    def displace_for_test(self, true_pose: Pose) -> None:
        """TEST ONLY: physically move a fixed camera (its believed pose stays as it was)."""
        if self.on_wrist:
            raise ValueError("only a fixed camera can be displaced")
        self.camera = SimCamera(self.camera.name, self.camera.config, FixedMount(true_pose))
        self._smaller.clear()


class SimCellSession(ClosesOnExit):
    """A running simulated cell with its scene; a context manager.

    Args:
        scene: a scene name in ``resources/scenes`` or a path.
        seed: randomisation seed of the scene.
        speed: 1.0 real time (GUI); None as fast as possible (CLI, tests).
        config: the cell configuration (default ``resources/cells/sim_default.json``).
        shoulder_size: (width, height) of the shoulder camera instead of the configured one.
        wrist_size: (width, height) of the wrist camera instead of the configured one.
        faults: the wire bender's fault rates instead of the scene file's.
        start_actors: start the scene's worker and bender now; False: they wait for
            :meth:`start_actors` (a run as fast as possible starts them with its plan, so
            that setting up the run costs no simulated time of theirs).
        lockstep: None: off (the world goes on while perception computes). A number: the
            simulated seconds each job of the worker pool (perception) takes: simulated time
            stands still from the tick that began it until it is done, as it does while a
            camera renders, and its result comes that long after it began. A run's executor
            then also drives the world (:meth:`run_lockstep`): it goes on one tick's period
            after each tick. A run as fast as possible (the CLI, tests, benches) then sees
            the world as its plan asks however loaded the machine, and a plan that polls
            perception without pause still lets time pass.
        still_until_run: in lockstep, the world stands still from the start until a run's
            executor drives it, so that the run begins at simulated time 0 whatever its
            set-up took (the CLI's runs); else it goes on by itself until then.
    """

    name = "sim"

    def __init__(
        self,
        scene: str | Path = "cup_to_bin",
        seed: int = 0,
        speed: float | None = None,
        config: CellConfig | None = None,
        shoulder_size: tuple[int, int] | None = None,
        wrist_size: tuple[int, int] | None = None,
        faults: FaultModel | None = None,
        start_actors: bool = True,
        lockstep: float | None = None,
        still_until_run: bool = False,
    ) -> None:
        self.sim = SimCell(config, speed, still=still_until_run and lockstep is not None)
        self.world_model = WorldModel()
        self._lockstep = lockstep
        # Perception computes while the world stands still (lockstep) or shares the GIL
        # with it every step (else it crawls beside a cell that steps as fast as it can).
        self.workers = WorkerPool(2, "costar-sim-worker", self.sim.job_pacing(lockstep))
        self.operator = OperatorConsole()
        self.worker: SimWorker | None = None  # the simulated person, if the scene has one
        self.live_view: LiveView | None = None  # live pictures (a mirror per camera)
        self.bender: WireBender | None = None  # the wire bender, if the scene has one
        self.sim.start()
        try:
            path = (
                Path(scene)
                if Path(str(scene)).suffix == ".json"
                else default_scene_path(str(scene))
            )
            holster = self.sim.config.holster_pose.position
            self.scene: SceneState = self.sim.call(
                lambda client: load_scene(
                    client,
                    path,
                    seed,
                    table_top_z=self.sim.table_top_z,
                    make_table=False,
                    keep_out=((holster[0], holster[1], 0.12),),
                )
            )
            sizes = {"shoulder": shoulder_size, "wrist": wrist_size}
            self.cameras: dict[str, CameraSource] = {
                name: self._device(name, settings, sizes.get(name))
                for name, settings in self.sim.config.cameras.items()
            }
            self.sim.name_bodies(self._body_name)
            self.worker = install_scene_worker(self.sim, self.scene, path, seed, start_actors)
            self.bender = install_scene_bender(
                self.sim, self.scene, path, seed, faults, start_actors
            )
            self._install_live_view(
                MirrorRecipe(
                    self.sim.config,
                    path,
                    seed,
                    self.sim.table_top_z,
                    ((holster[0], holster[1], 0.12),),
                )
            )
        except BaseException:
            self.close()
            raise

    def _device(
        self, name: str, settings: CameraSettings, size: tuple[int, int] | None
    ) -> CameraSource:
        """A rendered camera, or the recorded or real source the cell file names."""
        if settings.source == "sim":
            return SimCameraDevice(self.sim, self._camera(name, settings, size))
        return open_source(name, settings.source, settings.where, self.sim.config.folder())

    def _install_live_view(self, recipe: MirrorRecipe) -> None:
        """Give each camera the live view (its mirror starts on the first picture asked)."""
        sim = self.sim

        def snapshot(known: set[str]) -> Any:
            return sim.peek(lambda c: take_snapshot(c, sim.world, self.scene, sim.time(), known))

        rendered = {n: d for n, d in self.cameras.items() if isinstance(d, SimCameraDevice)}
        self.live_view = LiveView(recipe, {n: d.camera for n, d in rendered.items()}, snapshot)
        for device in rendered.values():  # a recorded or real source shows its own frames
            device.live = self.live_view

    def _camera(
        self, name: str, settings: CameraSettings, size: tuple[int, int] | None
    ) -> SimCamera:
        """A simulated camera as the cell configuration describes it."""
        width, height = size or settings.size
        optics = CameraConfig(
            width=width,
            height=height,
            fov_y=math.radians(settings.fov_y_deg),
            near=settings.near,
            far=settings.far,
        )
        if settings.on_wrist:
            mount = LinkMount(self.sim.robot_body_id, self.sim.robot.flange_link(), settings.pose)
            return SimCamera(name, optics, mount)
        return SimCamera(name, optics, FixedMount(settings.pose))

    def start_actors(self) -> None:
        """Start the scene's worker and bender if they wait (``start_actors=False``)."""
        for actor in (self.worker, self.bender):
            if actor is not None:
                actor.start()

    @property
    def ground_truth(self) -> Any:
        """GROUND TRUTH of the devices, for tests and scores only."""
        return self.sim.ground_truth

    def truth_pose(self, name: str) -> Pose:
        """GROUND TRUTH of an object's pose, for tests and scores only."""
        return self.sim.call(lambda client: self.scene.truth_pose(client, name))

    def interfaces(self) -> Mapping[str, Any]:
        return {
            "arm": self.sim.robot,
            "gripper": self.sim.gripper,
            "suction": self.sim.suction,
            "freedrive": self.sim.robot,
            **{f"rgbd:{name}": camera for name, camera in self.cameras.items()},
            "world": self.world_model,
            "workers": self.workers,
            "scene_layout": self.scene_layout(),
            "objects": self.scene.library,
            "operator": self.operator,
        }

    def scene_layout(self) -> dict[str, Any]:
        """What a worker configures about the cell (not ground truth of movable objects):
        marker sizes, which object carries which marker, the poses of the markers that never
        move (on the table, and on fixtures the scene file puts at one pose: a machine bolted
        down, measured once; the paper calibrated its cameras on the bender's), and the fixed
        furniture (table, holster) as boxes.
        """
        # Every marker the object library knows, not only those on objects present now: an
        # object handed in later must be recognised by its marker too.
        sizes = {m.marker_id: m.size for m in self.scene.fixed_markers.values()}
        library = self.scene.library
        for name in library.names():
            sizes.update({m.marker_id: m.size for m in library.get(name).markers})
        table = self.sim.config.table
        movable = [entry.model for entry in self.scene.spec.objects if not entry.fixed]
        return {
            "marker_sizes": sizes,
            # The models the scene puts on the table (not where): what a plan handles here.
            "objects": list(dict.fromkeys(movable)),
            "fixed_markers": {m.marker_id: m.pose for m in self.scene.fixed_markers.values()}
            | self._fixture_markers(),
            # The furniture, for views of the cell: boxes (name, centre pose, size x y z).
            "fixtures": [
                ("table", Pose((*table.center, table.top_z - table.size[2] / 2)), table.size),
                (
                    "holster",
                    self.sim.config.holster_pose.compose(Pose((0.0, 0.0, 0.05))),
                    (0.12, 0.12, 0.10),
                ),
            ],
        }

    def _fixture_markers(self) -> dict[int, Pose]:
        """World poses of the markers on fixtures placed at their nominal pose (no random)."""
        found: dict[int, Pose] = {}
        for entry in self.scene.spec.objects:
            if entry.fixed and not entry.random:
                x, y = entry.position
                frame = yaw_pose(x, y, self.scene.table_top_z, entry.yaw)
                for marker in self.scene.library.get(entry.model).markers:
                    found[marker.marker_id] = frame.compose(marker.pose)
        return found

    def clock(self) -> float:
        return self.sim.time()

    def run_lockstep(self) -> Lockstep | None:
        """The simulated cell, for a run's executor to drive, when this session is in lockstep."""
        return self.sim if self._lockstep is not None else None

    # ---------------------------------------------------------------- safety

    def hold_reason(self) -> str:
        """Why the robot cannot act now ("protective stop", or ""): the executor's hold check."""
        return PROTECTIVE_STOP if self.sim.robot.protective_stop() is not None else ""

    def clear_protective_stop(self) -> None:
        """Unlock a protective stop (blocks briefly; nothing when there is none).

        Raises:
            SimError: earlier than the unlock delay after the stop, as a UR refuses it.
        """
        self.sim.robot.unlock_protective_stop()

    def status(self) -> CellStatus | None:
        """The robot's state for the status bar while it is stopped (None while it can move:
        the simulated arm has no controller state worth a permanent label).
        """
        stop = self.sim.robot.protective_stop()
        if stop is None:
            return None
        allowed = self.sim.time() - stop.time >= self.sim.robot.unlock_delay
        return CellStatus(
            True,
            "RUNNING",
            "PROTECTIVE_STOP",
            "STOPPED",
            PROTECTIVE_STOP,
            "Unlock protective stop" if allowed else "",
        )

    def clear(self) -> None:
        """The operator's clear from the status bar: unlock the protective stop as soon as
        the unlock delay allows (returns at once; the physics thread does it).
        """
        self.sim.robot.clear_protective_stop()  # finishes by itself once allowed

    def _body_name(self, body: int) -> str:
        """A scene object's name by its body (physics thread; "" when not one)."""
        for name, spawned in self.scene.objects.items():
            if spawned.body_id == body:
                return name
        return ""

    def capability_settings(self) -> tuple[Mapping[str, Any], str]:
        """The ``capabilities`` block of the cell file and the file's path (for errors)."""
        config = self.sim.config
        return config.capabilities, config.source or "the simulated cell's configuration"

    def close(self) -> None:
        if self.live_view is not None:
            self.live_view.close()
        self.workers.close()
        self.sim.close()
