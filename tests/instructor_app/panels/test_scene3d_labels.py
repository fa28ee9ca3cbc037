"""The 3D scene's label layout (issue 26: "kit_bin 88%" drawn over "plate_8_holes 100%")."""

from __future__ import annotations

import itertools

from instructor_app.panels.scene3d_labels import GAP_PX, stack_labels


def _intersect(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]


def test_labels_of_objects_close_together_stack_upward_without_overlapping() -> None:
    anchors = [(400.0, 300.0), (405.0, 302.0), (398.0, 299.0), (600.0, 300.0), None]
    sizes = [(90.0, 18.0), (150.0, 18.0), (60.0, 18.0), (80.0, 18.0), (50.0, 18.0)]
    rects = stack_labels(anchors, sizes)
    assert rects[4] is None  # behind the eye: not drawn
    shown = [r for r in rects if r is not None]
    for a, b in itertools.combinations(shown, 2):
        assert not _intersect(a, b), rects
    # The lowest anchor's label sits right above it; the others above that one, centred.
    assert rects[1] == (405.0 - 75.0, 302.0 - GAP_PX - 18.0, 150.0, 18.0)
    assert all(r is not None and r[1] + r[3] <= 302.0 for r in rects[:3])
    # A label far from the others is not moved.
    assert rects[3] == (560.0, 300.0 - GAP_PX - 18.0, 80.0, 18.0)
