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
    with pytest.raises(hg.ParameterError, match="samples"):
        hg.simulate(model, 1e9, 1e-3)
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
