"""Fixtures of the engine tests; the fakes themselves live in ``bt_fakes`` (a module with a
unique name, so test modules can import them whatever other conftest files are loaded).
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import FakeClock, recording_ctx

from capabilities.base import CapabilityRegistry
from capabilities.debug import capability as debug_capability


@pytest.fixture
def clock() -> FakeClock:
    return FakeClock()


@pytest.fixture
def ctx(clock: FakeClock) -> Any:
    return recording_ctx(clock)


@pytest.fixture
def registry() -> CapabilityRegistry:
    """A registry with only the debug capability (no entry-point scan)."""
    return CapabilityRegistry([debug_capability()])
