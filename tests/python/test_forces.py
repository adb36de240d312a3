"""The 3D mesh force and moments and the bearing loads in the `helical_gear` Python package:
the keys of `MeshModel.evaluate`, the columns of `static_curve` and `simulate`, and
`bearing_loads` (the library's statics of a shaft on a locating and a floating bearing)."""

import json

import numpy as np
import pytest

hg = pytest.importorskip("helical_gear")

from conftest import ROOT  # noqa: E402

FORCES = ("F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y", "F_g_x", "F_g_y", "F_g_z", "M_g_x",
          "M_g_y")
BEARINGS = ROOT / "docs" / "loads" / "bearings_table1.json"


def test_evaluate_has_the_force_keys_and_newtons_third_law():
    assert hg.FORCE_NAMES == FORCES
    assert set(FORCES) <= set(hg.OUTPUT_NAMES)
    pair = hg.GearPair()
    g = hg.geometry(pair)
    gp, gg = g.base_radius_p_m, g.base_radius_g_m
    phi = np.linspace(0.0, 0.2, 5)
    out = hg.MeshModel(pair, slices=40).evaluate(phi, (20e-6 - phi * gp) / gg, 0.0, 0.0)
    for k in FORCES:
        assert out[k].shape == (5,), k
    for ax in "xyz":
        assert np.array_equal(out[f"F_g_{ax}"], -out[f"F_p_{ax}"])
    # Normal drive: pushed apart (x < 0), resisting rotation (y < 0), right-hand thrust (z > 0).
    assert (out["F_p_x"] < 0).all() and (out["F_p_y"] < 0).all() and (out["F_p_z"] > 0).all()


def test_static_curve_and_simulate_carry_the_force_columns():
    curve = hg.static_curve(points_per_pitch=6, slices=40)
    df = curve.to_dataframe()
    for k in FORCES:
        assert k in df.columns and len(df[k]) == 6
    tr = hg.simulate(None, 600.0, 2e-4, dt=1e-5, slices=40)
    df = tr.to_dataframe()
    for k in FORCES:
        assert k in df.columns and len(df[k]) == len(df["time"])


def test_bearing_loads_balance_the_mesh_force_on_static_curves_and_trajectories():
    curve = hg.static_curve(points_per_pitch=6, slices=40)
    tr = hg.simulate(None, 600.0, 2e-4, dt=1e-5, slices=40)
    for result in (curve, tr):
        loads = hg.bearing_loads(result, BEARINGS)
        for shaft, f in (("pinion", "F_p"), ("gear", "F_g")):
            for ax in "xyz":
                total = loads.arrays[f"{shaft}_locating_{ax}"] + loads.arrays[f"{shaft}_floating_{ax}"]
                np.testing.assert_allclose(total, -getattr(result, f"{f}_{ax}"), rtol=1e-12,
                                           atol=1e-9)
            assert not loads.arrays[f"{shaft}_floating_z"].any()
        assert len(loads.to_dataframe().columns) == 12
    # A dict works as a file does; a bad arrangement names the key.
    same = json.loads(BEARINGS.read_text())
    assert hg.bearing_loads(curve, same).mean() == hg.bearing_loads(curve, BEARINGS).mean()
    same["gear"]["floating_z_m"] = same["gear"]["locating_z_m"]
    with pytest.raises(hg.ParameterError, match="gear.floating_z_m"):
        hg.bearing_loads(curve, same)
