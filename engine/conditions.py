"""Pre- and post-conditions of any node: BehaviorTree.CPP v4's ``_failureIf`` ... ``_onHalted``.

Each is a script of :mod:`engine.script`, run in the node's scope (the scope its own
references are read in; an instance's conditions run where the instance is, not inside it).
As BehaviorTree.CPP's ``TreeNode::executeTick`` runs them:

- ``failure_if``, ``success_if``, ``skip_if`` are checked, in that order, when the node is
  IDLE (about to start): the first that is true gives FAILURE, SUCCESS or SKIPPED without
  the node running at all. ``while`` comes last: false gives SKIPPED; it is also checked on
  every tick while the node is RUNNING, and false then halts the node (``on_halted`` runs)
  and gives SKIPPED. The others are not re-checked while it runs.
- When a tick ends with SUCCESS, ``on_success`` runs, with FAILURE ``on_failure``; then,
  either way, ``post`` (a result given by a pre-condition counts as well). ``on_halted``
  runs when the node is halted while RUNNING (by its parent, a reset, a stop); ``post``
  does not then.

Where BehaviorTree.CPP throws (a script that fails while it runs), the node fails with
``invalid_input`` naming the condition; an ``on_halted`` that fails is a log line, as a halt
never raises.
"""

from __future__ import annotations

import enum
import types
from collections.abc import Callable, Mapping

from engine.blackboard import Blackboard
from engine.script import Script, ScriptEnv, ScriptRunError, parse_script
from engine.status import FAILURE, SKIPPED, SUCCESS, Status

__all__ = [
    "Condition",
    "ConditionFailed",
    "NodeConditions",
    "PRE_CONDITIONS",
    "POST_CONDITIONS",
    "BTCPP_ATTRIBUTES",
]


class Condition(str, enum.Enum):
    """A node's pre- or post-condition; its value is the plan file's key."""

    FAILURE_IF = "failure_if"
    SUCCESS_IF = "success_if"
    SKIP_IF = "skip_if"
    WHILE = "while"
    ON_SUCCESS = "on_success"
    ON_FAILURE = "on_failure"
    POST = "post"
    ON_HALTED = "on_halted"

    @property
    def attribute(self) -> str:
        """Its BehaviorTree.CPP XML attribute (``_skipIf``)."""
        return BTCPP_ATTRIBUTES[self]

    @property
    def is_pre(self) -> bool:
        return self in PRE_CONDITIONS


# In the order BehaviorTree.CPP checks them (PreCond) and lists them (PostCond).
PRE_CONDITIONS: tuple[Condition, ...] = (
    Condition.FAILURE_IF,
    Condition.SUCCESS_IF,
    Condition.SKIP_IF,
    Condition.WHILE,
)
POST_CONDITIONS: tuple[Condition, ...] = (
    Condition.ON_HALTED,
    Condition.ON_FAILURE,
    Condition.ON_SUCCESS,
    Condition.POST,
)

BTCPP_ATTRIBUTES: Mapping[Condition, str] = types.MappingProxyType(
    {
        Condition.FAILURE_IF: "_failureIf",
        Condition.SUCCESS_IF: "_successIf",
        Condition.SKIP_IF: "_skipIf",
        Condition.WHILE: "_while",
        Condition.ON_SUCCESS: "_onSuccess",
        Condition.ON_FAILURE: "_onFailure",
        Condition.POST: "_post",
        Condition.ON_HALTED: "_onHalted",
    }
)

_IF_TRUE: Mapping[Condition, Status] = types.MappingProxyType(
    {Condition.FAILURE_IF: FAILURE, Condition.SUCCESS_IF: SUCCESS, Condition.SKIP_IF: SKIPPED}
)


class ConditionFailed(Exception):
    """A condition's script failed while it ran; the message names the condition."""

    def __init__(self, condition: Condition, error: ScriptRunError) -> None:
        self.condition = condition
        super().__init__(f"{condition.value.replace('_', ' ')} script {error}")


class NodeConditions:
    """The parsed conditions of one runtime node and the scope they run in.

    Args:
        texts: condition -> script (empty texts are left out).
        blackboard: the tree's blackboard.
        key: a name in a script -> its blackboard key (the node's scope).
        writer: who the scripts' writes are from (the node's runtime id).
        enums: names that read as integers.

    Raises:
        ScriptSyntaxError: a script that does not parse.
    """

    __slots__ = ("_env", "scripts")

    def __init__(
        self,
        texts: Mapping[Condition, str],
        blackboard: Blackboard,
        *,
        key: Callable[[str], str] | None = None,
        writer: str = "",
        enums: Mapping[str, int] | None = None,
    ) -> None:
        self.scripts: dict[Condition, Script] = {
            Condition(c): parse_script(text) for c, text in texts.items() if text.strip()
        }
        self._env = ScriptEnv(blackboard, enums, key=key, writer=writer)

    def __bool__(self) -> bool:
        return bool(self.scripts)

    def _check(self, condition: Condition, script: Script) -> bool:
        try:
            return script.check(self._env)
        except ScriptRunError as exc:
            raise ConditionFailed(condition, exc) from exc

    def _run(self, condition: Condition) -> None:
        script = self.scripts.get(condition)
        if script is None:
            return
        try:
            script.run(self._env)
        except ScriptRunError as exc:
            raise ConditionFailed(condition, exc) from exc

    def before(self, running: bool) -> tuple[Status, Condition] | None:
        """The result the pre-conditions give instead of a tick, and which gave it; None
        when the node ticks. ``running``: the node is RUNNING (only ``while`` is checked).

        Raises:
            ConditionFailed: a script failed.
        """
        scripts = self.scripts
        for condition in PRE_CONDITIONS:
            script = scripts.get(condition)
            if script is None or (running and condition is not Condition.WHILE):
                continue
            if condition is Condition.WHILE:
                if not self._check(condition, script):
                    return SKIPPED, condition
            elif self._check(condition, script):
                return _IF_TRUE[condition], condition
        return None

    def after(self, status: Status) -> None:
        """Run ``on_success`` or ``on_failure`` for a result, then ``post``.

        Raises:
            ConditionFailed: a script failed (the ones after it do not run).
        """
        if status is SUCCESS:
            self._run(Condition.ON_SUCCESS)
        elif status is FAILURE:
            self._run(Condition.ON_FAILURE)
        self._run(Condition.POST)

    def halted(self) -> None:
        """Run ``on_halted``.

        Raises:
            ConditionFailed: its script failed.
        """
        self._run(Condition.ON_HALTED)
