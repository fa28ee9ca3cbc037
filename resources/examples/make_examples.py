"""Write the example plans of resources/examples from code (reproducible byte for byte).

Each plan's description ends with "Runs to SUCCESS." or "Runs to FAILURE.": the tests run
every example and check that sentence. Usage: python resources/examples/make_examples.py
"""

from __future__ import annotations

import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from engine.files import save_plan
from engine.kinds import setting
from engine.spec import (
    Binding,
    NodeKind,
    NodeSpec,
    ParameterDecl,
    PlanSpec,
    RunPolicy,
    SubtreePort,
    SubtreeSpec,
)
from engine.types import ParamType, Pose

HERE = Path(__file__).resolve().parent
_NAMESPACE = uuid.UUID("6f1c3d0e-8f61-4d0e-9a57-2b8f3c0d7e11")


class _Ids:
    """Stable ids: the same example always gets the same node ids."""

    def __init__(self, example: str) -> None:
        self.example = example
        self.count = 0

    def __call__(self) -> str:
        self.count += 1
        return uuid.uuid5(_NAMESPACE, f"{self.example}/{self.count}").hex


def _fixed(value: Any, ptype: ParamType) -> Binding:
    return Binding.fixed(value, ptype)


class _Maker:
    def __init__(self, example: str) -> None:
        self.ids = _Ids(example)

    def node(self, kind: NodeKind, name: str = "", *children: NodeSpec, **config: Any) -> NodeSpec:
        return NodeSpec(
            kind,
            name,
            self.ids(),
            params={k: setting(kind, k, v) for k, v in config.items()},
            children=list(children),
        )

    def op(self, op: str, label: str = "", **params: Binding) -> NodeSpec:
        return NodeSpec(NodeKind.OPERATION, label, self.ids(), op=f"debug.{op}", params=params)

    def running(self, name: str, ticks: int, then: str = "SUCCESS") -> NodeSpec:
        return self.op(
            "running",
            name,
            ticks=_fixed(ticks, ParamType.NUMBER),
            then=_fixed(then, ParamType.TEXT),
        )

    def set_flag(self, name: str, key: str, value: bool) -> NodeSpec:
        return self.op(
            "set_param", name, value=_fixed(value, ParamType.BOOL), name=Binding.reference(key)
        )

    def flag_is(self, name: str, key: str, value: bool) -> NodeSpec:
        return self.op(
            "check_param",
            name,
            value=Binding.reference(key),
            expected=_fixed(value, ParamType.BOOL),
        )


def figure3() -> PlanSpec:
    """The paper's Figure 3: find a cup, take it to the bin, fall back to waiting."""
    m = _Maker("figure3")
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
                m.op("succeed_after", "CUP found", failures=_fixed(2, ParamType.NUMBER)),
                m.op(
                    "query",
                    "pose of CUP",
                    value=_fixed(cup, ParamType.POSE),
                    result=Binding.reference("CUP_POSE"),
                ),
                m.op(
                    "query",
                    "pose of BIN",
                    value=_fixed(Pose((0.40, 0.35, 0.30), (1.0, 0, 0, 0)), ParamType.POSE),
                    result=Binding.reference("BIN_POSE"),
                ),
                m.op("pretend_move", "move to CUP_POSE", target=Binding.reference("CUP_POSE")),
                m.op("log", "grasp", message=_fixed("closing the gripper", ParamType.TEXT)),
                m.op("pretend_move", "move to BIN_POSE", target=Binding.reference("BIN_POSE")),
                m.op("log", "release", message=_fixed("opening the gripper", ParamType.TEXT)),
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
    build: Callable[[_Maker], NodeSpec],
    parameters: list[ParameterDecl] | None = None,
) -> PlanSpec:
    m = _Maker(example)
    return PlanSpec(
        build(m),
        title,
        text,
        RunPolicy.ONCE,
        parameters=parameters or [],
        id=uuid.uuid5(_NAMESPACE, example).hex,
    )


