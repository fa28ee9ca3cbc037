"""Plan validation: every class of problem, its path and severity, in tree order."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import pytest
from bt_fakes import settings

from engine.operations import (
    Availability,
    BoundPort,
    Direction,
    Operation,
    OperationKind,
    OperationManifest,
    OperationNotFound,
    PortSpec,
)
from engine.spec import Binding, NodeKind, NodeSpec, ParameterDecl, PlanSpec
from engine.types import JointConfig, ObjectModel, ParamType, Pose, Waypoint, WaypointFrame
from engine.validation import ERROR, WARNING, Problem, has_errors, validate_plan

P = ParamType
OUT = Direction.OUT


class FakeSource:
    """A few manifests, one of them on a capability this cell does not have."""

    def __init__(self) -> None:
        manifests = [
            OperationManifest("test.move_to", OperationKind.ACTION, "Move.", "test", (PortSpec("target", (P.POSE, P.WAYPOINT)), PortSpec("speed", (P.NUMBER,), default=0.25))),
            OperationManifest("test.find", OperationKind.QUERY, "Find.", "test", (PortSpec("model", (P.OBJECT,)), PortSpec("pose", (P.POSE,), OUT))),
            OperationManifest("test.found", OperationKind.CONDITION, "Seen?", "test", (PortSpec("model", (P.OBJECT,)),)),
            OperationManifest("test.count", OperationKind.QUERY, "Count.", "test", (PortSpec("count", (P.NUMBER,), OUT),)),
            OperationManifest("test.say", OperationKind.ACTION, "Say.", "test", (PortSpec("mode", (P.TEXT,), choices=("loud", "soft")), PortSpec("what", (P.ANY,), default=""))),
            OperationManifest("test.pick", OperationKind.ACTION, "Pick.", "test", (PortSpec("held", (P.BOOL,), OUT),)),
            OperationManifest("vision.detect", OperationKind.QUERY, "Detect.", "vision", (PortSpec("pose", (P.POSE,), OUT),), aliases=("vision.find",)),
        ]  # fmt: skip
        self.by_id = {m.id: m for m in manifests}

    def manifests(self) -> list[OperationManifest]:
        return list(self.by_id.values())

    def manifest(self, op_id: str) -> OperationManifest:
        op_id = self.aliases().get(op_id, op_id)
        if op_id not in self.by_id:
            raise OperationNotFound(op_id)
        return self.by_id[op_id]

    def availability(self, op_id: str) -> Availability:
        if self.manifest(op_id).capability == "vision":
            return Availability(False, "the cell has no wrist camera")
        return Availability()

    def create(self, op_id: str) -> Operation:
        raise NotImplementedError

    def aliases(self) -> Mapping[str, str]:
        return {"vision.find": "vision.detect"}


SOURCE = FakeSource()


def op(op_id: str | None, name: str = "", **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, name, op=op_id, params=params)


def seq(
    *children: NodeSpec, name: str = "", kind: NodeKind = NodeKind.SEQUENCE, **config: Any
) -> NodeSpec:
    return NodeSpec(kind, name, params=settings(kind, **config), children=list(children))


def ref(name: str) -> Binding:
    return Binding.reference(name)


CUP = Binding.fixed(ObjectModel("cup"), P.OBJECT)


def find(name: str = "find cup", out: str = "CUP_POSE") -> NodeSpec:
    return op("test.find", name, model=CUP, pose=ref(out))


def move(name: str = "move to cup", target: str = "CUP_POSE") -> NodeSpec:
    return op("test.move_to", name, target=ref(target))


def check(tree: NodeSpec | None, *parameters: ParameterDecl) -> list[Problem]:
    return validate_plan(PlanSpec(tree=tree, name="plan", parameters=list(parameters)), SOURCE)


def only(problems: list[Problem]) -> Problem:
    assert len(problems) == 1, problems
    return problems[0]


# --------------------------------------------------------------------------- good plans


def test_the_figure_3_plan_is_fine() -> None:
    tree = seq(find(), move(), op("test.found", "cup still there", model=CUP), name="Transfer")
    assert check(tree) == []
    assert not has_errors([])


def test_aliases_and_all_types_of_ok_values() -> None:
    tree = seq(
        op("vision.find", "old id", pose=ref("P")),  # unavailable, but found through its alias
        op(
            "test.move_to",
            target=Binding.fixed(Pose((0.1, 0, 0)), P.POSE),
            speed=Binding.fixed(0.5, P.NUMBER),
        ),
        op("test.say", mode=Binding.fixed("soft", P.TEXT), what=Binding.fixed([1, 2], P.ANY)),
    )
    problems = check(tree)
    assert [p.message for p in problems] == [
        "'old id' cannot run on this cell: the cell has no wrist camera."
    ]


# --------------------------------------------------------------------------- each problem


def test_empty_plan() -> None:
    problem = only(check(None))
    assert (problem.severity, problem.node_id, problem.path) == (ERROR, None, "plan")
    assert "empty" in problem.message


def test_unknown_operation_suggests_close_ids() -> None:
    problem = only(check(seq(op("test.move_too", "go"), name="T")))
    assert problem.path == "T/go[0]" and problem.severity == ERROR
    assert problem.message.startswith(
        "There is no operation 'test.move_too' (did you mean 'test.move_to'"
    )


def test_missing_op_and_unavailable_capability() -> None:
    problems = check(seq(op(None), op("vision.detect", "detect", pose=ref("P"))))
    assert [p.message for p in problems] == [
        "'operation' has no operation chosen.",
        "'detect' cannot run on this cell: the cell has no wrist camera.",
    ]
    assert problems[0].path == "sequence/operation[0]"


def test_unbound_required_input_and_unstored_output() -> None:
    problems = check(seq(op("test.move_to", "go"), op("test.find", "look", model=CUP)))
    assert [(p.severity, p.path, p.field) for p in problems] == [
        (ERROR, "sequence/go[0]", "target"),
        (WARNING, "sequence/look[1]", "pose"),
    ]
    assert problems[0].message == "'go' needs a value for 'target' (a Pose or a Waypoint)."
    assert check(op("test.pick", "pick")) == []  # an action's extra result may go unused
    empty = only(check(op("test.move_to", "go", target=Binding())))  # an empty binding is none
    assert empty.field == "target" and "needs a value" in empty.message


def test_unknown_port_name() -> None:
    problem = only(check(op("test.find", "look", model=CUP, pose=ref("P"), modle=CUP)))
    assert problem.field == "modle" and "did you mean 'model'" in problem.message


def test_output_bound_to_a_fixed_value() -> None:
    problem = only(check(op("test.find", "look", model=CUP, pose=Binding.fixed(Pose(), P.POSE))))
    assert (problem.severity, problem.field) == (ERROR, "pose")
    assert "give it a name" in problem.message


def test_reference_nothing_writes_is_an_error() -> None:
    problem = only(check(seq(find(out="CUP_POSE"), move(target="CUP_POSSE"))))
    assert (problem.severity, problem.path, problem.field) == (
        ERROR,
        "sequence/move to cup[1]",
        "target",
    )
    assert problem.message.startswith("Nothing sets CUP_POSSE")


def test_declared_parameter_without_value_may_be_read_too_early() -> None:
    problem = only(check(move(), ParameterDecl("CUP_POSE", P.POSE)))
    assert problem.severity == WARNING and "before anything has set it" in problem.message
    assert check(move(), ParameterDecl("CUP_POSE", P.POSE, Pose())) == []


@pytest.mark.parametrize(
    ("tree", "warned"),
    [
        (seq(move(), find()), True),  # read before the write in the same sequence
        (seq(find(), move()), False),
        (seq(find(), move(), kind=NodeKind.REACTIVE_SEQUENCE), False),
        (seq(seq(find(), find("find again"), kind=NodeKind.SELECTOR), move()), False),  # both write
        (
            seq(seq(find(), op("test.count", count=ref("N")), kind=NodeKind.SELECTOR), move()),
            True,
        ),  # one does not
        (seq(seq(find(), move(), kind=NodeKind.PARALLEL)), True),  # siblings start together
        (
            seq(seq(find(), op("test.count", count=ref("N")), kind=NodeKind.PARALLEL), move()),
            False,
        ),  # all succeed
        (
            seq(
                seq(
                    find(), op("test.count", count=ref("N")), kind=NodeKind.PARALLEL, success="any"
                ),
                move(),
            ),
            True,
        ),
        (
            seq(
                seq(
                    find(),
                    find("b"),
                    op("test.count", count=ref("N")),
                    kind=NodeKind.PARALLEL,
                    success=2,
                ),
                move(),
            ),
            False,
        ),
        (
            seq(
                seq(
                    find(),
                    op("test.count", count=ref("N")),
                    op("test.count", "c2", count=ref("N2")),
                    kind=NodeKind.PARALLEL,
                    success=2,
                ),
                move(),
            ),
            True,
        ),
        (seq(seq(find(), kind=NodeKind.INVERTER), move()), True),
        (seq(seq(find(), kind=NodeKind.FORCE_SUCCESS), move()), True),
        (seq(seq(find(), kind=NodeKind.RETRY, count=3), move()), False),
        (seq(seq(find(), kind=NodeKind.TIMEOUT, seconds=2), move()), False),
        (seq(seq(find(), kind=NodeKind.ENFORCE), move()), False),
        (seq(seq(find(), kind=NodeKind.ITERATOR, count=2), move()), False),
        (seq(seq(find(), kind=NodeKind.ITERATOR, timeout=5.0), move()), True),  # may time out first
        (seq(seq(find(), seq(move(), kind=NodeKind.RETRY, count=2))), False),
    ],
)
def test_read_before_guaranteed_write_is_a_warning(tree: NodeSpec, warned: bool) -> None:
    problems = check(tree)
    assert not has_errors(problems), problems
    assert [p.message.split(":")[0] for p in problems] == (
        ["'move to cup' may read CUP_POSE before anything has set it"] if warned else []
    )


def test_wrong_fixed_value_types() -> None:
    problems = check(
        seq(
            op("test.move_to", "go", target=Binding.fixed(3.0, P.NUMBER)),
            op("test.move_to", "go 2", target=Binding.fixed("home", P.POSE)),  # value is no Pose
            op("test.say", "say", mode=Binding.fixed("shout", P.TEXT)),
        )
    )
    assert [(p.path, p.field) for p in problems] == [
        ("sequence/go[0]", "target"),
        ("sequence/go 2[1]", "target"),
        ("sequence/say[2]", "mode"),
    ]
    assert (
        problems[0].message
        == "'target' of 'go' needs a Pose or a Waypoint, but it is set to a Number."
    )
    assert "must be one of loud, soft" in problems[2].message


def test_reference_of_the_wrong_type() -> None:
    problem = only(check(seq(op("test.count", "count", count=ref("N")), move(target="N"))))
    assert problem.severity == ERROR and problem.path == "sequence/move to cup[1]"
    assert "needs a Pose or a Waypoint, but N is a Number (from 'count')" in problem.message


def test_one_name_written_with_two_types() -> None:
    problems = check(seq(find(out="X"), op("test.count", "count", count=ref("X"))))
    problem = only(problems)
    assert (problem.path, problem.field) == ("sequence/count[1]", "X")
    assert problem.message == "X is written as a Pose by 'find cup' and as a Number by 'count'."
    declared = only(check(find(out="X"), ParameterDecl("X", P.NUMBER, 1.0)))
    assert declared.path == "find cup" and "the plan parameter X" in declared.message


def test_structure_problems() -> None:
    tree = seq(
        seq(kind=NodeKind.INVERTER),
        seq(find(), move(), kind=NodeKind.RETRY, count=2),
        seq(kind=NodeKind.SELECTOR),
        NodeSpec(
            NodeKind.WAIT,
            "pause",
            params=settings(NodeKind.WAIT, seconds=1),
            children=[find("inner")],
        ),
        name="T",
    )
    problems = [p for p in check(tree) if p.severity == ERROR]
    assert [(p.path, p.message) for p in problems] == [
        ("T/inverter[0]", "'inverter' needs one node below it."),
        ("T/retry[1]", "'retry' can hold only one node, not 2."),
        ("T/selector[2]", "'selector' has no nodes below it: add some or remove it."),
        ("T/pause[3]", "'pause' cannot have nodes below it; it has 1."),
    ]


def test_settings_of_logic_nodes() -> None:
    tree = seq(
        seq(find(), kind=NodeKind.RETRY),
        NodeSpec(NodeKind.WAIT, params=settings(NodeKind.WAIT, seconds=-1, secs=2)),
        seq(find(), move(), kind=NodeKind.PARALLEL, success=3),
    )
    problems = check(tree)
    assert [(p.severity, p.path, p.field) for p in problems if p.severity == ERROR] == [
        (ERROR, "sequence/retry[0]", "count"),
        (ERROR, "sequence/wait[1]", "seconds"),
        (ERROR, "sequence/wait[1]", "secs"),
        (ERROR, "sequence/parallel[2]", "success"),
    ]
    assert (
        problems[3].message == "'parallel' waits for 3 children to end with success but has only 2."
    )


def test_ports_of_logic_nodes_take_typed_fixed_values() -> None:
    retry = seq(find(), kind=NodeKind.RETRY)
    retry.params = {"count": Binding.reference("TRIES")}
    wait = NodeSpec(NodeKind.WAIT, "pause", params={"seconds": Binding.fixed("1", ParamType.TEXT)})
    parallel = seq(find(), move(), kind=NodeKind.PARALLEL, success="most", failure=1.5)
    problems = [p for p in check(seq(retry, wait, parallel)) if p.severity == ERROR]
    assert [(p.field, p.message) for p in problems] == [
        (
            "count",
            "'count' of 'retry' takes a fixed value, not a reference to TRIES: the settings "
            "of logic nodes are fixed when the plan starts.",
        ),
        ("seconds", "'seconds' of 'pause' needs a Duration, but it is set to a Text."),
        ("success", "'success' of 'parallel' must be one of all, any, not 'most'."),
        ("failure", "'failure' of 'parallel' must be a whole number other than 0, not 1.5."),
    ]


def test_unknown_kind_and_duplicate_ids() -> None:
    odd = NodeSpec(NodeKind.WAIT, "dance", params=settings(NodeKind.WAIT, seconds=1))
    # a spec built by hand, not read from a file, can hold any kind
    odd.kind = "dance"  # type: ignore[assignment]  # a wrong kind on purpose
    twin = find("twin")
    twin.id = "same"
    other = find("other")
    other.id = "same"
    problems = check(seq(odd, twin, other))
    assert [(p.path, p.message) for p in problems] == [
        ("sequence/dance[0]", "Unknown kind of node 'dance'; it cannot run."),
        (
            "sequence/other[2]",
            "This node has the same id as the node sequence/twin[1]; one of them must be given a new id.",
        ),
    ]


def test_parameter_problems() -> None:
    problems = check(
        move(), ParameterDecl("CUP_POSE", P.POSE, 3.0), ParameterDecl("CUP_POSE", P.POSE)
    )
    assert [(p.path, p.field, p.severity) for p in problems] == [
        ("parameters", "CUP_POSE", ERROR),
        ("parameters", "CUP_POSE", ERROR),
    ]


# --------------------------------------------------------------------------- as a whole


def test_every_problem_at_once_in_tree_order() -> None:
    tree = seq(
        seq(move(target="A"), op("test.move_to", "no target"), name="first"),
        op("nope.nope", "bogus"),
        seq(kind=NodeKind.INVERTER),
        name="T",
    )
    problems = check(tree)
    assert [p.path for p in problems] == [
        "T/first[0]/move to cup[0]",
        "T/first[0]/no target[1]",
        "T/bogus[1]",
        "T/inverter[2]",
    ]
    assert has_errors(problems)
    assert str(problems[0]).startswith("error: T/first[0]/move to cup[0] [target]: Nothing sets A")
    node = tree.children[0].children[0]
    assert problems[0].node_id == node.id


def test_warnings_alone_do_not_stop_a_plan() -> None:
    problems = check(seq(move(), find()))
    assert problems and not has_errors(problems)


def test_deep_and_large_plans() -> None:
    node = seq(find(), move())
    for _ in range(300):
        node = seq(node, kind=NodeKind.RETRY, count=2)
    assert check(node) == []
    wide = seq(*(n for _ in range(500) for n in (find(), move())))
    assert check(wide) == []


def test_messages_put_an_before_a_vowel() -> None:
    """'a ObjectModel', 'a inverter node': the article follows the word's sound."""
    import json

    from engine.files import loads_plan
    from engine.plan_format import PlanFileError
    from engine.validation_ports import type_names

    assert type_names([ParamType.OBJECT]) == "an ObjectModel"
    assert type_names([ParamType.POSE, ParamType.OBJECT]) == "a Pose or an ObjectModel"
    assert type_names([ParamType.ANY]) == "a value of any type"
    doc = {"format": "costar-plan", "format_version": 2, "name": "x",
           "tree": {"kind": "inverter", "id": "n1", "op": "debug.succeed"}}  # fmt: skip
    with pytest.raises(PlanFileError) as caught:
        loads_plan(json.dumps(doc), "x.costar.json")
    assert "an inverter node" in str(caught.value) and "a inverter" not in str(caught.value)


