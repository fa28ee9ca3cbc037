"""The object library's model.json files, read through the one JSON reader."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from capabilities.errors import CapabilityError
from capabilities.object_library import ObjectLibrary, ObjectLibraryError, default_library_path
from engine.json_reader import JsonFileError


def library_with(tmp_path: Path, edit: Any) -> ObjectLibrary:
    shutil.copytree(default_library_path() / "cup", tmp_path / "cup")
    file = tmp_path / "cup" / "model.json"
    data = json.loads(file.read_text(encoding="utf-8"))
    text = edit(data)
    file.write_text(text if isinstance(text, str) else json.dumps(data), encoding="utf-8")
    return ObjectLibrary(tmp_path)


def test_every_shipped_model_reads() -> None:
    library = ObjectLibrary()
    for name in library.names():
        assert library.get(name).name == name


@pytest.mark.parametrize(
    ("edit", "where", "expected"),
    [
        (lambda d: d.update(mass=0), "$.mass", "a number above 0"),
        (lambda d: d["markers"][1].update(id=50), "$.markers[1].id", "a whole number from 0 to 49"),
        (lambda d: d["markers"][0]["pose"].update(position=[0, 0]), "$.markers[0].pose.position",
         "a list of 3 numbers"),
        (lambda d: d["collision"].update(type="sphere"), "$.collision.type", "one of cylinder, box"),
        (lambda d: d["symmetry"].update(kind="discrete"), "$.symmetry.order", "required"),
        (lambda d: d.update(color=[1, 1, 1]), "$.color", "a list of 4 finite numbers"),
        (lambda d: d.update(name="mug"), "$.name", "the folder's name 'cup'"),
        (lambda d: d.update(format_version=2), "$.format_version", "newer version"),
        (lambda d: json.dumps(d).replace('"mass": 0.15', '"mass": NaN'), "$.mass",
         "a finite number (JSON has no NaN"),
        (lambda d: json.dumps(d).replace('"mass": 0.15', '"mass": 0.1, "mass": 0.2'), "$",
         "each field at most once"),
        (lambda d: d["grasps"][1].update(name="top"), "$.grasps[1].name", "not used before"),
        (lambda d: d["grasps"][0].update(tool="magnet"), "$.grasps[0].tool",
         "one of gripper, suction"),
        (lambda d: d["grasps"][0].update(approach=d["grasps"][0]["pose"]), "$.grasps[0].approach",
         "10 mm or more from the pose"),
        (lambda d: d["grasps"][0].pop("pose"), "$.grasps[0].pose", "required"),
    ],
)  # fmt: skip
def test_a_bad_model_names_file_path_and_expectation(
    tmp_path: Path, edit: Any, where: str, expected: str
) -> None:
    library = library_with(tmp_path, edit)
    with pytest.raises(ObjectLibraryError) as info:
        library.get("cup")
    message = str(info.value)
    assert message.startswith(f"{tmp_path / 'cup' / 'model.json'}: {where}: expected "), message
    assert expected in message
    assert isinstance(info.value, CapabilityError) and isinstance(
        info.value.__cause__, JsonFileError
    )


def test_text_that_is_not_json_gives_line_and_column(tmp_path: Path) -> None:
    library = library_with(tmp_path, lambda d: '{\n  "name": "cup",\n  oops\n}')
    with pytest.raises(
        ObjectLibraryError, match=r"model\.json: line 3 column 3: expected valid JSON"
    ):
        library.get("cup")
