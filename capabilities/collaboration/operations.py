"""Operations of the collaboration capability (the paper's Collaborator, section IV-B).

The operator side (``confirm``, ``button_pressed``, ``wait_for_button``) needs only the
cell's ``operator`` console, so it runs on every cell, the ``none`` cell included. The
handoff side (``wait_for_handoff``, ``object_in_region``) also needs the world model, the
object library and a camera; it looks them up when it starts and fails with the reason on
a cell that lacks them (availability is per capability, and the capability is the pair).

Times are on the cell's clock (``call.clock()``): simulated seconds on the simulated cell.
"""

from __future__ import annotations

from typing import Any

from capabilities.base import Capability, CapabilityEnv, CapabilityError
from capabilities.collaboration.console import (
    ConsoleEvent,
    ConsoleEventKind,
    OperatorConsole,
    Prompt,
    PromptState,
)
from capabilities.kit import (
    InPort,
    OperationKind,
    camera,
    camera_port,
    flag,
    manifest,
    object_model,
    output,
    region,
    text,
)
from capabilities.world_model import Detection, WorldModel
from engine.error_types import ErrorType
from engine.operations import Job, OperationCall, OperationFailed
from engine.status import RUNNING, Status
from engine.types import ObjectModel, ParamType

__all__ = ["CAP", "capability"]

CAP = "collaboration"


TIME = (ParamType.DURATION, ParamType.NUMBER)


def _time(name: str, default: float, doc: str) -> InPort[float]:
    """A time input in seconds (a Duration, or a Number)."""
    return InPort(name, TIME, default=default, unit="s", doc=doc)


TIMEOUT = _time("timeout", 0.0, "give up after this long (0: wait for ever)")
BUTTON = text("button", "continue", doc="the operator button")
OBJECT = object_model("object", doc="the object (by its model name)")
REGION = region("region", doc="where it must be (a sphere)")


def _seconds(call: OperationCall, port: InPort[float]) -> float:
    value = call.input(port)  # a Duration (validation checked the type, not the sign)
    if not value >= 0:
        raise OperationFailed(f"{port.name} must be a number of seconds, 0 or more, not {value!r}")
    return value


