"""Fixtures of the marker tests: a 320x240 camera with a 60 degree horizontal view."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from capabilities.markers.synthetic import camera_matrix
from tests.capabilities.markers.scenes import HEIGHT, WIDTH


@pytest.fixture
def k() -> NDArray[np.float64]:
    """The test camera's intrinsics."""
    return camera_matrix(WIDTH, HEIGHT, 60.0)
