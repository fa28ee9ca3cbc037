"""How a bench script prints its figures: a table, or one JSON object (``--json``)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping
from typing import Any

__all__ = ["figures_parser", "print_figures"]


def figures_parser(doc: str | None) -> argparse.ArgumentParser:
    """A bench script's argument parser: described by its doc's first line, with ``--json``."""
    parser = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def print_figures(
    figures: Mapping[str, Any], as_json: bool, width: int, indent: int | None = None
) -> None:
    """Print ``figures`` as one JSON object, or a line each with the name padded to ``width``."""
    if as_json:
        print(json.dumps(figures, indent=indent))
    else:
        for key, value in figures.items():
            print(f"{key:{width}s} {value}")
