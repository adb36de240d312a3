"""The stateful FMUs (HelicalGearPair, HelicalGearStage, HelicalGearDrive) driven by fmpy:
validation of every FMU of the family, the drive against `helical-gear simulate`, bit-for-bit FMU state
restore, error statuses and recovery."""

import math
import subprocess

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from conftest import EXE, MODELS, FMICallException, Instance, fmu_file



@pytest.mark.parametrize("model", MODELS)
def test_validate_fmu_reports_no_problem(model):
    assert validate_fmu(fmu_file(model)) == []


def test_one_binary_serves_every_model_by_guid():
    mds = [read_model_description(fmu_file(m)) for m in MODELS]
    assert len({md.guid for md in mds}) == len(MODELS)
    for m, md in zip(MODELS, mds):
        assert md.coSimulation.modelIdentifier == m
        assert md.coSimulation.canHandleVariableCommunicationStepSize


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    path = fmu_file("HelicalGearDrive")
    md = read_model_description(path)
    # Extracted under pytest's temporary directory, which pytest prunes.
    return md, extract(path, unzipdir=str(tmp_path_factory.mktemp("drive")))


def test_drive_reproduces_helical_gear_simulate(drive, tmp_path):
    """Same speed, same step: one RK4 sub-step per communication step (H below T_m/128 at
    every speed the run reaches), so the FMU repeats the CLI's RK4 trajectory."""
    if not EXE.exists():
        pytest.fail(f"{EXE} is not built (cargo build --release --bin helical-gear)")
    w = 532.0
    h = 0.99 * 2 * math.pi / (30 * w) / 128
    n = 1500
    t_end = n * h
    r = subprocess.run(
        [str(EXE), "simulate", "--omega-p", repr(w), "--t-end", repr(t_end), "--dt", repr(h),
         "--fidelity", "table", "--csv"],
        capture_output=True, text=True, check=True,
    )
    rows = r.stdout.strip().splitlines()
    header = rows[0].split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in rows[1:]])
    te_ref = data[:, header.index("te_m")]
    res = simulate_fmu(fmu_file("HelicalGearDrive"), step_size=h, stop_time=t_end,
                       output_interval=h, start_values={"w_p_start": w}, output=["TE", "w_p"])
    te = res["TE"]
    assert len(te) == len(te_ref)
    scale = np.max(np.abs(te_ref))
    err = np.max(np.abs(te - te_ref)) / scale
    assert err <= 1e-6, f"max TE difference {err:.3g} of max |TE|"
    assert abs(res["w_p"][-1] - w) < 0.05 * w


def _run(inst, t, n, h):
    out = []
    for _ in range(n):
        inst.slave.doStep(t, h)
        t += h
        out.append(inst.get("TE", "w_p", "phi_g", "M_F_p"))
    return t, out


def test_fmu_state_restore_repeats_the_trajectory_bit_for_bit(drive):
    md, unzip = drive
    a = Instance(md, unzip, "drive_state_a")
    b = Instance(md, unzip, "drive_state_b")
    try:
        a.init()
        h = 1e-4
        t, _ = _run(a, 0.0, 5, h)
        st = a.slave.getFMUstate()
        data = a.slave.serializeFMUstate(st)
        t1, first = _run(a, t, 5, h)
        a.slave.setFMUstate(st)
        _, again = _run(a, t, 5, h)
        assert again == first, "in-memory state"
        b.init()
        st_b = b.slave.deSerializeFMUstate(data)
        b.slave.setFMUstate(st_b)
        _, other = _run(b, t, 5, h)
        assert other == first, "serialised state in another instance"
        a.slave.freeFMUstate(st)
        b.slave.freeFMUstate(st_b)
    finally:
        a.free()
        b.free()


def test_bad_step_and_nan_input_are_errors_and_reset_recovers(drive):
    md, unzip = drive
    f = Instance(md, unzip, "drive_errors")
    try:
        f.init()
        with pytest.raises(FMICallException):
            f.slave.doStep(0.0, -1e-4)
        assert "h = -0.0001 s" in f.errors()[-1]
        f.slave.reset()
        f.init()
        with pytest.raises(FMICallException):
            f.set(M=math.nan)
        assert f.errors()[-1] == "fmi2SetReal: input `M` = NaN is not finite"
        f.slave.reset()
        f.init()
        f.slave.doStep(0.0, 1e-4)
        te, = f.get("TE")
        assert math.isfinite(te) and te > 0
    finally:
        f.free()
