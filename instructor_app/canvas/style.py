"""How a plan node looks on the canvas: colours, symbols and text (the paper's Figure 3).

Logic nodes are white (composites) or grey (decorators) and carry their symbol: sequence
"->", selector "?", parallel "|A|"; decorators are named. Operation leaves are coloured by
the operation's kind (action, query, condition) and show the operation id and their bound
parameters: references bare (CUP_POSE), fixed values in quotes ("CUP"). Run statuses
recolour the node body. Colours are plain RGB tuples here; the items turn them into QColors.
"""

from __future__ import annotations

from dataclasses import dataclass

from engine.operations import OperationKind
from engine.spec import Binding, Category, NodeKind, NodeSpec
from engine.status import Status

__all__ = [
    "RGB",
    "NodeLook",
    "STATUS_COLOURS",
    "HALTED_COLOUR",
    "look_of",
    "default_title",
    "binding_text",
]

RGB = tuple[int, int, int]

STATUS_COLOURS: dict[Status, RGB] = {
    Status.IDLE: (176, 176, 176),
    Status.RUNNING: (255, 190, 40),
    Status.SUCCESS: (96, 192, 96),
    Status.FAILURE: (226, 84, 72),
    # Passed over by its pre-conditions (skip_if, while) or because all its children were.
    Status.SKIPPED: (190, 150, 220),
}
# A node that was running when the run was stopped: halted, no longer running.
HALTED_COLOUR: RGB = (140, 162, 200)

_COMPOSITE_FILL: RGB = (250, 250, 250)
_DECORATOR_FILL: RGB = (214, 214, 214)
_WAIT_FILL: RGB = (205, 214, 228)
_BROKEN_FILL: RGB = (240, 200, 200)  # an operation the cell does not know
_OPERATION_FILL: dict[OperationKind, RGB] = {
    OperationKind.ACTION: (160, 196, 244),
    OperationKind.QUERY: (206, 180, 240),
    OperationKind.CONDITION: (170, 226, 220),
}

_SUBTREE_FILL: RGB = (246, 214, 160)  # an instance of a library subtree: one node

_SYMBOLS: dict[NodeKind, str] = {
    NodeKind.SEQUENCE: "->",
    NodeKind.SELECTOR: "?",
    NodeKind.PARALLEL: "|A|",
    NodeKind.REACTIVE_SEQUENCE: "R->",
    NodeKind.REACTIVE_SELECTOR: "R?",
    NodeKind.CATCH: "!?",  # try the first child; on a caught error, the second
    NodeKind.SEQUENCE_WITH_MEMORY: "M->",
    NodeKind.ASYNC_SEQUENCE: "A->",
    NodeKind.ASYNC_FALLBACK: "A?",
    NodeKind.PARALLEL_ALL: "|*|",
    NodeKind.IF_THEN_ELSE: "if?",
    NodeKind.WHILE_DO_ELSE: "w?",
    NodeKind.SWITCH: "=?",
    NodeKind.TRY_CATCH: "tr!",
}
# The symbol box is three characters wide: a longer symbol runs under the node's edge.

_MAX_PARAM_LINES = 4


@dataclass(frozen=True)
class NodeLook:
    """What a node item draws.

    Attributes:
        title: the editable label (the user's name, else the kind or operation id).
        symbol: the logic symbol ("->", "?", "|A|") or "" for leaves and decorators.
        subtitle: a second line: the operation id under a user name, a decorator's
            settings, a Wait's seconds.
        lines: bound parameters, one per line (at most a few, then "...").
        fill: body colour when no status is shown.
        header: colour of the band that keeps the category visible under a status colour.
        leaf: whether the node takes no children (no child port).
        broken: why the node cannot run as it is ("" when it can): an unknown operation.
    """

    title: str
    symbol: str
    subtitle: str
    lines: tuple[str, ...]
    fill: RGB
    header: RGB
    leaf: bool
    broken: str = ""


def default_title(node: NodeSpec) -> str:
    """The label shown when the user gave no name."""
    if node.kind is NodeKind.OPERATION:
        return node.op or "operation"
    return node.kind.value.replace("_", " ").capitalize()


def binding_text(binding: Binding) -> str:
    """A parameter as the paper writes it: a reference bare, a fixed value in quotes."""
    if binding.is_ref:
        return str(binding.ref)
    value = binding.value
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, bool | int | float):
        return f'"{value:g}"' if isinstance(value, float) else f'"{value}"'
    name = getattr(value, "name", None)  # waypoints and object models carry a name
    if isinstance(name, str) and name:
        return f'"{name}"'
    return f"<{binding.type.value if binding.type is not None else 'value'}>"


def _config_text(node: NodeSpec) -> str:
    """A logic node's settings in one line ("count 3", "success any")."""
    return ", ".join(
        f"{port} {binding_text(binding).strip(chr(34))}"
        for port, binding in sorted(node.params.items())
    )


def _param_lines(node: NodeSpec) -> tuple[str, ...]:
    lines = [f"{port}: {binding_text(binding)}" for port, binding in node.params.items()]
    if len(lines) > _MAX_PARAM_LINES:
        lines = [*lines[: _MAX_PARAM_LINES - 1], f"... {len(lines) - _MAX_PARAM_LINES + 1} more"]
    return tuple(lines)


def look_of(
    node: NodeSpec, op_kind: OperationKind | None = None, unknown: bool = False
) -> NodeLook:
    """The look of ``node``; ``op_kind`` is its operation's kind when known, ``unknown``
    says that the cell's registry has no such operation (the node is drawn as broken).
    """
    title = node.name or default_title(node)
    category = node.category
    if category is Category.COMPOSITE:
        symbol = _SYMBOLS.get(node.kind, "")
        return NodeLook(
            title, symbol, _config_text(node), (), _COMPOSITE_FILL, (120, 120, 120), False
        )
    if category is Category.DECORATOR:
        subtitle = _config_text(node)
        if node.name:
            subtitle = f"{default_title(node)} {subtitle}".strip()
        return NodeLook(title, "", subtitle, (), _DECORATOR_FILL, (120, 120, 120), False)
    if node.kind is NodeKind.WAIT:
        return NodeLook(title, "", _config_text(node), (), _WAIT_FILL, _WAIT_FILL, True)
    if node.kind is NodeKind.SUBTREE:
        version = f"version {node.subtree.version}" if node.subtree else "no subtree"
        return NodeLook(
            title,
            "[ ]",
            f"subtree, {version}",
            _param_lines(node),
            _SUBTREE_FILL,
            (200, 140, 60),
            True,
        )
    fill = _OPERATION_FILL.get(
        op_kind or OperationKind.ACTION, _OPERATION_FILL[OperationKind.ACTION]
    )
    subtitle = (node.op or "") if node.name else ""
    if unknown:
        broken = f"Unknown operation {node.op!r}: no capability of this cell provides it"
        return NodeLook(
            title,
            "",
            f"⚠ unknown: {node.op}",
            _param_lines(node),
            _BROKEN_FILL,
            _BROKEN_FILL,
            True,
            broken,
        )
    return NodeLook(title, "", subtitle, _param_lines(node), fill, fill, True)
