"""``costar export-xml`` and ``costar import-xml``: plans as BehaviorTree.CPP v4 XML.

The format is :mod:`engine.btcpp`'s; the operations' manifests (their typed ports) come from
the installed capabilities, so no cell is opened.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, TextIO

from capabilities.base import CapabilityRegistry
from engine.btcpp import XmlExportError, XmlFileError, export_xml, read_xml
from engine.btcpp.check import checked_plan_text
from engine.files import PlanFileError, load_plan
from engine.operations import OperationManifest
from engine.plan_writer import write_atomic

__all__ = ["add_xml_commands", "operation_manifests"]


def operation_manifests(registry: CapabilityRegistry | None = None) -> dict[str, OperationManifest]:
    """Operation id -> manifest of every installed capability (a cell-less registry)."""
    registry = registry if registry is not None else CapabilityRegistry()
    return {manifest.id: manifest for manifest in registry.manifests()}


def _cmd_export(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    ok, invalid = args.exit_codes
    registry = CapabilityRegistry()
    try:
        plan = load_plan(args.plan, aliases=registry.aliases())
        text = export_xml(plan, operation_manifests(registry))
        write_atomic(Path(args.out), text.encode("utf-8"))
    except (PlanFileError, XmlExportError) as exc:
        print(f"error: {exc}", file=err)
        return invalid
    nodes = sum(1 for _ in plan.walk())
    print(f"wrote {args.out}: {nodes} nodes, {len(plan.subtrees)} subtrees", file=out)
    return ok


def _cmd_import(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Read the XML, check the plan as ``costar validate --cell none`` would (every operation
    counted as available: there is no cell) and only then write it: a file import writes
    always loads and validates.
    """
    ok, invalid = args.exit_codes
    registry = CapabilityRegistry()
    try:
        imported = read_xml(args.xml, operation_manifests(registry))
        text = checked_plan_text(imported, registry)
        write_atomic(Path(args.out), text.encode("utf-8"))
    except XmlFileError as exc:
        for problem in exc.problems:
            print(f"error: {problem.describe(exc.file)}", file=err)
        return invalid
    except PlanFileError as exc:
        print(f"error: {exc}", file=err)
        return invalid
    print(f"wrote {args.out}: plan {imported.plan.name!r}", file=out)
    return ok


def add_xml_commands(sub: Any, exit_codes: tuple[int, int]) -> None:
    """Add ``export-xml`` and ``import-xml`` to the ``costar`` subcommands.

    Args:
        sub: the subparsers of ``costar``.
        exit_codes: ``costar``'s codes for success and for invalid input.
    """
    export = sub.add_parser(
        "export-xml", help="write a plan as BehaviorTree.CPP v4 XML (opens in Groot2)"
    )
    export.add_argument("plan", help="the plan (*.costar.json)")
    export.add_argument("out", help="the XML file to write")
    export.set_defaults(func=_cmd_export, exit_codes=exit_codes)
    imported = sub.add_parser(
        "import-xml", help="read BehaviorTree.CPP v4 XML into a plan; lists every problem"
    )
    imported.add_argument("xml", help="the XML file")
    imported.add_argument("out", help="the plan to write (*.costar.json)")
    imported.set_defaults(func=_cmd_import, exit_codes=exit_codes)
