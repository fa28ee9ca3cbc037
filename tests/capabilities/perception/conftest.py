"""Frames of the simulated cell shared by the perception tests (rendered once per worker)."""

from __future__ import annotations

import pytest

from capabilities.object_library import ObjectLibrary
from capabilities.perception.recognizer import Recognition, Recognizer
from tests.capabilities.perception.shots import SCENES, Shot, take_shots


@pytest.fixture(scope="session")
def shots() -> list[Shot]:
    return take_shots(SCENES)


@pytest.fixture(scope="session")
def recognizer() -> Recognizer:
    return Recognizer(ObjectLibrary())


@pytest.fixture(scope="session")
def recognitions(shots: list[Shot], recognizer: Recognizer) -> list[list[Recognition]]:
    """What the recognizer finds in each shot, in order. Recognition is deterministic (its
    RANSAC is seeded), so the tests that score the same frames share one pass over them.
    """
    return [recognizer.recognize(shot.frame) for shot in shots]
