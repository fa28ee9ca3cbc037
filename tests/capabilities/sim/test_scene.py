"""Object library, scene files, seeded placement and object physics of the simulated cell."""

from __future__ import annotations

import copy
import json
import math
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pybullet as p
import pytest

from capabilities.robot.cell_file import CellConfig
from capabilities.robot.kinematics import UR5Kinematics
from capabilities.sim.objects import (
    ObjectLibrary,
    ObjectLibraryError,
    SceneError,
    default_library_path,
)
from capabilities.sim.scene import default_scene_path, load_scene, sample_placements, yaw_pose
from capabilities.sim.scene_spec import SceneFileError, read_scene
from engine.types import Pose

SCENES = ("empty", "cup_to_bin", "kitting")
MODELS = (
    "bender_arm", "cup", "kit_bin", "plate_3_holes", "plate_4_holes", "plate_8_holes",
    "scrap_bin", "tending_rack", "waste_bin", "wire_bender", "wireform_step", "wireform_u",
)  # fmt: skip


@pytest.fixture
def client() -> Iterator[int]:
    cid = p.connect(p.DIRECT)
    p.setGravity(0, 0, -9.81, physicsClientId=cid)
    try:
        yield cid
    finally:
        p.disconnect(cid)


@pytest.fixture(scope="module")
def library() -> ObjectLibrary:
    return ObjectLibrary()


def _scene_json(name: str) -> dict[str, Any]:
    return json.loads(default_scene_path(name).read_text(encoding="utf-8"))


# --------------------------------------------------------------------------- library


def test_library_has_the_paper_objects(library: ObjectLibrary) -> None:
    assert set(MODELS) <= set(library.names())
    cup = library.get("cup")
    assert cup.collision.kind == "cylinder" and cup.symmetry.kind == "continuous"
    assert [m.marker_id for m in cup.markers] == [1, 2]
    assert library.get("waste_bin").symmetry.angles() == pytest.approx((0.0, math.pi))
    assert library.get("plate_4_holes").symmetry.order == 4
    for name in ("plate_3_holes", "plate_4_holes", "plate_8_holes"):
        plate = library.get(name)
        assert 0.003 <= plate.dimensions[2] <= 0.006 and not plate.markers
        assert len(plate.extra["holes"]) == int(name.split("_")[1])
    outlines = {library.get(n).dimensions[:2] for n in MODELS if n.startswith("plate")}
    assert len(outlines) == 3


def test_generated_meshes_are_reproduced_byte_for_byte() -> None:
    from tools.generators import make_objects

    files = make_objects.rendered_files()
    assert len(files) == 2 * len(MODELS)
    for path, text in files.items():
        assert path.read_bytes() == text.encode("ascii"), f"{path} differs from make_objects.py"


def _broken_library(tmp_path: Path, edit: Any) -> ObjectLibrary:
    shutil.copytree(default_library_path() / "cup", tmp_path / "cup")
    file = tmp_path / "cup" / "model.json"
    data = json.loads(file.read_text(encoding="utf-8"))
    edit(data)
    file.write_text(json.dumps(data), encoding="utf-8")
    return ObjectLibrary(tmp_path)


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d.pop("mass"), "$.mass"),
        (lambda d: d.update(mass="heavy"), "$.mass"),
        (lambda d: d["markers"][1].update(id=77), "$.markers[1].id"),
        (lambda d: d["collision"].update(type="sphere"), "$.collision.type"),
        (lambda d: d.update(mesh="missing.obj"), "$.mesh"),
        (lambda d: d["symmetry"].update(kind="discrete"), "$.symmetry.order"),
        (lambda d: d["markers"][0]["pose"].update(position=[0, 0]), "$.markers[0].pose.position"),
        (lambda d: d.update(format_version=9), "$.format_version"),
    ],
)
def test_library_errors_name_the_file_and_field(tmp_path: Path, edit: Any, field: str) -> None:
    lib = _broken_library(tmp_path, edit)
    with pytest.raises(ObjectLibraryError) as info:
        lib.get("cup")
    assert "model.json" in str(info.value) and field in str(info.value)


def test_library_error_for_an_unknown_model_lists_the_known_ones(library: ObjectLibrary) -> None:
    with pytest.raises(ObjectLibraryError, match=r"no such model 'mug'.*'cup'"):
        library.get("mug")


