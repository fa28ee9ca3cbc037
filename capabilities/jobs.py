"""Adapters from the ways cells report work to engine Jobs.

Operations must never block a tick: a motion returns a handle that the cell finishes later,
a camera frame takes tens of milliseconds. These helpers turn both into :class:`Job` objects
that the engine polls and can cancel.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Protocol

from capabilities.faults import fault_error
from engine.error_types import ErrorType
from engine.operations import Job, OperationFailed

__all__ = [
    "CommandHandleLike",
    "JobEnd",
    "JobPacing",
    "WorkerPool",
    "chain_jobs",
    "job_from_handle",
]


class CommandHandleLike(Protocol):
    """What a cell returns for a command (the simulated and the UR cell alike)."""

    ok: bool | None
    message: str

    def done(self) -> bool: ...

    def cancel(self) -> None: ...

    def add_done_callback(self, fn: Callable[[Any], None]) -> None: ...


def job_from_handle(
    handle: CommandHandleLike,
    describe: str = "",
    outputs: Callable[[], Mapping[str, Any]] | None = None,
) -> Job:
    """A Job that finishes with the handle and cancels it when halted.

    Args:
        handle: the cell's command handle.
        describe: what the command does, prefixed to a failure message.
        outputs: called on success for the values to write (output port -> value).
    """
    job = Job(on_cancel=handle.cancel)

    def finished(_: Any) -> None:
        if handle.ok:
            try:
                job.succeed(outputs=outputs() if outputs else None)
            except Exception as exc:  # computing outputs failed: the job fails, nothing is lost
                job.fail(f"{describe}: {type(exc).__name__}: {exc}" if describe else str(exc))
        else:
            text = handle.message or "failed"
            job.fail(f"{describe}: {text}" if describe else text, fault_error(text))

    handle.add_done_callback(finished)
    return job


JobEnd = Callable[[Callable[[], None]], None]
"""A job's end under a pacing: called on the worker thread once the function ran, with what
hands its result to the engine (it calls it now, or at a set simulated time)."""


class JobPacing(Protocol):
    """How a cell's clock goes on while its jobs compute (a simulated cell's lockstep)."""

    def begin(self) -> JobEnd:
        """A job begins: called on the submitting thread (the engine's, inside a tick) before
        the job runs; returns its end.
        """
        ...


def _hand_over_now(deliver: Callable[[], None]) -> None:
    deliver()


class WorkerPool:
    """Runs blocking work (camera frames, perception) off the engine thread.

    One pool per cell session; ``submit`` returns a Job whose result is what the function
    returns: a mapping of outputs (SUCCESS), or it raises (FAILURE with the message).

    Args:
        workers: threads.
        name: their name prefix.
        pacing: how the cell's clock goes on while a job computes (a simulated cell in
            lockstep holds its world from the job's tick and hands the result over at a set
            simulated time); None: results are handed over when they are ready.
    """

    def __init__(
        self, workers: int = 2, name: str = "costar-worker", pacing: JobPacing | None = None
    ) -> None:
        self._pacing = pacing
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix=name)
        self._closed = False
        self._lock = threading.Lock()

    def submit(self, fn: Callable[[], Mapping[str, Any] | None], describe: str = "") -> Job:
        cancelled = threading.Event()
        job = Job(on_cancel=cancelled.set)

        def succeed(outputs: Mapping[str, Any] | None) -> None:
            if not cancelled.is_set():
                job.succeed(outputs=outputs or None)

        def run(end: JobEnd) -> None:
            result: Callable[[], None]
            try:
                outputs = fn()
            except OperationFailed as exc:
                result = functools.partial(job.fail, str(exc), exc.error)
            except Exception as exc:  # a perception bug fails the node, never the engine
                prefix = f"{describe}: " if describe else ""
                text = f"{prefix}{type(exc).__name__}: {exc}"
                result = functools.partial(job.fail, text, ErrorType.ERROR)
            else:
                result = functools.partial(succeed, outputs)
            end(result)

        with self._lock:
            if self._closed:
                raise OperationFailed("the cell is shut down")
            end = self._pacing.begin() if self._pacing is not None else _hand_over_now
            try:
                future: Future[None] = self._pool.submit(run, end)
            except BaseException:
                end(lambda: None)  # nothing will run: release what the pacing holds
                raise
        del future
        return job

    def close(self) -> None:
        with self._lock:
            self._closed = True
        self._pool.shutdown(wait=True, cancel_futures=True)


class _ChainJob(Job):
    """Runs job factories one after another; cancelling cancels the current one."""

    def __init__(self, steps: list[tuple[str, Callable[[], Job]]]) -> None:
        super().__init__(on_cancel=self._cancel_current)
        self._steps = list(steps)
        self._current: Job | None = None
        self._step_name = ""
        self._index = 0

    def _cancel_current(self) -> None:
        current = self._current
        if current is not None:
            current.cancel()

    def poll(self) -> Any:
        from engine.status import FAILURE, RUNNING, SUCCESS

        while True:
            if self._cancelled:
                return FAILURE
            if self._current is None:
                if self._index >= len(self._steps):
                    return SUCCESS
                self._step_name, make = self._steps[self._index]
                self._index += 1
                try:
                    self._current = make()
                except Exception as exc:
                    self.message = f"{self._step_name}: {exc}"
                    self.error = exc.error if isinstance(exc, OperationFailed) else ErrorType.ERROR
                    return FAILURE
                if self._on_done is not None:
                    self._current.bind_wake(self._on_done)
            status = self._current.poll()
            if status is RUNNING:
                return RUNNING
            if status is FAILURE:
                self.message = f"{self._step_name}: {self._current.message}"
                self.error = self._current.error  # a protective stop mid-chain stays one
                return FAILURE
            self.outputs.update(self._current.outputs)
            self._current = None


def chain_jobs(steps: list[tuple[str, Callable[[], Job]]]) -> Job:
    """One Job made of steps run in order (unholster: approach, descend, grip, lift)."""
    return _ChainJob(steps)
