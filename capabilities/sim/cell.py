"""SimCell: the pybullet robot cell (UR5, parallel gripper, suction tool, table).

pybullet runs in DIRECT mode on one physics thread stepping at 240 Hz; every public object
here (robot, gripper, suction, ground_truth) sends its work there. ``speed=1.0`` paces the
simulation in real time (GUI), ``speed=None`` runs as fast as possible (CLI, tests).
``time()`` (simulated seconds) is the clock anything that waits should use.

Example::

    with SimCell() as cell:
        cell.robot.move_linear(pose).wait()
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Self, TypeVar

import numpy as np

from capabilities.bullet import pybullet
from capabilities.cell_features import ClosesOnExit
from capabilities.jobs import JobEnd, JobPacing
from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig
from capabilities.robot.kinematics import UR5Kinematics
from capabilities.sim.arm_controller import ArmController
from capabilities.sim.errors import SimError
from capabilities.sim.gripper import GripperController, SimGripper
from capabilities.sim.ground_truth import GroundTruth
from capabilities.sim.physics_thread import PhysicsThread, StepHook
from capabilities.sim.robot import SimRobot
from capabilities.sim.safety import CollisionWatch
from capabilities.sim.suction import SimSuctionTool, SuctionController
from capabilities.sim.transforms import matrix_to_pose, pose_to_matrix
from capabilities.sim.world import World, build_world
from engine.types import Pose

__all__ = ["SimCell"]

T = TypeVar("T")
TIME_STEP = 1.0 / 240.0
# Below these speeds a body or joint does not move (m/s, rad/s): the resting world's numerical
# creep is some micrometres and 1e-4 rad a second, a falling body exceeds them within a step.
REST_SPEED = 1e-3
REST_TURN = 1e-2


class SimCell(ClosesOnExit):
    """The simulated cell. Call ``start()`` (or use it as a context manager) before use.

    Attributes (after start):
        robot, gripper, suction: the devices.
        ground_truth: exact world state, for tests and scores only.
        robot_body_id, table_top_z, world: for the scene and camera helpers.

    Args:
        config: the cell's configuration (default: the shipped simulated cell).
        speed: real-time factor; None steps as fast as it can.
        driven: step only while a command runs or a thread waits for simulated time
            (``PhysicsThread.waited_on``): what happens no longer depends on how long the
            thread that drives the cell takes between two commands (tests).
        still: the world stands still from its start until a run's executor drives it
            (:meth:`advance`) or :meth:`release` lets it go (``PhysicsThread``'s ``still``).
        drawn: False for a cell no camera renders (the UR emulator's arm alone): the robot's
            visual meshes are not loaded (0.6 s of its start).
    """

    def __init__(
        self,
        config: CellConfig | None = None,
        speed: float | None = None,
        driven: bool = False,
        still: bool = False,
        drawn: bool = True,
    ) -> None:
        if config is None:
            config = (
                CellConfig.load(DEFAULT_CONFIG_PATH)
                if Path(DEFAULT_CONFIG_PATH).is_file()
                else CellConfig()
            )
        self.config = config
        self._drawn = drawn
        self.kinematics = UR5Kinematics(config.robot_base)
        self._physics = PhysicsThread(self._build, speed, TIME_STEP, still)
        if driven:
            self._physics.add_gate(self._physics.waited_on)
        self._tcp_matrices = {k: pose_to_matrix(v) for k, v in config.tcp_offsets.items()}
        self._world: World | None = None
        self._arm: ArmController | None = None
        self._gripper: GripperController | None = None
        self._suction: SuctionController | None = None
        self._namer: Callable[[int], str] | None = None

    # ---------------------------------------------------------------- lifecycle

    def start(self) -> None:
        """Build the world and start stepping.

        Raises:
            SimError: building the world failed (missing robot model, bad config).
        """
        self._physics.start()
        assert self._world and self._arm and self._gripper and self._suction
        world = self._world
        self.world = world
        self.robot_body_id = world.robot
        self.table_top_z = world.table_top_z
        self.robot = SimRobot(
            self._physics,
            self._arm,
            self.kinematics,
            self.config.home_joints,
            self.tcp_offset,
            world.robot,
            world.flange_link,
            self.config.robot.unlock_delay,
        )
        self.gripper = SimGripper(self._physics, self._gripper)
        self.suction = SimSuctionTool(
            self._physics,
            self._suction,
            self.config.holster_pose,
            self.config.handle_grasp,
            (self.config.tcp_offsets["gripper"], self.config.tcp_offsets["suction"]),
        )
        self.ground_truth = GroundTruth(self._physics, world, self._gripper, self._suction)

    def close(self) -> None:
        """Stop the physics thread and disconnect pybullet; unfinished commands fail. Idempotent."""
        self._physics.stop()
        # The physics thread has ended: no race with it any more.
        for part in (self._arm, self._gripper, self._suction):
            if part is not None:
                part.shutdown("the simulated cell was closed")

    def __enter__(self) -> Self:
        self.start()
        return self

    # ---------------------------------------------------------------- services

    @property
    def speed(self) -> float | None:
        """Real-time factor (None: as fast as possible)."""
        return self._physics.speed

    @property
    def time_step(self) -> float:
        """Seconds per physics step."""
        return self._physics.time_step

    def time(self) -> float:
        """Simulated seconds since start."""
        return self._physics.time()

    def steps(self) -> int:
        """Physics steps taken since start."""
        return self._physics.steps

    def call(self, fn: Callable[[int], T]) -> T:
        """Run ``fn(pybullet_client_id)`` on the physics thread and return its result."""
        return self._physics.call(fn)

    def standing_still(self) -> AbstractContextManager[None]:
        """A block in which simulated time stands still (see ``PhysicsThread``)."""
        return self._physics.standing_still()

    def sharing(self) -> AbstractContextManager[None]:
        """A block in which another thread computes: the world shares the GIL with it every
        step (see ``PhysicsThread.sharing``).
        """
        return self._physics.sharing()

    def job_pacing(self, latency: float | None) -> JobPacing:
        """How the world goes on while a job (perception) computes on another thread.

        None: it goes on, sharing the GIL with the job every step. A number (lockstep): it
        stands still from the tick that began the job until the job is done, and the job's
        result is handed over ``latency`` simulated seconds after it began (perception
        polled without pause still lets time pass), on the physics thread: a run sees the
        same results at the same ticks however busy the machine is.
        """
        if latency is None:
            return _SharingPacing(self._physics)
        return _LockstepPacing(self._physics, latency)

    def advance(self, seconds: float) -> None:
        """Lockstep with an engine: step the world ``seconds`` further, then stand still."""
        if not self._physics.advance(seconds, timeout=max(60.0, seconds * 100)):
            raise SimError(f"simulated time did not advance by {seconds} s")

    def release(self) -> None:
        """End the lockstep of :meth:`advance`: the world runs free again."""
        self._physics.release()

    def at(self, when: float, fn: Callable[[], None]) -> None:
        """Run ``fn()`` on the physics thread once simulated time reaches ``when`` (at the
        next step when it already has; dropped when the cell closes first): what an actor
        does at a set simulated time, the same in every run however loaded the machine.
        """
        self._physics.at(when, fn)

    def wait_sim(self, seconds: float) -> None:
        """Block until simulated time has advanced by ``seconds`` (tests, CLI)."""
        if not self._physics.wait_sim(seconds, timeout=max(60.0, seconds * 10)):
            raise SimError(f"simulated time did not advance by {seconds} s")

    def add_step_hook(self, pre: StepHook | None = None, post: StepHook | None = None) -> None:
        """Run callbacks on the physics thread before/after every step, with the sim time."""
        self._physics.call(lambda _c: self._physics.add_hooks(pre, post))

    def remove_step_hook(self, pre: StepHook | None = None, post: StepHook | None = None) -> None:
        """Stop callbacks added by :meth:`add_step_hook`."""
        self._physics.call(lambda _c: self._physics.remove_hooks(pre, post))

    def name_bodies(self, namer: Callable[[int], str]) -> None:
        """How a protective stop's message names a scene's body ("" when it does not know)."""
        self._namer = namer

    def tcp_offset(self) -> Pose:
        """The TCP of the tool in use, in the flange frame."""
        return matrix_to_pose(self._tcp_matrix())

    # ---------------------------------------------------------------- physics thread

    def _suction_in_hand(self) -> bool:
        return (
            self._gripper is not None
            and self._world is not None
            and self._gripper.attached == self._world.suction_tool
        )

    def _held_tool(self) -> int | None:
        return self._world.suction_tool if self._world and self._suction_in_hand() else None

    def _body_name(self, body: int) -> str:
        world = self._world
        if world is not None:
            fixed = {world.table: "table", world.stand: "robot stand", world.floor: "floor"}
            fixed[world.holster] = "holster"
            if body in fixed:
                return fixed[body]
        name = self._namer(body) if self._namer is not None else ""
        return name.replace("_", " ") or f"body {body}"

    def _still(self, client: int) -> bool:
        """Nothing moves and no controller has work (physics thread; the rest check of
        ``PhysicsThread``): every body's base and joints slower than ``REST_SPEED`` /
        ``REST_TURN``.
        """
        assert self._arm and self._gripper and self._suction
        if self._arm.has_work or self._gripper.moving or self._suction.has_work:
            return False
        for index in range(pybullet.getNumBodies(physicsClientId=client)):
            body = pybullet.getBodyUniqueId(index, physicsClientId=client)
            linear, angular = pybullet.getBaseVelocity(body, physicsClientId=client)
            if max(map(abs, linear)) > REST_SPEED or max(map(abs, angular)) > REST_TURN:
                return False
            joints = pybullet.getNumJoints(body, physicsClientId=client)
            if joints and any(
                abs(state[1]) > REST_TURN
                for state in pybullet.getJointStates(body, range(joints), physicsClientId=client)
            ):
                return False
        return True

    def peek(self, fn: Callable[[int], T]) -> T:
        """As :meth:`call`, for a ``fn`` that only reads (``PhysicsThread.peek``)."""
        return self._physics.peek(fn)

    def _tcp_matrix(self) -> np.ndarray:
        return self._tcp_matrices["suction" if self._suction_in_hand() else "gripper"]

    def _build(self, client: int) -> None:
        world = build_world(client, self.config, drawn=self._drawn)
        self._world = world
        self._arm = ArmController(client, world, self.kinematics, TIME_STEP, self._tcp_matrix)
        self._gripper = GripperController(
            client, world.robot, world.gripper_link, world.finger_joints
        )
        self._suction = SuctionController(
            client, world.suction_tool, world.robot, self._suction_in_hand
        )
        self._arm.watch = CollisionWatch(
            client, world.robot, self._held_tool, self.config.robot.force_limit, self._body_name
        )
        arm, gripper, suction = self._arm, self._gripper, self._suction
        physics = self._physics
        physics.add_hooks(pre=arm.pre_step, post=arm.post_step, may_rest=True)
        physics.add_hooks(
            pre=gripper.pre_step, post=lambda _t: gripper.post_step(TIME_STEP), may_rest=True
        )
        physics.add_hooks(pre=suction.pre_step, may_rest=True)
        physics.add_rest_check(lambda: self._still(client))


class _SharingPacing:
    """The world goes on while a job computes, handing it the GIL every step."""

    def __init__(self, physics: PhysicsThread) -> None:
        self._physics = physics

    def begin(self) -> JobEnd:
        block = self._physics.sharing()
        block.__enter__()

        def end(deliver: Callable[[], None]) -> None:
            block.__exit__(None, None, None)
            deliver()

        return end


class _LockstepPacing:
    """The world stands still from a job's start; its result comes ``latency`` later."""

    def __init__(self, physics: PhysicsThread, latency: float) -> None:
        self._physics = physics
        self._latency = latency

    def begin(self) -> JobEnd:
        release = self._physics.hold()
        started = self._physics.time()

        def end(deliver: Callable[[], None]) -> None:
            # Scheduled before the world may step again: it cannot be late.
            self._physics.at(started + self._latency, deliver)
            release()

        return end
