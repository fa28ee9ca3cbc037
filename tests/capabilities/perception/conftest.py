"""Frames of the simulated cell shared by the perception tests (rendered once per worker)."""

from __future__ import annotations

import pytest

from capabilities.object_library import ObjectLibrary
from capabilities.perception.recognizer import Recognizer
from tests.capabilities.perception.shots import SCENES, Shot, take_shots


@pytest.fixture(scope="session")
def shots() -> list[Shot]:
    return take_shots(SCENES)


@pytest.fixture(scope="session")
def recognizer() -> Recognizer:
    return Recognizer(ObjectLibrary())