# ------------------------------------------------------------- checks across ports (rules)


def _aim_rule(bound: Mapping[str, BoundPort]) -> Iterator[tuple[str, str]]:
    """'offset' is used only when 'target' is a Pose."""
    target = bound.get("target")
    if "offset" in bound and target is not None and not target.may_be(P.POSE):
        yield "offset", f"'offset' is ignored with a {target.types[0].value} target"


class RuleSource(FakeSource):
    def __init__(self) -> None:
        super().__init__()
        ports = (
            PortSpec("target", (P.POSE, P.WAYPOINT)),
            PortSpec("offset", (P.NUMBER,), default=0.0),
        )
        aim = OperationManifest(
            "test.aim", OperationKind.ACTION, "Aim.", "test", ports, rules=(_aim_rule,)
        )
        self.by_id[aim.id] = aim


def test_a_rule_across_ports_is_an_error_naming_the_node_and_port() -> None:
    waypoint = Binding.fixed(
        Waypoint("w", WaypointFrame.JOINTS, joints=JointConfig((0.0,))), P.WAYPOINT
    )
    node = op("test.aim", "aim at it", target=waypoint, offset=Binding.fixed(0.1, P.NUMBER))
    problem = only(validate_plan(PlanSpec(seq(node), "plan"), RuleSource()))
    assert (problem.severity, problem.node_id, problem.field) == (ERROR, node.id, "offset")
    assert problem.message == "'aim at it': 'offset' is ignored with a Waypoint target"


def test_a_rule_sees_the_types_of_what_writes_a_reference() -> None:
    node = op("test.aim", "aim", target=ref("W"), offset=Binding.fixed(0.1, P.NUMBER))
    source = RuleSource()
    as_waypoint = PlanSpec(seq(node), "plan", parameters=[ParameterDecl("W", P.WAYPOINT)])
    errors = [p for p in validate_plan(as_waypoint, source) if p.severity == ERROR]
    assert only(errors).field == "offset"
    as_pose = PlanSpec(seq(node), "plan", parameters=[ParameterDecl("W", P.POSE)])
    assert [p for p in validate_plan(as_pose, source) if p.severity == ERROR] == []
