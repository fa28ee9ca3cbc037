"""Lockstep: simulated time stands still while perception computes on another thread (a
``standing_still`` block of the physics thread; a lockstep session's worker pool runs every
job in one), and goes on as before outside such blocks.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator

import pytest

from capabilities.jobs import JobEnd, WorkerPool
from capabilities.robot.commands import CommandHandle
from capabilities.sim.errors import SimError
from capabilities.sim.physics_thread import PhysicsThread
from capabilities.sim.session import SimCellSession
from engine.status import RUNNING, SUCCESS


@pytest.fixture
def physics() -> Iterator[PhysicsThread]:
    thread = PhysicsThread(lambda _client: None)
    thread.start()
    yield thread
    thread.stop()


def test_time_stands_still_in_a_block_and_calls_are_still_served(physics: PhysicsThread) -> None:
    assert physics.wait_sim(0.05, timeout=10.0)
    with physics.standing_still():
        held = physics.time()
        assert physics.call(lambda client: client) == physics.client  # a render is served
        time.sleep(0.2)
        assert physics.time() == held
    assert physics.wait_sim(0.05, timeout=10.0)
    assert physics.time() > held


def test_blocks_of_several_threads_overlap(physics: PhysicsThread) -> None:
    first_in, second_out = threading.Event(), threading.Event()

    def second() -> None:
        with physics.standing_still():
            first_in.wait(5.0)
        second_out.set()

    with physics.standing_still():
        helper = threading.Thread(target=second)
        helper.start()
        first_in.set()
        assert second_out.wait(5.0)
        held = physics.time()
        time.sleep(0.1)
        assert physics.time() == held  # the other block ended, this one still holds
    helper.join()
    assert physics.wait_sim(0.05, timeout=10.0)


class _Holding:
    """A pacing that holds the world from a job's start until its end."""

    def __init__(self, physics: PhysicsThread) -> None:
        self.physics = physics

    def begin(self) -> JobEnd:
        release = self.physics.hold()

        def end(deliver: Callable[[], None]) -> None:
            release()
            deliver()

        return end


def test_a_lockstep_pool_holds_the_clock_while_a_job_runs(physics: PhysicsThread) -> None:
    pool = WorkerPool(1, "test-lockstep", pacing=_Holding(physics))
    seen: list[float] = []

    def perceive() -> dict[str, float]:
        seen.append(physics.time())
        time.sleep(0.2)  # wall time a loaded machine takes
        seen.append(physics.time())
        return {}

    job = pool.submit(perceive)
    deadline = time.monotonic() + 10.0
    while job.poll() is RUNNING and time.monotonic() < deadline:
        time.sleep(0.01)
    pool.close()
    assert job.poll() is SUCCESS
    assert seen[0] == seen[1]


def test_the_physics_thread_cannot_hold_itself(physics: PhysicsThread) -> None:
    def hold(_client: int) -> None:
        with physics.standing_still():
            pass

    with pytest.raises(SimError, match="other threads"):
        physics.call(hold)


def test_a_closed_gate_stops_the_world_until_it_opens_and_nudges(physics: PhysicsThread) -> None:
    """A follower (the engine) that falls behind holds the world; its tick opens it again."""
    with physics.standing_still():  # the world must not run ahead before the gate is there
        engine_at = [physics.time()]
        physics.add_gate(lambda: physics.time() - engine_at[0] <= 0.05)
    assert physics.wait_sim(0.04, timeout=10.0)
    time.sleep(0.2)
    stopped = physics.time()
    assert stopped - engine_at[0] <= 0.05 + physics.time_step + 1e-9  # one step past, at most
    time.sleep(0.1)
    assert physics.time() == stopped  # the engine did not tick: the world waits
    engine_at[0] = stopped
    physics.nudge()
    assert physics.wait_sim(0.04, timeout=10.0)


def test_a_lockstep_session_charges_each_perception_job_its_simulated_time() -> None:
    """Time stands still while the job computes, then goes on to its latency before the job
    finishes: a plan polling perception without pause still sees time pass.
    """
    with SimCellSession("empty", 0, lockstep=0.5) as session:
        seen: list[float] = []

        def perceive() -> dict[str, float]:
            seen.append(session.clock())
            time.sleep(0.2)
            seen.append(session.clock())
            return {}

        job = session.interfaces()["workers"].submit(perceive)
        deadline = time.monotonic() + 30.0
        while job.poll() is RUNNING and time.monotonic() < deadline:
            time.sleep(0.01)
        assert job.poll() is SUCCESS
        assert seen[0] == seen[1]
        assert session.clock() >= seen[0] + 0.5


def test_a_driven_world_steps_only_while_a_command_runs_or_someone_waits(
    physics: PhysicsThread,
) -> None:
    """The gate of a driven cell: nothing happens between two commands of a slow sender."""
    with physics.standing_still():  # the loop has seen the gate before the world goes on
        physics.add_gate(physics.waited_on)
    held = physics.time()
    time.sleep(0.2)
    assert physics.time() == held
    handle = CommandHandle("three steps")
    physics.track(handle)
    ended_at: list[float] = []

    def count(now: float) -> None:
        if not handle.done() and now >= held + 3 * physics.time_step - 1e-9:
            ended_at.append(now)
            handle.resolve(True)

    physics.add_hooks(post=count)
    physics.nudge()
    assert handle.wait(10.0)
    time.sleep(0.2)
    assert physics.time() == ended_at[0]  # not one step past the step the command ended in
    assert physics.wait_sim(0.1, timeout=10.0)  # a waiter drives it too
    time.sleep(0.1)
    assert abs(physics.time() - (ended_at[0] + 0.1)) <= physics.time_step + 1e-9


def test_a_shared_block_lets_the_world_go_on(physics: PhysicsThread) -> None:
    """Unlike standing still, sharing the GIL does not stop simulated time."""
    with physics.sharing():
        assert physics.wait_sim(0.05, timeout=10.0)


def test_a_world_driven_by_an_engine_steps_one_period_per_advance(physics: PhysicsThread) -> None:
    """Lockstep: each advance is whole steps, and between two the world stands still."""
    start = physics.steps
    assert physics.advance(0.05, timeout=10.0)
    assert physics.steps - start == 12  # 0.05 s of 1/240 s steps
    time.sleep(0.2)  # an engine that takes long over its tick
    assert physics.steps - start == 12
    assert physics.call(lambda client: client) == physics.client  # calls are still served
    for _ in range(3):
        assert physics.advance(0.05, timeout=10.0)
    assert physics.steps - start == 48
    physics.release()
    assert physics.wait_sim(0.05, timeout=10.0)  # free again
    assert physics.steps - start > 48


def test_a_lockstep_job_s_result_comes_at_its_simulated_time_however_long_it_took() -> None:
    """The world stands still from the tick that began the job; its result is handed over
    on the physics thread once the latency has passed, so a driven run sees it at the same
    tick whether it took 10 ms or 300 ms of wall time.
    """
    with SimCellSession("empty", 0, lockstep=0.1) as session:
        ticks_seen = []
        for work_s in (0.01, 0.3):
            session.sim.advance(0.05)
            job = session.workers.submit(lambda w=work_s: time.sleep(w) or {})
            begun = session.clock()
            ticks = 0
            while job.poll() is RUNNING:
                session.sim.advance(0.05)  # what the executor does after each tick
                ticks += 1
            ticks_seen.append(ticks)
            assert session.clock() == pytest.approx(begun + 0.1, abs=0.05 + 1e-9)
        session.sim.release()
        assert ticks_seen[0] == ticks_seen[1] == 2
