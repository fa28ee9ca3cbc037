"""Nodes with one child that change its result or repeat it.

Iterator and Enforce are the paper's (section III-B): Iterator resets its child on SUCCESS
(repeat while it succeeds), Enforce resets it on FAILURE (retry until it succeeds); both take
an optional count and timeout. Repeat(n) and Retry(n) are their counted forms under the
names BehaviorTree.CPP and py_trees users know, ticked as BehaviorTree.CPP ticks them. A
child that finishes at once gives the tick back before its next round (Iterator and Enforce:
any child), so a child that succeeds at once cannot spin the engine.

Every decorator passes a SKIPPED child up (BehaviorTree.CPP's do): it is SKIPPED itself,
except KeepRunningUntilFailure, which checks the child again on the next tick. Delay, RunOnce
and Precondition are BehaviorTree.CPP's.
"""

from __future__ import annotations

from collections.abc import Callable

from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.node import Node
from engine.script import ScriptEnv, ScriptRunError, parse_script
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, Status

__all__ = [
    "Decorator",
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "Iterator",
    "Enforce",
    "Repeat",
    "Retry",
    "Timeout",
    "KeepRunningUntilFailure",
    "Delay",
    "RunOnce",
    "Precondition",
]


class Decorator(Node):
    """A node with exactly one child."""

    kind = "decorator"

    @property
    def child(self) -> Node:
        return self.children[0]

    def set_children(self, children: list[Node] | tuple[Node, ...]) -> None:
        if len(children) != 1:
            raise ValueError(
                f"{self.kind} {self.name!r} needs exactly one child, got {len(children)}"
            )
        super().set_children(children)
        # A decorator that only maps a predicate's answer is itself a predicate.
        self.is_condition = self._passes_condition and self.children[0].is_condition

    _passes_condition = False


class _MapsResult(Decorator):
    """A decorator that passes RUNNING and SKIPPED through and maps the child's finished
    result.
    """

    _passes_condition = True

    def update(self) -> Status:
        status = self.children[0].tick()
        if status is RUNNING or status is SKIPPED:
            return status
        return self._finished(status)

    def _finished(self, status: Status) -> Status:
        raise NotImplementedError


class Inverter(_MapsResult):
    """SUCCESS <-> FAILURE; RUNNING passes through."""

    kind = "inverter"

    def _finished(self, status: Status) -> Status:
        if status is SUCCESS:
            return FAILURE
        if status is FAILURE:
            return SUCCESS
        return status


class ForceSuccess(_MapsResult):
    """SUCCESS once the child finished, whatever its result."""

    kind = "force_success"

    def _finished(self, status: Status) -> Status:
        return SUCCESS


class ForceFailure(_MapsResult):
    """FAILURE once the child finished, whatever its result."""

    kind = "force_failure"

    def _finished(self, status: Status) -> Status:
        return self.fail("forced failure", ErrorType.FAILED)


class _Clocked(Decorator):
    """A decorator that times its child from its first tick since the last reset."""

    _started: float | None = None

    def _tick_child(self) -> tuple[Node, Status]:
        if self._started is None:
            self._started = self.ctx.clock()
        child = self.children[0]
        return child, child.tick()

    def _elapsed(self) -> float:
        started = self._started
        return 0.0 if started is None else self.ctx.clock() - started

    def on_reset(self) -> None:
        self._started = None


class _Looping(_Clocked):
    """Shared loop of Iterator and Enforce: reset the child on ``repeat_on``."""

    repeat_on = SUCCESS
    on_count: Status = SUCCESS
    on_timeout: Status = SUCCESS

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str = "",
        count: int | None = None,
        timeout: float | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        if count is not None and count < 1:
            raise ValueError(f"{self.kind} count must be at least 1, not {count}")
        if timeout is not None and timeout <= 0:
            raise ValueError(f"{self.kind} timeout must be above 0 s, not {timeout}")
        self.count = count
        self.timeout = timeout
        self.done = 0

    # BehaviorTree.CPP's Repeat and RetryUntilSuccessful: a child that finished after it had
    # been running starts again in the same tick; one that finished at once gives the tick
    # back (the next round on the next tick).
    again_in_tick = False

    def update(self) -> Status:
        if self.again_in_tick:
            return self._btcpp_round()
        child, status = self._tick_child()
        if status is not RUNNING and status is not self.repeat_on:
            return status
        if status is self.repeat_on:
            self.done += 1
            if self.count is not None and self.done >= self.count:
                return self._finish_count()
            child.reset()
        if self.timeout is not None and self._elapsed() >= self.timeout:
            child.reset()
            self.message = f"time limit of {self.timeout:g} s reached after {self.done} rounds"
            if self.on_timeout is FAILURE:
                self.error = ErrorType.TIMEOUT
            return self.on_timeout
        return RUNNING

    def _btcpp_round(self) -> Status:
        child = self.children[0]
        while True:
            before = child.status
            status = child.tick()
            if status is not self.repeat_on:
                return status
            self.done += 1
            if self.count is not None and self.done >= self.count:
                return self._finish_count()
            child.reset()
            if before is IDLE:
                self.ctx.wake()  # BehaviorTree.CPP's emitWakeUpSignal: tick again soon
                return RUNNING

    def _finish_count(self) -> Status:
        if self.on_count is FAILURE:
            self.message = f"failed {self.done} times"
        return self.on_count

    def on_reset(self) -> None:
        super().on_reset()
        self.done = 0


