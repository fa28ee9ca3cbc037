"""BehaviorTree.CPP's nodes that ask whether an entry was written since they last looked:
SkipUnlessUpdated and WaitValueUpdate (decorators), WasEntryUpdated (a leaf).

Each remembers the entry's sequence number (:meth:`engine.blackboard.Blackboard.sequence`,
BehaviorTree.CPP's ``sequence_id``) it saw last, from 0: an entry written since then is
"updated". As in BehaviorTree.CPP's src/decorators/updated_decorator.cpp and
src/actions/updated_action.cpp, a missing entry is never updated and leaves the number seen
unchanged, and neither a halt nor a new round forgets it.
"""

from __future__ import annotations

from collections.abc import Callable

from engine.context import TreeContext
from engine.decorators import Decorator
from engine.error_types import ErrorType
from engine.node import Node
from engine.port_text import braced
from engine.script.values import ScriptEnv
from engine.status import FAILURE, RUNNING, SKIPPED, SUCCESS, Status

__all__ = ["SkipUnlessUpdated", "WaitValueUpdate", "WasEntryUpdated"]


class _Watch:
    """The entry a node watches (``entry`` is ``NAME`` or ``{NAME}``; ``@NAME``: at the top)
    and the sequence number it saw last.
    """

    def __init__(self, ctx: TreeContext, entry: str, key: Callable[[str], str] | None) -> None:
        name = braced(entry)
        self.name = (entry if name is None else name).strip()
        if not self.name:
            raise ValueError("the port entry names no entry")
        self._env = ScriptEnv(ctx.blackboard, key=key)
        self._seen = 0

    def updated(self) -> bool:
        """Whether the entry was written since the last call (a missing entry: False, and
        the number seen stays as it was).
        """
        board = self._env.blackboard
        current = board.sequence(self._env.key_of(self.name))
        if current == 0:
            return False
        previous, self._seen = self._seen, current
        return previous != current


class _EntryUpdated(Decorator):
    """Ticks its child when the entry was written since the last check, else answers
    ``if_not_updated``; a child that is running is ticked on without a check.
    """

    if_not_updated: Status = SKIPPED

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        entry: str,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.entry = entry
        self._watch = _Watch(ctx, entry, key)
        self._child_running = False

    def update(self) -> Status:
        if not self._child_running and not self._watch.updated():
            self.message = f"{self._watch.name} was not written since the last check"
            return self.if_not_updated
        status = self.children[0].tick()
        self._child_running = status is RUNNING
        return status

    def on_reset(self) -> None:
        self._child_running = False


class SkipUnlessUpdated(_EntryUpdated):
    """BehaviorTree.CPP's SkipUnlessUpdated: SKIPPED unless the entry was written since the
    last check.
    """

    kind = "skip_unless_updated"
    if_not_updated = SKIPPED


class WaitValueUpdate(_EntryUpdated):
    """BehaviorTree.CPP's WaitValueUpdate: RUNNING until the entry is written, then runs its
    child.
    """

    kind = "wait_value_update"
    if_not_updated = RUNNING


class WasEntryUpdated(Node):
    """BehaviorTree.CPP's WasEntryUpdated: SUCCESS when the entry was written since the last
    check, else FAILURE.
    """

    kind = "was_entry_updated"
    is_condition = True

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        entry: str,
        *,
        key: Callable[[str], str] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.entry = entry
        self._watch = _Watch(ctx, entry, key)

    def update(self) -> Status:
        if self._watch.updated():
            return SUCCESS
        self.fail(f"{self._watch.name} was not written since the last check", ErrorType.FAILED)
        return FAILURE