class _OperatorOp:
    """An operation on the cell's operator console."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._console: OperatorConsole = env.interface("operator")


def _interface(env: CapabilityEnv, name: str, what: str) -> Any:
    try:
        return env.interface(name)
    except CapabilityError as exc:
        raise OperationFailed(f"{what} needs {name!r}: {exc}") from exc


def _object_name(value: Any) -> str:
    return value.name if isinstance(value, ObjectModel) else str(value)


# ---------------------------------------------------------------------- operator


class _PromptJob(Job):
    """RUNNING while the prompt is open; a timeout (cell clock) or a halt withdraws it."""

    def __init__(
        self, console: OperatorConsole, prompt: Prompt, call: OperationCall, deadline: float | None
    ) -> None:
        super().__init__(on_cancel=self._withdraw)
        self._console, self._prompt, self._clock = console, prompt, call.clock
        self._deadline = deadline
        prompt.add_done_callback(self._closed)

    def _withdraw(self) -> None:
        self._console.cancel(self._prompt.id, "halted")

    def _closed(self, prompt: Prompt) -> None:
        if prompt.state is PromptState.YES:
            self.succeed("yes")
        elif prompt.state is PromptState.NO:
            self.fail("declined")
        else:
            self.fail(prompt.reason or "withdrawn")

    def poll(self) -> Status:
        deadline = self._deadline
        if self._status is RUNNING and deadline is not None and self._clock() >= deadline:
            self._console.cancel(self._prompt.id, "timed out")
        return self._status


class Confirm(_OperatorOp):
    """collaboration.confirm: asks the operator a yes/no question."""

    PROMPT = text("prompt", doc="the question shown to the operator")
    MANIFEST = manifest(
        CAP,
        "confirm",
        OperationKind.ACTION,
        "Asks the operator a yes/no question; succeeds on yes, fails on no.",
        PROMPT,
        TIMEOUT,
    )

    def start(self, call: OperationCall) -> Job:
        text = call.input(self.PROMPT).strip()
        if not text:
            raise OperationFailed("confirm needs the text of the question")
        timeout = _seconds(call, TIMEOUT)
        deadline = call.clock() + timeout if timeout > 0 else None  # counted from the asking
        prompt = self._console.ask(text, call.node_name)
        call.log(f"asked the operator: {text}")
        return _PromptJob(self._console, prompt, call, deadline)


class ButtonPressed(_OperatorOp):
    """collaboration.button_pressed: true once per latched press."""

    MANIFEST = manifest(
        CAP,
        "button_pressed",
        OperationKind.CONDITION,
        "True when the operator pressed the button since it was last checked.",
        BUTTON,
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._console.consume(call.input(BUTTON)))


class _ButtonJob(Job):
    """RUNNING until the button is pressed: a press finishes it at once from the thread that
    pressed (no wait for the next tick); a timeout is checked on the cell's clock.
    """

    def __init__(
        self, console: OperatorConsole, button: str, call: OperationCall, timeout: float
    ) -> None:
        super().__init__(on_cancel=lambda: console.remove_listener(self._heard))
        self._console, self._button, self._clock = console, button, call.clock
        self._deadline = call.clock() + timeout if timeout > 0 else None
        console.add_listener(self._heard)
        self._check()  # a press between clear() and add_listener() is not lost

    def _heard(self, event: ConsoleEvent) -> None:
        if event.kind is ConsoleEventKind.BUTTON_PRESSED and event.button == self._button:
            self._check()

    def _check(self) -> None:
        if not self.finished and self._console.consume(self._button):
            self._console.remove_listener(self._heard)
            self.succeed(f"{self._button} pressed")

    def poll(self) -> Status:
        deadline = self._deadline
        if self._status is RUNNING and deadline is not None and self._clock() >= deadline:
            self._console.remove_listener(self._heard)
            self.fail(f"timed out: {self._button!r} was not pressed", ErrorType.TIMEOUT)
        return self._status


class WaitForButton(_OperatorOp):
    """collaboration.wait_for_button: RUNNING until the button is pressed."""

    EARLIER = flag(
        "earlier_press_counts", False, doc="a press made before this node started counts"
    )
    MANIFEST = manifest(
        CAP,
        "wait_for_button",
        OperationKind.ACTION,
        "Waits until the operator presses the button (or the foot pedal).",
        BUTTON,
        TIMEOUT,
        EARLIER,
    )

    def start(self, call: OperationCall) -> Job:
        button = call.input(BUTTON)
        if not call.input(self.EARLIER):
            self._console.clear(button)
        return _ButtonJob(self._console, button, call, _seconds(call, TIMEOUT))


# ---------------------------------------------------------------------- handoff


class WaitForHandoff:
    """collaboration.wait_for_handoff: watches a camera until the object is put in the region."""

    CAMERA = camera_port("which camera watches")
    SETTLE = _time("settle", 0.0, "how long it must lie still first")
    INTERVAL = _time("interval", 0.1, "time between camera frames")
    MANIFEST = manifest(
        CAP,
        "wait_for_handoff",
        OperationKind.ACTION,
        "Waits until a person puts the object down in the region (seen by its markers).",
        OBJECT,
        REGION,
        CAMERA,
        TIMEOUT,
        SETTLE,
        INTERVAL,
        output("pose", ParamType.POSE, doc="where it was put"),
    )

    def __init__(self, env: CapabilityEnv) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        # Imported here: the handoff's marker detection needs numpy and OpenCV, which the
        # manifests (costar ops, validation, XML) do not.
        from capabilities.collaboration.handoff import HandoffJob, HandoffSettings, object_markers

        what = "wait_for_handoff"
        device = camera(self._env, call.input(self.CAMERA))
        world: WorldModel = _interface(self._env, "world", what)
        library = _interface(self._env, "objects", what)
        name = _object_name(call.input(OBJECT))
        if name not in library.names():
            raise OperationFailed(f"the object library has no model {name!r}")
        target = object_markers(library.get(name))
        if not target.markers:
            raise OperationFailed(f"{name} carries no marker: a handoff cannot be seen")
        settings = HandoffSettings(
            interval=max(_seconds(call, self.INTERVAL), 0.01),
            settle=_seconds(call, self.SETTLE),
            timeout=_seconds(call, TIMEOUT),
        )
        where = call.input(REGION)
        workers = _interface(self._env, "workers", what)
        return HandoffJob(device, target, where, world, call.clock, settings, workers, call.log)


def latest(world: WorldModel, name: str) -> Detection | None:
    """The newest detection of a class (by frame time), from any source."""
    found = world.detections(name)
    return max(found, key=lambda d: d.stamp) if found else None


class ObjectInRegion:
    """collaboration.object_in_region: the newest detection of the object is inside."""

    MAX_AGE = _time("max_age", 0.0, "ignore sightings older than this (0: any age)")
    MANIFEST = manifest(
        CAP,
        "object_in_region",
        OperationKind.CONDITION,
        "True when the object was last seen inside the region.",
        OBJECT,
        REGION,
        MAX_AGE,
    )

    def __init__(self, env: CapabilityEnv) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        world: WorldModel = _interface(self._env, "world", "object_in_region")
        detection = latest(world, _object_name(call.input(OBJECT)))
        if detection is None:
            return Job.answer(False)
        max_age = _seconds(call, self.MAX_AGE)
        if max_age > 0 and call.clock() - detection.stamp > max_age:
            return Job.answer(False)
        from capabilities.collaboration.handoff import in_region

        return Job.answer(in_region(detection.pose, call.input(REGION)))


def capability() -> Capability:
    """The collaboration capability (requires the cell's ``operator`` console)."""
    cap = Capability(
        CAP,
        "People and the robot: operator prompts and buttons, objects handed over.",
        requires=("operator",),
    )
    cap.add(Confirm, ButtonPressed, WaitForButton, WaitForHandoff, ObjectInRegion)
    return cap
