"""What the cell does beside a run's events, in the run's record, while the run goes.

Run listeners that start a thread of their own when the run starts and end it when the run
ends, so reading the cell never takes a tick of the engine's or a moment of the event
dispatcher's:

- :class:`JointSampler`: the robot's joints ten times a second, each a ``joints`` record
  (``q``: the six joint angles in radians); a replay or a timeline puts the robot there;
- :class:`ThumbnailSampler`: a small JPEG of each camera once a second, each a ``thumbnail``
  record (``camera``: its name, ``jpeg``: the picture in base64); a timeline shows it.
  A camera with ``preview(size)`` (the simulated cell's) is rendered by the cell's live view
  in a process of its own, as the camera panel's pictures are: the physics thread only takes
  a snapshot, and a run in lockstep is not held. Any other camera is read with ``capture()``
  (a real camera: its own device, not the cell's thread). At 160x120 and quality 60 a
  picture of the simulated cell is 2-3 KB (about 25 MB an hour for two cameras, in base64).

- :class:`OperatorActions`: what the operator console asked the people at the cell and
  what they did, as it happens (an ``operator`` record each: ``action`` asked, answered,
  withdrawn or pressed; the question's ``text`` and ``prompt`` id, who asked (``source``),
  the ``answer`` and who gave it (``by``), the ``button`` pressed). Stops and holds are the
  run's own events (``held``, ``paused``, ``finished``), kept by the recorder itself.

:func:`record_samplers` gives them for a cell, as `costar run` and the Instructor use them.
"""

from __future__ import annotations

import base64
import threading
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

from capabilities.collaboration.console import ConsoleEvent, ConsoleEventKind, OperatorConsole
from engine.events import Event, RunFinished, RunStarted
from engine.trace import TraceRecorder

if TYPE_CHECKING:
    import numpy as np

__all__ = [
    "JointSampler",
    "OperatorActions",
    "SAMPLE_PERIOD_S",
    "THUMBNAIL_PERIOD_S",
    "THUMBNAIL_QUALITY",
    "THUMBNAIL_SIZE",
    "ThumbnailSampler",
    "record_samplers",
]

SAMPLE_PERIOD_S = 0.1
THUMBNAIL_PERIOD_S = 1.0
THUMBNAIL_SIZE = (160, 120)  # (width, height)
THUMBNAIL_QUALITY = 60  # JPEG quality, 0-100


class _Arm(Protocol):
    def joint_positions(self) -> Sequence[float]: ...


