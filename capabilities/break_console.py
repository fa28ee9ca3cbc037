"""``costar run --break``: where a run pauses, and the commands a paused run takes.

A breakpoint is named by the node's path as ``costar`` prints it (``cup to bin/transfer or
wait[1]/transfer[0]/move to CUP_POSE[3]``; the indices may be left out when the path is
still unique) or by its id. When the run pauses, the console prints where and why and reads
commands, one a line, until one lets the run go on:

- ``step``: to the next status change of any node; ``next``: over the node paused at (its
  subtree runs to its end); ``continue``: on to the next breakpoint or the end;
- ``print NAME``: a named parameter in the paused node's scope, in mm and degrees;
  ``set NAME VALUE``: write it (checked against its type; a pose as x, y, z in mm and
  roll, pitch, yaw in degrees);
- ``quit``: stop the run (the robot stops as with Ctrl-C).

``--break-if NODE_PATH EXPR`` pauses before the node only when the script ``EXPR``
(BehaviorTree.CPP's language, :mod:`engine.script`) is true in the node's scope.

The end of the input continues the run. While paused the robot is held, as Pause holds it;
Ctrl-C stops the run there as anywhere.
"""

from __future__ import annotations

import collections
import math
import queue
import re
import threading
from collections.abc import Callable
from typing import Any, TextIO

from capabilities.errors import CapabilityError
from engine.blackboard import BlackboardError
from engine.btcpp.values import parse_value
from engine.debugger import Breakpoint
from engine.events import Event, RunPaused
from engine.executor import Executor
from engine.instances import runtime_paths
from engine.spec import PlanSpec
from engine.tree import BehaviorTree
from engine.types import JointConfig, ParamType, type_of_value
from engine.units import format_value, pose_from_display

__all__ = ["BreakConsole", "BreakpointNotFound", "find_node"]

HELP = (
    "commands: step, next (step over), continue, print NAME, set NAME VALUE, quit "
    "(the run goes on at the end of the input)"
)
_INDEX = re.compile(r"\[\d+\]")


class BreakpointNotFound(CapabilityError):
    """No node, or more than one, has the path a breakpoint names."""


def find_node(paths: dict[str, str], text: str) -> str:
    """The runtime id of the node ``text`` names: its id, its path, or its path without the
    indices when only one node has it.

    Args:
        paths: runtime id -> path (:func:`engine.instances.runtime_paths`).
        text: what ``--break`` says.

    Raises:
        BreakpointNotFound: none or several match; the message lists some paths.
    """
    if text in paths:
        return text
    exact = [node_id for node_id, path in paths.items() if path == text]
    if exact:
        return exact[0]
    bare = _INDEX.sub("", text)
    loose = [node_id for node_id, path in paths.items() if _INDEX.sub("", path) == bare]
    if len(loose) == 1:
        return loose[0]
    if loose:
        choices = ", ".join(repr(paths[n]) for n in loose)
        raise BreakpointNotFound(f"{text!r} names several nodes: {choices}")
    examples = "; ".join(list(paths.values())[1:4])
    raise BreakpointNotFound(f"no node has the path {text!r} (paths look like: {examples})")


def _parse(ptype: ParamType | None, text: str) -> Any:
    """A value typed at the console, as ``print`` shows it (mm and degrees)."""
    words = [v for v in re.split(r"[\s,;()]+", text.replace("°", "").replace("mm", "")) if v]
    try:
        if ptype is ParamType.POSE:
            if len(words) != 6:
                raise ValueError("6 numbers")
            return pose_from_display(tuple(float(v) for v in words))
        if ptype is ParamType.JOINTS:
            return JointConfig(tuple(math.radians(float(v)) for v in words))
    except ValueError:
        what = "x, y, z in mm and roll, pitch, yaw in degrees"
        if ptype is ParamType.JOINTS:
            what = "joint angles in degrees"
        raise ValueError(f"expected {what}, not {text!r}") from None
    return parse_value(ptype or ParamType.ANY, text)


