"""`vplane-mj import dynabarn`: DynaBARN's Gazebo worlds and the keyframes in their plugins' code.

The fixture tests/data/dynabarn/ is DynaBARN's world 0 as the BARN challenge ships it
(world_0.world, unchanged, malformations included), the 11 plugins it loads (plugins/), the
keyframes read from them (keyframes_world_0.json) and the MIT licence they come under (LICENSE).
The altered plugins are copies of easylibobs_120.so with a few bytes of its `Load` changed at
addresses read off its disassembly (file offsets equal addresses in its .text and .rodata).
"""

import json
import math
import os
import shutil
import struct
from pathlib import Path

import pytest

from vplane_mj.cli import main
from vplane_mj.errors import WorldFileError
from vplane_mj.scenario import load_scenario, parse_document
from vplane_mj.worlds import dynabarn_import, dynabarn_plugins
from vplane_mj.worlds.dynabarn_import import import_worlds, report_line
from vplane_mj.worlds.dynabarn_plugins import PluginAnimation, read_plugin

SAMPLE = Path(__file__).parent / "data" / "dynabarn"
WORLD = SAMPLE / "world_0.world"
EXPECTED = json.loads((SAMPLE / "keyframes_world_0.json").read_text())["models"]
PLUGIN_120 = SAMPLE / "plugins" / "easylibobs_120.so"


def _bits(value: float) -> bytes:
    return struct.pack("<d", value)


def _patched(tmp_path: Path, offset: int, old: bytes, new: bytes) -> Path:
    """A copy of easylibobs_120.so with the bytes `old` at `offset` replaced by `new`."""
    assert len(old) == len(new)
    data = bytearray(PLUGIN_120.read_bytes())
    assert data[offset : offset + len(old)] == old, "the fixture is not the plugin these offsets are for"
    data[offset : offset + len(old)] = new
    path = tmp_path / "easylibobs_120.so"
    path.write_bytes(bytes(data))
    return path


def _refused(path: Path, *fragments: str) -> WorldFileError:
    with pytest.raises(WorldFileError) as caught:
        read_plugin(path)
    assert caught.value.source == str(path) and str(path) in str(caught.value)
    for fragment in fragments:
        assert fragment in str(caught.value)
    return caught.value


@pytest.fixture(scope="module")
def world_0():
    """The sample world converted, once for the module."""
    (world,) = import_worlds([WORLD])
    return world


def test_the_fixture_holds_the_11_plugins_the_expected_keyframes_name():
    assert sorted(model["plugin"] for model in EXPECTED) == sorted(
        f"plugins/{path.name}" for path in (SAMPLE / "plugins").iterdir()
    )
    assert len(EXPECTED) == 11


@pytest.mark.parametrize("model", EXPECTED, ids=[model["model"] for model in EXPECTED])
def test_every_plugin_reads_as_the_keyframes_dynabarn_wrote(model):
    animation = read_plugin(SAMPLE / model["plugin"])
    assert animation.loop is True
    assert animation.duration_s == model["duration_s"]
    assert animation.keyframes == tuple(tuple(keyframe) for keyframe in model["keyframes"])
    values = [animation.duration_s, *(value for keyframe in animation.keyframes for value in keyframe)]
    assert all(round(value, 2) == value for value in values)  # two decimals, as DynaBARN wrote them


def test_the_world_converts_to_11_moving_cylinders_with_arena_frame_keyframes(world_0):
    document = world_0.case.document
    assert world_0.case.name == document["name"] == "dynabarn_world_0"
    assert document["world"]["size"] == [23.0, 22.0] and document["world"]["border"] is False
    assert document["robot"] == {
        "profile": "jackal",
        "start": [22.0, 11.0],
        "start_yaw_deg": 180.0,
        "goal": [2.0, 11.0],
        "goal_tolerance": 1.0,
    }
    assert document["run"] == {"time_limit_s": 100.0}
    obstacles = document["world"]["obstacles"]
    assert len(obstacles) == world_0.cylinders == 11
    for obstacle, model in zip(obstacles, EXPECTED, strict=True):  # in the world file's order
        expected = [[t, round(x + 11.0, 6), round(y + 11.0, 6)] for t, x, y in model["keyframes"]]
        motion = {"keyframes": expected, "loop": True, "interpolation": "spline", "phase_s": "random"}
        assert obstacle == {"kind": "cylinder", "radius": 0.5, "motion": motion}
        assert all(1.0 <= value <= 21.0 for _, x, y in expected for value in (x, y))
    scenario = parse_document(document, str(WORLD))
    assert len(scenario.world.moving) == 11 and not scenario.world.obstacles


