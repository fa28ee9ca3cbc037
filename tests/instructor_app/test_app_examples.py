"""costar-instructor opens a shipped plan by name and wears the application's icon."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtWidgets import QApplication

from instructor_app.app import EXIT_BAD_INPUT, EXIT_OK, main


def test_an_example_opens_by_name(qapp: Any, tmp_path: Path) -> None:
    png = tmp_path / "example.png"
    args = [
        "example:figure3_debug",
        "--cell",
        "none",
        "--screenshot",
        str(png),
        "--size",
        "800x600",
    ]
    assert main(args) == EXIT_OK
    assert png.is_file()
    assert not QApplication.windowIcon().isNull()


def test_an_unknown_example_is_bad_input_naming_the_examples(qapp: Any, capsys: Any) -> None:
    assert main(["example:teleport", "--cell", "none", "--screenshot", "x.png"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "no shipped example 'teleport'" in err and "cup_to_bin" in err