def test_a_user_model_is_a_new_folder(tmp_path: Path, client: int) -> None:
    lib = _broken_library(tmp_path, lambda d: None)
    (tmp_path / "cup").rename(tmp_path / "mug")
    model_file = tmp_path / "mug" / "model.json"
    model_file.write_text(model_file.read_text(encoding="utf-8").replace('"cup"', '"mug"'), "utf-8")
    assert lib.names() == ["mug"]
    scene = {
        "format_version": 1,
        "name": "t",
        "objects": [{"name": "m", "model": "mug", "position": [0.5, 0]}],
    }
    state = load_scene(client, scene, seed=0, library=lib)
    assert state.truth_pose(client, "m").position == pytest.approx((0.5, 0.0, 0.0), abs=1e-9)


# --------------------------------------------------------------------------- scene files


@pytest.mark.parametrize("name", SCENES)
def test_scene_loads(client: int, name: str) -> None:
    state = load_scene(client, default_scene_path(name), seed=3)
    assert state.name == name and state.table_body is not None
    assert set(state.fixed_markers) == {40, 41, 42, 43}
    for obj in state.names():
        assert state.truth_pose(client, obj).position[2] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(
    ("edit", "where"),
    [
        (lambda d: d["objects"][0]["random"].update(x=[0.7, 0.3]), "$.objects[0].random.x"),
        (lambda d: d["objects"][0]["random"].update(z=[0, 1]), "$.objects[0].random.z"),
        (
            lambda d: d["objects"][1].update(present_probability=1.5),
            "$.objects[1].present_probability",
        ),
        (lambda d: d["markers"][0].update(id=50), "$.markers[0].id"),
        (lambda d: d["table"].update(size=[1, 1]), "$.table.size"),
        (lambda d: d["objects"][1].update(name="cup"), "$.objects"),
        (lambda d: d.pop("format_version"), "$.format_version"),
    ],
)
def test_scene_file_errors_name_the_json_path(edit: Any, where: str) -> None:
    data = _scene_json("cup_to_bin")
    edit(data)
    with pytest.raises(SceneFileError) as info:
        read_scene(data)
    assert str(info.value).startswith(f"<scene dict>: {where}:")


