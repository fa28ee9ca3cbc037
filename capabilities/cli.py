"""The ``costar`` command line: validate, run, list operations and examples, show traces.

Commands work on the simulated cell unless ``--cell none`` (no robot) is given; a plan is a
file or ``example:NAME``, a plan shipped with the application (``costar examples``).

Exit codes: 0 success (or valid), 1 the plan ran and failed, 2 invalid input (bad file,
invalid plan, bad arguments), 3 stopped (Ctrl-C) or timed out.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple, TextIO

from capabilities.base import CapabilityError, CapabilityRegistry
from capabilities.break_console import BreakConsole, BreakpointNotFound, find_node
from capabilities.cell_features import ClosableCell, lockstep_of
from capabilities.cells import CellError, cell_argument, open_cell
from capabilities.collaboration.answers import CONFIRM_MODES, PromptAnswerer
from capabilities.doctor import cmd_doctor
from capabilities.faults import hold_check
from capabilities.hold_watch import DEFAULT_HOLD_TIMEOUT, HoldWatch
from capabilities.run_sampler import record_samplers
from capabilities.shipped_examples import cmd_examples
from capabilities.xml_commands import add_xml_commands
from engine.build import BuildError, build_tree
from engine.events import Event, LogMessage, RunFinished, StatusChanged
from engine.executor import Executor
from engine.files import PlanFileError, load_plan, loads_plan, plan_scene
from engine.instances import runtime_paths
from engine.library import Library, library_folder
from engine.operations import OperationManifest
from engine.run_records import (
    RUNS_ENV,
    RunRecordError,
    find_record,
    list_records,
    new_record_path,
    prune_records,
    runs_folder,
)
from engine.run_report import FailureLog
from engine.script import ScriptSyntaxError, parse_script
from engine.spec import PlanSpec
from engine.status import Status
from engine.trace import TraceError, TraceRecorder, format_timeline, read_trace
from engine.tree import BehaviorTree
from engine.types import encode_value
from engine.units import format_value
from engine.validation import Problem, has_errors, validate_plan
from resources import plan_argument

if TYPE_CHECKING:
    from capabilities.groot2.publisher import Groot2Publisher

__all__ = ["main"]

EXIT_SUCCESS, EXIT_FAILURE, EXIT_INVALID, EXIT_STOPPED = 0, 1, 2, 3
CELL_HELP = "the cell: sim, the simulated cell (default), or none, no robot"
GROOT2_PORT = 1667  # BehaviorTree.CPP's Groot2Publisher's default
PLAN_HELP = "a plan file, or example:NAME for a shipped plan (costar examples lists them)"


def _print_problems(file: str, problems: Sequence[Problem], out: TextIO) -> None:
    for problem in problems:
        where = problem.path + (f" [{problem.field}]" if problem.field else "")
        print(f"{file}: {problem.severity}: {where}: {problem.message}", file=out)


def _load(path: str, registry: CapabilityRegistry, err: TextIO) -> PlanSpec | None:
    try:
        return load_plan(path, aliases=registry.aliases())
    except PlanFileError as exc:
        print(f"error: {exc}", file=err)
        return None


def _open(args: argparse.Namespace, err: TextIO, start: bool) -> ClosableCell | None:
    """The cell the command asked for, or None after saying why it could not be opened.
    The simulated cell opens ``--scene``, else the scene the plan was taught on; for a run
    its world waits for the run (lockstep from simulated time 0: the same seed gives the
    same run), paced to real time as a robot moves unless ``--fast``.
    """
    plan = getattr(args, "plan", None)
    scene = args.scene or (plan_scene(plan) if plan else None)
    run = args.command == "run"
    speed = None if not run or args.fast else 1.0
    try:
        return open_cell(
            args.cell, seed=args.seed, start=start, scene=scene, speed=speed, still_until_run=run
        )
    except CellError as exc:
        print(f"error: {exc}", file=err)
        return None


def _library(args: argparse.Namespace, err: TextIO) -> Library:
    """The subtree library (to tell of newer versions); its broken files are named, skipped."""
    library = Library(library_folder(args.library)).scan()
    for problem in library.problems:
        print(f"warning: library file skipped: {problem}", file=err)
    return library


class _OpenPlan(NamedTuple):
    """A cell opened for a plan file: the cell, its capabilities, the plan and its problems."""

    cell: ClosableCell
    registry: CapabilityRegistry
    plan: PlanSpec
    problems: list[Problem]


def _open_plan(args: argparse.Namespace, err: TextIO, start: bool) -> _OpenPlan | None:
    """The cell ``args`` name opened, with ``args.plan`` loaded and validated on it.

    None when the cell does not open or the plan cannot be read (said on ``err``); the cell
    is closed then.
    """
    cell = _open(args, err, start=start)
    if cell is None:
        return None
    try:
        registry = CapabilityRegistry(cell=cell)
        plan = _load(args.plan, registry, err)
        if plan is None:
            cell.close()
            return None
        return _OpenPlan(cell, registry, plan, validate_plan(plan, registry, _library(args, err)))
    except BaseException:
        cell.close()
        raise


def _cmd_validate(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    opened = _open_plan(args, err, start=False)
    if opened is None:
        return EXIT_INVALID
    opened.cell.close()
    problems = opened.problems
    _print_problems(args.plan, problems, out)
    if has_errors(problems):
        count = sum(p.severity == "error" for p in problems)
        print(f"{args.plan}: invalid ({count} error{'' if count == 1 else 's'})", file=out)
        if args.cell == "none" and any("cannot run on this cell" in p.message for p in problems):
            print(
                "hint: some operations need a robot; leave out --cell none to use the "
                "simulated cell",
                file=out,
            )
        return EXIT_INVALID
    print(f"{args.plan}: valid", file=out)
    return EXIT_SUCCESS


class _VerbosePrinter:
    """Prints one line per status change (on the dispatcher thread)."""

    def __init__(self, plan: PlanSpec, out: TextIO) -> None:
        self._paths = runtime_paths(plan)  # instances' insides too
        self._out = out

    def __call__(self, event: Event) -> None:
        if isinstance(event, StatusChanged):
            path = self._paths.get(event.node_id, event.node_id)
            note = f"  ({event.message})" if event.message else ""
            print(
                f"tick {event.tick:>5}  {path}: {event.old.value} -> {event.new.value}{note}",
                file=self._out,
                flush=True,
            )
        elif isinstance(event, LogMessage):
            path = self._paths.get(event.node_id, event.node_id)
            print(f"tick {event.tick:>5}  {path}: {event.message}", file=self._out, flush=True)


_STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")  # Ctrl-C, kill, a closed terminal


def _install_interrupt(executor: Executor) -> Callable[[], None]:
    """Ctrl-C, SIGTERM and a closed terminal (SIGHUP) stop the run cleanly, halting what runs;
    returns a function to undo it.
    """
    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    signals = [getattr(signal, name) for name in _STOP_SIGNALS if hasattr(signal, name)]
    previous = {signum: signal.getsignal(signum) for signum in signals}

    def on_stop(signum: int, frame: Any) -> None:
        executor.stop("stopped", timeout=0)

    for signum in signals:
        signal.signal(signum, on_stop)

    def restore() -> None:
        for signum, handler in previous.items():
            signal.signal(signum, handler)

    return restore


def _cmd_run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    opened = _open_plan(args, err, start=True)
    if opened is None:
        return EXIT_INVALID
    cell, registry, plan, problems = opened
    with cell:
        if has_errors(problems):
            _print_problems(args.plan, problems, err)
            print(f"{args.plan}: invalid, not started", file=err)
            return EXIT_INVALID
        try:
            tree = build_tree(plan, registry, clock=cell.clock)
        except BuildError as exc:
            print(f"error: {exc}", file=err)
            return EXIT_INVALID
        if not _breaks_found(args, plan, err):
            return EXIT_INVALID
        # Before anything that must be undone (the trace file, the signals): it may refuse.
        publisher = _groot2(args, plan, registry, tree, out)  # Groot2Error: exit 2
        failures = FailureLog(plan)
        listeners: list[Callable[[Event], None]] = []
        record = _record_path(args, plan.name, err)
        if record is not None:  # first: what a line on screen says is already in the record
            recorder = TraceRecorder(record, plan, _run_settings(args))
            listeners += [recorder, *record_samplers(cell, recorder)]
        if publisher is not None:
            listeners.append(publisher.monitor)
        holds = HoldWatch(out, args.hold_timeout, cell)
        listeners += [failures, holds]
        if args.verbose:
            listeners.append(_VerbosePrinter(plan, out))
        executor = Executor(
            tree,
            args.rate,
            listeners,
            plan_name=plan.name,
            hold=hold_check(cell),
            lockstep=lockstep_of(cell),
        )
        _groot2_hooks(publisher, executor)
        console = _break_console(args, executor, plan, out)
        restore = _install_interrupt(executor)
        operator = cell.interfaces().get("operator")
        answerer = PromptAnswerer(operator, args.confirm, args.stdin, out) if operator else None
        try:
            executor.start()
            result = _wait(executor, args.timeout, holds, out, console)
        finally:
            restore()
            if answerer is not None:
                answerer.detach()
            if publisher is not None:
                publisher.close()
        if record is not None:
            print(f"run record: {record}", file=out)
        code = _report(
            result, plan, tree.blackboard.snapshot(), out, args.verbose, failures.cause()
        )
        _report_caught(failures, out)
        return code


def _run_settings(args: argparse.Namespace) -> dict[str, Any]:
    """How this run was started, kept in its record for a replay."""
    scene = args.scene or plan_scene(args.plan)
    return {"cell": args.cell, "scene": scene, "seed": args.seed, "rate": args.rate}


def _record_path(args: argparse.Namespace, plan_name: str, err: TextIO) -> Path | None:
    """Where this run's record goes: ``--trace FILE``, else a new record in the runs folder
    (the oldest records there removed past its size limit); None with ``--no-record`` or
    when the folder cannot be used (said on ``err``: the run goes on without a record).
    """
    if args.trace:
        return Path(args.trace)
    if args.no_record:
        return None
    folder = runs_folder(args.runs)
    try:
        path = new_record_path(folder, plan_name)
    except RunRecordError as exc:
        print(f"warning: no run record: {exc}", file=err)
        return None
    prune_records(folder, keep=path)
    return path


def _groot2(
    args: argparse.Namespace,
    plan: PlanSpec,
    registry: CapabilityRegistry,
    tree: BehaviorTree,
    out: TextIO,
) -> Groot2Publisher | None:
    """The Groot2 publisher ``--groot2`` asks for, serving already; None without the option.
    pyzmq is imported only here.

    Raises:
        Groot2Error: it cannot publish (a port taken, a plan BehaviorTree.CPP cannot hold).
    """
    if args.groot2 is None:
        return None
    from capabilities.groot2.protocol import Groot2Monitor
    from capabilities.groot2.publisher import DEFAULT_HOST, Groot2Error, Groot2Publisher
    from engine.btcpp import XmlExportError
    from engine.btcpp.runtime import loaded_tree

    try:
        loaded = loaded_tree(plan, {m.id: m for m in registry.manifests()})
    except XmlExportError as exc:
        raise Groot2Error(f"cannot publish for Groot2: {exc}") from exc
    monitor = Groot2Monitor(loaded, tree.blackboard.snapshot())
    publisher = Groot2Publisher(monitor, args.groot2, args.groot2_host or DEFAULT_HOST)
    print(f"Groot2: publishing the run on {publisher.address}", file=out, flush=True)
    return publisher


def _groot2_hooks(publisher: Groot2Publisher | None, executor: Executor) -> None:
    """Groot2's breakpoints pause this run (on its debugger)."""
    if publisher is None:
        return
    from capabilities.groot2.hooks import Groot2Hooks

    monitor = publisher.monitor
    monitor.hooks = Groot2Hooks(monitor.tree.uids, executor.debugger, executor.resume)


