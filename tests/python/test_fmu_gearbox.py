"""HelicalGearbox (the drive line of Eqs. 1-4 with both gear bodies on elastic supports) driven
by fmpy: Co-Simulation and Model Exchange (fmpy's CVode) give the same trajectory, the supports
JSON parameter overrides the Real ones, and the FMU declares that it has no directional
derivatives."""

import json
from pathlib import Path

import numpy as np
from fmpy import read_model_description, simulate_fmu

from conftest import ROOT, fmu_file

OUT = ["TE", "u_p_x", "u_g_y", "th_p_y", "R_p_y", "R_g_x", "F_p_y"]


def test_co_simulation_and_model_exchange_agree():
    """2 ms from the static start at 300 rad/s (about three mesh periods): RK4 inside the
    Co-Simulation steps against CVode (relative tolerance 1e-9) on the 28 states of Model
    Exchange. TE and the support force agree to 1e-5 of their size."""
    path = fmu_file("HelicalGearbox")
    kw = dict(stop_time=2e-3, output_interval=1e-4, output=OUT)
    cs = simulate_fmu(path, step_size=1e-4, **kw)
    me = simulate_fmu(path, fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-9,
                      **kw)
    for name in ["TE", "R_p_y", "u_g_y"]:
        a, b = cs[name], me[name]
        assert np.all(np.isfinite(a)) and np.all(np.isfinite(b))
        scale = np.max(np.abs(a))
        assert np.max(np.abs(a - b)) <= 1e-5 * scale, (name, np.max(np.abs(a - b)) / scale)
    # The start is the static equilibrium: the support balances the mesh force.
    assert abs(cs["R_p_y"][0] + cs["F_p_y"][0]) <= 1e-6 * abs(cs["F_p_y"][0])


def test_the_supports_json_overrides_the_real_parameters():
    """The guide's example file as the `supports` String parameter gives the trajectory of the
    Real parameters' defaults (which are that example) bit for bit; a softer gear support
    given as JSON moves the gear body further."""
    path = fmu_file("HelicalGearbox")
    text = Path(ROOT, "docs", "gear-bodies", "supports.json").read_text()
    kw = dict(stop_time=5e-4, step_size=1e-4, output=OUT)
    real = simulate_fmu(path, **kw)
    given = simulate_fmu(path, start_values={"supports": text}, **kw)
    for name in OUT:
        assert np.array_equal(real[name], given[name]), name
    soft = json.loads(text)
    soft["gear"]["stiffness"]["radial_n_per_m"] /= 4
    softer = simulate_fmu(path, start_values={"supports": json.dumps(soft)}, **kw)
    assert abs(softer["u_g_y"][0]) > 3 * abs(real["u_g_y"][0])


def test_no_directional_derivatives_are_declared():
    md = read_model_description(fmu_file("HelicalGearbox"))
    assert not md.modelExchange.providesDirectionalDerivative
    assert not md.coSimulation.providesDirectionalDerivative
    assert len(md.derivatives) == 28
