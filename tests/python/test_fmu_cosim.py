"""Co-simulation with fmpy as the master: J1 and J2 are the master's own units (integrated by
the master), the gear stage is an FMU, and signals are exchanged only at the communication
points t_k = k·H.

* Stage cut (``HelicalGearStage``: shafts, hubs and mesh inside; the master gives the shafts'
  far-end motion, zero-order hold on the torques it receives): TE within 1e-4 of the
  reference at H = 1e-4 s at 300 and 532 rad/s, bounded (< 1e-3) at H = 1e-3 s.
* Hub cut (``HelicalGearPair``; the shafts are in the master, which passes the shaft torques
  and, with ``setRealInputDerivatives``, their time derivatives): measured with and without
  the derivatives; with them alone the error converges at second order and is below 1e-4 at
  H = T_m/32 but not at H = 1e-4 s ≈ T_m/4 at 532 rad/s. With the shafts' stiffness and
  damping also given to the FMU (``hub_coupling.*`` parameters: it corrects the held torques
  by its own hub motion within the step) the hub cut is within 1e-4 at H = 1e-4 s and bounded
  (< 1e-3) at H = 1e-3 s, like the stage cut (docs/fmus.md).

Reference: ``helical-gear simulate`` (the whole 4-DOF model, table fidelity, RK4 at ≤ T_m/256)
sampled at the t_k. Error: largest |TE − TE_ref| over the largest |TE_ref|, over about 30 mesh
periods from the static equilibrium.
"""

import math
import subprocess
import tempfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from conftest import EXE, FMUS
Z_P, Z_G = 30, 47


def mesh_period(w):
    return 2 * math.pi / (Z_P * w)


def reference(w, h, n):
    if not EXE.exists():
        pytest.fail(f"{EXE} is not built (cargo build --release --bin helical-gear)")
    m = math.ceil(h / (mesh_period(w) / 256))
    r = subprocess.run(
        [str(EXE), "simulate", "--omega-p", repr(w), "--t-end", repr(n * h), "--dt",
         repr(h / m), "--fidelity", "table", "--csv"],
        capture_output=True, text=True, check=True,
    )
    rows = r.stdout.strip().splitlines()
    header = rows[0].split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in rows[1:]])
    return data[::m, header.index("te_m")][: n + 1]


def rel_err(te, ref):
    return np.max(np.abs(np.asarray(te) - ref)) / np.max(np.abs(ref))


class Slave:
    def __init__(self, model, tmp, w, coupled=False):
        path = FMUS / f"{model}.fmu"
        if not path.exists():
            pytest.fail(f"{path} is missing: build it with `cargo run --release -p fmu-build`")
        md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        # A fresh directory per instance: never overwrite a loaded shared library.
        unzip = extract(str(path), tempfile.mkdtemp(dir=tmp, prefix=model))
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                           modelIdentifier=model, instanceName=model)
        self.s.instantiate()
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        self.set(w_p_start=w)
        if coupled:
            d = drive(self)
            self.set(**{"hub_coupling.c_p_nm_per_rad": d["c1"], "hub_coupling.d_p_nms_per_rad": d["d1"],
                        "hub_coupling.c_g_nm_per_rad": d["c2"], "hub_coupling.d_g_nms_per_rad": d["d2"]})
        self.s.exitInitializationMode()

    def get(self, *names):
        return self.s.getReal([self.vr[n] for n in names])

    def set(self, **values):
        self.s.setReal([self.vr[n] for n in values], list(values.values()))

    def close(self):
        self.s.terminate()
        self.s.freeInstance()


# The drive line of Table 1, for the values a model does not list (the Pair lists only
# drive.torque_nm, the Stage also the shafts: each lists those it uses).
TABLE1_DRIVE = {"drive.j1_kgm2": 0.62, "drive.j2_kgm2": 0.62, "drive.c1_nm_per_rad": 984.0,
                "drive.c2_nm_per_rad": 984.0, "drive.d1_nms_per_rad": 0.04,
                "drive.d2_nms_per_rad": 0.04}


def drive(s):
    v = {k: (s.get(k)[0] if k in s.vr else x) for k, x in TABLE1_DRIVE.items()}
    (m,) = s.get("drive.torque_nm")
    return dict(j1=v["drive.j1_kgm2"], j2=v["drive.j2_kgm2"], c1=v["drive.c1_nm_per_rad"],
                c2=v["drive.c2_nm_per_rad"], d1=v["drive.d1_nms_per_rad"],
                d2=v["drive.d2_nms_per_rad"], m=m, load=m * Z_G / Z_P)


