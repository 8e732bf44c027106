"""Errors: a Python exception class per kind, with the location as attributes; never a
crash of the interpreter."""

from __future__ import annotations

import pytest

import restpose

MASS = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'


def test_missing_file_is_a_file_error(tmp_path):
    with pytest.raises(restpose.FileError) as e:
        restpose.load(tmp_path / "nope.urdf")
    assert isinstance(e.value, OSError) and isinstance(e.value, restpose.Error)
    assert e.value.file.endswith("nope.urdf") and e.value.errno == 2


def test_input_error_names_file_line_column_element(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(
        '<robot name="r">\n'
        '  <link name="base"/>\n'
        f'  <link name="arm">{MASS}</link>\n'
        '  <joint name="j" type="revolute">\n'
        '    <parent link="base"/><child link="arm"/>\n'
        '    <axis xyz="0 0 0"/>\n'
        "  </joint>\n"
        "</robot>\n"
    )
    with pytest.raises(restpose.InputError) as e:
        restpose.load(path)
    err = e.value
    assert isinstance(err, ValueError)
    assert err.file == str(path) and err.line == 6 and err.column == 5
    assert err.element == "axis"
    assert str(err).startswith(f"{path}:6:5:")


def test_malformed_xml_has_a_location_and_no_element():
    with pytest.raises(restpose.InputError) as e:
        restpose.load_string('<robot name="r"><link name="a"></robot>', file="bad.urdf")
    assert e.value.file == "bad.urdf" and e.value.line == 1 and e.value.element is None


def test_extension_element_is_named_as_written():
    text = (
        '<robot name="r" xmlns:mech="urn:urdf-mech:1"><link name="base"/>'
        f'<link name="arm">{MASS}</link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/></joint>'
        '<mech:joint_spring joint="j" stiffness="oops"/></robot>'
    )
    with pytest.raises(restpose.InputError) as e:
        restpose.load_string(text)
    assert e.value.element == "mech:joint_spring"


def test_unknown_joint_suggests_the_closest_name(robots):
    with pytest.raises(restpose.UnknownJointError) as e:
        restpose.load(robots / "pendulum.urdf", locks={"pivt": 0.0})
    assert e.value.joint == "pivt" and e.value.suggestion == "pivot"
    assert isinstance(e.value, LookupError)
    result = restpose.load(robots / "pendulum.urdf").solve()
    with pytest.raises(restpose.UnknownJointError):
        result.joint("nope")
    with pytest.raises(KeyError):
        result.link_transform("nope")


def test_coordinate_out_of_range_names_the_joint(robots):
    with pytest.raises(restpose.CoordinateError) as e:
        restpose.load(robots / "pendulum.urdf", locks={"pivot[3]": 0.0})
    err = e.value
    assert err.joint == "pivot" and err.dof == 3 and err.count == 1
    assert err.file.endswith("pendulum.urdf") and err.line > 0 and err.element == "joint"
    model = restpose.load(robots / "pendulum.urdf")
    with pytest.raises(restpose.CoordinateError) as e:
        model.verify({"pivot": [0.0, 1.0]})
    assert e.value.joint == "pivot" and e.value.count == 2


def test_bad_pose_file(robots, tmp_path):
    p = tmp_path / "pose.json"
    p.write_text("[1, 2, 3]")
    with pytest.raises(restpose.PoseError) as e:
        restpose.load(robots / "pendulum.urdf").verify(p)
    assert e.value.file == str(p)


def test_constant_energy(tmp_path):
    text = (
        '<robot name="free"><link name="base"/><link name="arm"/>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/></joint></robot>'
    )
    with pytest.raises(restpose.ConstantEnergyError) as e:
        restpose.load_string(text).solve()
    assert e.value.robot == "free" and e.value.dof == 1


def test_assembly_error_names_the_loop_joint():
    b = restpose.ModelBuilder("broken loop")
    b.add_rigid_body("a", mass=1.0, com=(0.5, 0, 0))
    b.add_joint("j1", "revolute", parent=None, child="a", axis=(0, 1, 0))
    # a rod of 10 m from the world to a point 1 m from the pivot cannot close
    b.add_joint("rod", "distance", parent=None, child="a", xyz=(20, 0, 0), loop=True, length=1.0)
    with pytest.raises(restpose.AssemblyError) as e:
        b.build().solve()
    assert e.value.joint == "rod" and e.value.residual > 1.0