def _subtree_example() -> PlanSpec:
    """Two instances of one subtree, each with its own target, each keeping its own GOAL."""
    inner = _Maker("subtree/inside")
    go_to = SubtreeSpec(
        "examples.go_to", "Go to",
        inner.node(
            NodeKind.SEQUENCE, "Go to",
            inner.op("query", "find", value=Binding.reference("TARGET"), result=Binding.reference("GOAL")),
            inner.op("pretend_move", "go", target=Binding.reference("GOAL")),
            inner.op("set_param", "report", value=Binding.reference("GOAL"), name=Binding.reference("REACHED")),
        ),
        version=1, date="2026-11-24T00:00:00Z",
        description="Finds where to go (a private GOAL) and goes there.",
        inputs=[SubtreePort("TARGET", ParamType.POSE, "where to go")],
        outputs=[SubtreePort("REACHED", ParamType.ANY, "where it went")],
    )  # fmt: skip
    m = _Maker("subtree")

    def visit(name: str, x: float, out: str) -> NodeSpec:
        params = {"TARGET": _fixed(Pose((x, 0.1, 0.2)), ParamType.POSE),
                  "REACHED": Binding.reference(out)}  # fmt: skip
        return NodeSpec(NodeKind.SUBTREE, name, m.ids(), params=params, subtree=go_to.ref)

    tree = m.node(
        NodeKind.SEQUENCE, "two visits", visit("left", 0.3, "LEFT"), visit("right", 0.5, "RIGHT")
    )
    return PlanSpec(
        tree, "Subtree instances",
        "One subtree used twice with different targets: each instance keeps its own GOAL and "
        "passes out where it went. Runs to SUCCESS.",
        RunPolicy.ONCE, id=uuid.uuid5(_NAMESPACE, "subtree").hex, subtrees=[go_to],
    )  # fmt: skip


def node_examples() -> dict[str, PlanSpec]:
    """One plan per node kind."""
    N = NodeKind
    flag = [ParameterDecl("PERSON_AWAY", ParamType.BOOL, True, "no one near the robot")]
    done = [ParameterDecl("PART_READY", ParamType.BOOL, False, "the machine dropped a part")]
    return {
        "sequence": _one(
            "sequence",
            "Sequence",
            "Three steps in order, the second takes 3 ticks. Runs to SUCCESS.",
            lambda m: m.node(
                N.SEQUENCE,
                "steps",
                m.op("succeed", "one"),
                m.running("two", 3),
                m.op("succeed", "three"),
            ),
        ),
        "selector": _one(
            "selector",
            "Selector",
            "The first option fails, the second succeeds. Runs to SUCCESS.",
            lambda m: m.node(
                N.SELECTOR,
                "options",
                m.op("fail", "first"),
                m.op("succeed", "second"),
                m.op("fail", "never tried"),
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
                m.op("succeed_after", "found", failures=_fixed(2, ParamType.NUMBER)),
                count=5,
            ),
        ),
        "inverter": _one(
            "inverter",
            "Inverter",
            "A failing check, inverted. Runs to SUCCESS.",
            lambda m: m.node(
                N.INVERTER,
                "not",
                m.op("condition", "is busy", result=_fixed(False, ParamType.BOOL)),
            ),
        ),
        "repeat": _one(
            "repeat",
            "Repeat",
            "Runs its child 4 times. Runs to SUCCESS.",
            lambda m: m.node(N.REPEAT, "four times", m.op("succeed", "pick"), count=4),
        ),
        "retry": _one(
            "retry",
            "Retry",
            "Tries a failing action 3 times, then gives up. Runs to FAILURE.",
            lambda m: m.node(
                N.RETRY,
                "three attempts",
                m.op(
                    "fail", "grasp", message=_fixed("nothing between the fingers", ParamType.TEXT)
                ),
                count=3,
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
                m.op(
                    "fail",
                    "grasp",
                    message=_fixed("nothing between the fingers", ParamType.TEXT),
                    error=_fixed("grasp_failed", ParamType.TEXT),
                ),
                m.op("log", "report it", message=Binding.reference("CAUGHT")),
                errors="grasp_failed, object_lost",
                error="CAUGHT",
            ),
        ),
        "force_success": _one(
            "force_success",
            "Force success",
            "A failing action made to succeed. Runs to SUCCESS.",
            lambda m: m.node(N.FORCE_SUCCESS, "ignore errors", m.op("fail", "optional step")),
        ),
        "force_failure": _one(
            "force_failure",
            "Force failure",
            "A succeeding action made to fail. Runs to FAILURE.",
            lambda m: m.node(N.FORCE_FAILURE, "then fail", m.op("succeed", "step")),
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
                m.op(
                    "query",
                    "find goal",
                    value=_fixed(Pose((0.4, 0.1, 0.2)), ParamType.POSE),
                    result=Binding.reference("GOAL"),
                ),
                m.op("pretend_move", "go", target=Binding.reference("GOAL")),
            ),
        ),
        "condition": _one(
            "condition",
            "Condition",
            "A predicate that is false. Runs to FAILURE.",
            lambda m: m.op("condition", "door closed", result=_fixed(False, ParamType.BOOL)),
        ),
        "subtree": _subtree_example(),
    }


def main() -> None:
    save_plan(figure3(), HERE / "figure3_debug.costar.json")
    for name, plan in node_examples().items():
        save_plan(plan, HERE / "nodes" / f"{name}.costar.json")
    print(f"wrote {1 + len(node_examples())} example plans")


if __name__ == "__main__":
    main()
