"""The gear bodies off their bearing axes in the Python package: the pose keywords of
`MeshModel.evaluate` (`POSE_NAMES`, the FMU's input names), broadcast like the angles."""

import numpy as np
import pytest

hg = pytest.importorskip("helical_gear")

# A loaded, running state of Table 1: φp = 0.01 rad at about 100 N·m, ω_p = 100 rad/s with the
# gear at the rigid ratio.
STATE = (0.01, -0.0060851, 100.0, -63.83)


def test_pose_names_are_the_fmu_inputs():
    assert len(hg.POSE_NAMES) == 20
    assert hg.POSE_NAMES[:5] == ("u_p_x", "u_p_y", "u_p_z", "th_p_x", "th_p_y")
    assert hg.POSE_NAMES[15:] == ("v_g_x", "v_g_y", "v_g_z", "om_g_x", "om_g_y")


def test_zero_pose_and_a_common_translation_change_nothing():
    m = hg.MeshModel(slices=60)
    plain = m.evaluate(*STATE)
    zero = m.evaluate(*STATE, **{k: 0.0 for k in hg.POSE_NAMES})
    assert all(zero[k].tobytes() == plain[k].tobytes() for k in hg.OUTPUT_NAMES)
    # Both bodies moved by the same vector: the relative pose is exactly zero.
    shift = {"u_p_x": 20e-6, "u_g_x": 20e-6, "u_p_z": -35e-6, "u_g_z": -35e-6}
    moved = m.evaluate(*STATE, **shift)
    assert all(moved[k].tobytes() == plain[k].tobytes() for k in hg.OUTPUT_NAMES)


def test_a_wider_centre_distance_unloads_the_mesh_and_broadcasts():
    m = hg.MeshModel(slices=60)
    du = np.array([0.0, 5e-6, 10e-6])
    out = m.evaluate(*STATE, u_g_x=du)
    assert out["M_F_p"].shape == (3,)
    # The flanks open by Δa·sin α_wt: the torque at a fixed TE falls monotonically.
    assert out["M_F_p"][0] > out["M_F_p"][1] > out["M_F_p"][2] > 0.0
    # A body moving away from the mesh opens it: the damping torque falls.
    fast = m.evaluate(*STATE, v_g_x=np.array([0.0, 0.01]))
    assert fast["M_D_p"][1] < fast["M_D_p"][0]


def test_bad_pose_input_names_the_keyword_or_the_component():
    m = hg.MeshModel(slices=30)
    with pytest.raises(hg.ParameterError, match="u_gx"):
        m.evaluate(*STATE, u_gx=1e-6)
    with pytest.raises(hg.ParameterError, match="u_g_y"):
        m.evaluate(*STATE, u_g_y=1.0)
    with pytest.raises(hg.ParameterError, match="om_p_x"):
        m.evaluate(*STATE, om_p_x=float("nan"))


def test_the_table_refuses_a_pose():
    m = hg.MeshModel(fidelity="table", slices=30)
    with pytest.raises(hg.GearMeshError, match="full fidelity"):
        m.evaluate(*STATE, u_g_x=1e-6)
