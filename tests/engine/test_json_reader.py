"""The one reader of user JSON files: loading refusals and typed access, each error with the
file as given, the JSON path and what was expected.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from engine.errors import EngineError
from engine.files import PlanFileError, loads_plan
from engine.json_reader import (
    MAX_DIGITS,
    JsonFileError,
    JsonReader,
    parse_json,
    read_json_file,
)
from engine.types import MAX_VALUE_DEPTH, ParamType, Pose, ValueShapeError, decode_value


def refusal(text: str | bytes, **kwargs: Any) -> JsonFileError:
    with pytest.raises(JsonFileError) as info:
        parse_json(text, "cells/left.cell.json", "cell", **kwargs)
    return info.value


def nested(depth: int, inner: Any = 1) -> Any:
    for _ in range(depth):
        inner = [inner]
    return inner


# --------------------------------------------------------------------------- loading


def test_the_error_class_is_an_engine_error_and_plan_errors_are_reader_errors() -> None:
    assert issubclass(JsonFileError, EngineError)
    assert issubclass(PlanFileError, JsonFileError)
    assert issubclass(ValueShapeError, EngineError)


def test_text_that_is_not_utf8_says_what_the_file_is_not() -> None:
    error = refusal(b'{"name": "\xff"}')
    assert str(error) == (
        "cells/left.cell.json: expected UTF-8 text (the file is not a cell file), "
        "got a byte that is not UTF-8 at offset 10"
    )


def test_a_byte_order_mark_is_skipped() -> None:
    assert parse_json('\ufeff{"a": 1}'.encode(), "x.json") == {"a": 1}


@pytest.mark.parametrize(
    ("text", "line", "column", "got"),
    [
        ('{\n  "a": 1,\n}', 3, 1, "a syntax error (Expecting property name enclosed in double quotes)"),
        ('{\n  "a": [1, 2', 2, 13, "the end of the file: it is cut off"),
    ],
)  # fmt: skip
def test_text_that_is_not_json_gives_line_and_column(
    text: str, line: int, column: int, got: str
) -> None:
    error = refusal(text)
    assert (error.line, error.column, error.got) == (line, column, got)
    assert str(error).startswith(
        f"cells/left.cell.json: line {line} column {column}: expected valid JSON"
    )


@pytest.mark.parametrize(
    ("text", "path", "expected", "got"),
    [
        ('{"a": {"b": 1, "b": 2}}', "$.a", "each field at most once", "'b' twice"),
        ('{"a": [1, NaN]}', "$.a[1]", "a finite number (JSON has no NaN or Infinity)", "NaN"),
        ('{"a": -Infinity}', "$.a", "a finite number", "-Infinity"),
        ('{"a": {"b": 1e999}}', "$.a.b", "a number a float can hold", "1e999... (too large)"),
        ('{"n": [' + "9" * (MAX_DIGITS + 1) + "]}", "$.n[0]", "a shorter number",
         f"an integer of {MAX_DIGITS + 1} digits"),
        ('{"n": ' + "9" * 5000 + "}", "$.n", "a shorter number", "an integer of 5000 digits"),
    ],
)  # fmt: skip
def test_what_python_reads_but_json_has_not_is_refused_with_its_path(
    text: str, path: str, expected: str, got: str
) -> None:
    error = refusal(text)
    assert (error.json_path, error.got) == (path, got)
    assert expected in error.expected
    assert str(error).startswith(f"cells/left.cell.json: {path}: expected ")


def test_a_long_integer_within_the_limit_is_read() -> None:
    assert parse_json("[" + "9" * MAX_DIGITS + "]") == [int("9" * MAX_DIGITS)]


def test_nesting_deeper_than_the_limit_names_the_path() -> None:
    error = refusal(json.dumps({"a": [nested(5)]}), max_depth=4)
    assert error.json_path == "$.a[0][0][0]"
    assert error.expected == "nesting at most 4 levels deep"
    assert parse_json(json.dumps({"a": [nested(2)]}), max_depth=4) == {"a": [[[1]]]}


def test_nesting_too_deep_for_python_names_the_path_line_and_column() -> None:
    text = '{"a": 1,\n "deep": {"x": [0, ' + "[" * 5000 + "]" * 5000 + "]}}"
    error = refusal(text, max_depth=50)
    assert error.json_path.startswith("$.deep.x[1]" + "[0]" * 20)
    assert (error.line, error.column) == (2, 67)  # the 48th of the brackets
    assert "nesting at most 50 levels deep" in str(error)
    assert len(str(error)) < 400  # the path is shortened in the message, whole in json_path


def test_a_missing_file_and_a_folder_are_named_as_given(tmp_path: Path) -> None:
    with pytest.raises(JsonFileError) as info:
        read_json_file(tmp_path / "none.scene.json", "scene")
    assert str(info.value) == (
        f"{tmp_path / 'none.scene.json'}: expected a scene file, "
        f"got no file at {tmp_path / 'none.scene.json'}"
    )
    with pytest.raises(JsonFileError, match="expected a readable scene file"):
        read_json_file(tmp_path, "scene")


def test_the_error_class_can_be_chosen(tmp_path: Path) -> None:
    with pytest.raises(PlanFileError):
        parse_json("{", "x", error=PlanFileError)


# --------------------------------------------------------------------------- typed access

DOC: dict[str, Any] = {
    "name": "cell",
    "speed": 0.5,
    "count": 3,
    "on": True,
    "mode": "fast",
    "size": [1, 2, 3],
    "pose": {"position": [0, 0, 1], "orientation": [0, 0, 0, 1]},
    "tree": {"children": [{"params": {}}, {"params": {}}, {"params": {"speed": "fast"}}]},
    "cameras": {"left": {"near": 0.1}},
}


def reader() -> JsonReader:
    return JsonReader(DOC, "cells/left.cell.json")


def test_typed_accessors_return_typed_values() -> None:
    r = reader()
    assert r.text("name") == "cell" and r.text("missing", "dflt") == "dflt"
    assert r.number("speed", lo=0.0, hi=1.0) == 0.5 and r.number("absent", 2.0) == 2.0
    assert r.integer("count", lo=1) == 3
    assert r.flag("on") is True and r.flag("off", False) is False
    assert r.choice("mode", ("fast", "slow")) == "fast"
    assert r.vector3("size") == (1.0, 2.0, 3.0)
    assert r.vector2("absent", (4, 5)) == (4.0, 5.0)
    assert r.pose("pose") == Pose((0, 0, 1))
    assert [name for name, _ in r.entries("cameras")] == ["left"]
    assert r.child("cameras").child("left").number("near") == 0.1
    assert r.child("absent").path == "$.absent" and r.items("absent") == []


def speed_of_third_child() -> None:
    reader().child("tree").items("children")[2].child("params").number("speed", lo=0.0)


@pytest.mark.parametrize(
    ("read", "message"),
    [
        (speed_of_third_child, "$.tree.children[2].params.speed: expected a number of 0 or more, got the text 'fast'"),
        (lambda: reader().text("speed"), "$.speed: expected a text, got the number 0.5"),
        (lambda: reader().text("nothing"), "$.nothing: expected a value here (it is required), got nothing"),
        (lambda: reader().number("speed", hi=0.25), "$.speed: expected a number of 0.25 or less"),
        (lambda: reader().number("speed", lo=0.5, above=True), "$.speed: expected a number above 0.5"),
        (lambda: reader().integer("speed"), "$.speed: expected a whole number, got the number 0.5"),
        (lambda: reader().integer("count", lo=0, hi=2), "$.count: expected a whole number from 0 to 2"),
        (lambda: reader().integer("on"), "$.on: expected a whole number, got true"),
        (lambda: reader().flag("count"), "$.count: expected true or false, got the number 3"),
        (lambda: reader().choice("mode", ("slow", "stop")), "$.mode: expected one of slow, stop"),
        (lambda: reader().vector2("size"), "$.size: expected a list of 2 finite numbers, got a list of 3 items"),
        (lambda: reader().as_object(("name",)), "$.speed: expected one of the fields name, got 'speed'"),
        (lambda: reader().as_object(None, ("format",)), "$.format: expected a value here (it is required)"),
        (lambda: reader().child("name"), "$.name: expected an object, got the text 'cell'"),
        (lambda: reader().items("name", "names"), "$.name: expected a list of names, got the text 'cell'"),
        (lambda: reader().items("gone", "waypoints", optional=False), "$.gone: expected a list of waypoints here"),
        (lambda: reader().typed("size", ParamType.POSE), "$.size: expected an object with position, orientation"),
        (lambda: reader().child("pose").typed("position", ParamType.POSE), "$.pose.position: expected an object"),
        (lambda: reader().check_version((1,)), "$.format_version: expected one of the format versions 1, got null"),
    ],
)  # fmt: skip
def test_every_error_has_file_path_and_expectation(read: Any, message: str) -> None:
    with pytest.raises(JsonFileError) as info:
        read()
    assert str(info.value).startswith(f"cells/left.cell.json: {message}")


def test_a_newer_version_says_so() -> None:
    with pytest.raises(JsonFileError, match="written by a newer version"):
        JsonReader({"format_version": 3}, "f.json").check_version((1, 2))


# --------------------------------------------------------------------------- Any values


def test_an_any_value_nested_too_deep_is_refused_with_its_path() -> None:
    assert decode_value(ParamType.ANY, nested(MAX_VALUE_DEPTH - 1)) == nested(MAX_VALUE_DEPTH - 1)
    with pytest.raises(ValueShapeError) as info:
        decode_value(ParamType.ANY, {"k": nested(MAX_VALUE_DEPTH)}, "$.v")
    assert info.value.path == "$.v.k" + "[0]" * (MAX_VALUE_DEPTH - 1)
    assert f"at most {MAX_VALUE_DEPTH} levels" in str(info.value)


def test_a_plan_whose_any_parameter_is_nested_900_deep_is_refused_with_its_path() -> None:
    doc = {
        "format": "costar-plan",
        "format_version": 1,
        "parameters": [{"name": "P", "type": "Any", "value": nested(900)}],
    }
    with pytest.raises(PlanFileError) as info:
        loads_plan(json.dumps(doc), "plans/deep.costar.json")
    assert info.value.json_path.startswith("$.parameters[0].value[0]")
    assert str(info.value).startswith("plans/deep.costar.json: $.parameters[0].value[0][0]")
    doc["parameters"][0]["value"] = nested(100)
    with pytest.raises(PlanFileError, match=rf"at most {MAX_VALUE_DEPTH} levels deep"):
        loads_plan(json.dumps(doc), "plans/deep.costar.json")
