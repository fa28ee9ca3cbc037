"""costar-instructor: arguments, exit codes, and --screenshot on a machine without a screen."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtGui import QImage

from engine.files import dump_plan
from instructor_app.app import EXIT_BAD_INPUT, EXIT_OK, EXIT_RUN_FAILED, EXIT_TIMEOUT, main
from tests.instructor_app.runtime.plans import endless_plan, invalid_plan


def picture(path: Path) -> QImage:
    image = QImage(str(path))
    assert not image.isNull(), f"{path} is not a PNG"
    return image


def test_screenshot_of_a_plan_writes_a_png(qapp: Any, tmp_path: Path, figure3_path: Path) -> None:
    png = tmp_path / "shots" / "window.png"
    assert main([str(figure3_path), "--cell", "none", "--screenshot", str(png)]) == EXIT_OK
    image = picture(png)
    assert (image.width(), image.height()) == (1920, 1080)


def test_screenshot_after_a_run(qapp: Any, tmp_path: Path, figure3_path: Path, capsys: Any) -> None:
    png = tmp_path / "run.png"
    args = [str(figure3_path), "--cell", "none", "--run", "--screenshot", str(png)]
    assert main(args) == EXIT_OK
    assert "run ended: SUCCESS" in capsys.readouterr().out
    picture(png)


def test_a_run_that_does_not_end_in_time_exits_3_with_a_picture(qapp: Any, tmp_path: Path) -> None:
    plan = tmp_path / "endless.costar.json"
    plan.write_text(dump_plan(endless_plan()), encoding="utf-8")
    png = tmp_path / "late.png"
    args = [str(plan), "--cell", "none", "--run", "--timeout", "0.3", "--screenshot", str(png)]
    assert main(args) == EXIT_TIMEOUT
    picture(png)


def test_an_invalid_plan_is_refused_with_exit_1(qapp: Any, tmp_path: Path, capsys: Any) -> None:
    plan = tmp_path / "invalid.costar.json"
    plan.write_text(dump_plan(invalid_plan()), encoding="utf-8")
    args = [str(plan), "--cell", "none", "--run", "--screenshot", str(tmp_path / "x.png")]
    assert main(args) == EXIT_RUN_FAILED
    assert "no_such_thing" in capsys.readouterr().err


def test_bad_arguments_and_unreadable_plans_exit_2(qapp: Any, tmp_path: Path) -> None:
    assert main(["--cell", "mars"]) == EXIT_BAD_INPUT
    broken = tmp_path / "broken.costar.json"
    broken.write_text("{", encoding="utf-8")
    png = tmp_path / "never.png"
    assert main([str(broken), "--cell", "none", "--screenshot", str(png)]) == EXIT_BAD_INPUT
    assert not png.exists()
    missing = tmp_path / "missing.costar.json"
    assert main([str(missing), "--cell", "none", "--screenshot", str(png)]) == EXIT_BAD_INPUT


def test_scene_chooses_the_simulated_cells_scene(qapp: Any, tmp_path: Path, capsys: Any) -> None:
    png = tmp_path / "scene.png"
    assert main(["--scene", "tending", "--size", "400x300", "--screenshot", str(png)]) == EXIT_OK
    assert "error" not in capsys.readouterr().err
    assert (
        main(["--scene", "no_such_scene", "--size", "400x300", "--screenshot", str(png)]) == EXIT_OK
    )
    assert "no_such_scene" in capsys.readouterr().err  # the cell failed on that scene
