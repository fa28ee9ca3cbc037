"""The ``costar`` command line: validate, run, list operations, show traces.

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
from typing import Any, TextIO

from capabilities.base import CapabilityError, CapabilityRegistry
from capabilities.cells import CELL_NAMES, CellError, open_cell
from capabilities.collaboration.answers import CONFIRM_MODES, PromptAnswerer
from capabilities.xml_commands import add_xml_commands
from engine.build import BuildError, build_tree
from engine.events import Event, LogMessage, RunFinished, StatusChanged
from engine.executor import Executor
from engine.files import PlanFileError, load_plan
from engine.library import Library, library_folder
from engine.operations import OperationManifest
from engine.spec import PlanSpec
from engine.status import Status
from engine.trace import TraceError, TraceRecorder, format_timeline, read_trace
from engine.types import encode_value
from engine.validation import Problem, has_errors, validate_plan

__all__ = ["main"]

EXIT_SUCCESS, EXIT_FAILURE, EXIT_INVALID, EXIT_STOPPED = 0, 1, 2, 3


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


def _open(args: argparse.Namespace, err: TextIO, start: bool) -> Any:
    """The cell the command asked for, or None after saying why it could not be opened."""
    try:
        return open_cell(args.cell, seed=args.seed, start=start, scene=args.scene)
    except CellError as exc:
        print(f"error: {exc}", file=err)
        return None


def _library(args: argparse.Namespace, err: TextIO) -> Library:
    """The subtree library (to tell of newer versions); its broken files are named, skipped."""
    library = Library(library_folder(args.library)).scan()
    for problem in library.problems:
        print(f"warning: library file skipped: {problem}", file=err)
    return library


def _cmd_validate(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    cell = _open(args, err, start=False)
    if cell is None:
        return EXIT_INVALID
    with cell:
        registry = CapabilityRegistry(cell=cell)
        plan = _load(args.plan, registry, err)
        if plan is None:
            return EXIT_INVALID
        problems = validate_plan(plan, registry, _library(args, err))
    _print_problems(args.plan, problems, out)
    if has_errors(problems):
        count = sum(p.severity == "error" for p in problems)
        print(f"{args.plan}: invalid ({count} error{'' if count == 1 else 's'})", file=out)
        if args.cell == "none" and any("cannot run on this cell" in p.message for p in problems):
            print("hint: some operations need a robot cell; try --cell sim", file=out)
        return EXIT_INVALID
    print(f"{args.plan}: valid", file=out)
    return EXIT_SUCCESS


class _VerbosePrinter:
    """Prints one line per status change (on the dispatcher thread)."""

    def __init__(self, plan: PlanSpec, out: TextIO) -> None:
        self._paths = dict((node.id, path) for path, node in plan.walk())
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


def _install_interrupt(executor: Executor) -> Callable[[], None]:
    """Ctrl-C stops the run cleanly (halting what runs); returns a function to undo it."""
    if threading.current_thread() is threading.main_thread():
        previous = signal.getsignal(signal.SIGINT)

        def on_interrupt(signum: int, frame: Any) -> None:
            executor.stop("stopped", timeout=0)

        signal.signal(signal.SIGINT, on_interrupt)

        def restore() -> None:
            signal.signal(signal.SIGINT, previous)

        return restore
    return lambda: None


def _cmd_run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    cell = _open(args, err, start=True)
    if cell is None:
        return EXIT_INVALID
    with cell:
        registry = CapabilityRegistry(cell=cell)
        plan = _load(args.plan, registry, err)
        if plan is None:
            return EXIT_INVALID
        problems = validate_plan(plan, registry, _library(args, err))
        if has_errors(problems):
            _print_problems(args.plan, problems, err)
            print(f"{args.plan}: invalid, not started", file=err)
            return EXIT_INVALID
        try:
            tree = build_tree(plan, registry, clock=cell.clock)
        except BuildError as exc:
            print(f"error: {exc}", file=err)
            return EXIT_INVALID
        listeners: list[Callable[[Event], None]] = []
        if args.verbose:
            listeners.append(_VerbosePrinter(plan, out))
        if args.trace:
            listeners.append(TraceRecorder(args.trace, plan))
        executor = Executor(tree, args.rate, listeners, plan_name=plan.name)
        restore = _install_interrupt(executor)
        console = cell.interfaces().get("operator")
        answerer = PromptAnswerer(console, args.confirm, args.stdin, out) if console else None
        try:
            executor.start()
            result = _wait(executor, args.timeout)
        finally:
            restore()
            if answerer is not None:
                answerer.detach()
        return _report(result, plan, tree.blackboard.snapshot(), out, args.verbose)


def _wait(executor: Executor, timeout: float | None) -> RunFinished:
    # Wait in short slices so that Ctrl-C is handled promptly in the main thread.
    waited = 0.0
    while True:
        result = executor.wait(0.1)
        if result is not None:
            return result
        waited += 0.1
        if timeout is not None and waited >= timeout:
            executor.stop("timeout")
            final = executor.wait(10.0)
            assert final is not None, "the engine did not stop within 10 s"
            return final


def _report(
    result: RunFinished, plan: PlanSpec, board: dict[str, Any], out: TextIO, verbose: bool
) -> int:
    if verbose and board:
        for key, value in sorted(board.items()):
            print(f"  {key} = {json.dumps(encode_value(value))}", file=out)
    name = plan.name or "plan"
    if result.reason in ("stopped", "timeout"):
        print(f"{name}: {result.reason} after {result.tick} ticks", file=out)
        return EXIT_STOPPED
    if result.reason == "error":
        print(f"{name}: engine error after {result.tick} ticks: {result.message}", file=out)
        return EXIT_FAILURE
    note = f" ({result.message})" if result.message else ""
    print(f"{name}: {result.status.value} after {result.tick} ticks{note}", file=out)
    return EXIT_SUCCESS if result.status is Status.SUCCESS else EXIT_FAILURE


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


def _cmd_trace_show(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    try:
        trace = read_trace(args.file)
    except TraceError as exc:
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
        p.add_argument(
            "--cell",
            choices=CELL_NAMES,
            default="none",
            help="the cell to run on (default: none, only cell-free capabilities)",
        )
        p.add_argument("--seed", type=int, default=0, help="scene seed of the simulated cell")
        p.add_argument(
            "--scene", help="scene of the simulated cell (name or path; default cup_to_bin)"
        )
        p.add_argument(
            "--library",
            help="the subtree library folder (default: $COSTAR_LIBRARY, else the user's)",
        )

    validate = sub.add_parser("validate", help="check a plan; exit 0 valid, 2 invalid")
    validate.add_argument("plan")
    add_cell(validate)
    validate.set_defaults(func=_cmd_validate)

    run = sub.add_parser("run", help="run a plan until it finishes")
    run.add_argument("plan")
    run.add_argument("--rate", type=float, default=20.0, help="ticks per second (default 20)")
    run.add_argument("--trace", help="write a trace (JSON lines) to this file")
    run.add_argument("--timeout", type=float, help="stop after this many seconds (exit 3)")
    run.add_argument("--verbose", "-v", action="store_true", help="print every status change")
    run.add_argument(
        "--confirm",
        choices=CONFIRM_MODES,
        default="ask",
        help="answer operator prompts: yes, no, or ask (read y/n lines from stdin, a pipe "
        "too; at the end of the input every prompt is answered no). Default: ask",
    )
    add_cell(run)
    run.set_defaults(func=_cmd_run)

    ops = sub.add_parser("ops", help="list every operation with its parameters")
    ops.add_argument("--json", action="store_true")
    ops.add_argument("--cell", choices=CELL_NAMES, default="none")
    ops.set_defaults(func=_cmd_ops)

    trace = sub.add_parser("trace", help="traces of runs")
    trace_sub = trace.add_subparsers(dest="trace_command", required=True)
    show = trace_sub.add_parser("show", help="print a trace as a readable timeline")
    show.add_argument("file")
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
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse exits 2 on bad arguments, 0 on --help
        return int(exc.code or 0)
    args.stdin = inp or sys.stdin
    if args.command == "run" and args.rate <= 0:
        print("error: --rate must be above 0", file=err)
        return EXIT_INVALID
    if getattr(args, "plan", None) and not Path(args.plan).exists():
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