def stage_cut(tmp, w, h, n):
    s = Slave("HelicalGearStage", tmp, w)
    try:
        d = drive(s)
        p1, w1, p2, w2 = s.get("phi_1", "w_1", "phi_2", "w_2")
        te = []
        t = 0.0
        for k in range(n + 1):
            s.set(phi_1=p1, w_1=w1, phi_2=p2, w_2=w2)
            te_k, tau1, tau2 = s.get("TE", "tau_1", "tau_2")
            te.append(te_k)
            if k == n:
                break
            # The master's inertias under held shaft torques: exact over the step.
            a1 = (d["m"] + tau1) / d["j1"]
            a2 = (d["load"] + tau2) / d["j2"]
            s.s.doStep(t, h)
            t += h
            p1, w1 = p1 + w1 * h + 0.5 * a1 * h * h, w1 + a1 * h
            p2, w2 = p2 + w2 * h + 0.5 * a2 * h * h, w2 + a2 * h
        return te
    finally:
        s.close()


def pair_cut(tmp, w, h, n, derivatives, coupled=False):
    s = Slave("HelicalGearPair", tmp, w, coupled)
    try:
        d = drive(s)
        pp, wp, pg, wg = s.get("phi_p", "w_p", "phi_g", "w_g")
        tp, tg = s.get("tau_p", "tau_g")
        # The master's inertias at the static start: the shafts twisted by the start torques.
        x = [pp + tp / d["c1"], wp, pg + tg / d["c2"], wg]
        te = []
        t = 0.0
        for k in range(n + 1):
            te_k, pp, wp, ap, pg, wg, ag = s.get("TE", "phi_p", "w_p", "a_p", "phi_g", "w_g", "a_g")
            te.append(te_k)
            if k == n:
                break
            s1 = d["c1"] * (x[0] - pp) + d["d1"] * (x[1] - wp)
            s2 = d["c2"] * (pg - x[2]) + d["d2"] * (wg - x[3])
            s.set(tau_p=s1, tau_g=-s2)
            if derivatives:
                a1 = (d["m"] - s1) / d["j1"]
                a2 = (d["load"] + s2) / d["j2"]
                r1 = d["c1"] * (x[1] - wp) + d["d1"] * (a1 - ap)
                r2 = d["c2"] * (wg - x[3]) + d["d2"] * (ag - a2)
                s.s.setRealInputDerivatives([s.vr["tau_p"], s.vr["tau_g"]], [1, 1], [r1, -r2])
            s.s.doStep(t, h)
            t += h

            # The master: J1, J2 and the shafts against the hub motion extrapolated linearly
            # from t_k (RK4, 8 sub-steps).
            def f(q, y):
                t1 = d["c1"] * (y[0] - (pp + wp * q)) + d["d1"] * (y[1] - wp)
                t2 = d["c2"] * ((pg + wg * q) - y[2]) + d["d2"] * (wg - y[3])
                return np.array([y[1], (d["m"] - t1) / d["j1"], y[3], (d["load"] + t2) / d["j2"]])

            y = np.array(x)
            hs = h / 8
            for i in range(8):
                q = i * hs
                k1 = f(q, y)
                k2 = f(q + hs / 2, y + hs / 2 * k1)
                k3 = f(q + hs / 2, y + hs / 2 * k2)
                k4 = f(q + hs, y + hs * k3)
                y = y + hs / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            x = list(y)
        return te
    finally:
        s.close()


def steps(w, h):
    return math.ceil(30 * mesh_period(w) / h)


@pytest.mark.parametrize("w", [300.0, 532.0])
def test_stage_cut_follows_the_whole_model(tmp_path, w):
    for h, bound in [(1e-4, 1e-4), (1e-3, 1e-3)]:
        n = steps(w, h)
        e = rel_err(stage_cut(tmp_path, w, h, n), reference(w, h, n))
        print(f"stage cut, {w} rad/s, H = {h:g} s: TE error {e:.2e}")
        assert e < bound, f"stage cut at {w} rad/s, H = {h} s: {e:.3g}"


@pytest.mark.parametrize("w", [300.0, 532.0])
def test_pair_cut_with_input_derivatives(tmp_path, w):
    h = 1e-4
    n = steps(w, h)
    ref = reference(w, h, n)
    e0 = rel_err(pair_cut(tmp_path, w, h, n, False), ref)
    e1 = rel_err(pair_cut(tmp_path, w, h, n, True), ref)
    print(f"pair cut, {w} rad/s, H = 1e-4 s: zero-order hold {e0:.2e}, first-order {e1:.2e}")
    assert e1 < 0.7 * e0 and e0 < 1e-2
    h = mesh_period(w) / 32
    n = steps(w, h)
    e = rel_err(pair_cut(tmp_path, w, h, n, True), reference(w, h, n))
    print(f"pair cut, {w} rad/s, H = T_m/32: first-order hold {e:.2e}")
    assert e < 1e-4


@pytest.mark.parametrize("w", [300.0, 532.0])
def test_pair_cut_with_hub_coupling_follows_the_whole_model(tmp_path, w):
    for h, bound in [(1e-4, 1e-4), (1e-3, 1e-3)]:
        n = steps(w, h)
        e = rel_err(pair_cut(tmp_path, w, h, n, True, coupled=True), reference(w, h, n))
        print(f"pair cut with hub coupling, {w} rad/s, H = {h:g} s: TE error {e:.2e}")
        assert e < bound, f"coupled pair cut at {w} rad/s, H = {h} s: {e:.3g}"