def test_the_report_line_gives_count_speed_difficulty_and_walls_left_out(world_0):
    speeds = [
        math.dist(a[1:], b[1:]) / (b[0] - a[0])
        for model in EXPECTED
        for a, b in zip(model["keyframes"], model["keyframes"][1:], strict=False)
    ]
    assert world_0.mean_speed_mps == pytest.approx(sum(speeds) / len(speeds))
    assert 0.66 <= world_0.mean_speed_mps <= 0.84  # DynaBARN's easy worlds, measured
    assert world_0.difficulty == "easy" and world_0.static_left_out == 3
    line = report_line(world_0)
    assert line == (
        "dynabarn_world_0: 11 moving cylinders, mean speed 0.74 m/s between keyframes, "
        "DynaBARN's easy third; 3 static models left out (walls)"
    )


THIRDS = [
    ("world_19.world", "easy"),
    ("world_20.world", "medium"),
    ("world_59.world", "hard"),
    ("world_60.world", None),
]


@pytest.mark.parametrize(("name", "difficulty"), THIRDS)
def test_the_difficulty_third_follows_the_file_number(name, difficulty):
    assert dynabarn_import.difficulty(Path(name)) == difficulty


def test_a_constant_moved_in_as_an_immediate_reads_as_well(tmp_path):
    """Keyframe 1's time, loaded through rax and a slot from .rodata, becomes `movabs rax, imm64;
    movq xmm0, rax` and 7 nops (the same 22 bytes)."""
    old = bytes.fromhex("488b0502400000 48898550ffffff f20f108550ffffff")
    for time_s in (1.24, 1.5):
        new = b"\x48\xb8" + _bits(time_s) + bytes.fromhex("66480f6ec0") + b"\x90" * 7
        animation = read_plugin(_patched(tmp_path, 0x12DCF, old, new))
        assert animation.keyframes[1][0] == time_s
        assert animation.keyframes[0] == (0.0, -2.0, 10.0) and len(animation.keyframes) == 9


@pytest.mark.parametrize(
    ("offset", "old", "new", "fragment"),
    [
        # keyframe 1's CreateKeyFrame call made nops: its Vector3 follows the Rotation
        (0x12DE8, "e8d3c7ffff", "9090909090", "where the template calls PoseAnimation::CreateKeyFrame(t)"),
        # the same call made `call rax`
        (0x12DE8, "e8d3c7ffff", "ffd0909090", "goes to a function the reader cannot name"),
        # keyframe 1's x loaded from [rax] instead of .rodata
        (0x12E07, "f20f1005d93f0000", "f20f100090909090", "a keyframe's x is not a constant"),
        # keyframe 1's z pointer (rcx) aimed at y's slot
        (0x12E17, "488d4da0", "488d4d80", "a keyframe's z is 9.56 m, not 0"),
        # the duration loaded from keyframe 1's time
        (0x12C99, "488b0520410000", "488b0538410000", "lasts 1.24 s, its last keyframe is at 15.05 s"),
        # PoseAnimation(name, duration, loop = false)
        (0x12CA0, "ba01000000", "ba00000000", "does not loop"),
        # keyframe 2's time loaded from keyframe 1's
        (0x12EBE, "488b052b3f0000", "488b05133f0000", "keyframe 2 at 1.24 s does not come after 1.24 s"),
    ],
    ids=["call-removed", "call-indirect", "x-unknown", "z-not-zero", "duration", "no-loop", "times-repeat"],
)
def test_a_plugin_whose_code_was_altered_is_refused(tmp_path, offset, old, new, fragment):
    path = _patched(tmp_path, offset, bytes.fromhex(old), bytes.fromhex(new))
    error = _refused(path, fragment)
    assert error.element == "gazebo::obs_120::Load"


def test_a_truncated_plugin_is_refused(tmp_path):
    path = tmp_path / "easylibobs_120.so"
    path.write_bytes(PLUGIN_120.read_bytes()[:100_000])
    _refused(path)


def test_a_file_that_is_not_elf_is_refused(tmp_path):
    path = tmp_path / "easylibobs_1.so"
    path.write_text("#!/bin/sh\necho not a plugin\n")
    _refused(path, "not an ELF file")


def test_an_elf_file_for_another_machine_is_refused(tmp_path):
    path = _patched(tmp_path, 18, b"\x3e\x00", b"\xb7\x00")  # e_machine: EM_AARCH64
    _refused(path, "not an x86-64 shared object", "EM_AARCH64")


def test_a_plugin_without_the_load_function_is_refused(tmp_path):
    path = tmp_path / "easylibobs_120.so"
    path.write_bytes(PLUGIN_120.read_bytes().replace(b"obs_1204LoadE", b"obs_1204LoadX"))
    _refused(path, "must define one gazebo::obs_N::Load function")


