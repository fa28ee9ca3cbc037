"""Operations of the occupancy capability: is a sphere of space occupied or empty?

Design (conditions never block a tick): every camera has a feed holding its latest point
cloud, renewed on the cell's worker pool whenever an operation finds it older than
``refresh_period`` (0.1 s of cell time). A condition answers at once from the latest frame
when that is not older than its ``max_age`` port (1 s); otherwise it returns a Job that
finishes as soon as a new frame lands. In a reactive sequence rechecked every tick, a frame
is therefore always being renewed and the condition answers in the same tick. The wait
actions poll frames the same way until the region turns occupied (or empty) or the timeout
of cell time passes. ``count_points`` always takes a fresh frame.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

from capabilities.base import Capability, CapabilityEnv, OperationClass
from capabilities.kit import (
    OperationKind,
    StatefulOperation,
    camera_port,
    duration,
    flag,
    manifest,
    number,
    output,
    region,
    variant,
)
from capabilities.occupancy.settings import SETTINGS
from engine.error_types import ErrorType
from engine.operations import Job, OperationCall, StartResult
from engine.status import RUNNING, Status
from engine.types import ParamType, Region

if TYPE_CHECKING:  # the point-cloud code (numpy) loads with the first cell's setup
    from capabilities.occupancy.feed import CameraFeed, Capture
    from capabilities.occupancy.state import OccupancyState

__all__ = ["FeedJob", "capability"]

CAP = "occupancy"

Verdict = tuple[bool, str, dict[str, Any]] | None
"""(succeeded, message, outputs), or None to keep waiting for the next frame."""


class FeedJob(Job):
    """Waits for a camera frame not older than ``newer_than`` and decides on it.

    Args:
        feed: the camera's feed.
        clock: the cell's clock.
        decide: a capture -> a verdict (None: wait for the next frame).
        newer_than: frames stamped before this (cell time) are not looked at.
        period: a frame older than this (s) is renewed while waiting.
        deadline: cell time to give up at (None: wait for the first good frame only).
        on_timeout: the failure message at the deadline, given the last verdict's message.
    """

    def __init__(
        self,
        feed: CameraFeed,
        clock: Callable[[], float],
        decide: Callable[[Capture], Verdict],
        newer_than: float,
        period: float,
        deadline: float | None = None,
        on_timeout: Callable[[str], str] = lambda last: f"timed out: {last}",
    ) -> None:
        super().__init__(on_cancel=self._unsubscribe)
        self._feed, self._clock, self._decide = feed, clock, decide
        self._newer_than, self._period, self._deadline = newer_than, period, deadline
        self._on_timeout = on_timeout
        self._seen: Capture | None = None
        self._last = "no frame yet"
        self._errors_at_start = feed.error_count()
        feed.subscribe(self._frame_landed)

    def _frame_landed(self) -> None:
        wake = self._on_done
        if wake is not None:
            wake()

    def _unsubscribe(self) -> None:
        self._feed.unsubscribe(self._frame_landed)

    def poll(self) -> Status:
        if self._status is RUNNING:
            self._step()
        if self._status is not RUNNING:
            self._unsubscribe()
        return self._status

    def _step(self) -> None:
        capture = self._feed.latest()
        if capture is not None and capture is not self._seen and capture.stamp >= self._newer_than:
            self._seen = capture
            verdict = self._decide(capture)
            if verdict is not None:
                ok, message, outputs = verdict
                if ok:
                    self.succeed(message, outputs)
                else:
                    self.fail(message)
                return
        if self._feed.error_count() > self._errors_at_start:
            self.fail(f"{self._feed.name} camera: {self._feed.error()}")
            return
        now = self._clock()
        # Never time out before one frame was judged: on a simulated cell running faster
        # than real time, a short timeout can pass while the first frame renders.
        if self._deadline is not None and now >= self._deadline and self._seen is not None:
            self.fail(self._on_timeout(self._last), ErrorType.TIMEOUT)
            return
        if capture is None or now - capture.stamp >= self._period:
            self._feed.refresh()

    def note(self, message: str) -> None:
        """Remember what the last frame said (for the timeout message)."""
        self._last = message


REGION = region("region", doc="the sphere of space (world frame)")
CAMERA = camera_port("which camera's depth image looks")
MIN_POINTS = number("min_points", 30.0, doc="this many points in the region make it occupied")
MASK_ROBOT = flag("mask_robot", True, doc="leave the robot's own arm and tool out")
COMMON = (REGION, CAMERA, MIN_POINTS, MASK_ROBOT)
MAX_AGE = duration(
    "max_age", 1.0, doc="answer from a frame up to this old; older: wait for a new one"
)
TIMEOUT = duration("timeout", 10.0, doc="fail after this long (cell time)")
PERIOD = duration("period", 0.1, doc="look again this often")


class _Args:
    """The common ports of a call (typed by the engine)."""

    def __init__(self, call: OperationCall) -> None:
        self.region = call.input(REGION)
        self.camera = call.input(CAMERA)
        min_points = call.input(MIN_POINTS)
        self.min_points = max(1, round(min_points))
        self.mask_robot = call.input(MASK_ROBOT)


def _region_text(region: Region) -> str:
    c = region.center
    return (
        f"region ({c[0] * 1000:.0f}, {c[1] * 1000:.0f}, {c[2] * 1000:.0f}) mm "
        f"r {region.radius * 1000:.0f} mm"
    )


class _RegionCondition(StatefulOperation["OccupancyState"]):
    """``is_occupied`` (WANT True) or ``is_empty`` (WANT False)."""

    WANT: ClassVar[bool]

    @classmethod
    def of(cls, name: str, want: bool, doc: str) -> OperationClass:
        """The condition ``name``: true when the region is occupied (``want``) or empty."""
        ports = (*COMMON, MAX_AGE)
        return variant(cls, manifest(CAP, name, OperationKind.CONDITION, doc, *ports), WANT=want)

    def start(self, call: OperationCall) -> StartResult:
        args = _Args(call)
        max_age = call.input(MAX_AGE)
        state = self._state
        feed = state.feed(args.camera)
        want = self.WANT

        def decide(capture: Capture) -> Verdict:
            reading = state.read(capture, args.region, args.mask_robot)
            occupied = reading.occupied(args.min_points)
            word = "occupied" if occupied else "empty"
            return occupied == want, f"{word}: {reading.describe(args.min_points)}", {}

        return FeedJob(feed, state.clock, decide, state.clock() - max_age, state.refresh_period)


IsOccupied = _RegionCondition.of(
    "is_occupied", True, "True when something (not the table, not the robot) is in the region."
)
IsEmpty = _RegionCondition.of(
    "is_empty", False, "True when nothing (but the table or the robot) is in the region."
)


class _WaitForRegion(StatefulOperation["OccupancyState"]):
    """``wait_until_occupied`` / ``wait_until_empty``: poll frames until it turns so."""

    WANT: ClassVar[bool]

    @classmethod
    def of(cls, name: str, want: bool, doc: str) -> OperationClass:
        """The action ``name``: waits until the region is occupied (``want``) or empty."""
        ports = (*COMMON, TIMEOUT, PERIOD)
        return variant(cls, manifest(CAP, name, OperationKind.ACTION, doc, *ports), WANT=want)

    def start(self, call: OperationCall) -> StartResult:
        args = _Args(call)
        timeout = call.input(TIMEOUT)
        period = call.input(PERIOD)
        state = self._state
        feed = state.feed(args.camera)
        want, now = self.WANT, state.clock()
        holder: list[FeedJob] = []

        def decide(capture: Capture) -> Verdict:
            reading = state.read(capture, args.region, args.mask_robot)
            text = reading.describe(args.min_points)
            if reading.occupied(args.min_points) == want:
                return True, f"{'occupied' if want else 'empty'}: {text}", {}
            holder[0].note(text)
            return None

        word = "occupied" if want else "empty"
        job = FeedJob(
            feed,
            state.clock,
            decide,
            now - period,
            period,
            now + timeout,
            lambda last: (
                f"timed out after {timeout:g} s: {_region_text(args.region)} "
                f"never {word}; last frame: {last}"
            ),
        )
        holder.append(job)
        return job


WaitUntilOccupied = _WaitForRegion.of(
    "wait_until_occupied", True, "Waits until something is in the region; fails after the timeout."
)
WaitUntilEmpty = _WaitForRegion.of(
    "wait_until_empty", False, "Waits until the region is clear; fails after the timeout."
)


class CountPoints(StatefulOperation["OccupancyState"]):
    """``count_points``: a fresh frame's occupant points in the region."""

    MANIFEST = manifest(
        CAP,
        "count_points",
        OperationKind.QUERY,
        "How many points of a fresh frame are in the region (table and robot left out).",
        *COMMON,
        output("count", ParamType.NUMBER, doc="the occupant points counted"),
    )

    def start(self, call: OperationCall) -> StartResult:
        args = _Args(call)
        state = self._state
        feed = state.feed(args.camera)

        def decide(capture: Capture) -> Verdict:
            reading = state.read(capture, args.region, args.mask_robot)
            return True, reading.describe(args.min_points), {"count": float(reading.points)}

        # A frame taken after this call started: stamped at or after now.
        return FeedJob(feed, state.clock, decide, state.clock(), 0.0)


def setup(env: CapabilityEnv) -> OccupancyState:
    """The per-cell hook (``state.setup``), imported when a cell first needs it."""
    from capabilities.occupancy import state

    return state.setup(env)


def capability() -> Capability:
    """The occupancy capability; its per-cell state comes from ``state.setup``."""
    cap = Capability(
        CAP,
        "Whether a sphere of space is occupied, from the depth cameras' point clouds.",
        requires=("workers", "arm", "rgbd:shoulder"),
        settings=SETTINGS,
        setup=setup,
    )
    cap.add(IsOccupied, IsEmpty, WaitUntilOccupied, WaitUntilEmpty, CountPoints)
    return cap
