"""The robot's facts read from robot.xml without MuJoCo agree with the model MuJoCo compiles."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from vplane_mj.files import model_path
from vplane_mj.robots.facts import BASE_BODY, RobotFacts, read_robot_facts, robot_facts, robot_geometry

SHIPPED = model_path("robot.xml")


def compiled_facts(path: Path) -> RobotFacts:
    """The same facts from the model MuJoCo compiles, posed by mj_forward (the reference)."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    origin = data.xpos[model.body(BASE_BODY).id][:2]
    reach = 0.0
    ring = np.linspace(0.0, 2 * math.pi, 73)
    for g in range(model.ngeom):
        if model.geom_bodyid[g] == 0:
            continue
        pos, rot, size = data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3), model.geom_size[g]
        gtype = model.geom_type[g]
        if gtype == mujoco.mjtGeom.mjGEOM_SPHERE:
            reach = max(reach, float(np.hypot(*(pos[:2] - origin))) + size[0])
            continue
        if gtype == mujoco.mjtGeom.mjGEOM_CYLINDER:
            rim = np.column_stack((size[0] * np.cos(ring), size[0] * np.sin(ring)))
            local = np.vstack([np.column_stack((rim, np.full(len(rim), z))) for z in (-size[1], size[1])])
        else:
            assert gtype == mujoco.mjtGeom.mjGEOM_BOX
            signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            local = signs * size
        points = pos + local @ rot.T
        reach = max(reach, float(np.max(np.hypot(*(points[:, :2] - origin).T))))
    left, right = model.body("wheel_left").pos, model.body("wheel_right").pos
    return RobotFacts(
        wheel_radius_m=float(model.geom("wheel_left").size[0]),
        track_m=float(abs(left[1] - right[1])),
        torque_limit_nm=float(model.actuator("wheel_left").forcerange[1]),
        radius_m=round(reach, 9),
    )


def test_the_shipped_robot_facts_are_those_of_the_compiled_model_bit_for_bit():
    assert robot_facts() == compiled_facts(SHIPPED)
    expected = {"wheel_radius_m": 0.04, "track_m": 0.15, "torque_limit_nm": 0.3, "radius_m": 0.11}
    assert robot_facts() == RobotFacts(**expected)
    assert robot_geometry() == expected


CHASSIS = '<geom name="chassis" type="cylinder" size="0.11 0.03" pos="0 0 0.025" mass="2.0"/>'
CASTER = '<geom name="caster_front" class="caster" pos="0.08 0 -0.025"/>'
VARIANTS = {
    "a wider chassis": [(CHASSIS, CHASSIS.replace("0.11 0.03", "0.13 0.03"))],
    "a caster further out": [(CASTER, CASTER.replace("0.08 0", "0.12 0"))],
    "wheels further apart, stronger motors (from the default class)": [
        ('pos="0 0.075 0"', 'pos="0 0.09 0"'),
        ('pos="0 -0.075 0"', 'pos="0 -0.1 0"'),
        ('forcerange="-0.3 0.3"', 'forcerange="-0.45 0.45"'),
    ],
    "bigger wheels (from the default class), base_link off the origin": [
        ('size="0.04 0.0125"', 'size="0.05 0.0125"'),
        ('pos="0 0 0.04" childclass', 'pos="0.5 -0.2 0.05" childclass'),
    ],
    "a mast turned by a quaternion, holding a box": [
        (
            CHASSIS,
            CHASSIS + '<body name="mast" pos="0.05 0 0.05" quat="0.924 0 0 0.383">'
            '<geom type="box" size="0.1 0.02 0.01"/></body>',
        )
    ],
    "a box tilted by Euler angles in degrees": [
        ('angle="radian"', 'angle="degree"'),
        ('euler="1.5707963 0 0"', 'euler="90 0 0"'),
        (CHASSIS, CHASSIS + '<geom type="box" size="0.09 0.03 0.06" pos="0.02 0 0.1" euler="20 35 50"/>'),
    ],
    "a body turned by Euler angles in radians, a sphere on it": [
        (
            CHASSIS,
            CHASSIS + '<body pos="0 0 0.1" euler="0.4 -0.3 1.1"><geom size="0.03" pos="0.1 0.02 0"/></body>',
        )
    ],
}


@pytest.mark.parametrize("edits", VARIANTS.values(), ids=VARIANTS.keys())
def test_facts_of_changed_models_agree_with_mujoco(edits, tmp_path):
    text = SHIPPED.read_text()
    for old, new in edits:
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "robot.xml"
    path.write_text(text)
    read, compiled = read_robot_facts(path), compiled_facts(path)
    assert read != robot_facts()  # the edit changed a fact
    assert read.wheel_radius_m == compiled.wheel_radius_m
    assert read.track_m == compiled.track_m
    assert read.torque_limit_nm == compiled.torque_limit_nm
    assert read.radius_m == pytest.approx(compiled.radius_m, abs=2e-9)


@pytest.mark.parametrize(
    ("old", "new", "refused"),
    [
        (CHASSIS, CHASSIS.replace('type="cylinder"', 'type="capsule"'), "capsule"),
        (CASTER, CASTER.replace('pos="0.08 0 -0.025"', 'fromto="0 0 0 0.1 0 0"'), "fromto"),
        ('angle="radian"', 'angle="radian" eulerseq="zyx"', "eulerseq"),
    ],
)
def test_what_the_reader_does_not_understand_is_refused(old, new, refused, tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(SHIPPED.read_text().replace(old, new))
    with pytest.raises(ValueError, match=refused):
        read_robot_facts(path)


LOADED = """
import sys
from vplane_mj.cli import main
statuses = [main(["check", "paper_c_escape", "single_box"]), main(["list"])]
print(statuses, "mujoco" in sys.modules)
"""


def test_checking_and_listing_do_not_load_mujoco():
    done = subprocess.run([sys.executable, "-c", LOADED], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "[0, 0] False"
