"""A copy-me capability: one condition over a backend interface, with its test.

To make your own: copy this folder, rename ``template`` everywhere, describe your operations
in ``operations.py`` (its docstring shows the one shape), the cell-side interface in
``backend.py``, and register the package's ``capability`` function under
``[project.entry-points."costar.capabilities"]``. This template itself is not registered,
so it stays out of the palette.
"""

from __future__ import annotations

from capabilities.template.operations import capability

__all__ = ["capability"]
