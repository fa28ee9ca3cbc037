"""The waypoint file of a plan: round trip, edits, atomic save and clear errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capabilities.waypoints import (
    FORMAT,
    WaypointFileError,
    WaypointLibrary,
    waypoints_path_for,
)
from engine.types import JointConfig, Pose, Waypoint, WaypointFrame

DOWN = (1.0, 0.0, 0.0, 0.0)


def _library() -> WaypointLibrary:
    return WaypointLibrary(
        [
            Waypoint(
                "home",
                WaypointFrame.JOINTS,
                joints=JointConfig((0.0, -1.57, 1.57, -1.57, -1.57, 0.0)),
            ),
            Waypoint("above_bin", WaypointFrame.WORLD, Pose((0.6, -0.2, 0.3), DOWN)),
            Waypoint(
                "grasp_cup", WaypointFrame.OBJECT, Pose((0.0, 0.0, 0.06), DOWN), reference="cup"
            ),
            Waypoint("over_tag", WaypointFrame.MARKER, Pose((0.0, 0.0, 0.2), DOWN), reference="7"),
        ]
    )


def test_path_next_to_the_plan() -> None:
    assert waypoints_path_for("/cell/task.costar.json") == Path("/cell/task.waypoints.json")
    assert waypoints_path_for("plans/pick.json") == Path("plans/pick.waypoints.json")


def test_round_trip_keeps_everything_in_order(tmp_path: Path) -> None:
    file = tmp_path / "task.waypoints.json"
    library = _library()
    library.save(file)
    data = json.loads(file.read_text())
    assert data["format"] == FORMAT and data["format_version"] == 1
    loaded = WaypointLibrary.load(file)
    assert list(loaded) == list(library)
    assert loaded.names() == ["home", "above_bin", "grasp_cup", "over_tag"]
    assert [p.name for p in tmp_path.iterdir()] == ["task.waypoints.json"]  # no temp file left


def test_add_remove_rename() -> None:
    library = _library()
    with pytest.raises(WaypointFileError, match="already a waypoint 'home'"):
        library.add(Waypoint("home", WaypointFrame.WORLD, Pose()))
    library.add(Waypoint("home", WaypointFrame.WORLD, Pose()), replace=True)
    assert library.get("home").frame is WaypointFrame.WORLD
    renamed = library.rename("above_bin", "drop")
    assert renamed.name == "drop" and library.names() == ["home", "drop", "grasp_cup", "over_tag"]
    with pytest.raises(WaypointFileError, match="already a waypoint 'home'"):
        library.rename("drop", "home")
    assert library.remove("drop").name == "drop" and "drop" not in library
    with pytest.raises(WaypointFileError, match="no waypoint 'drop'"):
        library.remove("drop")
    with pytest.raises(WaypointFileError, match="needs a name"):
        library.add(Waypoint(" ", WaypointFrame.WORLD, Pose()))


def _write(tmp_path: Path, data: object) -> Path:
    file = tmp_path / "bad.waypoints.json"
    file.write_text(json.dumps(data) if not isinstance(data, str) else data)
    return file


@pytest.mark.parametrize(
    ("data", "path", "words"),
    [
        ("{not json", "$", "line 1 column 2: expected valid JSON"),
        ([], "$", "expected an object with format"),
        ({"format": "other", "format_version": 1, "waypoints": []}, "$.format", "costar-waypoints"),
        ({"format": FORMAT, "format_version": 2, "waypoints": []}, "$.format_version", "written by a newer version"),
        ({"format": FORMAT, "format_version": 1}, "$.waypoints", "a list of waypoints"),
        (
            {"format": FORMAT, "format_version": 1, "waypoints": [
                {"name": "a", "frame": "world", "pose": {"position": [0, 0], "orientation": [0, 0, 0, 1]}},
            ]},
            "$.waypoints[0].pose.position", "a list of 3 numbers",
        ),
        (
            {"format": FORMAT, "format_version": 1, "waypoints": [
                {"name": "a", "frame": "joints", "joints": [0.0]},
                {"name": "b", "frame": "sideways", "joints": [0.0]},
            ]},
            "$.waypoints[1].frame", "one of",
        ),
        (
            {"format": FORMAT, "format_version": 1, "waypoints": [
                {"name": "a", "frame": "joints", "joints": [0.0]},
                {"name": "a", "frame": "joints", "joints": [1.0]},
            ]},
            "$.waypoints[1].name", "a second waypoint 'a'",
        ),
    ],
)  # fmt: skip
def test_errors_name_the_file_and_json_path(
    tmp_path: Path, data: object, path: str, words: str
) -> None:
    file = _write(tmp_path, data)
    with pytest.raises(WaypointFileError) as caught:
        WaypointLibrary.load(file)
    assert caught.value.file == file and caught.value.path == path
    assert str(file) in str(caught.value) and words in str(caught.value)


def test_missing_file_and_unwritable_folder(tmp_path: Path) -> None:
    with pytest.raises(WaypointFileError, match="expected a waypoint file, got no file at"):
        WaypointLibrary.load(tmp_path / "nothing.json")
    with pytest.raises(WaypointFileError, match="cannot write"):
        _library().save(tmp_path / "no_such_folder" / "x.waypoints.json")


def test_a_failed_save_keeps_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    file = tmp_path / "task.waypoints.json"
    _library().save(file)
    before = file.read_text()

    def broken_replace(src: object, dst: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("capabilities.waypoints.os.replace", broken_replace)
    with pytest.raises(WaypointFileError, match="No space left"):
        WaypointLibrary([Waypoint("x", WaypointFrame.WORLD, Pose())]).save(file)
    assert file.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ["task.waypoints.json"]
