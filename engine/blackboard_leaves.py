"""BehaviorTree.CPP's small leaves: AlwaysSuccess, AlwaysFailure, SetBlackboard and
UnsetBlackboard; each answers in one tick.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.blackboard import MISSING, BlackboardError
from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.node import Node
from engine.port_text import braced, port_text
from engine.script.values import ScriptEnv
from engine.status import FAILURE, SUCCESS, Status
from engine.types import ParamType

__all__ = ["AlwaysSuccess", "AlwaysFailure", "SetBlackboard", "UnsetBlackboard"]

_BOOL_TEXT = {"true": True, "false": False, "1": True, "0": False}


class AlwaysSuccess(Node):
    """SUCCESS, at once."""

    kind = "always_success"

    def update(self) -> Status:
        return SUCCESS


class AlwaysFailure(Node):
    """FAILURE, at once."""

    kind = "always_failure"

    def update(self) -> Status:
        return self.fail("it always fails", ErrorType.FAILED)


class _Entries(Node):
    """A leaf that reads its texts as BehaviorTree.CPP's ports (``{key}``: an entry)."""

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        self._env = ScriptEnv(ctx.blackboard, key=key, writer=node_id)

    def _name(self, port: str, text: str) -> str | None:
        """The entry name a port gives, or None (the node failed: the message says why)."""
        name = port_text(text, self._env)
        if name is None:
            self.fail(f"{port} {text} has no value", ErrorType.INVALID_INPUT)
        return name


class SetBlackboard(_Entries):
    """Writes ``value`` to the entry ``output_key``: ``{key}`` copies that entry, other text
    is written as it is, or converted to the Number or Bool the entry already holds (or is
    declared as), as BehaviorTree.CPP converts to the entry's type.
    """

    kind = "set_blackboard"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        value: str,
        output_key: str,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name, key=key)
        self.value = value
        self.output_key = output_key

    def update(self) -> Status:
        target = self._name("output_key", self.output_key)
        if target is None:
            return FAILURE
        env = self._env
        dst = env.key_of(target)
        source = braced(self.value)
        if source is not None:
            value = env.blackboard.get(env.key_of(source), MISSING)
            if value is MISSING:
                return self.fail(f"value {self.value} has no value", ErrorType.INVALID_INPUT)
        else:
            try:
                value = self._converted(dst, self.value)
            except ValueError as exc:
                return self.fail(str(exc), ErrorType.INVALID_INPUT)
        try:
            self.ctx.write(dst, value, self.id)
        except BlackboardError as exc:
            return self.fail(str(exc), ErrorType.INVALID_INPUT)
        return SUCCESS

    def _converted(self, dst: str, text: str) -> Any:
        board = self._env.blackboard
        current = board.get(dst, MISSING)
        declared = board.type_of(dst)
        if isinstance(current, bool) or (current is MISSING and declared is ParamType.BOOL):
            if text.strip() not in _BOOL_TEXT:
                raise ValueError(f"{dst} holds true or false, not {text!r}")
            return _BOOL_TEXT[text.strip()]
        if isinstance(current, (int, float)) or (
            current is MISSING and declared in (ParamType.NUMBER, ParamType.DURATION)
        ):
            try:
                number = float(text)
            except ValueError:
                raise ValueError(f"{dst} holds a number, not {text!r}") from None
            return int(number) if isinstance(current, int) and number.is_integer() else number
        return text


class UnsetBlackboard(_Entries):
    """Removes the entry ``key`` (SUCCESS also when there was none)."""

    kind = "unset_blackboard"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        entry: str,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name, key=key)
        self.entry = entry

    def update(self) -> Status:
        target = self._name("key", self.entry)
        if target is None:
            return FAILURE
        self._env.blackboard.unset(self._env.key_of(target))
        return SUCCESS