def test_reads_are_bounded(tmp_path, monkeypatch):
    monkeypatch.setattr(dynabarn_plugins, "MAX_FUNCTION_BYTES", 1000)
    _refused(PLUGIN_120, "is 2976 bytes long, must be 1 to 1000")
    monkeypatch.setattr(dynabarn_plugins, "MAX_FILE_BYTES", 1000)
    _refused(PLUGIN_120, "larger than 1000 bytes")


def _world(tmp_path: Path, text: str | None = None) -> Path:
    path = tmp_path / "world_0.world"
    path.write_text(WORLD.read_text() if text is None else text)
    return path


@pytest.fixture
def fake_plugins(monkeypatch):
    """Plugins "read" from keyframes_world_0.json by file name, recording the paths read."""
    by_name = {Path(model["plugin"]).name: model for model in EXPECTED}
    read: list[Path] = []

    def fake(path: Path, source: str | None = None) -> PluginAnimation:
        read.append(path)
        model = by_name[path.name]
        return PluginAnimation(model["duration_s"], True, tuple(map(tuple, model["keyframes"])))

    monkeypatch.setattr(dynabarn_import, "read_plugin", fake)
    return read


def test_plugins_are_found_in_the_folder_given_else_in_plugins_beside_else_beside(tmp_path, fake_plugins):
    world = _world(tmp_path)
    (given,) = import_worlds([world], plugins=SAMPLE / "plugins")
    assert {path.parent for path in fake_plugins} == {SAMPLE / "plugins"} and given.cylinders == 11
    fake_plugins.clear()
    for plugin in (SAMPLE / "plugins").iterdir():
        shutil.copy(plugin, tmp_path / plugin.name)
    import_worlds([world])
    assert {path.parent for path in fake_plugins} == {tmp_path}
    fake_plugins.clear()
    (beside,) = import_worlds([SAMPLE])  # a directory of world_N.world files
    assert {path.parent for path in fake_plugins} == {SAMPLE / "plugins"}
    assert beside.case.document == given.case.document


def test_a_missing_plugin_is_refused_naming_the_world_and_the_plugin(tmp_path, fake_plugins):
    world = _world(tmp_path)
    with pytest.raises(WorldFileError) as caught:
        import_worlds([world])
    assert caught.value.source == str(world)
    assert caught.value.element == "model[@name='easylibobs_51']/plugin"
    message = str(caught.value)
    assert "easylibobs_51.so is in none of" in message and str(tmp_path / "plugins") in message


def test_an_altered_plugin_refuses_the_world_naming_the_plugin(tmp_path):
    shutil.copytree(SAMPLE / "plugins", tmp_path / "plugins")
    world = _world(tmp_path)
    bad = _patched(tmp_path / "plugins", 0x12CA0, bytes.fromhex("ba01000000"), bytes.fromhex("ba00000000"))
    with pytest.raises(WorldFileError) as caught:
        import_worlds([world])
    assert caught.value.source == str(bad) and "does not loop" in str(caught.value)


@pytest.mark.parametrize(
    ("old", "new", "fragment"),
    [
        ("<uri>model://sun</uri>", "<uri>model://jackal</uri>", "include/uri: 'model://jackal' is not"),
        ("<pose frame=''>", "<pose frame=world>", "not well-formed XML"),
        ("</sdf>", "", "not well-formed XML"),
        ('<model name="top_wall">', '<model name="middle_wall">', "has no plugin and is not one of"),
        ("filename='easylibobs_51.so'", "filename='../easylibobs_51.so'", "must name a DynaBARN plugin"),
        ("<include>", "<actor name='a'/><include>", "actor: <actor> is not supported"),
        ("<cylinder>", "<box><size>1 1 1</size></box><cylinder>", "must be one <cylinder> (a moving model)"),
    ],
    ids=["include", "unquoted-attribute", "truncated", "unknown-static-model", "plugin-path", "actor", "box"],
)
def test_a_world_that_is_not_dynabarns_is_refused(tmp_path, fake_plugins, old, new, fragment):
    text = WORLD.read_text()
    assert old in text
    world = _world(tmp_path, text.replace(old, new, 1))
    with pytest.raises(WorldFileError) as caught:
        import_worlds([world], plugins=SAMPLE / "plugins")
    assert caught.value.source == str(world) and fragment in str(caught.value)


