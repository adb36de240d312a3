"""The gear bodies off their bearing axes in the Python package: the pose keywords of
`MeshModel.evaluate` (`POSE_NAMES`, the FMU's input names), broadcast like the angles."""

import json
from pathlib import Path

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


def test_the_table_takes_a_pose():
    """At table fidelity a pose is evaluated with the table's pose sensitivities (built at the
    first posed call), close to the full model (1e-3 of 100 N·m); beyond the table's pose bound
    (0.02·m_n) it is refused, naming the relative component."""
    full = hg.MeshModel(slices=30)
    table = hg.MeshModel(fidelity="table", slices=30)
    pose = {"u_g_x": 4e-6, "th_g_y": -1.5e-5}
    a, b = full.evaluate(*STATE, **pose), table.evaluate(*STATE, **pose)
    assert abs(a["M_F_p"] - b["M_F_p"]) < 1e-3 * 100.0, (a["M_F_p"], b["M_F_p"])
    with pytest.raises(hg.GearMeshError, match="U_y"):
        table.evaluate(*STATE, u_g_y=61e-6)


# The guide's example supports (the file its figures were made with).
SUPPORTS = json.loads(
    (Path(__file__).resolve().parents[2] / "docs" / "gear-bodies" / "supports.json").read_text()
)


def test_simulate_on_supports_reports_poses_and_support_forces():
    """`simulate(..., supports=...)` is the CLI's `simulate --supports`: the poses and support
    forces per output time, and the statistics over the last whole mesh periods. The mean
    support force on each body balances its mean mesh force within 2 % (whole mesh periods:
    small mean accelerations), and the statistics are those of the arrays."""
    tr = hg.simulate(None, 300.0, 2.2e-3, slices=60, supports=SUPPORTS)
    s = tr.supports
    assert s["window_mesh_periods"] == 3
    assert len(s["modes_hz"]) >= 12 and all(f > 0 for f in s["modes_hz"])
    n = tr.time.size
    for k in hg.POSE_NAMES + ("R_p_x", "R_g_my"):
        assert tr.arrays[k].shape == (n,), k
    w = 3 * 128
    r = s["support_forces"]["R_p_x"]
    assert abs(tr.R_p_x[-w:].mean() - r["reaction_mean_n"]) < 1e-9 * abs(r["reaction_mean_n"])
    assert len(r["orders"]) == 3
    f = tr.F_p_x[-w:].mean()
    assert abs(r["reaction_mean_n"] + f) < 0.02 * abs(f)
    # Refused with the reason: an explicit step, DOPRI5, friction.
    for bad in ({"dt": 1e-5}, {"method": "dopri5"}, {"friction": {"model": "constant", "mu": 0.05}}):
        with pytest.raises(hg.ParameterError, match="supports"):
            hg.simulate(None, 300.0, 2.2e-3, supports=SUPPORTS, **bad)
    # A bad support names its key.
    with pytest.raises(hg.ParameterError, match="supports.gear.mass_kg"):
        hg.simulate(None, 300.0, 2.2e-3, supports={"gear": {**SUPPORTS["gear"], "mass_kg": -1}})


def test_sweep_on_supports_reports_the_supported_curve():
    """`sweep(..., supports=...)` is the CLI's `sweep --supports`: per speed TE_max/STE_max on
    the supports, steady, the coupled modes and where mesh order 1 meets them. Around the mode
    at 1.89 kHz (395.8 rad/s) the response peaks inside the range."""
    r = hg.sweep(None, np.linspace(380.0, 400.0, 5), supports=SUPPORTS, refine_runs=0)
    s = r.supports
    ratio = np.array(s["te_max_over_ste_max"])
    assert ratio.shape == (5,) and all(s["steady"])
    assert any(abs(w - 395.8) < 1.0 for w in s["mode_speeds_rad_s"])
    assert ratio.max() > ratio[0] and ratio.max() > ratio[-1]
    assert len(s["support_forces"]["R_g_y"]["order_1_n"]) == 5
    with pytest.raises(hg.ParameterError, match="friction"):
        hg.sweep(None, [300.0], supports=SUPPORTS, friction={"model": "constant", "mu": 0.05})
