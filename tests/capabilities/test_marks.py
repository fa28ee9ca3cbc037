"""tests/conftest.py marks a test ``sim`` by what it uses, not by the folder it lives in."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from capabilities.sim.session import SimCellSession


@pytest.fixture
def would_start_the_sim() -> Iterator[object]:
    """Names SimCellSession as a fixture that starts the cell does (without starting it)."""
    yield SimCellSession if False else None


@pytest.fixture
def through_another_fixture(would_start_the_sim: object) -> object:
    return would_start_the_sim


def test_a_fixture_that_starts_the_sim_marks_sim(
    through_another_fixture: object, request: pytest.FixtureRequest
) -> None:
    assert request.node.get_closest_marker("sim") is not None


def test_a_test_that_uses_no_sim_is_not_marked(request: pytest.FixtureRequest) -> None:
    assert request.node.get_closest_marker("sim") is None
