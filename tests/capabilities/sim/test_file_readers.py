"""Scene files and the cell configuration, read through the one JSON reader: each error names
the file as given, the JSON path and what was expected.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from capabilities.errors import CapabilityError
from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig, CellConfigError
from capabilities.sim.scene import default_scene_path
from capabilities.sim.scene_spec import SceneFileError, read_scene


def scene_text() -> str:
    return default_scene_path("cup_to_bin").read_text(encoding="utf-8")


def test_a_scene_error_names_the_file_as_given(tmp_path: Path) -> None:
    data = json.loads(scene_text())
    data["markers"][0]["size"] = "big"
    file = tmp_path / "scenes" / "mine.json"
    file.parent.mkdir()
    file.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(SceneFileError) as info:
        read_scene(file)
    assert str(info.value).startswith(
        f"{file}: $.markers[0].size: expected a number from 0.001 to 1"
    )
    assert isinstance(info.value, CapabilityError)


@pytest.mark.parametrize(
    ("old", "new", "where", "expected"),
    [
        ('"format_version": 1', '"format_version": 1, "extra": NaN', "$.extra", "a finite number"),
        ('"format_version": 1', '"format_version": 1, "deep": ' + "[" * 3000 + "]" * 3000, "$.deep[0]",
         "nesting at most 100 levels deep"),
        ('"format_version": 1', '"format_version": 1, "format_version": 1', "$", "each field at most once"),
    ],
)  # fmt: skip
def test_what_json_has_not_is_refused_with_its_path(
    tmp_path: Path, old: str, new: str, where: str, expected: str
) -> None:
    text = scene_text()
    assert old in text
    file = tmp_path / "bad.json"
    file.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(SceneFileError) as info:
        read_scene(file)
    assert str(info.value).startswith(f"{file}: "), str(info.value)
    assert f"{where}" in str(info.value) and expected in str(info.value)


def write_config(tmp_path: Path, data: object) -> Path:
    file = tmp_path / "cell.json"
    file.write_text(json.dumps(data), encoding="utf-8")
    return file


@pytest.mark.parametrize(
    ("edit", "where", "expected"),
    [
        (lambda d: d.update(home_joint=[0] * 6), "$.home_joint", "one of the fields format_version"),
        (lambda d: d.update(home_joints=[0] * 5), "$.home_joints", "a list of 6 finite numbers"),
        (lambda d: d["table"].update(top_z="low"), "$.table.top_z", "a number"),
        (lambda d: d["cameras"]["wrist"].update(near=0), "$.cameras.wrist.near", "a number above 0"),
        (lambda d: d["cameras"]["wrist"].update(zoom=2), "$.cameras.wrist.zoom", "one of the fields pose"),
        (lambda d: d["tcp_offsets"].update(gripper=[0, 0, 0.1]), "$.tcp_offsets.gripper",
         "an object with position, orientation"),
    ],
)  # fmt: skip
def test_a_bad_cell_config_names_file_path_and_expectation(
    tmp_path: Path, edit: Callable[[Any], None], where: str, expected: str
) -> None:
    data = json.loads(DEFAULT_CONFIG_PATH.read_text(encoding="utf-8"))
    edit(data)
    file = write_config(tmp_path, data)
    with pytest.raises(CellConfigError) as info:
        CellConfig.load(file)
    assert str(info.value).startswith(f"{file}: {where}: expected "), str(info.value)
    assert expected in str(info.value)
    assert isinstance(info.value, CapabilityError)


def test_a_missing_cell_config_is_named(tmp_path: Path) -> None:
    with pytest.raises(CellConfigError, match="expected a cell configuration file, got no file"):
        CellConfig.load(tmp_path / "none.json")
