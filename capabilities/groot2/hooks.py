"""Groot2's breakpoints (BehaviorTree.CPP's hooks, ``loggers/groot2_protocol.h``) on the
engine's debugger (:mod:`engine.debugger`).

A hook is at a node's ``_uid``, PRE (before the node starts) or POST (once its tick made it
SUCCESS or FAILURE), as BehaviorTree.CPP's pre- and post-tick callbacks. An enabled hook of
mode BREAKPOINT (0) is a debugger breakpoint there: the run pauses, the publisher announces
BREAKPOINT_REACHED with the ``_uid`` on its PUB socket, and BREAKPOINT_UNLOCK lets it go on,
giving the node SUCCESS or FAILURE instead of running it when asked so at a PRE hook
(anything else: the node runs). ``once`` (and an unlock's ``remove_when_done``) removes the
hook when it has been reached and unlocked. DISABLE_ALL_HOOKS and REMOVE_ALL_HOOKS free a run
paused at a hook, as BehaviorTree.CPP wakes a waiting hook.

Not here: hooks of mode REPLACE (1), which BehaviorTree.CPP runs as a result given on every
tick without pausing: an insert of one is refused with the error reply; and a POST unlock's
result, which BehaviorTree.CPP puts in place of the node's own (here the node keeps its own).
Breakpoints the debugger has from elsewhere (``--break``, the Instructor) are not Groot2's:
a hook at the same node replaces one while it is set.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from capabilities.errors import CapabilityError
from engine.debugger import AFTER, BEFORE, Breakpoint, Debugger, Forced
from engine.status import FAILURE, SUCCESS

__all__ = ["Groot2Hooks", "HookRefused", "PRE", "POST"]

PRE, POST = 0, 1
_BREAKPOINT, _REPLACE = 0, 1
_RESULTS = {"SUCCESS": SUCCESS, "FAILURE": FAILURE}


class HookRefused(CapabilityError):
    """A hook request answered with BehaviorTree.CPP's error reply (the reason)."""


@dataclass
class _Hook:
    uid: int
    position: int
    enabled: bool = True
    mode: int = _BREAKPOINT
    once: bool = False
    desired_status: str = "SKIPPED"

    def as_json(self) -> dict[str, Any]:
        """As BehaviorTree.CPP's ``to_json(Hook)`` writes it."""
        return {
            "enabled": self.enabled,
            "uid": self.uid,
            "mode": self.mode,
            "once": self.once,
            "desired_status": self.desired_status,
            "position": self.position,
        }


