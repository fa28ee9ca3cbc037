"""The Instructor's user settings (QSettings): recent files, folders, window layout, Groot2.

Everything goes through :class:`AppSettings`, made with a QSettings the caller chooses, so
that tests use a temporary file and never the user's settings.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from importlib import metadata
from pathlib import Path

from PySide6.QtCore import QByteArray, QSettings
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QMenu, QWidget

from engine.debugger import Breakpoint
from engine.json_text import JsonFileError, parse_json
from engine.script import ScriptSyntaxError
from resources import resource_path

__all__ = [
    "AppSettings",
    "RecentFilesMenu",
    "ORGANIZATION",
    "APPLICATION",
    "MAX_RECENT",
    "EXAMPLES_DIR",
    "GROOT2_PORT",
    "app_version",
    "is_shipped_example",
]

ORGANIZATION = "CoSTAR"
APPLICATION = "Instructor"
MAX_RECENT = 10

# The plans shipped with the application (the start page lists them).
EXAMPLES_DIR = resource_path("examples")
DISTRIBUTION = "costar-instructor"

_RECENT = "files/recent"
_LAST_DIR = "files/last_dir"
_LIBRARY = "library/folder"
_RUNS = "runs/folder"
_GEOMETRY = "window/geometry"
_STATE = "window/state"
_BREAKPOINTS = "debug/breakpoints"  # + "/<plan id>": the node ids, kept out of the plan file
_GROOT2 = "groot2/publish"
_GROOT2_PORT = "groot2/port"
GROOT2_PORT = 1667  # BehaviorTree.CPP's Groot2Publisher's default


def app_version() -> str:
    """The installed package's version ("unknown" when it runs from an uninstalled tree)."""
    try:
        return metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        return "unknown"


def is_shipped_example(path: Path) -> bool:
    """Whether ``path`` is in the shipped examples folder (those files stay as shipped)."""
    try:
        return path.resolve().is_relative_to(EXAMPLES_DIR.resolve())
    except OSError:
        return False


