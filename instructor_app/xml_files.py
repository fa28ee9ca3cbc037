"""File > Export / Import BehaviorTree.CPP XML: the plan as BehaviorTree.CPP v4 XML
(engine.btcpp), for Groot2 and BehaviorTree.CPP, and such XML back as a new, unsaved plan.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from capabilities.xml_commands import operation_manifests
from engine.btcpp import XmlExportError, XmlFileError, export_xml, load_xml
from engine.files import PlanFileError, dump_plan
from engine.plan_writer import write_atomic
from instructor_app.document.model import DocumentError

if TYPE_CHECKING:
    from instructor_app.main_window import MainWindow

__all__ = ["export_plan_xml", "import_plan_xml"]

XML_SUFFIX = ".xml"


def export_plan_xml(window: MainWindow) -> bool:
    """Ask where, then write the open plan as XML (atomically); False when not written."""
    folder = Path(window.settings.last_dir() or Path.home())
    stem = (
        window.document.path.name.removesuffix(".costar.json")
        if window.document.path
        else window.document.plan.name or "plan"
    )
    chosen = window.dialogs.xml_save_path(window, str(folder / f"{stem}{XML_SUFFIX}"))
    if not chosen:
        return False
    path = Path(chosen) if chosen.endswith(XML_SUFFIX) else Path(chosen + XML_SUFFIX)
    manifests = operation_manifests(window.session.registry)
    try:
        write_atomic(path, export_xml(window.document.plan, manifests).encode("utf-8"))
    except (XmlExportError, PlanFileError) as exc:
        window.dialogs.error(window, "Cannot export the plan", str(exc))
        return False
    window.show_message(f"Exported {path}")
    return True


def import_plan_xml(window: MainWindow) -> bool:
    """Ask for an XML file and open it as a new plan (unsaved, no file yet); on problems
    show every one with its line and keep the open plan. False when nothing was imported.
    """
    if not window.maybe_save():
        return False
    chosen = window.dialogs.xml_open_path(window, window.settings.last_dir())
    if not chosen:
        return False
    try:
        plan = load_xml(chosen, operation_manifests(window.session.registry))
        window.document.load_text(dump_plan(plan), None, source=chosen)
    except (XmlFileError, DocumentError, PlanFileError) as exc:
        window.dialogs.error(window, "Cannot import the XML", str(exc))
        return False
    window.show_canvas()
    window.show_message(f"Imported {chosen}: save it to keep it as a plan")
    return True
