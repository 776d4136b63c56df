"""`vplane-mj import barn`: BARN's Gazebo worlds as scenarios of the challenge's layout.

The fixture tests/data/barn/ is world 1 of BARN (world_1.world, path_1.npy), unchanged, with
the MIT licence it is distributed under (see its README.md).
"""

import copy
import io
import math
import os
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from vplane_mj.cli import main
from vplane_mj.errors import ScenarioError, WorldFileError
from vplane_mj.geometry.shapes import scene_footprints
from vplane_mj.scenario import parse_document
from vplane_mj.sim.metrics import path_quality
from vplane_mj.worlds import sdf
from vplane_mj.worlds.barn_import import barn_path_length, import_worlds
from vplane_mj.worlds.barn_layout import JACKAL_RADIUS_M, to_arena
from vplane_mj.worlds.sdf import read_world_shapes

SAMPLE = Path(__file__).parent / "data" / "barn"


@pytest.fixture(scope="module")
def world_1(tmp_path_factory):
    """The sample imported through the command line: (its TOML document, what it printed)."""
    out = tmp_path_factory.mktemp("imported")
    assert main(["import", "barn", str(SAMPLE), "--out", str(out)]) == 0
    return tomllib.loads((out / "barn_world_1.toml").read_text()), out


def test_the_transform_takes_barns_start_and_goal_to_the_layouts():
    assert to_arena(-2.25, 3.0) == (2.1, 2.85)
    assert to_arena(-2.25, 13.0) == (2.1, 12.85)


def test_the_sample_becomes_a_scenario_of_the_challenges_layout(world_1):
    doc, _ = world_1
    assert doc["name"] == "barn_world_1"
    assert doc["world"]["size"] == [4.2, 14.0] and doc["world"]["border"] is True
    assert doc["robot"] == {
        "profile": "jackal",
        "start": [2.1, 2.85],
        "start_yaw_deg": 90.0,
        "goal": [2.1, 12.85],
        "goal_tolerance": 1.0,
    }
    assert doc["run"] == {"time_limit_s": 100.0}
    assert "path_1.npy" in doc["description"]
    scenario = parse_document(doc, "barn_world_1.toml")
    assert len(scenario.world.obstacles) == 237


def test_its_cylinders_stand_where_gazebo_puts_them_moved_by_the_transform(world_1):
    doc, _ = world_1
    obstacles = doc["world"]["obstacles"]  # in the world file's order, unit_cylinder_0 first
    assert all(ob["kind"] == "cylinder" and ob["radius"] == 0.075 for ob in obstacles)
    # unit_cylinder_N at Gazebo (x, y), read off world_1.world, plus (4.35, -0.15):
    assert obstacles[0]["center"] == [4.275, -0.075]  # (-0.075, 0.075): back wall corner
    assert obstacles[126]["center"] == [0.075, 5.175]  # (-4.275, 5.325): field, beside the left wall
    assert obstacles[149]["center"] == [1.125, 6.075]  # (-3.225, 6.225)
    assert obstacles[172]["center"] == [2.175, 8.775]  # (-2.175, 8.925)


def test_the_field_fills_the_layouts_field_and_the_walls_stand_outside_the_arena(world_1):
    doc, _ = world_1
    centers = np.array([ob["center"] for ob in doc["world"]["obstacles"]])
    in_arena = (centers[:, 0] > 0) & (centers[:, 0] < 4.2) & (centers[:, 1] > 0)
    field, walls = centers[in_arena], centers[~in_arena]
    assert len(field) == 81
    assert field[:, 1].min() - 0.075 >= 4.95 and field[:, 1].max() + 0.075 <= 9.6
    rows, columns = (field[:, 1] - 4.95) / 0.15 - 0.5, field[:, 0] / 0.15 - 0.5
    np.testing.assert_allclose(rows, np.round(rows), atol=1e-9)  # on the layout's 0.15 m cells
    np.testing.assert_allclose(columns, np.round(columns), atol=1e-9)
    left, right, back = walls[walls[:, 0] < 0], walls[walls[:, 0] > 4.2], walls[walls[:, 1] < 0]
    assert set(left[:, 0]) == {-0.075} and set(right[:, 0]) == {4.275}  # touching x = 0 and 4.2
    assert set(back[:, 1]) == {-0.075}  # touching y = 0
    assert len(left) == len(right) == 64 and len(walls) == 64 + 64 + 28  # the back wall between
    assert left[:, 1].min() == -0.075 and left[:, 1].max() == 9.375


