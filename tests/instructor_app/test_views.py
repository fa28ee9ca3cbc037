"""What the views offer, computed from the cell's interfaces."""

from __future__ import annotations

from instructor_app.views import offered_object_names


class _Library:
    def names(self) -> list[str]:
        return ["bender_arm", "cup", "kit_bin", "waste_bin"]


def test_object_fields_offer_the_scenes_objects_first_then_the_library() -> None:
    interfaces = {"objects": _Library(), "scene_layout": {"objects": ["waste_bin", "cup", "ghost"]}}
    assert offered_object_names(interfaces) == ["waste_bin", "cup", "bender_arm", "kit_bin"]
    assert offered_object_names({"objects": _Library()}) == [
        "bender_arm",
        "cup",
        "kit_bin",
        "waste_bin",
    ]
    assert offered_object_names({}) == []
