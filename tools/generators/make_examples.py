"""Write the example plans of resources/examples from code (reproducible byte for byte).

Each plan's description ends with "Runs to SUCCESS." or "Runs to FAILURE.": the tests run
every example and check that sentence. Usage: python -m tools.generators.make_examples
"""

from __future__ import annotations

from collections.abc import Callable

from engine.conditions import Condition
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, ParameterDecl, PlanSpec, RunPolicy
from engine.types import ParamType, Pose
from tools.generators import RESOURCES
from tools.generators.plan_builder import (
    EXAMPLES,
    PlanBuilder,
    fixed,
    port,
    stable_id,
    subtree,
)

HERE = RESOURCES / "examples"  # where the plans are written
N = NodeKind


class _Debug(PlanBuilder):
    """The examples' nodes (ids in their own namespace), built from debug operations."""

    def __init__(self, example: str) -> None:
        super().__init__(EXAMPLES, example)

    def debug(self, op: str, name: str, /, **params: Binding) -> NodeSpec:
        """The debug operation ``debug.<op>``."""
        return self.op(f"debug.{op}", name, **params)

    def running(self, name: str, ticks: int, then: str = "SUCCESS") -> NodeSpec:
        return self.debug(
            "running",
            name,
            ticks=fixed(ticks, ParamType.NUMBER),
            then=fixed(then, ParamType.TEXT),
        )

    def set_flag(self, name: str, key: str, value: bool) -> NodeSpec:
        return self.debug(
            "set_param", name, value=fixed(value, ParamType.BOOL), name=Binding.reference(key)
        )

    def flag_is(self, name: str, key: str, value: bool) -> NodeSpec:
        return self.debug(
            "check_param",
            name,
            value=Binding.reference(key),
            expected=fixed(value, ParamType.BOOL),
        )


def figure3() -> PlanSpec:
    """The paper's Figure 3: find a cup, take it to the bin, fall back to waiting."""
    m = _Debug("figure3")
    cup = Pose((0.55, -0.10, 0.05), (1.0, 0.0, 0.0, 0.0))
    tree = m.node(
        NodeKind.SEQUENCE,
        "cup to bin",
        m.node(
            NodeKind.PARALLEL,
            "detect objects",
            m.running("detect CUP", 2),
            m.running("detect BIN", 3),
        ),
        m.node(
            NodeKind.SELECTOR,
            "transfer or wait",
            m.node(
                NodeKind.SEQUENCE,
                "transfer",
                m.debug("succeed_after", "CUP found", failures=fixed(2, ParamType.NUMBER)),
                m.debug(
                    "query",
                    "pose of CUP",
                    value=fixed(cup, ParamType.POSE),
                    result=Binding.reference("CUP_POSE"),
                ),
                m.debug(
                    "query",
                    "pose of BIN",
                    value=fixed(Pose((0.40, 0.35, 0.30), (1.0, 0, 0, 0)), ParamType.POSE),
                    result=Binding.reference("BIN_POSE"),
                ),
                m.debug("pretend_move", "move to CUP_POSE", target=Binding.reference("CUP_POSE")),
                m.debug("log", "grasp", message=fixed("closing the gripper", ParamType.TEXT)),
                m.debug("pretend_move", "move to BIN_POSE", target=Binding.reference("BIN_POSE")),
                m.debug("log", "release", message=fixed("opening the gripper", ParamType.TEXT)),
            ),
            m.node(
                NodeKind.FORCE_FAILURE, "then try again", m.node(NodeKind.WAIT, "WAIT", seconds=0.2)
            ),
        ),
    )
    return PlanSpec(
        tree,
        "Figure 3: cup to bin (debug operations)",
        "The paper's Figure 3 built from debug operations. The cup is not found on the first two "
        "runs: the selector falls back to WAIT (forced to fail so that the root, which runs until "
        "success, starts again); on the third run the cup is found, its pose and the bin's are "
        "queried into CUP_POSE and BIN_POSE, and the transfer completes. Runs to SUCCESS.",
        RunPolicy.UNTIL_SUCCESS,
        id="f1a9e3c4b2d84e6f9a0b1c2d3e4f5a6b",
    )