class BreakConsole:
    """Sets the breakpoints of a run and serves its pauses from a terminal.

    It is a listener of the executor (it hears the pauses on the dispatcher thread);
    :meth:`serve` is called by the thread that waits for the run, and reads the commands.
    """

    def __init__(self, executor: Executor, plan: PlanSpec, inp: TextIO, out: TextIO) -> None:
        self._executor = executor
        self._tree: BehaviorTree = executor.tree
        self._paths = runtime_paths(plan)
        self._in, self._out = inp, out
        self._paused: collections.deque[RunPaused] = collections.deque()
        self._eof = False
        self._helped = False
        self._lines: queue.Queue[str] = queue.Queue()
        self._reader: threading.Thread | None = None
        self._commands: dict[str, Callable[[str], bool]] = {
            "step": lambda _: self._go(executor.step_next),
            "next": lambda _: self._go(executor.step_over),
            "continue": lambda _: self._go(executor.resume),
            "c": lambda _: self._go(executor.resume),
            "print": self._print,
            "set": self._set,
            "quit": self._quit,
            "help": self._help,
        }

    def add(self, text: str, before: bool = True, condition: str = "") -> str:
        """A breakpoint at the node ``text`` names (before or after it; only when the script
        ``condition`` is true in the node's scope, if one is given); its path.

        Raises:
            BreakpointNotFound: no such node.
            ScriptSyntaxError: the condition is not a script.
        """
        node_id = find_node(self._paths, text)
        old = self._executor.debugger.breakpoints.get(node_id)
        both = old is not None and old.before != before
        self._executor.debugger.set_breakpoint(
            Breakpoint(
                node_id,
                before=before or both,
                after=not before or both,
                condition=condition or (old.condition if old is not None else ""),
            )
        )
        return self._paths.get(node_id, node_id)

    def __call__(self, event: Event) -> None:
        if isinstance(event, RunPaused):
            self._paused.append(event)

    def serve(self) -> None:
        """Serve a pause that came (the waiting thread): print it, read commands until one
        lets the run go on.
        """
        if not self._paused:
            return
        event = self._paused.popleft()
        path = self._paths.get(event.node_id, event.node_id)
        self._say(f"paused {event.where} {path}: {event.why}")
        if not self._helped and not self._eof:
            self._helped = True
            self._say(HELP)
        while True:
            line = self._line()
            if line is None:  # the run ended while paused (Ctrl-C)
                return
            if not line:
                self._eof = True
                self._say("end of input: continuing")
                self._executor.resume()
                return
            word, _, rest = line.strip().partition(" ")
            command = self._commands.get(word.lower())
            if command is None:
                self._say(f"unknown command {word!r}; {HELP}" if word else HELP)
            elif command(rest.strip()):
                return

    def _line(self) -> str | None:
        """The next line typed ("" at the end of the input); None once the run has ended.

        A reader thread reads the input, so that a run stopped while paused (Ctrl-C) ends
        without waiting for a line.
        """
        if self._eof:
            return ""
        if self._reader is None:
            self._reader = threading.Thread(target=self._read, name="costar-break", daemon=True)
            self._reader.start()
        while self._executor.result is None:
            try:
                return self._lines.get(timeout=0.1)
            except queue.Empty:
                continue
        return None

    def _read(self) -> None:
        while True:
            line = self._in.readline()
            self._lines.put(line)
            if not line:
                return

    # ------------------------------------------------------------------ commands

    def _say(self, text: str) -> None:
        print(text, file=self._out, flush=True)

    def _help(self, _: str) -> bool:
        self._say(HELP)
        return False

    def _go(self, action: Callable[[], None]) -> bool:
        action()
        return True

    def _quit(self, _: str) -> bool:
        self._executor.stop("stopped", timeout=0)
        return True

    def _key(self, name: str) -> str:
        """The blackboard key of ``name`` where the run paused."""
        current = self._executor.debugger.current
        scope = self._tree.scopes.get(current)
        return scope(name) if scope is not None else name

    def _print(self, name: str) -> bool:
        if not name:
            self._say("print NAME: which named parameter?")
            return False
        board = self._tree.blackboard
        key = self._key(name)
        if key not in board:
            names = ", ".join(sorted(k for k in board if "/" not in k)) or "none yet"
            self._say(f"{name}: no value (named parameters: {names})")
        else:
            self._say(f"{name} = {format_value(board.get(key))}")
        return False

    def _set(self, rest: str) -> bool:
        name, _, text = rest.partition(" ")
        if not name or not text.strip():
            self._say("set NAME VALUE: which parameter, and its value?")
            return False
        board = self._tree.blackboard
        key = self._key(name)
        ptype = board.type_of(key)
        if ptype is None and key in board:  # not declared: the type of the value it holds
            ptype = type_of_value(board.get(key))
        try:
            value = _parse(ptype, text.strip())
            board.set(key, value, "operator")
        except (ValueError, BlackboardError) as exc:
            kind = f" ({ptype.value})" if ptype is not None else ""
            self._say(f"{name}{kind} not set: {exc}")
            return False
        self._say(f"{name} = {format_value(value)}")
        return False
