"""The example plans of BehaviorTree.CPP's built-in nodes (resources/examples/nodes),
written with :mod:`tools.generators.make_examples`.
"""

from __future__ import annotations

from collections.abc import Callable

from engine.conditions import Condition
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType
from tools.generators.plan_builder import fixed

N = NodeKind
One = Callable[[str, str, str, Callable[..., NodeSpec]], PlanSpec]


def _skip_if(node: NodeSpec, script: str) -> NodeSpec:
    """``node`` skipped when ``script`` is true (BehaviorTree.CPP's ``_skipIf``)."""
    node.conditions = {Condition.SKIP_IF: script}
    return node


def builtin_examples(one: One) -> dict[str, PlanSpec]:
    """The examples, each made by ``one(file name, title, description, build)``."""
    return {
        "branches": one(
            "branches",
            "IfThenElse, WhileDoElse, Switch, SetBlackboard",
            "BehaviorTree.CPP's branching nodes: SetBlackboard names the bin, a Switch2 takes "
            "the case of that bin, a WhileDoElse places the part while the bin is still the "
            "left one, an IfThenElse checks the count, and UnsetBlackboard forgets the bin. "
            "Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "sort a part",
                m.node(N.SET_BLACKBOARD, "left bin", value="left", output_key="BIN"),
                m.node(
                    N.SWITCH,
                    "which bin",
                    m.debug("succeed", "to the left bin"),
                    m.debug("succeed", "to the right bin"),
                    m.debug("fail", "no bin"),
                    variable="{BIN}",
                    case_1="left",
                    case_2="right",
                ),
                m.node(N.SCRIPT, "count", code="PARTS := 1"),
                m.node(
                    N.WHILE_DO_ELSE,
                    "while left",
                    m.node(N.SCRIPT_CONDITION, "still left", code="BIN == 'left'"),
                    m.running("place", 2),
                    m.debug("fail", "stop"),
                ),
                m.node(
                    N.IF_THEN_ELSE,
                    "one part?",
                    m.node(N.SCRIPT_CONDITION, "one part", code="PARTS == 1"),
                    m.node(N.ALWAYS_SUCCESS, "done"),
                    m.node(N.ALWAYS_FAILURE, "recount"),
                ),
                m.node(N.UNSET_BLACKBOARD, "forget the bin", key="BIN"),
            ),
        ),
        "sequence_variants": one(
            "sequence_variants",
            "SequenceWithMemory, AsyncSequence, AsyncFallback, ParallelAll",
            "BehaviorTree.CPP's other sequences: an AsyncSequence and an AsyncFallback give a "
            "tick back after each child that finished at once, a ParallelAll waits for all of "
            "its children and tolerates one failure, and a SequenceWithMemory would resume "
            "where it failed. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE_WITH_MEMORY,
                "cycle",
                m.node(
                    N.ASYNC_SEQUENCE,
                    "prepare",
                    m.debug("succeed", "open gripper"),
                    m.debug("succeed", "home"),
                ),
                m.node(
                    N.ASYNC_FALLBACK,
                    "find a part",
                    m.debug("fail", "in the tray"),
                    m.debug("succeed", "in the bin"),
                ),
                m.node(
                    N.PARALLEL_ALL,
                    "scan and move",
                    m.debug("fail", "optional scan"),
                    m.running("move", 2),
                    max_failures=2,
                ),
            ),
        ),
        "try_catch": one(
            "try_catch",
            "TryCatch",
            "BehaviorTree.CPP's TryCatch: the lift fails, so the catch releases the part, and "
            "the TryCatch fails. Runs to FAILURE.",
            lambda m: m.node(
                N.TRY_CATCH,
                "lift safely",
                m.running("grip", 1),
                m.debug("fail", "lift"),
                m.debug("log", "release the part", message=fixed("released", ParamType.TEXT)),
                catch_on_halt="true",
            ),
        ),
        "entry_updates": one(
            "entry_updates",
            "SkipUnlessUpdated, WaitValueUpdate, WasEntryUpdated",
            "BehaviorTree.CPP's nodes that look whether a named parameter was written since "
            "they last looked: three rounds count on, a SkipUnlessUpdated sees the count in "
            "the two rounds that wrote it (the second does not), a WaitValueUpdate runs its "
            "check at once (the count was written before it first looked), and "
            "WasEntryUpdated succeeds on its first look. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "watch the count",
                m.node(N.SCRIPT, "none yet", code="COUNT := 0; SEEN := 0; ROUND := 0"),
                m.node(
                    N.REPEAT,
                    "three rounds",
                    m.node(
                        N.SEQUENCE,
                        "one round",
                        m.node(N.SCRIPT, "next round", code="ROUND += 1"),
                        _skip_if(m.node(N.SCRIPT, "count", code="COUNT += 1"), "ROUND == 2"),
                        m.node(
                            N.SKIP_UNLESS_UPDATED,
                            "when counted",
                            m.node(N.SCRIPT, "see it", code="SEEN += 1"),
                            entry="COUNT",
                        ),
                    ),
                    count=3,
                ),
                m.node(
                    N.WAIT_VALUE_UPDATE,
                    "a count",
                    m.node(N.SCRIPT_CONDITION, "seen twice", code="SEEN == 2"),
                    entry="{COUNT}",
                ),
                m.node(N.WAS_ENTRY_UPDATED, "counted?", entry="COUNT"),
            ),
        ),
        "btcpp_decorators": one(
            "btcpp_decorators",
            "Delay, RunOnce, Precondition, KeepRunningUntilFailure, LoopInt",
            "BehaviorTree.CPP's decorators: a Delay of 0.1 s, a RunOnce that counts one try, a "
            "Precondition on that count, a KeepRunningUntilFailure that counts on until "
            "the count reaches 3 (inverted: its failure is the success), and a LoopInt that "
            "adds up the sizes 1, 2 and 3. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "tries",
                m.node(N.SCRIPT, "none yet", code="TRIES := 0; SUM := 0"),
                m.node(N.DELAY, "settle", m.debug("succeed", "start"), seconds=0.1),
                m.node(N.RUN_ONCE, "once", m.node(N.SCRIPT, "one try", code="TRIES += 1")),
                m.node(
                    N.PRECONDITION,
                    "after one try",
                    m.debug("succeed", "go"),
                    **{"if": "TRIES == 1"},
                ),
                m.node(
                    N.INVERTER,
                    "until 3",
                    m.node(
                        N.KEEP_RUNNING_UNTIL_FAILURE,
                        "count on",
                        m.node(
                            N.SEQUENCE,
                            "one more",
                            m.node(N.SCRIPT, "add", code="TRIES += 1"),
                            m.node(N.SCRIPT_CONDITION, "below 3", code="TRIES < 3"),
                        ),
                    ),
                ),
                m.node(
                    N.LOOP,
                    "each size",
                    m.node(N.SCRIPT, "add it", code="SUM += SIZE"),
                    queue="1;2;3",
                    value="{SIZE}",
                    type="int",
                ),
                m.node(N.SCRIPT_CONDITION, "all added", code="SUM == 6"),
            ),
        ),
    }