def test_the_command_writes_the_scenario_and_refuses_an_altered_plugin_writing_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["import", "dynabarn", str(WORLD), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "dynabarn_world_0: 11 moving cylinders" in printed
    written = out / "dynabarn_world_0.toml"
    assert written.is_file() and len(load_scenario(str(written)).world.moving) == 11
    plugins = tmp_path / "plugins"
    shutil.copytree(SAMPLE / "plugins", plugins)
    data = bytearray((plugins / "easylibobs_120.so").read_bytes())
    data[:4] = b"\x00ELF"  # not an ELF file any more
    (plugins / "easylibobs_120.so").write_bytes(bytes(data))
    refused = tmp_path / "refused"
    assert main(["import", "dynabarn", str(WORLD), "--plugins", str(plugins), "--out", str(refused)]) == 2
    err = capsys.readouterr().err
    assert f"error: {plugins / 'easylibobs_120.so'}" in err and "Traceback" not in err
    assert not refused.exists()
    assert main(["import", "barn", str(WORLD), "--plugins", str(plugins), "--out", str(refused)]) == 2
    assert "--plugins" in capsys.readouterr().err


def _imports_nothing(capsys, *args: Path) -> str:
    """Import `args` into the last one, which must exit 2 and write nothing: what it printed on stderr."""
    out = args[-1]
    command = ["import", "dynabarn", *map(str, args[:-1]), "--plugins", str(SAMPLE / "plugins")]
    assert main([*command, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err) < 600 and not out.exists()
    return err


FIRST_LINK = "model[@name='easylibobs_51']/link[@name='link']"
RADIUS = f"{FIRST_LINK}/collision[@name='collision']/geometry/cylinder/radius"


@pytest.mark.parametrize(
    ("old", "new", "element", "reason"),
    [
        (
            "<self_collide>0</self_collide>",
            "<include><uri>model://sun</uri></include>",
            f"{FIRST_LINK}/include",
            "<include> is not supported inside another element",
        ),
        (
            "<self_collide>0</self_collide>",
            "<model name='rock'/>",
            f"{FIRST_LINK}/model[@name='rock']",
            "<model> is not supported inside another element",
        ),
        (
            "<radius>0.5000</radius>",
            "<radius>0.5_000</radius>",
            RADIUS,
            "must be a number (metres) in decimal or scientific notation, each within +-10000, got '0.5_000'",
        ),
        ("<radius>0.5000</radius>", "<radius>1e300</radius>", RADIUS, "got '1e300'"),
        (
            "<radius>0.5000</radius>",
            "<radius>2e3</radius>",
            RADIUS,
            "must be greater than 0 and at most 1000 m",
        ),
    ],
    ids=["include-in-link", "model-in-link", "underscore", "radius-1e300", "radius-2-km"],
)
def test_a_hostile_world_exits_2_naming_file_and_element_and_writes_nothing(
    tmp_path, capsys, fake_plugins, old, new, element, reason
):
    text = WORLD.read_text()
    assert old in text
    world = _world(tmp_path, text.replace(old, new, 1))
    err = _imports_nothing(capsys, world, tmp_path / "out")
    assert err.startswith(f"error: {world}: {element}: ") and reason in err


def test_a_long_name_is_cut_in_messages(tmp_path, capsys, fake_plugins):
    name = "x" * 2**20
    world = _world(
        tmp_path, WORLD.read_text().replace("'easylibobs_51'>", f"'{name}'><link name='link'/>", 1)
    )
    err = _imports_nothing(capsys, world, tmp_path / "out")
    element = "model[@name='" + "x" * 80 + "'... (1048576 characters)]"
    assert err.startswith(f"error: {world}: {element}: must have one link with one collision, got 2 and 1")


def test_two_files_of_one_world_number_exit_2_naming_both(tmp_path, capsys, fake_plugins):
    for name in ("world_0.world", "world_00.world"):
        shutil.copy(WORLD, tmp_path / name)
    err = _imports_nothing(capsys, tmp_path, tmp_path / "out")
    first, second = tmp_path / "world_0.world", tmp_path / "world_00.world"  # in the order of their names
    assert err == f"error: {second}: has the world number 0, as {first} does\n"


def test_a_file_name_that_is_not_utf8_imports_and_is_shown_escaped(tmp_path, capsys, fake_plugins):
    world = Path(os.fsdecode(os.fsencode(tmp_path) + b"/w\xff.world"))
    shutil.copy(WORLD, world)
    out = tmp_path / "out"
    assert (
        main(["import", "dynabarn", str(world), "--plugins", str(SAMPLE / "plugins"), "--out", str(out)]) == 0
    )
    assert f"wrote {out / 'dynabarn_w_.toml'}" in capsys.readouterr().out
    description = load_scenario(str(out / "dynabarn_w_.toml")).description
    assert description.startswith("DynaBARN world w\\xff.world (Gazebo)")
    world.write_text("<sdf>")
    err = _imports_nothing(capsys, world, tmp_path / "refused")
    assert err.startswith(f"error: {tmp_path}/w\\xff.world: not well-formed XML")