def test_start_and_goal_are_clear_for_the_jackal(world_1):
    doc, _ = world_1
    scenario = parse_document(doc, "barn_world_1.toml")
    scene = scene_footprints(scenario.world.obstacles, scenario.world.size)
    gaps = scene.distance(np.array([scenario.robot.start, scenario.robot.goal]))
    assert np.all(gaps >= JACKAL_RADIUS_M)


def test_barns_path_length_is_reported_beside_the_reference(tmp_path, capsys):
    assert main(["import", "barn", str(SAMPLE / "world_1.world"), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "BARN's own path 12.312 m" in out and "reference path 10.1" in out
    [world] = import_worlds([SAMPLE / "world_1.world"])
    assert world.barn_path_m == pytest.approx(12.312, abs=1e-3)
    assert 10.0 < world.reference_m < world.barn_path_m


def test_the_score_takes_its_ot_from_barns_own_path(world_1):
    doc = copy.deepcopy(world_1[0])
    assert doc["world"]["score_path_m"] == pytest.approx(12.312, abs=1e-3)
    scenario = parse_document(doc, "barn_world_1.toml")
    # reached in 8 s: BARN's OT is 12.312 / 2 m/s = 6.16 s, so T is clipped to 2 OT
    quality = path_quality(scenario, JACKAL_RADIUS_M, True, 10.0, 8.0, 2.0)
    assert quality["score_path_m"] == doc["world"]["score_path_m"] and quality["score_path_source"] == "world"
    assert quality["score"] == pytest.approx(0.5)
    later = path_quality(scenario, JACKAL_RADIUS_M, True, 10.0, 20.0, 2.0)
    assert later["score"] == pytest.approx(12.312491 / 2.0 / 20.0)
    del doc["world"]["score_path_m"]  # a world without BARN's path: the reference path's OT
    plain = path_quality(parse_document(doc, "plain.toml"), JACKAL_RADIUS_M, True, 10.0, 20.0, 2.0)
    assert plain["score_path_source"] == "reference" and plain["score_path_m"] == plain["reference_length_m"]
    assert plain["score"] == pytest.approx(plain["reference_length_m"] / 2.0 / 20.0)


def test_a_score_path_must_be_a_length(world_1):
    doc = copy.deepcopy(world_1[0])
    doc["world"]["score_path_m"] = 0.0
    with pytest.raises(ScenarioError) as caught:
        parse_document(doc, "bad.toml")
    assert caught.value.key == "world.score_path_m" and "greater than 0" in caught.value.reason


def test_barns_path_length_is_the_polyline_through_its_cells(tmp_path):
    path = tmp_path / "path_9.npy"
    np.save(path, np.array([[15, 0], [15, 29]]))  # Gazebo (-2.325, 5.075) and (-2.325, 9.425)
    expected = math.hypot(0.325, 2.075) + 4.35 + math.hypot(0.325, 3.575)
    assert barn_path_length(path) == pytest.approx(expected)
    np.save(path, np.asfortranarray(np.array([[15, 0], [15, 29]], dtype=">i2")))  # column-major, big-endian
    assert barn_path_length(path) == pytest.approx(expected)


def test_state_poses_win_and_link_and_collision_poses_compose(tmp_path):
    world = tmp_path / "world_5.world"
    world.write_text(
        _sdf(
            _model("post", "<pose>9 9 0 0 0 0</pose>", _cylinder(0.1))
            + _model(
                "crate",
                "<pose>1 2 0 0 0 1.5707963267948966</pose>",
                _link(
                    "<pose>1 0 0 0 0 0</pose>",
                    "<pose>0 0.5 0 0 0 0.5</pose>",
                    "<box><size>0.4 0.2 1</size></box>",
                ),
            ),
            state="<model name='post'><pose frame=''>-2 5 0 0 0 0</pose><scale>1 1 1</scale></model>",
        )
    )
    post, crate = read_world_shapes(world)
    assert (post.kind, post.x, post.y, post.radius) == ("cylinder", -2.0, 5.0, 0.1)  # the state's pose
    assert crate.kind == "box" and crate.size == (0.4, 0.2)
    # model at (1, 2) turned 90 degrees; link 1 m ahead of it, collision 0.5 m to the link's left
    assert (crate.x, crate.y, crate.yaw) == pytest.approx((0.5, 3.0, math.pi / 2 + 0.5))


def _sdf(models: str, state: str = "") -> str:
    state_block = f"<state world_name='default'>{state}</state>" if state else ""
    ground = _model(
        "ground_plane", "", _link("", "", "<plane><normal>0 0 1</normal><size>100 100</size></plane>")
    )
    return f"<sdf version='1.6'><world name='default'>{ground}{models}{state_block}</world></sdf>"


def _model(name: str, pose: str, link: str, static: str = "<static>1</static>") -> str:
    return f"<model name='{name}'>{static}{pose}{link}</model>"


def _link(link_pose: str, collision_pose: str, shape: str) -> str:
    collision = f"<collision name='collision'>{collision_pose}<geometry>{shape}</geometry></collision>"
    return f"<link name='link'>{link_pose}{collision}</link>"


def _cylinder(radius: float) -> str:
    return _link("", "", f"<cylinder><radius>{radius}</radius><length>1</length></cylinder>")


COLLISION = "model[@name='{}']/link[@name='link']/collision[@name='collision']/geometry"

BAD = {
    "malformed XML": (
        "<sdf version='1.6'><world name='default'><model name='a'></world></sdf>",
        "",
        "not well-formed XML: mismatched tag: line 1",
    ),
    "an entity bomb": (
        "<!DOCTYPE x [<!ENTITY a 'aaaaaaaaaa'>"
        + "".join(f"<!ENTITY {chr(98 + i)} '{('&' + chr(97 + i) + ';') * 10}'>" for i in range(9))
        + "]><sdf><world><model name='&j;'/></world></sdf>",
        "",
        "not well-formed XML: limit on input amplification factor",
    ),
    "a mesh": (
        _sdf(_model("rock", "", _link("", "", "<mesh><uri>model://rock/rock.dae</uri></mesh>"))),
        COLLISION.format("rock") + "/mesh",
        "<mesh> is not supported: only <cylinder> and <box>",
    ),
    "a non-static model": (
        _sdf(_model("crate", "", _cylinder(0.2), static="<static>0</static>")),
        "model[@name='crate']",
        "is not static: only static models can be imported",
    ),
    "a model without <static>": (
        _sdf(_model("crate", "", _cylinder(0.2), static="")),
        "model[@name='crate']",
        "is not static",
    ),
    "a missing radius": (
        _sdf(_model("post", "", _link("", "", "<cylinder><length>1</length></cylinder>"))),
        COLLISION.format("post") + "/cylinder",
        "has no <radius>",
    ),
    "a negative radius": (
        _sdf(_model("post", "", _cylinder(-0.1))),
        COLLISION.format("post") + "/cylinder/radius",
        "must be greater than 0 and at most 1000 m, got '-0.1'",
    ),
    "a non-numeric pose": (
        _sdf(_model("post", "<pose>1 2 x 0 0 0</pose>", _cylinder(0.1))),
        "model[@name='post']/pose",
        "must be 6 numbers (x y z roll pitch yaw) in decimal or scientific notation, each within "
        "+-10000, got '1 2 x 0 0 0'",
    ),
    "a pose of five numbers": (
        _sdf(_model("post", "", _link("<pose>1 2 0 0 0</pose>", "", "<box><size>1 1 1</size></box>"))),
        "model[@name='post']/link[@name='link']/pose",
        "must be 6 numbers",
    ),
    "a non-finite state pose": (
        _sdf(
            _model("post", "", _cylinder(0.1)), state="<model name='post'><pose>nan 0 0 0 0 0</pose></model>"
        ),
        "state/model[@name='post']/pose",
        "must be 6 numbers",
    ),
    "a tilted box": (
        _sdf(_model("ramp", "<pose>0 0 0 0.3 0 0</pose>", _link("", "", "<box><size>1 1 1</size></box>"))),
        "model[@name='ramp']/pose",
        "is tilted (roll 0.3, pitch 0 rad): only upright shapes",
    ),
    "an included model": (
        "<sdf version='1.6'><world name='default'><include><uri>model://sun</uri></include></world></sdf>",
        "include",
        "<include> is not supported",
    ),
    "an include inside a link": (
        _sdf(
            _model(
                "post",
                "",
                _link("<include><uri>model://rock</uri></include>", "", "<box><size>1 1 1</size></box>"),
            )
        ),
        "model[@name='post']/link[@name='link']/include",
        "<include> is not supported inside another element",
    ),
    "a model inside a link": (
        _sdf(
            _model("post", "", _link(_model("rock", "", _cylinder(0.1)), "", "<box><size>1 1 1</size></box>"))
        ),
        "model[@name='post']/link[@name='link']/model[@name='rock']",
        "<model> is not supported inside another element",
    ),
    "an include 1000 elements deep": (
        _sdf(
            _model(
                "post",
                "",
                _link("<a>" * 1000 + "<include/>" + "</a>" * 1000, "", "<box><size>1 1 1</size></box>"),
            )
        ),
        "model[@name='post']/link[@name='link']/a/a/...(995 steps).../a/a/a/include",
        "<include> is not supported inside another element",
    ),
    "a number with an underscore": (
        _sdf(_model("post", "", _cylinder("0.0_75"))),
        COLLISION.format("post") + "/cylinder/radius",
        "must be a number (metres) in decimal or scientific notation, each within +-10000, got '0.0_75'",
    ),
    "a yaw of 1e300": (
        _sdf(
            _model("crate", "<pose>-1 8 0 0 0 1e300</pose>", _link("", "", "<box><size>1 1 1</size></box>"))
        ),
        "model[@name='crate']/pose",
        "must be 6 numbers (x y z roll pitch yaw) in decimal or scientific notation, each within "
        "+-10000, got '-1 8 0 0 0 1e300'",
    ),
    "a position 2 km away": (
        _sdf(_model("post", "<pose>2000 8 0 0 0 0</pose>", _cylinder(0.1))),
        "model[@name='post']/pose",
        "x, y and z must lie within +-1000 m, got 2000, 8, 0",
    ),
    "a box 2 km long": (
        _sdf(_model("crate", "", _link("", "", "<box><size>2e3 1 1</size></box>"))),
        COLLISION.format("crate") + "/box/size",
        "must be greater than 0 and at most 1000 m, got '2e3 1 1'",
    ),
    "a 1 MB model name": (
        _sdf(_model("x" * 2**20, "", _cylinder(-1))),
        "model[@name='"
        + "x" * 80
        + "'... (1048576 characters)]/link[@name='link']/collision[@name='collision']"
        "/geometry/cylinder/radius",
        "must be greater than 0",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_world_that_cannot_be_converted_exits_2_naming_file_and_element_and_writes_nothing(
    tmp_path, capsys, case
):
    text, element, reason = BAD[case]
    inputs = tmp_path / "worlds"
    inputs.mkdir()
    shutil.copy(SAMPLE / "world_1.world", inputs / "world_1.world")  # a good world is not written either
    bad = inputs / "world_2.world"
    bad.write_text(text)
    out = tmp_path / "out"
    assert main(["import", "barn", str(inputs), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {bad}: {element}: " if element else f"error: {bad}: ")
    assert reason in err and "Traceback" not in err and len(err) < 600
    assert not out.exists()


def test_a_directory_without_world_files_exits_2(tmp_path, capsys):
    assert main(["import", "barn", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert f"error: {tmp_path}: holds no world_N.world file" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("gazebo_y", "reason"),
    [
        (
            3.05,
            "does not make a valid scenario: robot.start: the jackal robot's footprint at yaw 90 deg "
            "overlaps",
        ),
        (3.36, "the start [2.1, 2.85] is 0.285 m from an obstacle, closer than the Jackal's half diagonal"),
    ],
)
def test_a_start_the_jackal_would_overlap_is_refused(tmp_path, capsys, gazebo_y, reason):
    world = tmp_path / "world_3.world"
    world.write_text(_sdf(_model("post", f"<pose>-2.25 {gazebo_y} 0 0 0 0</pose>", _cylinder(0.075))))
    assert main(["import", "barn", str(world), "--out", str(tmp_path / "out")]) == 2
    assert f"error: {world}: {reason}" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def _imports_nothing(capsys, *args: Path) -> str:
    """Import `args` into tmp/out, which must exit 2 and write nothing: what it printed on stderr."""
    out = args[-1]
    assert main(["import", "barn", *map(str, args[:-1]), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and not out.exists()
    return err


def test_a_file_name_that_is_not_utf8_imports_and_is_shown_escaped(tmp_path, capsys):
    world = Path(os.fsdecode(os.fsencode(tmp_path) + b"/w\xff.world"))
    shutil.copy(SAMPLE / "world_1.world", world)
    out = Path(os.fsdecode(os.fsencode(tmp_path) + b"/out\xe9"))
    assert main(["import", "barn", str(SAMPLE / "world_1.world"), str(world), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"wrote {tmp_path}/out\\xe9/barn_w_.toml" in printed
    document = tomllib.loads((out / "barn_w_.toml").read_text(encoding="utf-8"))
    assert document["description"].startswith("BARN world w\\xff.world (Gazebo)")


def test_a_bad_world_of_a_name_that_is_not_utf8_exits_2_naming_it_escaped(tmp_path, capsys):
    bad = Path(os.fsdecode(os.fsencode(tmp_path) + b"/w\xff.world"))
    bad.write_text("<sdf>")
    err = _imports_nothing(capsys, SAMPLE / "world_1.world", bad, tmp_path / "out")
    assert err.startswith(f"error: {tmp_path}/w\\xff.world: not well-formed XML")


def _npy(header: dict, data: bytes = b"") -> bytes:
    """An .npy file (format 1.0) of this header and these data bytes."""
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(buffer, header)
    return buffer.getvalue() + data


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (
            _npy({"descr": "<i8", "fortran_order": False, "shape": (2**40, 2)}),
            "must hold 1 to 10000 (row, column) integer pairs, its header declares int64 of shape "
            "(1099511627776, 2)",
        ),
        (
            _npy({"descr": "|O", "fortran_order": False, "shape": (1, 2)}, b"\x80\x04N."),
            "its header declares object of shape (1, 2)",
        ),
        (
            _npy(
                {"descr": "<f8", "fortran_order": False, "shape": (1, 2)}, np.array([np.nan, 0.0]).tobytes()
            ),
            "its header declares float64 of shape (1, 2)",
        ),
        (
            _npy({"descr": "<i8", "fortran_order": False, "shape": (37, 2)}, bytes(16)),
            "holds 16 bytes of data",
        ),
        (b"\x93NUMPY\x03\x00", "cannot read BARN's path: .npy format version 3.0, not 1.0 or 2.0"),
        (b"PK\x03\x04" + bytes(26), "cannot read BARN's path: the magic string is not correct"),
    ],
    ids=["huge-shape", "pickle", "floats", "truncated", "version-3", "not-npy"],
)
def test_a_path_file_whose_header_is_not_barns_exits_2_before_reading_its_data(
    tmp_path, capsys, content, reason
):
    shutil.copy(SAMPLE / "world_1.world", tmp_path / "world_1.world")
    (tmp_path / "path_1.npy").write_bytes(content)
    err = _imports_nothing(capsys, tmp_path, tmp_path / "out")
    assert err.startswith(f"error: {tmp_path / 'path_1.npy'}: ") and reason in err


@pytest.mark.parametrize(
    ("cells", "reason"),
    [
        (
            np.array([[9, 0], [2**64 - 1, 0], [9, 1]], dtype=np.uint64),  # 5.5e18 m there and back
            "cell 1 (row 18446744073709551615, column 0)",
        ),
        (np.array([[15, 0], [30, 1]]), "cell 1 (row 30, column 1)"),
        (np.array([[15, -1]], dtype=np.int8), "cell 0 (row 15, column -1)"),
    ],
    ids=["2.8e18-m-away", "row-30", "column-minus-1"],
)
def test_a_path_off_barns_grid_exits_2(tmp_path, capsys, cells, reason):
    shutil.copy(SAMPLE / "world_1.world", tmp_path / "world_1.world")
    np.save(tmp_path / "path_1.npy", cells)
    err = _imports_nothing(capsys, tmp_path, tmp_path / "out")
    assert err.startswith(
        f"error: {tmp_path / 'path_1.npy'}: {reason} is off BARN's grid: rows and columns are 0 to 29"
    )


def test_two_files_of_one_world_number_exit_2_naming_both(tmp_path, capsys):
    for name in ("world_1.world", "world_01.world"):
        shutil.copy(SAMPLE / "world_1.world", tmp_path / name)
    err = _imports_nothing(capsys, tmp_path, tmp_path / "out")
    first, second = tmp_path / "world_01.world", tmp_path / "world_1.world"  # in the order of their names
    assert err == f"error: {second}: has the world number 1, as {first} does\n"


def test_two_files_of_one_scenario_name_exit_2_naming_both(tmp_path, capsys):
    for name in ("Crate.world", "crate.world"):
        shutil.copy(SAMPLE / "world_1.world", tmp_path / name)
    first, second = tmp_path / "Crate.world", tmp_path / "crate.world"
    err = _imports_nothing(capsys, first, second, tmp_path / "out")
    assert err == f"error: {second}: has the scenario name 'barn_crate', as {first} does\n"


def test_angles_are_wrapped(tmp_path):
    world = tmp_path / "world_5.world"
    world.write_text(
        _sdf(
            _model(
                "crate",
                "<pose>1 2 0 6.283185307179586 0 7</pose>",
                _link("", "", "<box><size>1 1 1</size></box>"),
            )
        )
    )
    (crate,) = read_world_shapes(world)
    assert crate.yaw == pytest.approx(7 - 2 * math.pi)


def test_a_world_file_is_read_up_to_a_bound(monkeypatch):
    monkeypatch.setattr(sdf, "MAX_WORLD_BYTES", 1000)
    with pytest.raises(WorldFileError, match="is larger than 1000 bytes: not a world of BARN or DynaBARN"):
        read_world_shapes(SAMPLE / "world_1.world")