class Iterator(_Looping):
    """Repeat the child while it succeeds: reset on SUCCESS, FAILURE ends it.

    With a count, SUCCESS after that many successes; with a timeout, SUCCESS when the time
    is up (the child kept succeeding for the whole time).
    """

    kind = "iterator"
    repeat_on = SUCCESS
    on_count = SUCCESS
    on_timeout = SUCCESS


class Enforce(_Looping):
    """Retry the child until it succeeds: reset on FAILURE, SUCCESS ends it.

    With a count, FAILURE after that many failures; with a timeout, FAILURE when the time
    is up.
    """

    kind = "enforce"
    repeat_on = FAILURE
    on_count = FAILURE
    on_timeout = FAILURE


class Repeat(Iterator):
    """Run the child ``count`` times while it succeeds (BehaviorTree.CPP's Repeat); a
    ``count`` of -1 has no limit, as its ``num_cycles="-1"``.
    """

    kind = "repeat"
    again_in_tick = True

    def __init__(self, ctx: TreeContext, node_id: str, name: str = "", count: int = 1) -> None:
        super().__init__(ctx, node_id, name, count=None if count == -1 else count)


class Retry(Enforce):
    """Try the child up to ``count`` times until it succeeds (RetryUntilSuccessful); a
    ``count`` of -1 has no limit, as its ``num_attempts="-1"``.
    """

    kind = "retry"
    again_in_tick = True

    def __init__(self, ctx: TreeContext, node_id: str, name: str = "", count: int = 1) -> None:
        super().__init__(ctx, node_id, name, count=None if count == -1 else count)


class Timeout(_Clocked):
    """FAILURE, halting the child, when it runs longer than ``seconds``."""

    kind = "timeout"

    def __init__(
        self, ctx: TreeContext, node_id: str, name: str = "", seconds: float = 1.0
    ) -> None:
        super().__init__(ctx, node_id, name)
        if seconds <= 0:
            raise ValueError(f"timeout must be above 0 s, not {seconds}")
        self.seconds = seconds

    def update(self) -> Status:
        child, status = self._tick_child()
        if status is RUNNING and self._elapsed() >= self.seconds:
            child.reset()
            return self.fail(f"timed out after {self.seconds:g} s", ErrorType.TIMEOUT)
        return status


class KeepRunningUntilFailure(Decorator):
    """RUNNING while the child succeeds (it starts again on the next tick); FAILURE when it
    fails. A skipped child is checked again on the next tick (BehaviorTree.CPP's).
    """

    kind = "keep_running_until_failure"

    def update(self) -> Status:
        child = self.children[0]
        status = child.tick()
        if status is FAILURE:
            return self.fail(f"{child.name} failed")
        if status is not RUNNING:
            child.reset()
        return RUNNING


class Delay(_Clocked):
    """BehaviorTree.CPP's Delay: RUNNING for ``seconds``, then ticks the child and gives its
    result. The first tick always answers RUNNING (BehaviorTree.CPP's timer fires on another
    thread, after the tick that started it).
    """

    kind = "delay"

    def __init__(
        self, ctx: TreeContext, node_id: str, name: str = "", seconds: float = 0.0
    ) -> None:
        super().__init__(ctx, node_id, name)
        if seconds < 0:
            raise ValueError(f"a delay of at least 0 s, not {seconds}")
        self.seconds = seconds

    def update(self) -> Status:
        if self._started is None:
            self._started = self.ctx.clock()
            return RUNNING
        if self._elapsed() < self.seconds:
            return RUNNING
        return self.children[0].tick()


class RunOnce(Decorator):
    """Runs its child to the end once; afterwards, even after a reset, it is SKIPPED
    (``then_skip``) or gives the child's result again without ticking it.
    """

    kind = "run_once"

    def __init__(
        self, ctx: TreeContext, node_id: str, name: str = "", then_skip: bool = True
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.then_skip = then_skip
        self._result: Status | None = None

    def update(self) -> Status:
        result = self._result
        if result is not None:
            if self.then_skip:
                self.message = "skipped: it has run once"
                return SKIPPED
            if result is FAILURE:
                return self.fail("it ran once and failed")
            return result
        status = self.children[0].tick()
        if status is SUCCESS or status is FAILURE:
            self._result = status
        return status

    # on_reset keeps the result: BehaviorTree.CPP's halt does not forget it either.


class Precondition(Decorator):
    """BehaviorTree.CPP's Precondition: ticks the child when the script ``if`` is true, else
    gives ``otherwise`` (its ``else``: FAILURE unless told). Once the child has started, the
    script is not checked again until the child finishes; as in BehaviorTree.CPP, a halt does
    not change that.

    Args:
        code: the script (a syntax error raises ScriptSyntaxError).
        otherwise: the status when the script is false.
        key: a name in the script -> its blackboard key (the node's scope).
    """

    kind = "precondition"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        code: str,
        otherwise: Status = FAILURE,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.script = parse_script(code)
        self.otherwise = otherwise
        self._env = ScriptEnv(ctx.blackboard, key=key, writer=node_id)
        self._child_started = False

    def update(self) -> Status:
        if not self._child_started:
            try:
                holds = self.script.check(self._env)
            except ScriptRunError as exc:
                return self.fail(f"script {exc}", ErrorType.INVALID_INPUT)
            if not holds:
                if self.otherwise is FAILURE:
                    return self.fail(f"its condition ({self.script.text.strip()}) is false")
                return self.otherwise
            self._child_started = True
        status = self.children[0].tick()
        if status is SUCCESS or status is FAILURE:
            self._child_started = False
        return status
