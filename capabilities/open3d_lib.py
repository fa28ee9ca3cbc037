"""The one place that imports Open3D: without the web visualiser we never use.

``import open3d`` imports ``open3d.visualization.draw_plotly``, which imports Dash and
Plotly at once: measured here, the import costs 1.4 CPU s with them and 0.8 s without, paid
by every ``costar run`` that looks with a camera and by every test process. We draw with Qt and pyqtgraph, never with
Plotly, so during the import those two packages are stand-ins, removed again right after
(a later ``import dash`` or ``import plotly`` gets the real ones). Every module of the
project imports Open3D from here (``from capabilities.open3d_lib import o3d``), as pybullet
comes from :mod:`capabilities.bullet`.
"""

from __future__ import annotations

import sys
import threading
import types
from typing import TYPE_CHECKING

__all__ = ["o3d"]

# The names ``open3d.visualization.draw_plotly`` takes from Dash and Plotly at import.
_STAND_INS = {
    "dash": ("Dash", "dcc", "html"),
    "plotly": ("graph_objects",),
    "plotly.graph_objects": (),
}
_LOCK = threading.Lock()


def _import_open3d() -> types.ModuleType:
    with _LOCK:
        if "open3d" in sys.modules:
            return sys.modules["open3d"]
        placed: dict[str, types.ModuleType] = {}
        for name, attributes in _STAND_INS.items():
            if name in sys.modules:
                continue  # already really imported: open3d uses the real one
            module = types.ModuleType(name, "stand-in while open3d imports (not used by us)")
            module.__path__ = []
            for attribute in attributes:
                setattr(module, attribute, None)
            placed[name] = module
        if "plotly" in placed and "plotly.graph_objects" in placed:
            placed["plotly"].__dict__["graph_objects"] = placed["plotly.graph_objects"]
        sys.modules.update(placed)
        try:
            import open3d
        finally:
            for name, module in placed.items():
                if sys.modules.get(name) is module:
                    del sys.modules[name]
        return open3d


if TYPE_CHECKING:
    import open3d as o3d  # its own stubs, as a plain import would give
else:
    o3d = _import_open3d()
