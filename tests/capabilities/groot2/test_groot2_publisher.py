"""``costar run --groot2``: a client written from groot2_protocol.h watches the run."""

from __future__ import annotations

import io
import os
import socket
import threading
from pathlib import Path
from typing import Any

from capabilities.cli import _parser, main
from capabilities.groot2.protocol import RequestType
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType
from tests.capabilities.groot2.groot2_client import Client, free_port_pair

IDLE, RUNNING, SUCCESS = 0, 1, 2


def _plan(folder: Path) -> str:
    """A plan that waits on the operator at its second step: RUNNING until the test answers."""
    steps = [
        NodeSpec(NodeKind.OPERATION, name="first", op="debug.succeed"),
        NodeSpec(NodeKind.OPERATION, name="ask", op="collaboration.confirm",
                 params={"prompt": Binding.fixed("Go on?", ParamType.TEXT)}),
    ]  # fmt: skip
    path = folder / "groot2.costar.json"
    save_plan(PlanSpec(NodeSpec(NodeKind.SEQUENCE, "steps", children=steps), "watched"), path)
    return str(path)


def _run_in_thread(argv: list[str], inp: io.TextIOBase) -> tuple[threading.Thread, dict[str, Any]]:
    result: dict[str, Any] = {"out": io.StringIO(), "err": io.StringIO()}

    def run() -> None:
        result["code"] = main(argv, result["out"], result["err"], inp)  # type: ignore[arg-type]

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread, result


def test_a_client_gets_the_tree_and_every_node_with_its_status(tmp_path: Path) -> None:
    port = free_port_pair()
    read_end, write_end = os.pipe()
    answers = os.fdopen(write_end, "w")
    with os.fdopen(read_end) as inp:
        argv = ["run", _plan(tmp_path), "--cell", "none", "--groot2", str(port)]
        thread, result = _run_in_thread([*argv, "--timeout", "60", "--confirm", "ask"], inp)
        client = Client(port)
        try:
            tree_id, uid_of = client.uids()
            assert set(uid_of) == {"steps", "first", "ask"}
            statuses = client.statuses_once(uid_of["ask"], RUNNING)  # the run reached the prompt
            assert sorted(statuses) == sorted(uid_of.values())  # every node Groot2 sees
            assert statuses == {
                uid_of["steps"]: RUNNING,
                uid_of["first"]: SUCCESS,
                uid_of["ask"]: RUNNING,
            }
            header, _ = client.ask(RequestType.STATUS)
            assert header.tree_id == tree_id
        finally:
            answers.write("y\n")
            answers.close()
            client.close()
            thread.join(30)
    assert result["code"] == 0, result["out"].getvalue() + result["err"].getvalue()
    assert f"Groot2: publishing the run on 127.0.0.1:{port}" in result["out"].getvalue()
    with socket.socket() as again:  # the run's end freed the port
        again.bind(("127.0.0.1", port))


def test_a_taken_port_is_a_clear_error(tmp_path: Path) -> None:
    port = free_port_pair()
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", port))
        taken.listen()
        out, err = io.StringIO(), io.StringIO()
        argv = ["run", _plan(tmp_path), "--cell", "none", "--groot2", str(port)]
        code = main([*argv, "--confirm", "yes"], out, err)
    assert code == 2
    assert f"127.0.0.1:{port}" in err.getvalue()
    assert "taken" in err.getvalue()


def test_groot2_defaults_to_btcpp_port_on_the_loopback() -> None:
    args = _parser().parse_args(["run", "plan.costar.json", "--groot2"])
    assert (args.groot2, args.groot2_host) == (1667, None)  # None: 127.0.0.1
    assert _parser().parse_args(["run", "p"]).groot2 is None


def test_a_port_out_of_range_or_a_host_alone_is_refused(tmp_path: Path) -> None:
    plan = _plan(tmp_path)
    for extra, says in (
        (["--groot2", "65535"], "from 1 to 65534"),
        (["--groot2-host", "*"], "--groot2-host needs --groot2"),
    ):
        err = io.StringIO()
        code = main(["run", plan, "--cell", "none", "--confirm", "yes", *extra], io.StringIO(), err)
        assert code == 2 and says in err.getvalue(), err.getvalue()
