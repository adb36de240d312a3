"""Model Exchange through fmpy: every FMU offers both interfaces and both platforms
(``fmpy info``), fmpy's CVode integrates HelicalGearDrive in Model Exchange mode and
reproduces ``helical-gear simulate`` (RK4 at T_m/128, table fidelity) to 1e-5 relative in TE
at 300 and 532 rad/s, and fmpy's FMU2Model reads directional derivatives that agree with
central differences of its own derivatives."""

import math
import subprocess
from ctypes import POINTER, c_double

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu, supported_platforms
from fmpy.fmi2 import FMU2Model
from fmpy.util import fmu_info

from conftest import EXE, MODELS, fmu_file



@pytest.mark.parametrize("model", MODELS)
def test_fmpy_info_lists_both_interfaces_and_platforms(model):
    info = fmu_info(fmu_file(model))
    assert "Model Exchange" in info and "Co-Simulation" in info, info
    platforms = supported_platforms(fmu_file(model))
    assert "linux64" in platforms
    if "win64" not in platforms:
        pytest.skip("the FMU was built without binaries/win64 (x86_64-pc-windows-gnu or its "
                    "MinGW linker missing; ./test.sh installs both)")
    md = read_model_description(fmu_file(model))
    assert md.modelExchange.modelIdentifier == md.coSimulation.modelIdentifier == model
    # HelicalGearbox does not provide them (its mesh Jacobian covers the torques, not the 3D
    # force and moments on the bodies).
    assert md.modelExchange.providesDirectionalDerivative == (model != "HelicalGearbox")
    assert md.coSimulation.providesDirectionalDerivative == (model != "HelicalGearbox")


def cli_te(w, h, n):
    if not EXE.exists():
        pytest.fail(f"{EXE} is not built (cargo build --release --bin helical-gear)")
    r = subprocess.run(
        [str(EXE), "simulate", "--omega-p", repr(w), "--t-end", repr(n * h), "--dt", repr(h),
         "--fidelity", "table", "--csv"],
        capture_output=True, text=True, check=True,
    )
    rows = r.stdout.strip().splitlines()
    header = rows[0].split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in rows[1:]])
    return data[:, header.index("time_s")], data[:, header.index("te_m")]


@pytest.mark.parametrize("w", [300.0, 532.0])
def test_model_exchange_with_cvode_reproduces_helical_gear_simulate(w):
    """About 12 mesh periods from the static equilibrium (the transient of the start), CVode
    (BDF, fmpy's default solver for Model Exchange) at rtol 1e-8 with the FMU's nominals
    against the CLI's RK4 at T_m/128 (converged to ~1e-7 at this step)."""
    h = 0.99 * 2 * math.pi / (30 * w) / 128
    n = 1500
    t_ref, te_ref = cli_te(w, h, n)
    res = simulate_fmu(fmu_file("HelicalGearDrive"), fmi_type="ModelExchange", solver="CVode",
                       relative_tolerance=1e-8, stop_time=n * h, output_interval=h,
                       start_values={"w_p_start": w}, output=["TE", "w_p"])
    te = np.interp(t_ref, res["time"], res["TE"])
    err = np.max(np.abs(te - te_ref)) / np.max(np.abs(te_ref))
    print(f"Model Exchange (CVode, rtol 1e-8) vs helical-gear simulate at {w} rad/s: {err:.3g}")
    assert err <= 1e-5, f"max TE difference {err:.3g} of max |TE|"
    assert abs(res["w_p"][-1] - w) < 0.05 * w


def _ptr(a):
    return a.ctypes.data_as(POINTER(c_double))


def test_fmpy_reads_directional_derivatives_that_match_central_differences(tmp_path):
    path = fmu_file("HelicalGearPair")
    md = read_model_description(path)
    unzip = extract(path, unzipdir=str(tmp_path / "pair"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Model(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.modelExchange.modelIdentifier, instanceName="dd")
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.newDiscreteStates()
        fmu.enterContinuousTimeMode()
        nx = len(md.derivatives)
        x0, nominals = np.zeros(nx), np.zeros(nx)
        fmu.getContinuousStates(_ptr(x0), nx)
        fmu.getNominalsOfContinuousStates(_ptr(nominals), nx)
        x0[0] += 0.0037  # off the table's phase nodes

        def derivatives(x):
            fmu.setContinuousStates(_ptr(x), nx)
            dx = np.zeros(nx)
            fmu.getDerivatives(_ptr(dx), nx)
            return dx

        ders = [vr[d.variable.name] for d in md.derivatives]
        for j, d in enumerate(md.derivatives):
            state = d.variable.derivative.name
            step = 1e-5 * nominals[j]
            xp, xm = x0.copy(), x0.copy()
            xp[j] += step
            xm[j] -= step
            central = (derivatives(xp) - derivatives(xm)) / (2 * step)
            derivatives(x0)
            exact = fmu.getDirectionalDerivative(ders, [vr[state]], [1.0])
            scale = max(np.max(np.abs(central)), 1e-300)
            assert np.max(np.abs(np.array(exact) - central)) <= 1e-5 * scale, (state, exact, central)
    finally:
        fmu.terminate()
        fmu.freeInstance()