def _one(
    example: str,
    title: str,
    text: str,
    build: Callable[[_Debug], NodeSpec],
    parameters: list[ParameterDecl] | None = None,
) -> PlanSpec:
    m = _Debug(example)
    return PlanSpec(
        build(m),
        title,
        text,
        RunPolicy.ONCE,
        parameters=parameters or [],
        id=stable_id(EXAMPLES, example),
    )


def _subtree_example() -> PlanSpec:
    """Two instances of one subtree, each with its own target, each keeping its own GOAL."""
    inner = _Debug("subtree/inside")
    go_to = subtree(
        "examples.go_to",
        "Go to",
        "Finds where to go (a private GOAL) and goes there.",
        inner.node(
            NodeKind.SEQUENCE,
            "Go to",
            inner.debug(
                "query", "find", value=Binding.reference("TARGET"), result=Binding.reference("GOAL")
            ),
            inner.debug("pretend_move", "go", target=Binding.reference("GOAL")),
            inner.debug(
                "set_param",
                "report",
                value=Binding.reference("GOAL"),
                name=Binding.reference("REACHED"),
            ),
        ),
        inputs=[port("TARGET", ParamType.POSE, "where to go")],
        outputs=[port("REACHED", ParamType.ANY, "where it went")],
    )
    m = _Debug("subtree")

    def visit(name: str, x: float, out: str) -> NodeSpec:
        return m.instance(
            go_to,
            name,
            TARGET=fixed(Pose((x, 0.1, 0.2)), ParamType.POSE),
            REACHED=Binding.reference(out),
        )

    tree = m.node(
        NodeKind.SEQUENCE, "two visits", visit("left", 0.3, "LEFT"), visit("right", 0.5, "RIGHT")
    )
    return PlanSpec(
        tree,
        "Subtree instances",
        "One subtree used twice with different targets: each instance keeps its own GOAL and "
        "passes out where it went. Runs to SUCCESS.",
        RunPolicy.ONCE,
        id=stable_id(EXAMPLES, "subtree"),
        subtrees=[go_to],
    )


def _composites() -> dict[str, PlanSpec]:
    """Sequence, Selector and the three Parallel policies."""
    return {
        "sequence": _one(
            "sequence",
            "Sequence",
            "Three steps in order, the second takes 3 ticks. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "steps",
                m.debug("succeed", "one"),
                m.running("two", 3),
                m.debug("succeed", "three"),
            ),
        ),
        "selector": _one(
            "selector",
            "Selector",
            "The first option fails, the second succeeds. Runs to SUCCESS.",
            lambda m: m.node(
                N.SELECTOR,
                "options",
                m.debug("fail", "first"),
                m.debug("succeed", "second"),
                m.debug("fail", "never tried"),
            ),
        ),
        "parallel": _one(
            "parallel",
            "Parallel (all)",
            "Two children run together; both succeed. Runs to SUCCESS.",
            lambda m: m.node(
                N.PARALLEL, "together", m.running("detect CUP", 2), m.running("detect BIN", 4)
            ),
        ),
        "parallel_any": _one(
            "parallel_any",
            "Parallel (any)",
            "Succeeds as soon as one child succeeds, halting the other. Runs to SUCCESS.",
            lambda m: m.node(
                N.PARALLEL, "first wins", m.running("fast", 1), m.running("slow", 50), success="any"
            ),
        ),
        "parallel_m_of_n": _one(
            "parallel_m_of_n",
            "Parallel (2 of 3, fail on 2)",
            "Two of three must succeed; two fail, so it fails. Runs to FAILURE.",
            lambda m: m.node(
                N.PARALLEL,
                "vote",
                m.running("a", 1),
                m.running("b", 2, "FAILURE"),
                m.running("c", 3, "FAILURE"),
                success=2,
                failure=2,
            ),
        ),
    }