def _parse(body: bytes) -> dict[str, Any]:
    try:
        data = json.loads(body.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise HookRefused(f"not a JSON object: {exc}") from exc
    if not isinstance(data, dict):
        raise HookRefused("not a JSON object")
    return data


def _field(data: Mapping[str, Any], name: str, kind: type) -> Any:
    value = data.get(name)
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        raise HookRefused(f"[json.exception.out_of_range] key '{name}' not found or wrong type")
    return value


class Groot2Hooks:
    """The hooks Groot2 set on one run, kept as breakpoints of its executor's debugger.

    Args:
        uids: runtime node id -> ``_uid`` (:attr:`engine.btcpp.runtime.LoadedTree.uids`).
        debugger: the run's debugger.
        resume: lets a paused run go on (the executor's ``resume``).
    """

    def __init__(
        self, uids: Mapping[str, int], debugger: Debugger, resume: Callable[[], None]
    ) -> None:
        self._nodes = {uid: node_id for node_id, uid in uids.items()}
        self._debugger = debugger
        self._resume = resume
        self._lock = threading.Lock()
        self._hooks: dict[tuple[int, int], _Hook] = {}  # (position, uid) -> hook
        self._paused_at: tuple[int, int] | None = None  # the hook the run waits at
        self._ours: set[str] = set()  # nodes whose debugger breakpoint a hook set

    # ---------------------------------------------------------------- requests

    def insert(self, body: bytes) -> None:
        """HOOK_INSERT: a new hook, or new settings of the one at that uid and position."""
        data = _parse(body)
        uid, position = _field(data, "uid", int), _field(data, "position", int)
        mode = _field(data, "mode", int)
        if mode == _REPLACE:
            raise HookRefused("hooks of mode REPLACE are not supported by the CoSTAR publisher")
        if position not in (PRE, POST) or mode != _BREAKPOINT:
            raise HookRefused(f"no hook position {position} or mode {mode}")
        if uid not in self._nodes:
            raise HookRefused("Node ID not found")
        hook = _Hook(
            uid,
            position,
            _field(data, "enabled", bool),
            mode,
            _field(data, "once", bool),
            str(data.get("desired_status", "SKIPPED")),
        )
        with self._lock:
            self._hooks[(position, uid)] = hook
            self._apply(uid)

    def remove(self, body: bytes) -> None:
        """HOOK_REMOVE: the hook at that uid and position ("Node ID not found": none)."""
        data = _parse(body)
        key = (_field(data, "position", int), _field(data, "uid", int))
        with self._lock:
            if self._hooks.pop(key, None) is None:
                raise HookRefused("Node ID not found")
            self._apply(key[1])
            wake = self._paused_at == key
        if wake:
            self._go_on()

    def unlock(self, body: bytes) -> None:
        """BREAKPOINT_UNLOCK: the run paused at that hook goes on."""
        data = _parse(body)
        uid, position = _field(data, "uid", int), _field(data, "position", int)
        status = _field(data, "desired_status", str)
        remove = _field(data, "remove_when_done", bool)
        with self._lock:
            hook = self._hooks.get((position, uid))
            if hook is None or uid not in self._nodes:
                raise HookRefused("Node ID not found")
            hook.desired_status = status
            hook.once = hook.once or remove
            if self._paused_at != (position, uid):
                return  # BehaviorTree.CPP wakes no one either (the next stop passes at once)
            if position == PRE and status in _RESULTS:
                self._debugger.force(self._nodes[uid], Forced(_RESULTS[status]))
        self._go_on()

    def remove_all(self) -> None:
        """REMOVE_ALL_HOOKS."""
        with self._lock:
            uids = {uid for _, uid in self._hooks}
            self._hooks.clear()
            for uid in uids:
                self._apply(uid)
            wake = self._paused_at is not None
        if wake:
            self._go_on()

    def disable_all(self) -> None:
        """DISABLE_ALL_HOOKS: every hook stays, disabled."""
        with self._lock:
            for hook in self._hooks.values():
                hook.enabled = False
            for uid in {uid for _, uid in self._hooks}:
                self._apply(uid)
            wake = self._paused_at is not None
        if wake:
            self._go_on()

    def dump(self) -> bytes:
        """HOOKS_DUMP: every hook as BehaviorTree.CPP writes them (PRE ones first)."""
        with self._lock:
            hooks = sorted(self._hooks.values(), key=lambda h: (h.position, h.uid))
            return json.dumps([h.as_json() for h in hooks]).encode("utf-8")

    # ---------------------------------------------------------------- the run

    def reached(self, node_id: str, where: str) -> int | None:
        """The run paused at ``node_id`` (before or after it): the ``_uid`` to announce as a
        reached breakpoint when a hook of ours is there, else None.
        """
        uid = next((u for u, n in self._nodes.items() if n == node_id), None)
        position = PRE if where == BEFORE else POST if where == AFTER else None
        if uid is None or position is None:
            return None
        with self._lock:
            hook = self._hooks.get((position, uid))
            if hook is None or not hook.enabled:
                return None
            self._paused_at = (position, uid)
        return uid

    def _go_on(self) -> None:
        with self._lock:
            key, self._paused_at = self._paused_at, None
            hook = self._hooks.get(key) if key is not None else None
            if hook is not None and hook.once:
                del self._hooks[hook.position, hook.uid]
                self._apply(hook.uid)
        self._resume()

    def _apply(self, uid: int) -> None:
        """The debugger's breakpoint at the node: what its enabled hooks say (lock held)."""
        node_id = self._nodes.get(uid)
        if node_id is None:
            return
        before = self._enabled(PRE, uid)
        after = self._enabled(POST, uid)
        if before or after:
            self._debugger.set_breakpoint(Breakpoint(node_id, before=before, after=after))
            self._ours.add(node_id)
        elif node_id in self._ours:
            self._ours.discard(node_id)
            self._debugger.clear_breakpoint(node_id)

    def _enabled(self, position: int, uid: int) -> bool:
        hook = self._hooks.get((position, uid))
        return hook is not None and hook.enabled
