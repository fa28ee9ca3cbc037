"""BehaviorTree.CPP's LoopInt, LoopDouble, LoopBool and LoopString: one decorator that takes
the values of a queue one by one, writes each to an entry and runs its child with it
(include/behaviortree_cpp/decorators/loop_node.h).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

from engine.blackboard import MISSING, BlackboardError
from engine.context import TreeContext
from engine.decorators import Decorator
from engine.error_types import ErrorType
from engine.port_text import braced
from engine.script.values import ScriptEnv
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status

__all__ = ["LOOP_TYPES", "Loop", "parse_queue"]

_INT = re.compile(r"-?\d+")
_BOOLS = {"true": True, "True": True, "TRUE": True, "1": True}
_BOOLS |= {"false": False, "False": False, "FALSE": False, "0": False}


def _real(text: str) -> float:
    return float(text)


def _integer(text: str) -> int:
    if not _INT.fullmatch(text):
        raise ValueError(f"not an integer: {text!r}")
    return int(text)


def _boolean(text: str) -> bool:
    if text not in _BOOLS:
        raise ValueError(f"not true or false: {text!r}")
    return _BOOLS[text]


# The element type (BehaviorTree.CPP's LoopInt ...) -> how one element of a text is read.
LOOP_TYPES: dict[str, Callable[[str], Any]] = {
    "int": _integer,
    "double": _real,
    "bool": _boolean,
    "string": str,
}


def parse_queue(text: str, of: str) -> list[Any]:
    """The elements of a ``;``-separated queue of type ``of`` (empty text: no element).

    Raises:
        ValueError: an element that is not of the type.
    """
    if text == "":
        return []
    read = LOOP_TYPES[of]
    return [read(part) for part in text.split(";")]


class Loop(Decorator):
    """Each tick while its child is not running, takes the next value of the queue, writes it
    to the ``value`` entry and ticks the child; RUNNING after the child succeeded (the next
    value on the next tick), FAILURE when it failed, and ``if_empty`` when no value is left.

    The queue is a text of values separated by ``;``, or ``{key}``: an entry holding such a
    text or a list, read when the loop (re)starts. The entry is never changed (BehaviorTree.CPP
    consumes a shared queue in place; the blackboard here holds none).

    Args:
        queue: the queue's text, or ``{key}``.
        value: ``{key}``, the entry each value is written to.
        of: the element type: int, double, bool or string.
        if_empty: the status when the queue has no value left.
        key: a name -> its blackboard key (the node's scope).
    """

    kind = "loop"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        queue: str,
        value: str,
        of: str = "string",
        if_empty: Status = SUCCESS,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        target = braced(value)
        if not target:
            raise ValueError(f"a loop writes its value to an entry, {{key}}, not {value!r}")
        self.of = of
        self.if_empty = if_empty
        self._env = ScriptEnv(ctx.blackboard, key=key, writer=node_id)
        self._target = self._env.key_of(target)
        self._source = braced(queue)
        self._static = None if self._source is not None else parse_queue(queue, of)
        self._queue: list[Any] | None = None
        self._child_running = False

    def update(self) -> Status:
        if self.status is IDLE:
            self._child_running = False
            self._queue = None if self._static is None else list(self._static)
        if not self._child_running:
            if self._queue is None:
                try:
                    self._queue = self._read_queue()
                except ValueError as exc:
                    return self.fail(f"queue: {exc}", ErrorType.INVALID_INPUT)
            if not self._queue:
                return self._empty()
            try:
                self.ctx.write(self._target, self._queue.pop(0), self.id)
            except BlackboardError as exc:
                return self.fail(str(exc), ErrorType.INVALID_INPUT)
        child = self.children[0]
        status = child.tick()
        self._child_running = status is RUNNING
        if status is SUCCESS or status is FAILURE:
            child.reset()
        if status is FAILURE:
            return self.fail(f"{child.name} failed")
        return RUNNING

    def _read_queue(self) -> list[Any]:
        """The queue entry's values (none when the entry has no value)."""
        assert self._source is not None
        held = self._env.blackboard.get(self._env.key_of(self._source), MISSING)
        if held is MISSING:
            return []
        if isinstance(held, str):
            return parse_queue(held, self.of)
        if isinstance(held, (list, tuple)):
            return list(held)
        raise ValueError(f"{self._source} holds neither a list nor a text of values")

    def _empty(self) -> Status:
        self.message = "the queue is empty"
        if self.if_empty is FAILURE:
            return self.fail("the queue is empty")
        return self.if_empty

    def on_reset(self) -> None:
        self._queue = None
        self._child_running = False
