"""The Python paths of the dynamics' step rule and work bounds (the library's
`dynamics::limits`): the default `simulate` step is stable at low speed and at rest, and
requests whose cost grows with an input raise `ParameterError` at once instead of running for
hours or aborting the interpreter on a failed allocation."""

import numpy as np
import pytest

hg = pytest.importorskip("helical_gear")

# A coarse table (builds in well under a second) of Table 1.
FAST = dict(fidelity="table", slices=60, table_size=(24, 16))


@pytest.fixture(scope="module")
def model():
    return hg.MeshModel(hg.GearPair(), **FAST)


def test_simulate_default_step_is_stable_at_8_rad_s(model):
    tr = hg.simulate(model, 8.0, 0.02)
    te = np.asarray(tr.TE)
    te0 = te[0]
    assert np.all(np.isfinite(te))
    # Quasi-static running: TE stays near the static TE (the old step T_m/128 gave ±0.8 m).
    assert np.max(np.abs(te - te0)) < 0.5 * te0
    # The step resolves the mesh mode (~1.6e4 rad/s), not the mesh period (2.6e-4 s / 128).
    dt = tr.time[1] - tr.time[0]
    assert dt < 2e-5


@pytest.mark.parametrize("w_p", [0.0, 0.5, 1.0, 5.0, 8.0, 10.0])
def test_simulate_from_rest_to_10_rad_s_agrees_with_a_4x_finer_step(model, w_p):
    t_end = 0.005
    coarse = hg.simulate(model, w_p, t_end)
    dt = coarse.time[1] - coarse.time[0]
    fine = hg.simulate(model, w_p, t_end, dt=dt / 4.0)
    te_c = np.asarray(coarse.TE)
    te_f = np.asarray(fine.TE)[::4]
    assert te_f.shape == te_c.shape
    assert np.max(np.abs(te_c - te_f)) / te_c[0] < 1e-3


def test_simulate_refuses_an_unstable_explicit_step(model):
    # T_m/128 at 8 rad/s: ω_fast·dt ≈ 3.2, outside RK4's stability region.
    t_m = 2 * np.pi / (30 * 8.0)
    with pytest.raises(hg.ParameterError, match="unstable"):
        hg.simulate(model, 8.0, 100 * t_m / 128, dt=t_m / 128)


def test_simulate_refuses_a_39_gb_trajectory(model):
    # At the largest speed, 1e5 rad/s, one second at the default step: 6e7 samples (8.8 GB).
    with pytest.raises(hg.ParameterError, match="samples"):
        hg.simulate(model, 1e5, 1.0)
    with pytest.raises(hg.ParameterError, match="samples"):
        hg.simulate(model, 100.0, 1e-3, dt=1e-12)


def test_sweep_at_0_01_rad_s_ends_within_bounds(model):
    # Refused at once (the run would take 2e10 RK4 steps), reported for its speed.
    with pytest.raises(hg.GearMeshError, match="at most"):
        hg.sweep(model, [0.01, 0.02])


def test_sweep_refuses_1e9_refine_runs(model):
    with pytest.raises(hg.ParameterError, match="refine"):
        hg.sweep(model, [300.0, 400.0], refine_runs=10**9)


def test_table_size_4096_is_refused():
    with pytest.raises(hg.ParameterError, match="65536"):
        hg.MeshModel(hg.GearPair(), fidelity="table", slices=60, table_size=(4096, 4096))


# ---------------------------------------------------------------------------------------------
# Never silent: results carry their pair, interfaces agree, limits are usable, messages name
# the cause.

BEARINGS_TABLE1 = {
    "pinion": {"locating_z_m": -0.02, "floating_z_m": 0.035},
    "gear": {"locating_z_m": -0.02, "floating_z_m": 0.035},
}


def test_bearing_loads_use_the_pair_the_result_carries():
    wide = hg.GearPair(face_width_m=0.03)
    c = hg.compliance(wide, fe_density="coarse")
    curve = hg.static_curve(hg.MeshModel(wide, slices=40, compliance=c), points_per_pitch=3)
    assert curve.pair == wide
    own = hg.bearing_loads(curve, BEARINGS_TABLE1)
    same = hg.bearing_loads(curve, BEARINGS_TABLE1, pair=wide)
    assert np.array_equal(own.arrays["pinion_locating_x"], same.arrays["pinion_locating_x"])
    # Statics by hand (the oracle): the locating bearing's x reaction of a shaft with the gear
    # centre at b/2 = 15 mm, (d_f·F_x − M_y)/(d_l − d_f).
    d_l, d_f = -0.02 - 0.015, 0.035 - 0.015
    fx, my = np.asarray(curve.F_p_x), np.asarray(curve.M_p_y)
    np.testing.assert_allclose(own.arrays["pinion_locating_x"], (d_f * fx - my) / (d_l - d_f),
                               rtol=1e-12, atol=1e-9)
    with pytest.raises(hg.ParameterError, match="differs"):
        hg.bearing_loads(curve, BEARINGS_TABLE1, pair=hg.GearPair())

    class Bare:
        pass

    bare = Bare()
    for k in hg.FORCE_NAMES:
        setattr(bare, k, np.asarray(getattr(curve, k)))
    with pytest.raises(hg.ParameterError, match="pair="):
        hg.bearing_loads(bare, BEARINGS_TABLE1)
    assert np.array_equal(
        hg.bearing_loads(bare, BEARINGS_TABLE1, pair=wide).arrays["pinion_locating_x"],
        own.arrays["pinion_locating_x"],
    )