def test_unreadable_scene_file_is_named(tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{ nope", encoding="utf-8")
    with pytest.raises(SceneFileError, match=r"bad\.json: line 1"):
        read_scene(bad)
    with pytest.raises(SceneFileError, match=r"missing\.json"):
        read_scene(tmp_path / "missing.json")


def test_nominal_pose_that_overlaps_is_an_error(library: ObjectLibrary) -> None:
    data = _scene_json("cup_to_bin")
    for obj in data["objects"]:
        obj.pop("random")
        obj["position"] = [0.5, 0.0]
    with pytest.raises(
        SceneError, match="'waste_bin' does not fit at its nominal pose: it overlaps object 'cup'"
    ):
        sample_placements(read_scene(data), library, seed=0)


# --------------------------------------------------------------------------- randomisation


def test_same_seed_same_scene_other_seed_other_scene(library: ObjectLibrary) -> None:
    spec = read_scene(default_scene_path("kitting"))
    assert sample_placements(spec, library, 5) == sample_placements(spec, library, 5)
    assert sample_placements(spec, library, 5) != sample_placements(spec, library, 6)


def test_seeded_load_is_deterministic_in_pybullet(client: int) -> None:
    first = load_scene(client, default_scene_path("cup_to_bin"), seed=11)
    poses = [first.truth_pose(client, n) for n in first.names()]
    p.resetSimulation(physicsClientId=client)
    second = load_scene(client, default_scene_path("cup_to_bin"), seed=11)
    assert [second.truth_pose(client, n) for n in second.names()] == poses


def _tool_target(name: str, height: float) -> tuple[Pose, float]:
    """The TCP offset and TCP height the task needs over an object (tool pointing down)."""
    if name.startswith("plate"):
        return Pose((0.0, 0.0, 0.28)), height  # suction tip on the plate's top
    if name.endswith("bin"):
        return Pose((0.0, 0.0, 0.145)), height + 0.05  # gripper holding a cup over the bin
    return Pose((0.0, 0.0, 0.145)), height / 2  # fingers around the cup's middle


def _min_distance(client: int, a: int, b: int) -> float:
    points = p.getClosestPoints(a, b, 0.2, physicsClientId=client)
    return min((pt[8] for pt in points), default=0.2)


@pytest.mark.parametrize("name", ["cup_to_bin", "kitting"])
def test_random_poses_are_reachable_and_apart(client: int, name: str) -> None:
    config = CellConfig()
    ik = UR5Kinematics(config.robot_base)
    hx, hy, _ = config.holster_pose.position
    holster = p.createCollisionShape(
        p.GEOM_CYLINDER, radius=0.12, height=0.1, physicsClientId=client
    )
    for seed in range(15):
        p.resetSimulation(physicsClientId=client)
        state = load_scene(client, default_scene_path(name), seed=seed, make_table=False)
        assert len(state.names()) == len(state.spec.objects)
        keep_out = p.createMultiBody(0, holster, -1, [hx, hy, 0.05], physicsClientId=client)
        bodies = [state.body_id(n) for n in state.names()]
        for i, a in enumerate(state.names()):
            assert _min_distance(client, bodies[i], keep_out) > 0.0, (seed, a)
            for j in range(i + 1, len(bodies)):  # ground-truth shapes, not the sampler's boxes
                assert _min_distance(client, bodies[i], bodies[j]) > 0.015, (seed, a)
            pose = state.truth_pose(client, a)
            tcp, z = _tool_target(a, state.model(a).dimensions[2])
            target = Pose((pose.position[0], pose.position[1], z), (1.0, 0.0, 0.0, 0.0))
            assert ik.inverse(target, config.home_joints, tcp) is not None, (seed, a, pose)


def test_present_probability_draws_presence(client: int) -> None:
    data = _scene_json("kitting")
    for obj in data["objects"][1:]:
        obj["present_probability"] = 0.5
    counts = []
    for seed in range(12):
        state = load_scene(client, copy.deepcopy(data), seed=seed, make_table=False)
        counts.append(len(state.names()))
        assert set(state.absent) | set(state.names()) == {o["name"] for o in data["objects"]}
        p.resetSimulation(physicsClientId=client)
    assert min(counts) < 4 and max(counts) == 4


def test_table_top_can_move(client: int) -> None:
    state = load_scene(client, default_scene_path("cup_to_bin"), seed=1, table_top_z=0.1)
    assert state.truth_pose(client, "cup").position[2] == pytest.approx(0.1)
    assert state.fixed_markers[40].pose.position[2] == pytest.approx(0.1005)
    _, hi = p.getAABB(state.table_body, physicsClientId=client)
    assert hi[2] == pytest.approx(0.1, abs=1e-6)


# --------------------------------------------------------------------------- physics


@pytest.mark.parametrize("name", ["cup_to_bin", "kitting"])
def test_objects_settle_on_the_table(client: int, name: str) -> None:
    state = load_scene(client, default_scene_path(name), seed=2)
    before = {n: state.truth_pose(client, n) for n in state.names()}
    for _ in range(480):
        p.stepSimulation(physicsClientId=client)
    for n, start in before.items():
        now = state.truth_pose(client, n)
        assert now.position[2] == pytest.approx(0.0, abs=0.002), n
        assert math.dist(now.position[:2], start.position[:2]) < 0.002, n


def test_bins_are_hollow(client: int) -> None:
    state = load_scene(client, default_scene_path("cup_to_bin"), seed=4)
    bin_pose = state.truth_pose(client, "waste_bin")
    cup = state.body_id("cup")
    above = yaw_pose(bin_pose.position[0], bin_pose.position[1], 0.3, 0.0)
    p.resetBasePositionAndOrientation(
        cup, above.position, above.orientation, physicsClientId=client
    )
    for _ in range(480):
        p.stepSimulation(physicsClientId=client)
    cup_pose = state.truth_pose(client, "cup")
    assert cup_pose.position[2] == pytest.approx(0.008, abs=0.003)  # on the bin's floor
    assert math.dist(cup_pose.position[:2], bin_pose.position[:2]) < 0.1


def test_spawn_and_remove(client: int) -> None:
    state = load_scene(client, default_scene_path("empty"), seed=0)
    body = state.spawn(client, "bin", "kit_bin", yaw_pose(0.5, 0.2, 0.0, 0.3))
    assert state.marker_owner(21) == "bin" and state.marker_owner(40) == "table"
    assert state.marker_sizes()[20] == pytest.approx(0.05)
    assert state.truth_pose(client, "bin").position == pytest.approx((0.5, 0.2, 0.0))
    state.remove(client, "bin")
    with pytest.raises(p.error):
        p.getBasePositionAndOrientation(body, physicsClientId=client)
    with pytest.raises(SceneError, match="no object 'bin'"):
        state.truth_pose(client, "bin")