class _Sampler:
    """A run listener whose thread calls :meth:`_take` every ``period`` s from the run's
    start to its end. A take that fails (a controller gone, a cell closing) writes nothing
    that time: the record goes on with the run's events.
    """

    _name = "costar-sampler"

    def __init__(self, recorder: TraceRecorder, period: float) -> None:
        self._recorder = recorder
        self._period = period
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._sample, name=self._name, daemon=True)

    def __call__(self, event: Event) -> None:
        if isinstance(event, RunStarted) and not self._thread.is_alive():
            self._thread.start()
        elif isinstance(event, RunFinished):
            self._done.set()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the sampling thread ended (after the run's end); whether it has."""
        if self._thread.is_alive():
            self._thread.join(timeout)
        return not self._thread.is_alive()

    def _sample(self) -> None:
        while not self._done.is_set():
            try:
                records = self._take()
            except Exception:  # the cell cannot answer now: nothing this time
                records = []
            for record in records:
                self._recorder.note(record)
            self._done.wait(self._period)

    def _take(self) -> list[dict[str, Any]]:
        raise NotImplementedError


class JointSampler(_Sampler):
    """A run listener that writes ``arm``'s joints to ``recorder`` every ``period`` s."""

    _name = "costar-joints"

    def __init__(self, arm: _Arm, recorder: TraceRecorder, period: float = SAMPLE_PERIOD_S) -> None:
        super().__init__(recorder, period)
        self._arm = arm

    def _take(self) -> list[dict[str, Any]]:
        q = [round(float(a), 6) for a in self._arm.joint_positions()]
        return [{"event": "joints", "q": q}] if q else []


def thumbnail_jpeg(
    rgb: np.ndarray, size: tuple[int, int] = THUMBNAIL_SIZE, quality: int = THUMBNAIL_QUALITY
) -> bytes:
    """An HxWx3 RGB picture as a ``size`` JPEG (shrunk when it is larger)."""
    import cv2  # here: a command that runs no camera loads neither
    import numpy as np

    picture: np.ndarray = np.asarray(rgb, dtype=np.uint8)[..., :3]
    if (picture.shape[1], picture.shape[0]) != tuple(size):
        picture = cv2.resize(picture, size, interpolation=cv2.INTER_AREA)
    ok, data = cv2.imencode(
        ".jpg",
        cv2.cvtColor(np.ascontiguousarray(picture), cv2.COLOR_RGB2BGR),
        [cv2.IMWRITE_JPEG_QUALITY, int(quality)],
    )
    if not ok:
        raise ValueError("the picture could not be encoded as a JPEG")
    return bytes(data)


class ThumbnailSampler(_Sampler):
    """A run listener that writes a thumbnail of each camera to ``recorder`` every
    ``period`` s (see the module doc).

    Args:
        cameras: name -> camera interface (``preview(size)`` or ``capture()`` giving a frame
            with ``rgb``), e.g. the cell's ``rgbd:shoulder`` and ``rgbd:wrist``.
        recorder: the run's record.
        period: seconds between two thumbnails of a camera.
        size: (width, height) of a thumbnail.
        quality: JPEG quality.
    """

    _name = "costar-thumbnails"

    def __init__(
        self,
        cameras: Mapping[str, Any],
        recorder: TraceRecorder,
        period: float = THUMBNAIL_PERIOD_S,
        size: tuple[int, int] = THUMBNAIL_SIZE,
        quality: int = THUMBNAIL_QUALITY,
    ) -> None:
        super().__init__(recorder, period)
        self._cameras = dict(sorted(cameras.items()))
        self._size = size
        self._quality = quality
        self.failures: dict[str, str] = {}  # camera -> why its last picture failed

    def _grab(self, camera: Any) -> Any:
        preview: Callable[..., Any] | None = getattr(camera, "preview", None)
        if callable(preview):
            return preview(self._size)
        return camera.capture()

    def _take(self) -> list[dict[str, Any]]:
        records = []
        for name, camera in self._cameras.items():
            try:  # one camera failing keeps the others' pictures
                jpeg = thumbnail_jpeg(self._grab(camera).rgb, self._size, self._quality)
            except Exception as exc:
                self.failures[name] = str(exc) or type(exc).__name__
                continue
            self.failures.pop(name, None)
            text = base64.b64encode(jpeg).decode("ascii")
            records.append({"event": "thumbnail", "camera": name, "jpeg": text})
        return records


class OperatorActions:
    """A run listener that writes the operator console's questions, answers and button
    presses to ``recorder`` from its making (before the run starts: a plan may ask at its
    first tick) to the run's end (see the module doc). The console's listener runs on the
    thread that made the change and only writes a line.
    """

    def __init__(self, console: OperatorConsole, recorder: TraceRecorder) -> None:
        self._console = console
        self._recorder = recorder
        self._lock = threading.Lock()
        self._asked: set[str] = set()  # the prompts whose question is in the record
        console.add_listener(self._heard)

    def __call__(self, event: Event) -> None:
        if isinstance(event, RunFinished):
            self._console.remove_listener(self._heard)

    def _heard(self, event: ConsoleEvent) -> None:
        prompt = event.prompt
        by = {"by": event.by} if event.by else {}
        if event.kind is ConsoleEventKind.BUTTON_PRESSED:
            self._note({"action": "pressed", "button": event.button, **by})
            return
        if prompt is None:
            return
        with self._lock:  # a question before its answer, though another thread may answer
            if prompt.id not in self._asked:  # it before this one hears it was shown
                self._asked.add(prompt.id)
                source = {"source": prompt.source} if prompt.source else {}
                self._note({"action": "asked", "prompt": prompt.id, "text": prompt.text, **source})
            if event.kind is ConsoleEventKind.PROMPT_SHOWN:
                return
            self._asked.discard(prompt.id)
        closed = {"prompt": prompt.id, "text": prompt.text}
        if prompt.answer is None:
            self._note({"action": "withdrawn", **closed, "reason": prompt.reason, **by})
        else:
            answer = "yes" if prompt.answer else "no"
            self._note({"action": "answered", **closed, "answer": answer, **by})

    def _note(self, record: dict[str, Any]) -> None:
        self._recorder.note({"event": "operator", **record})


def record_samplers(cell: Any, recorder: TraceRecorder) -> list[Callable[[Event], None]]:
    """What ``cell`` adds to a run's record: its arm's joints, its cameras' thumbnails, its
    operator console's questions and answers (none for a cell without them).
    """
    interfaces = cell.interfaces() if cell is not None else {}
    listeners: list[Callable[[Event], None]] = []
    arm = interfaces.get("arm")
    if arm is not None:
        listeners.append(JointSampler(arm, recorder))
    cameras = {k.split(":", 1)[1]: v for k, v in interfaces.items() if k.startswith("rgbd:")}
    if cameras:
        listeners.append(ThumbnailSampler(cameras, recorder))
    console = interfaces.get("operator")
    if isinstance(console, OperatorConsole):
        listeners.append(OperatorActions(console, recorder))
    return listeners