def test_bearing_inputs_name_the_key_the_path_and_the_cause(tmp_path):
    curve = hg.static_curve(points_per_pitch=2, slices=40)
    bad = {"pinion": {"locating_z_m": float("nan"), "floating_z_m": 0.035},
           "gear": BEARINGS_TABLE1["gear"]}
    with pytest.raises(hg.ParameterError, match=r"pinion\.locating_z_m"):
        hg.bearing_loads(curve, bad)
    with pytest.raises(hg.ParameterError, match="no such file.*bearngs.json"):
        hg.bearing_loads(curve, str(tmp_path / "bearngs.json"))
    with pytest.raises(hg.ParameterError, match="directory"):
        hg.bearing_loads(curve, tmp_path)
    latin1 = tmp_path / "latin1.json"
    latin1.write_bytes(b'{"pinion": "\xe9"}')
    with pytest.raises(hg.ParameterError, match="UTF-8"):
        hg.bearing_loads(curve, latin1)
    with pytest.raises(hg.ParameterError, match=r"gear\.floating_z_m"):
        hg.bearing_loads(curve, '{"pinion": {"locating_z_m": 0, "floating_z_m": 0.03}, '
                                '"gear": {"locating_z_m": 0}}')


def test_sweep_carries_the_dynamic_factors_of_force_and_root_stress(model):
    r = hg.sweep(model, [300.0, 400.0], max_periods=400, refine_runs=0, threads=1)
    for k in ("mesh_force_max_over_static", "root_stress_max_over_static"):
        v = getattr(r, k)
        assert v.shape == (2,) and np.all(np.isfinite(v) & (v > 0.5)), (k, v)
        assert k in r.to_dataframe().columns


def test_sweep_and_model_arguments_are_refused_first_naming_them():
    for kw, needle in [
        (dict(speeds=[]), "at least one speed"),
        (dict(speeds=[100.0, 2e5]), "1e5"),
        (dict(speeds=[100.0], threads=0), "threads"),
        (dict(speeds=[100.0], min_prominence=float("nan")), "min_prominence"),
        (dict(speeds=[100.0], refine_runs=-1), "refine_runs"),
    ]:
        # A pair (not a model): the refusal must come before the table is built.
        with pytest.raises(hg.ParameterError, match=needle):
            hg.sweep(hg.GearPair(), **kw)
    with pytest.raises(hg.ParameterError, match="slices"):
        hg.MeshModel(slices=-1)
    with pytest.raises(hg.ParameterError, match=r"table_size\[0\]"):
        hg.MeshModel(fidelity="table", table_size=(-5, 12))


def test_negative_speed_runs_backwards_and_speeds_beyond_1e5_are_refused(model):
    tr = hg.simulate(model, -100.0, 2e-3)
    w = np.asarray(tr.arrays[hg.STATE_NAMES[5]])
    assert np.all(np.isfinite(tr.TE)) and abs(w[-1] + 100.0) < 1.0
    with pytest.raises(hg.ParameterError, match="1e5"):
        hg.simulate(model, 2e5, 1e-3)


def test_iso_torque_and_face_width_limits_name_the_key():
    with pytest.raises(hg.ParameterError, match="torque_nm"):
        hg.iso_root_stress(torque=1e308)
    with pytest.raises(hg.ParameterError, match="torque_nm"):
        hg.iso_root_stress(torque=1e12)
    with pytest.raises(hg.ParameterError, match="face_width_m"):
        hg.geometry(hg.GearPair(face_width_m=10.0))
    with pytest.raises(hg.ParameterError, match="driving flanks"):
        hg.DriveLine(torque_nm=-100.0)


def test_study_refuses_bad_speed_rows_and_survives_a_corrupted_journal(tmp_path):
    import pandas as pd

    designs = pd.DataFrame({"_name": ["a", "b"], "omega_points": [-3, 4]})
    table = hg.study.run(designs, analyses=("static",), static_points=2, slices=40,
                         fe_density="coarse", progress=False)
    assert "omega_points" in table["error"][0] and "-3" in table["error"][0]
    out = tmp_path / "r.parquet"
    parts = tmp_path / "r.parquet.parts"
    parts.mkdir()
    (parts / "part-00000.parquet").write_bytes(b"not parquet at all")
    good = pd.DataFrame({"face_width_m": [0.014]})
    with pytest.warns(UserWarning, match="part-00000.parquet"):
        table = hg.study.run(good, analyses=("static",), static_points=2, slices=40, out=out,
                             fe_density="coarse", progress=False)
    assert table["error"].isna().all() and (table["ste_max_um"] > 0).all()
