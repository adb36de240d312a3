"""The FMU driven by fmpy: validation, error paths, several instances, FMU states and
simulate_fmu with input signals."""

import math
import threading
from ctypes import byref

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from conftest import ROOT, FMICallException, Instance

# The worked example of docs/conventions.md (Table 1): TE = +20 µm, both gears rolling.
LOADED = dict(phi_p=0.01, phi_g=-0.0060851, w_p=100.0, w_g=-100.0 * 30 / 47)
OUTPUTS = ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "F_n", "contact_length", "p_max"]


def test_validate_fmu_reports_no_problem(fmu_path):
    assert validate_fmu(fmu_path) == []


def test_packed_model_description_is_the_checked_in_one(fmu_path):
    import zipfile

    with zipfile.ZipFile(fmu_path) as z:
        packed = z.read("modelDescription.xml").decode()
        names = z.namelist()
    assert packed == (ROOT / "modelDescription" / "HelicalGearMesh" / "modelDescription.xml").read_text()
    assert "binaries/linux64/HelicalGearMesh.so" in names
    assert "documentation/index.html" in names
    assert "resources/compliance_table1.json" in names


def test_outputs_are_direct_feedthrough(fmu):
    fmu.init()
    fmu.set(**LOADED)
    m_f_p, m_f_g, te, g_p, g_g = fmu.get("M_F_p", "M_F_g", "TE", "base_radius_p", "base_radius_g")
    assert te == pytest.approx(LOADED["phi_p"] * g_p + LOADED["phi_g"] * g_g, abs=1e-18)
    assert te == pytest.approx(20e-6, abs=1e-8)
    assert m_f_p > 0 and m_f_g > 0, "positive mesh torques in normal drive"
    # Between communication points the master may set inputs and read outputs at will.
    fmu.set(phi_g=LOADED["phi_g"] - 2e-6 / g_g)
    assert fmu.get("TE")[0] == pytest.approx(te - 2e-6, rel=1e-12)
    assert fmu.get("M_F_p")[0] < m_f_p, "less overlap, less torque"


def test_nan_input_is_an_error_naming_the_input_and_reset_recovers(fmu):
    fmu.init()
    with pytest.raises(FMICallException, match="fmi2SetReal failed with status 3"):
        fmu.set(w_g=math.nan)
    assert fmu.errors()[-1] == "fmi2SetReal: input `w_g` = NaN is not finite"
    with pytest.raises(FMICallException):
        fmu.slave.doStep(0.0, 1e-3)
    assert "not allowed in state error" in fmu.errors()[-1]
    fmu.slave.reset()
    fmu.init()
    fmu.set(**LOADED)
    assert fmu.get("M_F_p")[0] > 0


def test_invalid_parameter_is_named_at_exit_initialization(fmu):
    fmu.slave.setInteger([fmu.vr["z_p"]], [12])
    fmu.slave.setupExperiment(startTime=0.0)
    fmu.slave.enterInitializationMode()
    with pytest.raises(FMICallException, match="fmi2ExitInitializationMode failed"):
        fmu.slave.exitInitializationMode()
    assert fmu.errors()[-1].startswith(
        "fmi2ExitInitializationMode: invalid parameter `z_p` = 12: allowed >= "
    )
    fmu.slave.reset()
    fmu.init()
    assert fmu.slave.getInteger([fmu.vr["z_p"]]) == [30], "reset restored the start value"


def test_invalid_tunable_parameter_names_the_fmi_variable(fmu):
    fmu.init()
    with pytest.raises(FMICallException):
        fmu.set(d_mesh=-1.0)
    assert "(FMI parameter `d_mesh`)" in fmu.errors()[-1]


def test_illegal_call_order_and_recovery(fmu):
    with pytest.raises(FMICallException):
        fmu.slave.exitInitializationMode()
    assert fmu.errors()[-1] == (
        "fmi2ExitInitializationMode: not allowed in state instantiated "
        "(allowed in: initializationMode)"
    )
    fmu.slave.reset()
    fmu.init()
    with pytest.raises(FMICallException):
        fmu.slave.setInteger([fmu.vr["slices"]], [100])
    assert "parameter `slices` is fixed" in fmu.errors()[-1]
    fmu.slave.reset()
    fmu.init()
    fmu.slave.doStep(0.0, 1e-3)
    with pytest.raises(FMICallException):
        fmu.slave.doStep(0.0, 1e-3)
    assert "currentCommunicationPoint = 0 s differs from the FMU's time 0.001 s" in fmu.errors()[-1]
    fmu.slave.reset()
    fmu.init()
    fmu.set(**LOADED)
    fmu.slave.doStep(0.0, 1e-3)
    assert fmu.get("M_F_p")[0] > 0