def _reactive() -> dict[str, PlanSpec]:
    """The reactive Sequence and Selector, each halting a child when a flag changes."""
    flag = [ParameterDecl("PERSON_AWAY", ParamType.BOOL, True, "no one near the robot")]
    done = [ParameterDecl("PART_READY", ParamType.BOOL, False, "the machine dropped a part")]
    return {
        "reactive_sequence": _one(
            "reactive_sequence",
            "Reactive sequence",
            "A long motion runs while PERSON_AWAY holds; a person arrives after 5 ticks, the condition "
            "turns false, the motion is halted and the plan stops. Runs to FAILURE.",
            lambda m: m.node(
                N.PARALLEL,
                "robot and person",
                m.node(
                    N.REACTIVE_SEQUENCE,
                    "guarded motion",
                    m.flag_is("person away", "PERSON_AWAY", True),
                    m.running("long motion", 100),
                ),
                m.node(
                    N.SEQUENCE,
                    "a person arrives",
                    m.running("walking", 5),
                    m.set_flag("arrives", "PERSON_AWAY", False),
                ),
            ),
            flag,
        ),
        "reactive_selector": _one(
            "reactive_selector",
            "Reactive selector",
            "A slow fallback runs until PART_READY turns true after 5 ticks; the higher-priority branch "
            "takes over and the fallback is halted. Runs to SUCCESS.",
            lambda m: m.node(
                N.PARALLEL,
                "watch and wait",
                m.node(
                    N.REACTIVE_SELECTOR,
                    "part or wait",
                    m.flag_is("part ready", "PART_READY", True),
                    m.running("idle motion", 100),
                ),
                m.node(
                    N.SEQUENCE,
                    "the machine",
                    m.running("bending", 5),
                    m.set_flag("drops a part", "PART_READY", True),
                ),
                success="any",
            ),
            done,
        ),
    }


def _loops() -> dict[str, PlanSpec]:
    """The decorators that run their child again: Iterator, Enforce, Repeat, Retry."""
    return {
        "iterator": _one(
            "iterator",
            "Iterator",
            "Repeats its child while it succeeds, 3 times. Runs to SUCCESS.",
            lambda m: m.node(N.ITERATOR, "three rounds", m.running("pick", 1), count=3),
        ),
        "enforce": _one(
            "enforce",
            "Enforce",
            "Retries a check until it holds (false twice, then true). Runs to SUCCESS.",
            lambda m: m.node(
                N.ENFORCE,
                "until found",
                m.debug("succeed_after", "found", failures=fixed(2, ParamType.NUMBER)),
                count=5,
            ),
        ),
        "repeat": _one(
            "repeat",
            "Repeat",
            "Runs its child 4 times. Runs to SUCCESS.",
            lambda m: m.node(N.REPEAT, "four times", m.debug("succeed", "pick"), count=4),
        ),
        "retry": _one(
            "retry",
            "Retry",
            "Tries a failing action 3 times, then gives up. Runs to FAILURE.",
            lambda m: m.node(
                N.RETRY,
                "three attempts",
                m.debug(
                    "fail", "grasp", message=fixed("nothing between the fingers", ParamType.TEXT)
                ),
                count=3,
            ),
        ),
    }


def _decorators() -> dict[str, PlanSpec]:
    """The decorators that change or bound one run of their child."""
    return {
        "inverter": _one(
            "inverter",
            "Inverter",
            "A failing check, inverted. Runs to SUCCESS.",
            lambda m: m.node(
                N.INVERTER,
                "not",
                m.debug("condition", "is busy", result=fixed(False, ParamType.BOOL)),
            ),
        ),
        "timeout": _one(
            "timeout",
            "Timeout",
            "A motion that needs 100 ticks gets 0.3 s. Runs to FAILURE.",
            lambda m: m.node(N.TIMEOUT, "0.3 s", m.running("slow motion", 100), seconds=0.3),
        ),
        "catch": _one(
            "catch",
            "Catch",
            "A grasp fails with grasp_failed; the Catch keeps the error in CAUGHT and runs its "
            "handler, which logs it. Runs to SUCCESS.",
            lambda m: m.node(
                N.CATCH,
                "on a failed grasp",
                m.debug(
                    "fail",
                    "grasp",
                    message=fixed("nothing between the fingers", ParamType.TEXT),
                    error=fixed("grasp_failed", ParamType.TEXT),
                ),
                m.debug("log", "report it", message=Binding.reference("CAUGHT")),
                errors="grasp_failed, object_lost",
                error="CAUGHT",
            ),
        ),
        "force_success": _one(
            "force_success",
            "Force success",
            "A failing action made to succeed. Runs to SUCCESS.",
            lambda m: m.node(N.FORCE_SUCCESS, "ignore errors", m.debug("fail", "optional step")),
        ),
        "force_failure": _one(
            "force_failure",
            "Force failure",
            "A succeeding action made to fail. Runs to FAILURE.",
            lambda m: m.node(N.FORCE_FAILURE, "then fail", m.debug("succeed", "step")),
        ),
    }


