"""CellSession: opens a cell, makes its registry, falls back to "none" when a cell fails."""

from __future__ import annotations

import json
import threading
from pathlib import Path
from typing import Any

from capabilities.cells import CellError, ManagedCell
from instructor_app.runtime.session import CellSession, opening_words


class FakeCell(ManagedCell):
    def __init__(self, name: str) -> None:
        self.name = name
        self.closed = False

    def close(self) -> None:
        self.closed = True


class Opener:
    """Opens fake cells; "sim" fails when told to."""

    def __init__(self, sim_fails: bool = False) -> None:
        self.sim_fails = sim_fails
        self.opened: list[tuple[str, dict[str, Any]]] = []

    def __call__(self, name: str, **kwargs: Any) -> FakeCell:
        self.opened.append((name, kwargs))
        if name == "sim" and self.sim_fails:
            raise CellError("the simulated cell did not start: no GPU today")
        return FakeCell(name)


def test_open_makes_a_registry_for_the_cell_and_tells_the_panels(qtbot: Any) -> None:
    opener = Opener()
    session = CellSession("sim", seed=3, speed=None, opener=opener)
    with qtbot.waitSignals([session.cell_changed, session.registry_changed]):
        assert session.open() is True
    assert opener.opened == [("sim", {"seed": 3, "scene": None, "speed": None})]
    assert session.registry.cell is session.cell and session.name == "sim"
    assert "debug.succeed" in {m.id for m in session.registry.manifests()}
    assert session.clock() is not None


def test_switching_closes_the_old_cell(qtbot: Any) -> None:
    session = CellSession("none", opener=Opener())
    session.open()
    old, old_registry = session.cell, session.registry
    session.open("sim")
    assert old.closed and session.cell.name == "sim" and session.registry is not old_registry
    session.close()
    assert session.cell is None and session.clock() is None


def test_a_cell_that_fails_falls_back_to_none_and_says_why(qtbot: Any) -> None:
    session = CellSession("sim", opener=Opener(sim_fails=True))
    with qtbot.waitSignal(session.cell_failed) as failed:
        assert session.open() is False
    assert "no GPU today" in failed.args[0]
    assert session.name == "none" and session.cell.name == "none"
    motion = [m.id for m in session.registry.manifests() if m.id.startswith("motion.")]
    assert motion and not session.registry.availability(motion[0]).available


def test_the_real_none_cell_opens(none_session: CellSession) -> None:
    assert none_session.name == "none"
    assert none_session.registry.availability("debug.succeed").available


class BlockingOpener(Opener):
    """Opens fake cells on the worker thread once :attr:`go` is set; records the thread."""

    def __init__(self, sim_fails: bool = False) -> None:
        super().__init__(sim_fails)
        self.go = threading.Event()
        self.threads: list[str] = []
        self.cells: list[FakeCell] = []

    def __call__(self, name: str, **kwargs: Any) -> FakeCell:
        self.threads.append(threading.current_thread().name)
        assert self.go.wait(10.0), "the test never let the opening go on"
        cell = super().__call__(name, **kwargs)
        self.cells.append(cell)
        return cell


def test_a_background_opening_keeps_the_old_cell_until_the_new_one_is_there(qtbot: Any) -> None:
    opener = BlockingOpener()
    opener.go.set()
    session = CellSession("none", opener=opener)
    session.open()
    old = session.cell
    opener.go.clear()
    with qtbot.waitSignal(session.cell_opening) as opening:
        assert session.open_in_background("sim")
    assert opening.args == ["sim", "Starting the simulated cell…"]
    assert session.opening == "sim" and session.cell is old and session.name == "none"
    assert not session.open_in_background("none"), "one opening at a time"
    assert not session.open("none") and session.cell is old
    with qtbot.waitSignal(session.cell_ready) as ready:
        opener.go.set()
    assert ready.args == [True] and session.name == "sim" and session.cell.name == "sim"
    assert opener.threads[-1].startswith("costar-cell") and session.opening == ""
    qtbot.waitUntil(lambda: old.closed)  # closed on the worker, after the views moved on
    session.close()


def test_a_background_failure_keeps_the_cell_that_was_open(qtbot: Any) -> None:
    opener = BlockingOpener(sim_fails=True)
    opener.go.set()
    session = CellSession("none", opener=opener)
    session.open()
    old = session.cell
    failures: list[str] = []
    session.cell_failed.connect(failures.append)
    with qtbot.waitSignal(session.cell_ready) as ready:
        session.open_in_background("sim")
    assert ready.args == [False] and len(failures) == 1 and "no GPU today" in failures[0]
    assert session.cell is old and not old.closed and session.name == "none"
    session.close()


def test_closing_while_a_cell_opens_closes_it_when_it_arrives(qtbot: Any) -> None:
    opener = BlockingOpener()
    opener.go.set()
    session = CellSession("none", opener=opener)
    session.open("none")
    opener.go.clear()
    session.open_in_background("sim")
    session.close()
    assert session.cell is None and session.opening == ""
    opener.go.set()
    qtbot.waitUntil(lambda: len(opener.cells) == 2 and opener.cells[-1].closed)
    assert session.cell is None, "a cell nobody waits for any more is not used"


def test_what_an_opening_does_is_said_in_words(tmp_path: Path) -> None:
    ur = tmp_path / "ur.cell.json"
    ur.write_text(json.dumps({"format_version": 2, "robot": {"kind": "ur", "host": "10.0.0.5"}}))
    simulated = tmp_path / "sim.cell.json"
    simulated.write_text(json.dumps({"format_version": 2, "robot": {"kind": "sim"}}))
    broken = tmp_path / "broken.cell.json"
    broken.write_text("{")
    assert opening_words("sim") == "Starting the simulated cell…"
    assert opening_words(str(ur)) == "Connecting to 10.0.0.5…"
    assert opening_words(str(simulated)) == "Starting the simulated cell of sim.cell.json…"
    assert opening_words(str(broken)) == "Opening broken.cell.json…"


def test_a_plans_scene_reopens_the_simulated_cell_and_the_default_comes_back(qtbot: Any) -> None:
    opener = BlockingOpener()
    opener.go.set()
    session = CellSession("sim", scene="tending", opener=opener)
    session.open()
    assert not session.use_scene("tending"), "the cell holds it already"
    with qtbot.waitSignal(session.cell_ready):
        assert session.use_scene("kitting")
    assert opener.opened[-1][1]["scene"] == "kitting"
    opener.go.clear()  # a plan naming none opens while that opening is under way ...
    assert session.use_scene("")
    assert not session.use_scene("kitting") and session.opening == "sim"
    with qtbot.waitSignal(session.cell_ready, timeout=5000):
        opener.go.set()  # ... so the scene chosen meanwhile is opened after it
    assert opener.opened[-1][1]["scene"] == "kitting" and session.scene == "kitting"
    session.close()


def test_a_plans_scene_waits_on_a_cell_without_a_scene(qtbot: Any) -> None:
    opener = Opener()
    session = CellSession("none", opener=opener)
    session.open()
    assert not session.use_scene("kitting") and len(opener.opened) == 1
    session.open("sim")
    assert opener.opened[-1][0] == "sim" and opener.opened[-1][1]["scene"] == "kitting"
    session.close()
