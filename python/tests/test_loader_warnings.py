"""Loader warnings reach Python (issue 31): each is issued as an ``armsim.LoaderWarning``
(a ``UserWarning``) pointing at the caller's line and kept in ``model.warnings``; a clean
file gives none; ``strict=True`` raises the first instead."""

from __future__ import annotations

import pickle
import warnings

import pytest

import armsim as am
from conftest import ROBOTS

INERTIA = '<inertial><mass value="1"/><inertia ixx="{}" iyy="{}" izz="{}" ixy="0" ixz="0" iyz="0"/></inertial>'


def urdf(joint_type: str, izz: float) -> str:
    """A base on a `joint_type` joint to the world, and an arm whose inertia has
    `izz` (above 0.02 it breaks the triangle inequality)."""
    return f"""<robot name="float">
  <link name="world"/>
  <link name="base">{INERTIA.format(0.1, 0.1, 0.1)}</link>
  <link name="arm">{INERTIA.format(0.01, 0.01, izz)}</link>
  <joint name="free" type="{joint_type}"><parent link="world"/><child link="base"/></joint>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def loaded(text: str, **kw):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        m = am.Model.from_string(text, "float.urdf", **kw)
    return m, got


def test_a_floating_joint_and_a_bad_inertia_warn_and_are_kept():
    m, got = loaded(urdf("floating", 0.5))
    assert [w.category for w in got] == [am.LoaderWarning, am.LoaderWarning]
    assert issubclass(am.LoaderWarning, UserWarning)
    msgs = [str(w.message) for w in got]
    assert msgs == m.warnings
    assert msgs[0].startswith("float.urdf:5: joint 'free': floating joint: modelled as the one-axis joints free_x")
    assert msgs[1].startswith("float.urdf:4: link 'arm': inertial: principal moments") and "triangle inequality" in msgs[1]
    assert got[0].filename == __file__, "the warning points at the caller"
    assert m.joint_names[:6] == ["free_x", "free_y", "free_z", "free_yaw", "free_pitch", "free_roll"]


def test_a_clean_model_has_no_warnings():
    m, got = loaded(urdf("fixed", 0.01))
    assert got == [] and m.warnings == []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert am.Model.from_file(ROBOTS / "ur5.urdf").warnings == []


def test_strict_raises_the_first_warning_as_an_error():
    with pytest.raises(am.ArmsimError, match="float.urdf:5: joint 'free': floating joint"):
        am.Model.from_string(urdf("floating", 0.5), "float.urdf", strict=True)
    with pytest.raises(am.ArmsimError, match="link 'arm'.*triangle inequality"):
        am.Model.from_string(urdf("fixed", 0.5), "float.urdf", strict=True)


def test_files_and_robots_warn_too_and_filters_apply(tmp_path):
    path = tmp_path / "float.urdf"
    path.write_text(urdf("planar", 0.01))
    with pytest.warns(am.LoaderWarning) as got:
        m = am.Model.from_file(path)
    assert [str(w.message) for w in got] == m.warnings and len(m.warnings) == 2
    assert m.warnings[0].startswith(f"{path}:5: joint 'free': planar joint: modelled as the one-axis joints free_x, free_y, free_yaw")
    assert "planar joint: <axis xyz=\"1 0 0\"> is not the joint frame's z" in m.warnings[1]
    with pytest.warns(am.LoaderWarning, match="planar joint"):
        r = am.Robot.from_file(path)
    assert r.model.warnings == m.warnings
    # A warning filter set to "error" makes loading raise (as for any Python warning).
    with warnings.catch_warnings():
        warnings.simplefilter("error", am.LoaderWarning)
        with pytest.raises(am.LoaderWarning, match="planar joint"):
            am.Model.from_file(path)


def test_warnings_survive_pickling_without_being_issued_again():
    m, _ = loaded(urdf("floating", 0.5))
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        m2 = pickle.loads(pickle.dumps(m))
    assert got == []
    assert m2.warnings == m.warnings and len(m2.warnings) == 2
