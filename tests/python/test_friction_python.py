"""The mesh friction in the Python package: ``friction=`` (a dict, JSON text or None) on
`MeshModel`, `static_curve`, `simulate` and `sweep`, ``w_p=`` on `static_curve`, and the loss
outputs ``P_loss``, ``eta_mesh``, ``M_R_p``, ``M_R_g``, ``Q_p``, ``Q_g``."""

import json
import pickle

import numpy as np
import pytest

hg = pytest.importorskip("helical_gear")

CONSTANT = {"model": "constant", "mu": 0.05}

# A loaded, running state of Table 1: φp = 0.01 rad at about 100 N·m, ω_p = 100 rad/s with the
# gear at the rigid ratio.
STATE = (0.01, -0.0060851, 100.0, -63.83)


def test_friction_gives_a_loss_at_a_running_state_and_none_the_frictionless_numbers():
    plain = hg.MeshModel(slices=60).evaluate(*STATE)
    none = hg.MeshModel(slices=60, friction=None).evaluate(*STATE)
    assert all(none[k].tobytes() == plain[k].tobytes() for k in hg.OUTPUT_NAMES)
    assert float(plain["P_loss"]) == 0.0 and float(plain["eta_mesh"]) == 1.0

    for friction in (CONSTANT, json.dumps(CONSTANT)):
        out = hg.MeshModel(slices=60, friction=friction).evaluate(*STATE)
        loss = float(out["P_loss"])
        assert loss > 0.0
        assert 0.99 < float(out["eta_mesh"]) < 1.0
        assert float(out["Q_p"]) + float(out["Q_g"]) == pytest.approx(loss, rel=1e-9)
        # The friction torque is inside M_F; the elastic torque is the frictionless one.
        elastic = float(out["M_F_p"]) - float(out["M_R_p"])
        assert elastic == pytest.approx(float(plain["M_F_p"]), rel=1e-6)
    # At standstill nothing slides.
    rest = hg.MeshModel(slices=60, friction=CONSTANT).evaluate(0.01, -0.0060851, 0.0, 0.0)
    assert float(rest["P_loss"]) == 0.0


def test_static_curve_with_friction_reports_loss_and_efficiency():
    plain = hg.static_curve(points_per_pitch=4, slices=60)
    assert plain.mesh_loss_mean == 0.0 and plain.mesh_efficiency_mean == 1.0
    assert plain.mu_mean is None and 0.1 < plain.loss_factor_h_v < 0.15
    assert np.all(plain.P_loss == 0.0)
    none = hg.static_curve(points_per_pitch=4, slices=60, friction=None, w_p=500.0)
    assert none.ste.tobytes() == plain.ste.tobytes()

    c = hg.static_curve(points_per_pitch=4, slices=60, friction=CONSTANT, w_p=300.0)
    assert c.w_p == 300.0 and c.mu_mean == 0.05
    assert np.all(c.P_loss > 0.0) and c.mesh_loss_mean == pytest.approx(np.mean(c.P_loss))
    assert 0.99 < c.mesh_efficiency_mean < 1.0
    assert c.mesh_efficiency_mean == pytest.approx(1.0 - c.mesh_loss_mean / (100.0 * 300.0))
    assert np.allclose(c.Q_p + c.Q_g, c.P_loss, rtol=1e-9)
    assert set(hg.LOSS_NAMES) <= set(c.to_dataframe().columns)

    rest = hg.static_curve(points_per_pitch=4, slices=60, friction=CONSTANT, w_p=0.0)
    assert rest.mesh_loss_mean == 0.0 and rest.mesh_efficiency_mean == 1.0
    assert rest.ste.tobytes() == plain.ste.tobytes()


def test_a_model_with_friction_pickles_and_bad_friction_names_the_key():
    m = hg.MeshModel(slices=60, friction=CONSTANT)
    again = pickle.loads(pickle.dumps(m))
    assert again.friction == m.friction
    assert again.evaluate(*STATE)["P_loss"].tobytes() == m.evaluate(*STATE)["P_loss"].tobytes()

    with pytest.raises(hg.ParameterError, match=r"friction\.mu"):
        hg.MeshModel(slices=60, friction={"model": "constant", "mu": 2})
    with pytest.raises(hg.ParameterError, match="mu_max"):
        hg.MeshModel(slices=60, friction={"model": "constant", "mu_max": 0.1})
    with pytest.raises(hg.ParameterError, match=r"friction\.mu"):
        hg.MeshModel(slices=60, friction={"model": "constant", "mu": float("nan")})
    with pytest.raises(hg.ParameterError, match="friction"):
        hg.MeshModel(slices=60, friction=0.05)
    # A model carries its own friction: friction= beside it is refused, not ignored.
    with pytest.raises(hg.ParameterError, match="friction"):
        hg.static_curve(m, friction=CONSTANT)
    with pytest.raises(hg.ParameterError, match="w_p"):
        hg.static_curve(points_per_pitch=2, slices=60, friction=CONSTANT, w_p=float("nan"))


def test_simulate_trajectory_carries_the_loss():
    tr = hg.simulate(None, 300.0, 5e-4, slices=60, friction=CONSTANT)
    for name in hg.LOSS_NAMES:
        assert name in tr.arrays
    assert np.all(tr.P_loss > 0.0)
    assert np.all((tr.eta_mesh > 0.99) & (tr.eta_mesh < 1.0))


def test_study_builds_its_models_with_the_friction(tmp_path):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    pytest.importorskip("tqdm")
    designs = pd.DataFrame({"drive.torque_nm": [100.0]})
    kw = dict(analyses=("static",), static_points=4, slices=60, progress=False)
    plain = hg.study.run(designs, out=tmp_path / "plain.parquet", **kw)
    rough = hg.study.run(designs, out=tmp_path / "rough.parquet", friction=CONSTANT, **kw)
    assert plain["error"].isna().all() and rough["error"].isna().all()
    # The static curve runs at 300 rad/s with the friction torque inside M_F = M: the elastic
    # torque, and so the STE, differs from the frictionless one by a few per cent at most.
    ratio = rough["ste_max_um"][0] / plain["ste_max_um"][0]
    assert ratio != 1.0 and abs(ratio - 1.0) < 0.05, ratio
    with pytest.raises(hg.ParameterError, match="friction"):
        hg.study.run(designs, out=tmp_path / "bad.parquet", friction=0.05, **kw)