def _breaks_found(args: argparse.Namespace, plan: PlanSpec, err: TextIO) -> bool:
    """Whether every ``--break`` names a node of the plan (else said on ``err``)."""
    try:
        for text in [*args.breaks, *args.breaks_after, *(path for path, _ in args.breaks_if)]:
            find_node(runtime_paths(plan), text)
        for _, condition in args.breaks_if:
            parse_script(condition)
    except BreakpointNotFound as exc:
        print(f"error: --break: {exc}", file=err)
        return False
    except ScriptSyntaxError as exc:
        print(f"error: --break-if: {exc}", file=err)
        return False
    return True


def _break_console(
    args: argparse.Namespace, executor: Executor, plan: PlanSpec, out: TextIO
) -> BreakConsole | None:
    """The console that serves the pauses at ``--break`` nodes (None without one)."""
    if not (args.breaks or args.breaks_after or args.breaks_if):
        return None
    console = BreakConsole(executor, plan, args.stdin, out)
    executor.add_listener(console)
    for text in args.breaks:
        console.add(text)
    for text in args.breaks_after:
        console.add(text, before=False)
    for text, condition in args.breaks_if:
        console.add(text, condition=condition)
    return console


def _wait(
    executor: Executor,
    timeout: float | None,
    holds: HoldWatch,
    out: TextIO,
    console: BreakConsole | None = None,
) -> RunFinished:
    # Wait in short slices so that Ctrl-C is handled promptly in the main thread; a pause
    # at a breakpoint is served here, its time not counted.
    waited = 0.0
    while True:
        result = executor.wait(0.1)
        if result is not None:
            return result
        if console is not None:
            console.serve()
        waited += 0.1
        reason = ""
        if timeout is not None and waited >= timeout:
            reason = "timeout"
        elif holds.expired():
            print(holds.give_up(), file=out, flush=True)
            reason = "hold timeout"
        if reason:
            executor.stop(reason)
            final = executor.wait(10.0)
            assert final is not None, "the engine did not stop within 10 s"
            return final


