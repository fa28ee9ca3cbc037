"""A cell's fault words become error types a Catch node matches; jobs keep the type."""

from __future__ import annotations

import threading

import pytest

from capabilities.faults import fault_error
from capabilities.jobs import WorkerPool, chain_jobs, job_from_handle
from capabilities.robot.commands import CommandHandle
from engine.error_types import ErrorType
from engine.operations import Job, OperationFailed
from engine.status import FAILURE


@pytest.mark.parametrize(
    ("message", "error"),
    [
        ("move_linear: protective stop", ErrorType.PROTECTIVE_STOP),
        ("move_joints: emergency stop", ErrorType.EMERGENCY_STOP),
        ("set tool digital output 0: connection lost (timed out)", ErrorType.CONNECTION_LOST),
        ("move_joints: the move ended away from its target", ErrorType.FAILED),
    ],
)
def test_a_failed_handle_gives_the_type_of_its_fault(message: str, error: ErrorType) -> None:
    assert fault_error(message) is error
    job = job_from_handle(CommandHandle.failed("move", message), "approach")
    assert job.poll() is FAILURE and job.error is error and job.message.startswith("approach: ")


def test_a_chain_keeps_the_type_of_the_step_that_failed() -> None:
    stop = CommandHandle.failed("descend", "descend: protective stop")
    job = chain_jobs([("ok", Job.done), ("descend", lambda: job_from_handle(stop))])
    assert job.poll() is FAILURE and job.error is ErrorType.PROTECTIVE_STOP

    def raises() -> Job:
        raise OperationFailed("no part", ErrorType.OBJECT_LOST)

    job = chain_jobs([("take", raises)])
    assert job.poll() is FAILURE and job.error is ErrorType.OBJECT_LOST


def test_the_worker_pool_keeps_the_type_of_what_its_work_raised() -> None:
    pool = WorkerPool(2)
    try:

        def unseen() -> None:
            raise OperationFailed("cup has not been seen", ErrorType.NOT_FOUND)

        def broken() -> None:
            raise ZeroDivisionError("bug")

        seen, bug = pool.submit(unseen), pool.submit(broken)
        done = threading.Event()
        for job in (seen, bug):
            job.bind_wake(lambda: done.set() if seen.finished and bug.finished else None)
        assert done.wait(10)
    finally:
        pool.close()
    assert seen.error is ErrorType.NOT_FOUND and bug.error is ErrorType.ERROR