def test_percent_in_a_message_reaches_the_logger_intact(md, unzipdir):
    inst = Instance(md, unzipdir, "percent", logging_on=True)
    try:
        # A second instance with a resource URI whose bad escape is quoted in the warning.
        c = inst.slave.fmi2Instantiate(
            b"percent", 1, md.guid.encode(), b"file:///tmp/100%zz", byref(inst.callbacks), 0, 1
        )
        assert c
        assert any("bad escape `%zz`" in m for _, _, m in inst.messages), inst.messages
        inst.slave.fmi2FreeInstance(c)
    finally:
        inst.free()


def test_two_instances_with_different_parameters_side_by_side(fmu, md, unzipdir):
    other = Instance(md, unzipdir, "other")
    try:
        other.slave.setInteger([other.vr["slices"]], [100])
        other.set(d_mesh=300.0)
        other.init()
        fmu.init()
        states = [dict(LOADED, phi_p=0.01 + 2e-4 * k) for k in range(8)]

        def run(inst):
            out = []
            for s in states:
                inst.set(**s)
                out.append(inst.get(*OUTPUTS))
            return out

        # Interleaved on one thread …
        a, b = [], []
        for s in states:
            fmu.set(**s)
            other.set(**s)
            a.append(fmu.get(*OUTPUTS))
            b.append(other.get(*OUTPUTS))
        assert a != b
        assert other.get("d_mesh") == [300.0] and fmu.get("d_mesh") == [100.0]
        # … and concurrently on two threads (ctypes releases the GIL during the calls),
        # after a reset each: the same numbers.
        for inst, slices, d_mesh in ((fmu, 200, 100.0), (other, 100, 300.0)):
            inst.slave.reset()
            inst.slave.setInteger([inst.vr["slices"]], [slices])
            inst.set(d_mesh=d_mesh)
            inst.init()
        results = {}
        threads = [
            threading.Thread(target=lambda i=i, k=k: results.__setitem__(k, run(i)))
            for k, i in (("a", fmu), ("b", other))
        ]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert results["a"] == a
        assert results["b"] == b
    finally:
        other.free()


def test_fmu_state_save_restore_and_serialisation_reproduce_outputs_exactly(fmu):
    fmu.init()
    fmu.set(**LOADED)
    fmu.slave.doStep(0.0, 1e-3)
    before = fmu.get(*OUTPUTS)
    state = fmu.slave.getFMUstate()
    data = fmu.slave.serializeFMUstate(state)
    assert data[:8] == b"HGMSTATE"

    fmu.set(phi_p=0.02, d_mesh=250.0)
    fmu.slave.doStep(1e-3, 1e-3)
    assert fmu.get(*OUTPUTS) != before

    fmu.slave.setFMUstate(state)
    assert fmu.get(*OUTPUTS) == before
    assert fmu.slave.getRealStatus(2) == 1e-3, "time restored (fmi2LastSuccessfulTime)"
    fmu.slave.doStep(1e-3, 1e-3)

    restored = fmu.slave.deSerializeFMUstate(data)
    fmu.set(phi_p=0.03)
    fmu.slave.setFMUstate(restored)
    assert fmu.get(*OUTPUTS) == before
    assert fmu.get("d_mesh") == [100.0]
    fmu.slave.freeFMUstate(state)
    fmu.slave.freeFMUstate(restored)

    with pytest.raises(FMICallException):
        fmu.slave.deSerializeFMUstate(data[:-1])
    assert "serialised state truncated" in fmu.errors()[-1]


def test_simulate_fmu_with_input_signals(fmu_path, md):
    g_p, g_g = 0.042860629350090065, 0.06714831931514112
    t = np.linspace(0.0, 2e-3, 5)
    w_p = 100.0
    phi_p = w_p * t
    # Gear angle for a constant TE of 25 µm on top of rigid rolling.
    phi_g = (25e-6 - phi_p * g_p) / g_g
    signals = np.array(
        list(zip(t, phi_p, phi_g, np.full_like(t, w_p), np.full_like(t, -w_p * g_p / g_g))),
        dtype=[("time", float), ("phi_p", float), ("phi_g", float), ("w_p", float), ("w_g", float)],
    )
    res = simulate_fmu(
        fmu_path,
        stop_time=2e-3,
        output_interval=1e-4,
        input=signals,
        output=["TE", "M_F_p", "M_D_p", "separated"],
    )
    assert len(res) == 21
    # TE is recorded after each step, from the inputs applied at the step's start.
    assert np.allclose(res["TE"][1:], 25e-6, rtol=1e-9, atol=0)
    assert np.all(res["M_F_p"][1:] > 0) and not np.any(res["separated"][1:])
    assert np.all(np.abs(res["M_D_p"][1:]) < 1e-6 * res["M_F_p"][1:]), "rigid rolling: dTE/dt = 0"