def _report(
    result: RunFinished,
    plan: PlanSpec,
    board: dict[str, Any],
    out: TextIO,
    verbose: bool,
    cause: str = "",
) -> int:
    """Print the run's result (with ``cause``, the failing leaf and its message, when it
    failed); returns the exit code.
    """
    if verbose and board:
        for key, value in sorted(board.items()):
            print(f"  {key} = {format_value(value)}", file=out)
    name = plan.name or "plan"
    if result.reason in ("stopped", "timeout", "hold timeout"):
        print(f"{name}: {result.reason} after {result.tick} ticks", file=out)
        return EXIT_STOPPED
    if result.reason == "error":
        print(f"{name}: engine error after {result.tick} ticks: {result.message}", file=out)
        return EXIT_FAILURE
    why = cause if result.status is Status.FAILURE and cause else result.message
    note = f" ({why})" if why else ""
    print(f"{name}: {result.status.value} after {result.tick} ticks{note}", file=out)
    # A run its conditions skipped (BehaviorTree.CPP's SKIPPED) did what it was told.
    return EXIT_SUCCESS if result.status in (Status.SUCCESS, Status.SKIPPED) else EXIT_FAILURE


def _report_caught(failures: FailureLog, out: TextIO) -> None:
    """The failures other than the run's cause (those the plan carried on past with a
    fallback or a retry, a fallback that failed too), one line each.
    """
    others = failures.on_the_way()
    if others:
        print("  on the way:", file=out)
        for failure in others:
            print(f"  - {failure.describe()}", file=out)