def _given(node: NodeSpec, **scripts: str) -> NodeSpec:
    """``node`` with pre- and post-conditions (``while_`` for while)."""
    node.conditions = {Condition(key.rstrip("_")): text for key, text in scripts.items()}
    return node


def _conditions_example() -> PlanSpec:
    """Pre- and post-conditions on nodes (BehaviorTree.CPP's _skipIf ...)."""
    return _one(
        "conditions",
        "Pre- and post-conditions",
        "Conditions on nodes (BehaviorTree.CPP's _skipIf, _while, _onSuccess, _successIf): the "
        "alarm is skipped while the door is closed, the part is placed while it stays closed "
        "and counted when placed, and the inspection is not needed once one part is in. "
        "Runs to SUCCESS.",
        lambda m: m.node(
            N.SEQUENCE,
            "place a part",
            m.node(N.SCRIPT, "start", code="PARTS := 0; DOOR := 'closed'"),
            _given(m.debug("fail", "alarm"), skip_if="DOOR == 'closed'"),
            _given(
                m.running("place part", 2),
                while_="DOOR == 'closed'",
                on_success="PARTS += 1",
                on_halted="PARTS := -1",
            ),
            _given(m.debug("fail", "inspect"), success_if="PARTS == 1"),
            m.node(N.SCRIPT_CONDITION, "one part in", code="PARTS == 1"),
        ),
    )


def _leaves() -> dict[str, PlanSpec]:
    """Wait, an action, a query, a condition and the script leaves."""
    return {
        "script": _one(
            "script",
            "Script and ScriptCondition",
            "Scripts (BehaviorTree.CPP's language) count three parts into PARTS, check the "
            "count and write a REPORT that an action logs. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "count parts",
                m.node(N.SCRIPT, "start", code="PARTS := 0; BIN := 'left'"),
                m.node(
                    N.REPEAT,
                    "three parts",
                    m.node(N.SCRIPT, "one more", code="PARTS += 1"),
                    count=3,
                ),
                m.node(N.SCRIPT_CONDITION, "all counted", code="PARTS == 3 && BIN == 'left'"),
                m.node(N.SCRIPT, "report", code="REPORT := 'counted ' .. PARTS .. ' parts'"),
                m.debug("log", "log it", message=Binding.reference("REPORT")),
            ),
        ),
        "wait": _one(
            "wait",
            "Wait",
            "Waits 0.2 s. Runs to SUCCESS.",
            lambda m: m.node(N.WAIT, "pause", seconds=0.2),
        ),
        "action": _one(
            "action",
            "Action",
            "An action that runs for 3 ticks. Runs to SUCCESS.",
            lambda m: m.running("move", 3),
        ),
        "query": _one(
            "query",
            "Query then use",
            "A query writes GOAL; an action reads it. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "find and go",
                m.debug(
                    "query",
                    "find goal",
                    value=fixed(Pose((0.4, 0.1, 0.2)), ParamType.POSE),
                    result=Binding.reference("GOAL"),
                ),
                m.debug("pretend_move", "go", target=Binding.reference("GOAL")),
            ),
        ),
        "condition": _one(
            "condition",
            "Condition",
            "A predicate that is false. Runs to FAILURE.",
            lambda m: m.debug("condition", "door closed", result=fixed(False, ParamType.BOOL)),
        ),
    }


def node_examples() -> dict[str, PlanSpec]:
    """One plan per node kind (a subtree instance included), by file name."""
    from tools.generators.builtin_examples import builtin_examples  # it builds with _one

    return {
        **_composites(),
        **_reactive(),
        **_loops(),
        **_decorators(),
        **_leaves(),
        "subtree": _subtree_example(),
        "conditions": _conditions_example(),
        **builtin_examples(_one),
    }


def main() -> None:
    """Write Figure 3's debug plan and the example plan of each node kind."""
    save_plan(figure3(), HERE / "figure3_debug.costar.json")
    for name, plan in node_examples().items():
        save_plan(plan, HERE / "nodes" / f"{name}.costar.json")
    print(f"wrote {1 + len(node_examples())} example plans")


if __name__ == "__main__":
    main()
