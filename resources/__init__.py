"""The files shipped with CoSTAR Instructor, found where the package is installed.

Example plans, scenes, object models with their meshes, robot models, cell files, schemas and
icons are package data of this package: in a wheel they sit beside this module, in a checkout
they are this folder. Everything that reads a shipped file asks this module for its path
(``importlib.resources``), so the application works from any folder and from an installed
wheel, never through a path relative to the repository.
"""

from __future__ import annotations

from importlib import resources as _importlib_resources
from pathlib import Path

__all__ = [
    "EXAMPLE_PREFIX",
    "example_name",
    "example_names",
    "example_path",
    "example_plans",
    "plan_argument",
    "resource_path",
    "root",
]

EXAMPLE_PREFIX = "example:"
_PLAN_SUFFIX = ".costar.json"


def root() -> Path:
    """The folder that holds the shipped files (the ``resources`` package's folder).

    Raises:
        FileNotFoundError: the package is installed in a form without a real folder (a zip).
    """
    files = _importlib_resources.files(__name__)
    if not isinstance(files, Path):
        raise FileNotFoundError(
            f"the shipped files are not in a folder ({files}); install CoSTAR Instructor "
            "as a regular package (pip install), not as a zip"
        )
    return files


def resource_path(*parts: str) -> Path:
    """The path of a shipped file or folder, e.g. ``resource_path("scenes", "empty.json")``.

    The path may not exist (a caller that looks for an optional file checks ``exists()``).
    """
    return root().joinpath(*parts)


def example_plans(with_node_examples: bool = False) -> list[Path]:
    """The shipped example plans (``examples/*.costar.json``), in name order.

    Args:
        with_node_examples: also the one-plan-per-node-kind examples of ``examples/nodes``.
    """
    examples = resource_path("examples")
    pattern = f"**/*{_PLAN_SUFFIX}" if with_node_examples else f"*{_PLAN_SUFFIX}"
    # Top-level plans first, then those in sub-folders; each group in name order.
    return sorted(examples.glob(pattern), key=lambda path: (example_name(path).count("/"), path))


def example_name(path: Path) -> str:
    """The name ``example:NAME`` accepts for a shipped plan (``cup_to_bin``, ``nodes/retry``)."""
    relative = path.relative_to(resource_path("examples")).as_posix()
    return relative.removesuffix(_PLAN_SUFFIX)


def example_names(with_node_examples: bool = False) -> list[str]:
    """The names of :func:`example_plans`, in the same order."""
    return [example_name(path) for path in example_plans(with_node_examples)]


def example_path(name: str) -> Path:
    """The shipped plan called ``name`` (``cup_to_bin`` or ``nodes/sequence``).

    Raises:
        FileNotFoundError: no shipped plan has that name (the message lists the names).
    """
    examples = resource_path("examples")
    path = examples.joinpath(*name.removesuffix(_PLAN_SUFFIX).split("/"))
    path = path.with_name(path.name + _PLAN_SUFFIX)
    if not name or ".." in name.split("/") or not path.is_file():
        raise FileNotFoundError(
            f"no shipped example {name!r}; examples: {', '.join(example_names())} "
            "(costar examples lists them)"
        )
    return path


def plan_argument(argument: str) -> str:
    """A plan given on the command line: ``example:NAME`` becomes the shipped plan's path;
    anything else is a file name, returned exactly as given (messages name it so).

    Raises:
        FileNotFoundError: ``example:NAME`` names no shipped plan.
    """
    if argument.startswith(EXAMPLE_PREFIX):
        return str(example_path(argument.removeprefix(EXAMPLE_PREFIX)))
    return argument
