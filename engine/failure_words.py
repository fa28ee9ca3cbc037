"""How a failure is put in words, the same in the engine's root, run reports and the GUI.

``grasp CUP failed 4 times (grasp_failed): nothing between the fingers``: the node's title,
how often (when more than once), the error type (left out when it is the untyped
``failed``) and the message.
"""

from __future__ import annotations

from engine.error_types import ErrorType

__all__ = ["failed_words", "node_title", "stopped_words"]

_UNTYPED = ("", ErrorType.FAILED.value)


def node_title(kind: str, name: str, *, leaf: bool) -> str:
    """What a report calls a node: a leaf by its name ("grasp CUP"), a logic node by its
    kind and name ("Retry 'pick 4 times'"), or by its kind alone when it has no name of its
    own ("Force failure").
    """
    if leaf:
        return name or kind
    title = kind.replace("_", " ").capitalize()
    plain = not name or name.lower() in (kind, title.lower())  # "Selector" named "Selector"
    return title if plain else f"{title} '{name}'"


def failed_words(title: str, error: str, message: str, times: int = 1) -> str:
    """``grasp CUP failed 4 times (grasp_failed): nothing between the fingers``."""
    count = "" if times == 1 else f" {times} times"
    kind = "" if error in _UNTYPED else f" ({error})"
    return f"{title} failed{count}{kind}" + (f": {message}" if message else "")


def stopped_words(limit: int) -> str:
    """Why a root that runs until success gave up: ``stopped after 5 identical failures in a
    row``.
    """
    return f"stopped after {limit} identical failures in a row"
