"""Our logic node kinds as BehaviorTree.CPP nodes, and their settings both ways.

Most kinds are BehaviorTree.CPP built-ins (Sequence, Fallback, Parallel, ...); Iterator and
Enforce (paper III-B) and Catch have no built-in twin and are declared as custom decorators in the
file's TreeNodesModel. A setting is written as the built-in's own port (a Parallel's
``success`` as ``success_count``, a Wait's seconds as Sleep's ``msec``); where that text
would not give back the exact setting (``success`` = 1, a time that is no whole number of
milliseconds), the exact value goes beside it in ``_<setting>``, which reading prefers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from engine.spec import NodeKind, NodeSpec

__all__ = [
    "BUILTIN_MODELS",
    "LOGIC",
    "LOGIC_BY_MODEL",
    "LogicModel",
    "SWITCH_MODELS",
    "SettingMap",
    "model_of",
]

Setting = str | float


def _count_text(value: Setting) -> str:
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value) if isinstance(value, str) else repr(value)


def _number(text: str) -> Setting:
    return float(text)


def _words(out: dict[str, str]) -> tuple[Callable[[Setting], str], Callable[[str], Setting]]:
    """A count port whose words (``all`` / ``any``) are counts in BehaviorTree.CPP."""
    back = {text: word for word, text in out.items()}

    def write(value: Setting) -> str:
        return out[value] if isinstance(value, str) and value in out else _count_text(value)

    def read(text: str) -> Setting:
        return back[text] if text in back else float(text)

    return write, read


def _word_text(value: Setting) -> str:
    """A word setting (a Catch's error types) is written as it is."""
    return value if isinstance(value, str) else _count_text(value)


def _word_read(text: str) -> Setting:
    return text


def _msec_text(value: Setting) -> str:
    if isinstance(value, str):
        return value
    return str(round(value * 1000.0))


def _msec_read(text: str) -> Setting:
    return int(text) / 1000.0


_BOOL_WORDS = {"true": "true", "True": "true", "TRUE": "true", "1": "true"}
_BOOL_WORDS |= {"false": "false", "False": "false", "FALSE": "false", "0": "false"}


def _bool_read(text: str) -> Setting:
    """A bool port's text as our word, true or false (BehaviorTree.CPP's spellings)."""
    if text.strip() not in _BOOL_WORDS:
        raise ValueError(f"true or false, not {text!r}")
    return _BOOL_WORDS[text.strip()]


@dataclass(frozen=True)
class SettingMap:
    """One setting of a kind: its port in BehaviorTree.CPP and the text both ways.

    ``raw``: the text is kept as it is, ``{key}`` too (the node reads the entry itself).
    """

    port: str
    write: Callable[[Setting], str] = _count_text
    read: Callable[[str], Setting] = _number
    raw: bool = False


@dataclass(frozen=True)
class LogicModel:
    """A logic kind as a BehaviorTree.CPP node.

    Attributes:
        kind: our kind.
        model: BehaviorTree.CPP's id (the compact element name).
        element: its model type: Control, Decorator or Action.
        builtin: True when BehaviorTree.CPP has it; False: declared in the TreeNodesModel.
        settings: our setting name -> how it is written.
        implied: settings the model's id gives, not written as ports (LoopInt: type int).
    """

    kind: NodeKind
    model: str
    element: str
    builtin: bool = True
    settings: dict[str, SettingMap] = field(default_factory=dict)
    implied: dict[str, str] = field(default_factory=dict)


_SUCCESS = _words({"all": "-1", "any": "1"})
_FAILURE = _words({"any": "1"})
_MSEC = SettingMap("msec", _msec_text, _msec_read)
_CODE = SettingMap("code", _word_text, _word_read)  # a script, as it is
_BOOL = (_word_text, _bool_read)
_CODE_IF = SettingMap("if", _word_text, _word_read)


def _text(port: str) -> SettingMap:
    """A text port kept as written, ``{key}`` included."""
    return SettingMap(port, _word_text, _word_read, raw=True)


_LOOP_TYPES = ("int", "double", "bool", "string")


def _loop(of: str) -> LogicModel:
    """LoopInt, LoopDouble, LoopBool or LoopString: our Loop with that ``type``."""
    settings = {
        "queue": _text("queue"),
        "value": _text("value"),
        "if_empty": SettingMap("if_empty", _word_text, _word_read),
    }
    return LogicModel(
        NodeKind.LOOP,
        f"Loop{of.capitalize()}",
        "Decorator",
        settings=settings,
        implied={"type": of},
    )


def _switch_settings() -> dict[str, SettingMap]:
    cases = {f"case_{n}": _text(f"case_{n}") for n in range(1, 7)}
    return {"variable": _text("variable"), **cases}


LOGIC: dict[NodeKind, LogicModel] = {
    m.kind: m
    for m in (
        LogicModel(NodeKind.SEQUENCE, "Sequence", "Control"),
        LogicModel(NodeKind.SELECTOR, "Fallback", "Control"),
        LogicModel(
            NodeKind.PARALLEL,
            "Parallel",
            "Control",
            settings={
                "success": SettingMap("success_count", *_SUCCESS),
                "failure": SettingMap("failure_count", *_FAILURE),
            },
        ),
        LogicModel(NodeKind.REACTIVE_SEQUENCE, "ReactiveSequence", "Control"),
        LogicModel(NodeKind.REACTIVE_SELECTOR, "ReactiveFallback", "Control"),
        LogicModel(
            NodeKind.CATCH,
            "Catch",
            "Control",
            builtin=False,
            settings={
                "errors": SettingMap("errors", _word_text, _word_read),
                "error": SettingMap("error", _word_text, _word_read),
            },
        ),
        LogicModel(
            NodeKind.ITERATOR,
            "Iterator",
            "Decorator",
            builtin=False,
            settings={"count": SettingMap("count"), "timeout": SettingMap("timeout")},
        ),
        LogicModel(
            NodeKind.ENFORCE,
            "Enforce",
            "Decorator",
            builtin=False,
            settings={"count": SettingMap("count"), "timeout": SettingMap("timeout")},
        ),
        LogicModel(NodeKind.INVERTER, "Inverter", "Decorator"),
        LogicModel(
            NodeKind.REPEAT, "Repeat", "Decorator", settings={"count": SettingMap("num_cycles")}
        ),
        LogicModel(
            NodeKind.RETRY,
            "RetryUntilSuccessful",
            "Decorator",
            settings={"count": SettingMap("num_attempts")},
        ),
        LogicModel(NodeKind.TIMEOUT, "Timeout", "Decorator", settings={"seconds": _MSEC}),
        LogicModel(NodeKind.FORCE_SUCCESS, "ForceSuccess", "Decorator"),
        LogicModel(NodeKind.FORCE_FAILURE, "ForceFailure", "Decorator"),
        LogicModel(NodeKind.WAIT, "Sleep", "Action", settings={"seconds": _MSEC}),
        LogicModel(NodeKind.SCRIPT, "Script", "Action", settings={"code": _CODE}),
        LogicModel(
            NodeKind.SCRIPT_CONDITION, "ScriptCondition", "Condition", settings={"code": _CODE}
        ),
        LogicModel(NodeKind.SEQUENCE_WITH_MEMORY, "SequenceWithMemory", "Control"),
        LogicModel(NodeKind.ASYNC_SEQUENCE, "AsyncSequence", "Control"),
        LogicModel(NodeKind.ASYNC_FALLBACK, "AsyncFallback", "Control"),
        LogicModel(
            NodeKind.PARALLEL_ALL,
            "ParallelAll",
            "Control",
            settings={"max_failures": SettingMap("max_failures")},
        ),
        LogicModel(NodeKind.IF_THEN_ELSE, "IfThenElse", "Control"),
        LogicModel(NodeKind.WHILE_DO_ELSE, "WhileDoElse", "Control"),
        # Written Switch2 .. Switch6 by its number of children (switch_model).
        LogicModel(NodeKind.SWITCH, "Switch", "Control", settings=_switch_settings()),
        LogicModel(
            NodeKind.TRY_CATCH,
            "TryCatch",
            "Control",
            settings={"catch_on_halt": SettingMap("catch_on_halt", *_BOOL)},
        ),
        LogicModel(NodeKind.KEEP_RUNNING_UNTIL_FAILURE, "KeepRunningUntilFailure", "Decorator"),
        LogicModel(
            NodeKind.DELAY,
            "Delay",
            "Decorator",
            settings={"seconds": SettingMap("delay_msec", _msec_text, _msec_read)},
        ),
        LogicModel(
            NodeKind.RUN_ONCE,
            "RunOnce",
            "Decorator",
            settings={"then_skip": SettingMap("then_skip", *_BOOL)},
        ),
        LogicModel(
            NodeKind.PRECONDITION,
            "Precondition",
            "Decorator",
            settings={"if": _CODE_IF, "else": SettingMap("else", _word_text, _word_read)},
        ),
        _loop("string"),
        LogicModel(NodeKind.ALWAYS_SUCCESS, "AlwaysSuccess", "Action"),
        LogicModel(NodeKind.ALWAYS_FAILURE, "AlwaysFailure", "Action"),
        LogicModel(
            NodeKind.SET_BLACKBOARD,
            "SetBlackboard",
            "Action",
            settings={"value": _text("value"), "output_key": _text("output_key")},
        ),
        LogicModel(
            NodeKind.UNSET_BLACKBOARD, "UnsetBlackboard", "Action", settings={"key": _text("key")}
        ),
        LogicModel(
            NodeKind.SKIP_UNLESS_UPDATED,
            "SkipUnlessUpdated",
            "Decorator",
            settings={"entry": _text("entry")},
        ),
        LogicModel(
            NodeKind.WAIT_VALUE_UPDATE,
            "WaitValueUpdate",
            "Decorator",
            settings={"entry": _text("entry")},
        ),
        LogicModel(
            NodeKind.WAS_ENTRY_UPDATED,
            "WasEntryUpdated",
            "Action",
            settings={"entry": _text("entry")},
        ),
    )
}
SWITCH_MODELS = tuple(f"Switch{n}" for n in range(2, 7))
_LOOPS = {m.model: m for m in map(_loop, ("int", "double", "bool", "string"))}
LOGIC_BY_MODEL: dict[str, LogicModel] = {
    **{m.model: m for m in LOGIC.values() if m.kind not in (NodeKind.SWITCH, NodeKind.LOOP)},
    **{model: LOGIC[NodeKind.SWITCH] for model in SWITCH_MODELS},
    **_LOOPS,
}


def model_of(node: NodeSpec) -> str:
    """BehaviorTree.CPP's id of a node: its kind's, a Switch's by its number of cases (its
    children less the default), a Loop's by its type (LoopInt ...).
    """
    if node.kind is NodeKind.SWITCH:
        return f"Switch{len(node.children) - 1}"
    if node.kind is NodeKind.LOOP:
        binding = node.params.get("type")
        of = binding.value if binding is not None and isinstance(binding.value, str) else ""
        return _loop(of if of in _LOOP_TYPES else "string").model
    return LOGIC[node.kind].model


# Every built-in id of BehaviorTree.CPP 4.10 (an operation's model id must not be one).
BUILTIN_MODELS: frozenset[str] = frozenset(
    {
        "AlwaysFailure",
        "AlwaysSuccess",
        "AsyncFallback",
        "AsyncSequence",
        "Delay",
        "EntryUpdated",
        "Fallback",
        "ForceFailure",
        "ForceSuccess",
        "IfThenElse",
        "Inverter",
        "KeepRunningUntilFailure",
        "LoopBool",
        "LoopDouble",
        "LoopInt",
        "LoopString",
        "Parallel",
        "ParallelAll",
        "Precondition",
        "ReactiveFallback",
        "ReactiveSequence",
        "Repeat",
        "RetryUntilSuccessful",
        "RunOnce",
        "Script",
        "ScriptCondition",
        "Sequence",
        "SequenceWithMemory",
        "SetBlackboard",
        "SkipUnlessUpdated",
        "Sleep",
        "SubTree",
        "Switch2",
        "Switch3",
        "Switch4",
        "Switch5",
        "Switch6",
        "Timeout",
        "TryCatch",
        "UnsetBlackboard",
        "WaitValueUpdate",
        "WasEntryUpdated",
        "WhileDoElse",
        "Iterator",
        "Enforce",
    }
)
