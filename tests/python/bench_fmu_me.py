"""Benchmark: HelicalGearDrive through fmpy in Model Exchange (fmpy's CVode) against
Co-Simulation (the FMU's own RK4 on the mesh-period grid), same scene, same outputs.

Scene: Table 1, table fidelity, static-equilibrium start at ``w`` rad/s, ``T`` s of drive-line
time, TE recorded every 1e-4 s. Error: largest |TE − TE_ref| over the largest |TE_ref|, with
TE_ref from ``helical-gear simulate`` (RK4 at T_m/512, converged). Wall time of
``simulate_fmu`` minus that of a run of one output interval (the smaller of two; the table
build at initialisation, about 2.5 s, is reported separately).

    python tests/python/bench_fmu_me.py [--speeds 300 532] [--t-end 0.05]
"""

import argparse
import math
import subprocess
import time
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

ROOT = Path(__file__).resolve().parents[2]
FMU = str(ROOT / "target" / "fmu" / "HelicalGearDrive.fmu")
EXE = ROOT / "target" / "release" / "helical-gear"
H = 1e-4


def reference(w, t_end):
    t_m = 2 * math.pi / (30 * w)
    m = math.ceil(H / (t_m / 512))
    dt = H / m
    r = subprocess.run([str(EXE), "simulate", "--omega-p", repr(w), "--t-end", repr(t_end),
                        "--dt", repr(dt), "--fidelity", "table", "--csv"],
                       capture_output=True, text=True, check=True)
    rows = r.stdout.strip().splitlines()
    header = rows[0].split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in rows[1:]])
    return data[::m, header.index("time_s")], data[::m, header.index("te_m")]


def run(w, t_end, **kw):
    t0 = time.perf_counter()
    res = simulate_fmu(FMU, stop_time=t_end, output_interval=H, start_values={"w_p_start": w},
                       output=["TE"], **kw)
    return res, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--speeds", type=float, nargs="+", default=[300.0, 532.0])
    ap.add_argument("--t-end", type=float, default=0.5)
    a = ap.parse_args()
    cases = [
        ("CS, RK4 128/T_m (default), H = 1e-4 s", dict(step_size=H)),
        ("ME, CVode rtol 1e-6", dict(fmi_type="ModelExchange", solver="CVode",
                                     relative_tolerance=1e-6)),
        ("ME, CVode rtol 1e-8", dict(fmi_type="ModelExchange", solver="CVode",
                                     relative_tolerance=1e-8)),
    ]
    print(f"| ω_p, rad/s | run ({a.t_end} s simulated) | init, s | wall after init, s | "
          "simulated s per wall s | TE error |")
    print("| --- | --- | --- | --- | --- | --- |")
    for w in a.speeds:
        t_ref, te_ref = reference(w, a.t_end)
        for name, kw in cases:
            t_init = min(run(w, H, **kw)[1] for _ in range(2))
            res, t_all = run(w, a.t_end, **kw)
            te = np.interp(t_ref, res["time"], res["TE"])
            err = np.max(np.abs(te - te_ref)) / np.max(np.abs(te_ref))
            wall = max(t_all - t_init, 1e-9)
            print(f"| {w:g} | {name} | {t_init:.2f} | {wall:.2f} | {a.t_end / wall:.3g} | "
                  f"{err:.2g} |")


if __name__ == "__main__":
    main()