class AppSettings:
    """Typed access to the application's QSettings.

    Args:
        settings: where to keep them (default: the user's CoSTAR/Instructor settings).
    """

    def __init__(self, settings: QSettings | None = None) -> None:
        self.qsettings = settings if settings is not None else QSettings(ORGANIZATION, APPLICATION)

    # ------------------------------------------------------------------ recent files

    def recent_files(self) -> list[str]:
        """Most recent first; at most MAX_RECENT."""
        value = self.qsettings.value(_RECENT, [])
        if isinstance(value, str):  # QSettings gives a lone string for a one-item list
            value = [value]
        return [str(v) for v in (value or []) if v][:MAX_RECENT]

    def add_recent(self, path: str | Path) -> None:
        text = str(Path(path).resolve())
        files = [text] + [f for f in self.recent_files() if f != text]
        self._set_recent(files[:MAX_RECENT])
        self.set_last_dir(Path(text).parent)

    def clear_recent(self) -> None:
        self._set_recent([])

    def _set_recent(self, files: list[str]) -> None:
        self.qsettings.setValue(_RECENT, files)
        self.qsettings.sync()

    # ------------------------------------------------------------------ folders and window

    def last_dir(self) -> str:
        return str(self.qsettings.value(_LAST_DIR, "") or "")

    def set_last_dir(self, folder: str | Path) -> None:
        self.qsettings.setValue(_LAST_DIR, str(folder))

    def library_folder(self) -> str:
        """The subtree library folder chosen in the settings ("" when none was)."""
        return str(self.qsettings.value(_LIBRARY, "") or "")

    def set_library_folder(self, folder: str | Path) -> None:
        self.qsettings.setValue(_LIBRARY, str(folder))

    def runs_folder(self) -> str:
        """The runs folder chosen in the settings ("" when none was: $COSTAR_RUNS, else the
        user's data folder; ``engine.run_records.runs_folder``).
        """
        return str(self.qsettings.value(_RUNS, "") or "")

    def set_runs_folder(self, folder: str | Path) -> None:
        """Keep run records in ``folder`` ("": back to the default)."""
        self.qsettings.setValue(_RUNS, str(folder))

    def groot2_publish(self) -> bool:
        """Whether runs are published for Groot2 (Run > Publish Runs for Groot2)."""
        return str(self.qsettings.value(_GROOT2, "false")).lower() == "true"

    def set_groot2_publish(self, publish: bool) -> None:
        self.qsettings.setValue(_GROOT2, "true" if publish else "false")
        self.qsettings.sync()

    def groot2_port(self) -> int:
        """The port runs are published on for Groot2 (and the next one), 1667 by default."""
        try:
            port = int(str(self.qsettings.value(_GROOT2_PORT, GROOT2_PORT)))
        except ValueError:
            return GROOT2_PORT
        return port if 1 <= port <= 65534 else GROOT2_PORT

    def set_groot2_port(self, port: int) -> None:
        self.qsettings.setValue(_GROOT2_PORT, int(port))
        self.qsettings.sync()

    def breakpoints(self, plan_id: str) -> list[Breakpoint]:
        """The breakpoints the operator set in the plan ``plan_id`` (one a setting cannot
        give back is left out).
        """
        value = self.qsettings.value(f"{_BREAKPOINTS}/{plan_id}", [])
        if isinstance(value, str):  # QSettings gives a lone string for a one-item list
            value = [value]
        found = []
        for text in (str(v) for v in (value or []) if v):
            try:
                found.append(_breakpoint_of(text))
            except (JsonFileError, KeyError, ValueError, ScriptSyntaxError):
                continue  # written by another version, or edited by hand
        return found

    def set_breakpoints(self, plan_id: str, breakpoints: list[Breakpoint]) -> None:
        key = f"{_BREAKPOINTS}/{plan_id}"
        if breakpoints:
            texts = sorted(_breakpoint_text(b) for b in breakpoints)
            self.qsettings.setValue(key, texts)
        else:
            self.qsettings.remove(key)

    def save_window(self, geometry: QByteArray, state: QByteArray) -> None:
        self.qsettings.setValue(_GEOMETRY, geometry)
        self.qsettings.setValue(_STATE, state)
        self.qsettings.sync()

    def window_geometry(self) -> QByteArray | None:
        value = self.qsettings.value(_GEOMETRY)
        return value if isinstance(value, QByteArray) else None

    def window_state(self) -> QByteArray | None:
        value = self.qsettings.value(_STATE)
        return value if isinstance(value, QByteArray) else None


class RecentFilesMenu(QMenu):
    """File > Open Recent: rebuilt from the settings each time it is shown.

    Args:
        settings: where the list lives.
        open_file: called with the path the user picked.
    """

    def __init__(
        self,
        settings: AppSettings,
        open_file: Callable[[str], object],
        parent: QWidget | None = None,
    ) -> None:
        super().__init__("Open &Recent", parent)
        self._settings = settings
        self._open_file = open_file
        self.aboutToShow.connect(self.rebuild)
        self.rebuild()

    def rebuild(self) -> None:
        self.clear()
        files = self._settings.recent_files()
        for number, path in enumerate(files, start=1):
            action = QAction(f"&{number % 10} {Path(path).name}", self)
            action.setToolTip(path)
            action.setData(path)
            action.triggered.connect(lambda _=False, p=path: self._open_file(p))
            self.addAction(action)
        if not files:
            self.addAction("No recent files").setEnabled(False)
            return
        self.addSeparator()
        self.addAction("Clear Menu", self._clear)

    def _clear(self) -> None:
        self._settings.clear_recent()
        self.rebuild()


def _breakpoint_text(breakpoint: Breakpoint) -> str:
    """A plain node id for a breakpoint before it, else a JSON object."""
    if breakpoint.before and not breakpoint.after and not breakpoint.condition:
        return breakpoint.node_id
    fields = {"node": breakpoint.node_id, "before": breakpoint.before, "after": breakpoint.after}
    return json.dumps({**fields, "if": breakpoint.condition}, sort_keys=True)


def _breakpoint_of(text: str) -> Breakpoint:
    if not text.startswith("{"):
        return Breakpoint(text)
    data = parse_json(text, "settings", "breakpoint")
    if not isinstance(data, dict):
        raise ValueError("a breakpoint is an object")
    return Breakpoint(
        str(data["node"]), bool(data["before"]), bool(data["after"]), str(data.get("if", ""))
    )