def _manifest_json(manifest: OperationManifest, available: bool, reason: str) -> dict[str, Any]:
    return {
        "id": manifest.id,
        "kind": manifest.kind.value,
        "capability": manifest.capability,
        "doc": manifest.doc,
        "available": available,
        "reason": reason,
        "params": [
            {
                "name": port.name,
                "direction": port.direction.value,
                "types": [t.value for t in port.types],
                "default": encode_value(port.default),
                "required": port.required,
                "unit": port.unit,
                "doc": port.doc,
                **({"choices": list(port.choices)} if port.choices else {}),
            }
            for port in manifest.ports
        ],
    }


def _cmd_ops(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    try:
        cell = open_cell(args.cell, seed=0, start=False)
    except CellError as exc:
        print(f"error: {exc}", file=err)
        return EXIT_INVALID
    with cell:
        registry = CapabilityRegistry(cell=cell)
        entries = []
        for manifest in sorted(registry.manifests(), key=lambda m: m.id):
            availability = registry.availability(manifest.id)
            entries.append(_manifest_json(manifest, availability.available, availability.reason))
    if args.json:
        print(json.dumps(entries, indent=2), file=out)
        return EXIT_SUCCESS
    for entry in entries:
        flag = "" if entry["available"] else f"  [unavailable: {entry['reason']}]"
        print(f"{entry['id']}  ({entry['kind']})  {entry['doc']}{flag}", file=out)
        for param in entry["params"]:
            arrow = "->" if param["direction"] == "out" else "  "
            default = (
                ""
                if param["required"] or param["direction"] == "out"
                else f" = {json.dumps(param['default'])}"
            )
            unit = f" [{param['unit']}]" if param["unit"] else ""
            print(
                f"    {arrow} {param['name']}: {'|'.join(param['types'])}{unit}{default}  {param['doc']}",
                file=out,
            )
    return EXIT_SUCCESS


def _cmd_runs_list(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    folder = runs_folder(args.runs)
    records = list_records(folder)
    print(f"{len(records)} run records in {folder} (newest first)", file=out)
    for summary in records[: args.most]:
        print(summary.line(), file=out)
    return EXIT_SUCCESS


def _cmd_runs_export(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    if not (args.btlog or args.sqlite):
        print("error: say what to write: --btlog FILE and/or --sqlite FILE", file=err)
        return EXIT_INVALID
    from engine.btcpp import XmlExportError
    from engine.btcpp.run_logs import transitions, write_btlog, write_sqlite
    from engine.btcpp.runtime import loaded_tree

    try:
        path = find_record(runs_folder(args.runs), args.record)
        trace = read_trace(path)
        document = trace.header.get("plan_document")
        if not isinstance(document, dict):
            raise RunRecordError(f"{path}: the record does not hold its plan (an older record)")
        registry = CapabilityRegistry()
        plan = loads_plan(json.dumps(document), f"{path} (its plan)", registry.aliases())
        loaded = loaded_tree(plan, {m.id: m for m in registry.manifests()})
        changes = list(transitions(trace.events, loaded.uids))
        started = int(trace.header.get("started_us", 0))
        written = []
        if args.btlog:
            write_btlog(Path(args.btlog), loaded, started, changes)
            written.append(args.btlog)
        if args.sqlite:
            write_sqlite(Path(args.sqlite), loaded, started, changes)
            written.append(args.sqlite)
    except (TraceError, RunRecordError, PlanFileError, XmlExportError, OSError) as exc:
        print(f"error: {exc}", file=err)
        return EXIT_INVALID
    nodes = len(loaded.uids)
    print(f"{len(changes)} transitions of {nodes} nodes written to {', '.join(written)}", file=out)
    return EXIT_SUCCESS


def _changes(events: list[dict[str, Any]]) -> list[tuple[int, str, str]]:
    return [(e["tick"], e["node"], e["new"]) for e in events if e.get("event") == "status"]


def _cmd_runs_replay(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Run a recorded simulated run again (in lockstep, as fast as it can) and say whether
    it is the same run: every status change at the same tick; else the first that differs.
    """
    try:
        path = find_record(runs_folder(args.runs), args.record)
        trace = read_trace(path)
        document, settings = trace.header.get("plan_document"), trace.header.get("run")
        if not isinstance(document, dict) or not isinstance(settings, dict):
            raise RunRecordError(f"{path}: the record does not hold its plan and how it ran")
        if settings.get("cell") != "sim":
            raise RunRecordError(
                f"{path}: only a run on the simulated cell replays, not on {settings.get('cell')!r}"
            )
        cell = open_cell(
            "sim", int(settings.get("seed") or 0), scene=settings.get("scene"), still_until_run=True
        )
    except (TraceError, RunRecordError, CellError) as exc:
        print(f"error: {exc}", file=err)
        return EXIT_INVALID
    recorded = _changes(trace.events)
    replayed: list[tuple[int, str, str]] = []

    def heard(event: Event) -> None:
        if isinstance(event, StatusChanged):
            replayed.append((event.tick, event.node_id, event.new.value))

    with cell:
        registry = CapabilityRegistry(cell=cell)
        try:
            plan = loads_plan(json.dumps(document), f"{path} (its plan)", registry.aliases())
            tree = build_tree(plan, registry, clock=cell.clock)
        except (PlanFileError, BuildError) as exc:
            print(f"error: {exc}", file=err)
            return EXIT_INVALID
        executor = Executor(
            tree, float(settings.get("rate") or 20.0), [heard], lockstep=lockstep_of(cell)
        )
        executor.start()
        if executor.wait(args.timeout) is None:
            executor.stop("timed out")
    first = next(
        (i for i, (a, b) in enumerate(zip(recorded, replayed, strict=False)) if a != b), None
    )
    if first is None and len(recorded) == len(replayed):
        print(f"the same run: {len(recorded)} status changes at the same ticks", file=out)
        return EXIT_SUCCESS
    at = first if first is not None else min(len(recorded), len(replayed))
    labels = trace.labels()

    def said(change: tuple[int, str, str] | None) -> str:
        if change is None:
            return "nothing (the run had ended)"
        tick, node, status = change
        return f"tick {tick}: {labels.get(node, node)} -> {status}"

    was = recorded[at] if at < len(recorded) else None
    now = replayed[at] if at < len(replayed) else None
    print(
        f"the runs part at status change {at + 1}: recorded {said(was)}; replayed {said(now)}",
        file=out,
    )
    return EXIT_FAILURE


def _cmd_trace_show(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    try:
        trace = read_trace(find_record(runs_folder(getattr(args, "runs", None)), args.record))
    except (TraceError, RunRecordError) as exc:
        print(f"error: {exc}", file=err)
        return EXIT_INVALID
    print(f"trace of {trace.header.get('plan') or 'a plan'}: {len(trace.events)} events", file=out)
    for line in format_timeline(trace):
        print(line, file=out)
    return EXIT_SUCCESS


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="costar", description="CoSTAR task plans from the command line."
    )
    sub = parser.add_subparsers(dest="command", required=True)

    def add_cell(p: argparse.ArgumentParser) -> None:
        p.add_argument("--cell", type=cell_argument, default="sim", help=CELL_HELP)
        p.add_argument("--seed", type=int, default=0, help="scene seed of the simulated cell")
        p.add_argument(
            "--scene", help="scene of the simulated cell (name or path; default cup_to_bin)"
        )
        p.add_argument(
            "--library",
            help="the subtree library folder (default: $COSTAR_LIBRARY, else the user's)",
        )

    validate = sub.add_parser("validate", help="check a plan; exit 0 valid, 2 invalid")
    validate.add_argument("plan", help=PLAN_HELP)
    add_cell(validate)
    validate.set_defaults(func=_cmd_validate)

    run = sub.add_parser("run", help="run a plan until it finishes")
    run.add_argument("plan", help=PLAN_HELP)
    run.add_argument("--rate", type=float, default=20.0, help="ticks per second (default 20)")
    run.add_argument(
        "--trace", help="write the run's record (a trace, JSON lines) to this file instead"
    )
    run.add_argument(
        "--runs",
        help=f"the runs folder for the run's record (default: ${RUNS_ENV}, else the user's)",
    )
    run.add_argument("--no-record", action="store_true", help="keep no record of this run")
    run.add_argument(
        "--fast",
        action="store_true",
        help="the simulated cell as fast as it can (the same run: it is in lockstep); "
        "default: at the pace of a real robot",
    )
    run.add_argument("--timeout", type=float, help="stop after this many seconds (exit 3)")
    run.add_argument(
        "--hold-timeout",
        type=float,
        default=DEFAULT_HOLD_TIMEOUT,
        metavar="SECONDS",
        help="give up when the cell holds the run this long without a break (a stop nobody "
        "clears, a controller that is gone): exit 3 (default 600)",
    )
    run.add_argument("--verbose", "-v", action="store_true", help="print every status change")
    run.add_argument(
        "--break",
        dest="breaks",
        action="append",
        default=[],
        metavar="NODE_PATH",
        help="pause before this node (its path as --verbose prints it, or its id; "
        "repeatable) and read commands from stdin: step, next, continue, print NAME, "
        "set NAME VALUE, quit",
    )
    run.add_argument(
        "--break-if",
        dest="breaks_if",
        action="append",
        nargs=2,
        default=[],
        metavar=("NODE_PATH", "EXPR"),
        help="pause before this node when the script EXPR is true in its scope "
        "(e.g. 'attempts >= 3'), as --break",
    )
    run.add_argument(
        "--break-after",
        dest="breaks_after",
        action="append",
        default=[],
        metavar="NODE_PATH",
        help="pause once this node succeeded or failed (as --break)",
    )
    run.add_argument(
        "--confirm",
        choices=CONFIRM_MODES,
        default="ask",
        help="answer operator prompts: yes, no, or ask (read y/n lines from stdin, a pipe "
        "too; at the end of the input every prompt is answered no). Default: ask",
    )
    run.add_argument(
        "--groot2",
        type=int,
        nargs="?",
        const=GROOT2_PORT,
        metavar="PORT",
        help="publish the run for Groot2 as BehaviorTree.CPP's Groot2Publisher does: "
        f"requests on PORT (default {GROOT2_PORT}), PUB on PORT+1",
    )
    run.add_argument(
        "--groot2-host",
        metavar="HOST",
        help="the interface --groot2 binds (default 127.0.0.1; * for all)",
    )
    add_cell(run)
    run.set_defaults(func=_cmd_run)

    ops = sub.add_parser("ops", help="list every operation with its parameters")
    ops.add_argument("--json", action="store_true")
    ops.add_argument("--cell", type=cell_argument, default="sim", help=CELL_HELP)
    ops.set_defaults(func=_cmd_ops)

    examples = sub.add_parser("examples", help="list the plans shipped with the application")
    examples.set_defaults(func=cmd_examples)

    doctor = sub.add_parser("doctor", help="check this computer can run the Instructor")
    doctor.add_argument("--cell", help="also check this cell file's robot and cameras")
    doctor.set_defaults(func=cmd_doctor)

    sub.add_parser(  # handled in main(): its own options are the emulator's
        "ur-emulator",
        add_help=False,
        help="a loopback UR controller backed by the simulated cell (--help for its options)",
    )

    runs = sub.add_parser("runs", help="the records of runs (every `costar run` keeps one)")
    runs_sub = runs.add_subparsers(dest="runs_command", required=True)

    def runs_command(name: str, what: str, func: Callable[..., int], one: bool = True) -> Any:
        """A ``costar runs`` command: of one record (``one``) or of the folder."""
        command = runs_sub.add_parser(name, help=what)
        if one:
            command.add_argument("record", help="a record's path or name (its start), or last")
        command.add_argument(
            "--runs", help=f"the runs folder (default: ${RUNS_ENV}, else the user's)"
        )
        command.set_defaults(func=func)
        return command

    listing = runs_command("list", "the run records, newest first", _cmd_runs_list, one=False)
    listing.add_argument("--most", type=int, default=50, help="list at most this many (50)")
    runs_command("show", "print a run record as a readable timeline", _cmd_trace_show)
    export = runs_command(
        "export", "write a run record as BehaviorTree.CPP's loggers write a run", _cmd_runs_export
    )
    export.add_argument("--btlog", help="a Groot2 file log (FileLogger2) to write: *.btlog")
    export.add_argument("--sqlite", help="a SqliteLogger database to write: *.db3 or *.btdb")
    replay = runs_command(
        "replay", "run a recorded simulated run again and say where it differs", _cmd_runs_replay
    )
    replay.add_argument("--timeout", type=float, default=600.0, help="wall seconds (600)")
    trace = sub.add_parser("trace", help="traces of runs (as `costar runs show`)")
    trace_sub = trace.add_subparsers(dest="trace_command", required=True)
    show = trace_sub.add_parser("show", help="print a trace as a readable timeline")
    show.add_argument("record", metavar="file")
    show.set_defaults(func=_cmd_trace_show)
    add_xml_commands(sub, (EXIT_SUCCESS, EXIT_INVALID))
    return parser


def main(
    argv: Sequence[str] | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
    inp: TextIO | None = None,
) -> int:
    """Entry point of ``costar``; returns the exit code (``inp``: answers to prompts)."""
    out = out or sys.stdout
    err = err or sys.stderr
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["ur-emulator"]:
        from capabilities.ur_emulator.__main__ import main as emulator_main

        try:
            return emulator_main(argv[1:], prog="costar ur-emulator")
        except SystemExit as exc:  # its argparse: bad arguments or --help
            return int(exc.code or 0)
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse exits 2 on bad arguments, 0 on --help
        return int(exc.code or 0)
    args.stdin = inp or sys.stdin
    if args.command == "run" and args.rate <= 0:
        print("error: --rate must be above 0", file=err)
        return EXIT_INVALID
    if args.command == "run" and args.hold_timeout <= 0:
        print("error: --hold-timeout must be above 0", file=err)
        return EXIT_INVALID
    if args.command == "run" and args.groot2_host is not None and args.groot2 is None:
        print("error: --groot2-host needs --groot2", file=err)
        return EXIT_INVALID
    if getattr(args, "plan", None):
        try:
            args.plan = plan_argument(args.plan)
        except FileNotFoundError as exc:
            print(f"error: {exc}", file=err)
            return EXIT_INVALID
        if not Path(args.plan).exists():
            print(f"error: {args.plan}: no such file", file=err)
            return EXIT_INVALID
    try:
        return int(args.func(args, out, err))
    except CapabilityError as exc:
        print(f"error: {exc}", file=err)
        return EXIT_INVALID
    except BrokenPipeError:
        # The reader went away (costar ops | head): say nothing more, as Unix tools do.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_FAILURE


if __name__ == "__main__":
    sys.exit(main())
