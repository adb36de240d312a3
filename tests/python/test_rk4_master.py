"""The key test: a Python RK4 master integrates the 4-DOF torsional model of Eqs. 1–4 with the
mesh torques read from the FMU at every Runge–Kutta stage, and must reproduce the library's own
RK4 reference (``helical-gear simulate --csv``) to 1e-9 relative.

Eqs. 1–4 (all angles in one absolute sense, mesh torques positive in normal drive):

    J1 φ1'' = M − c1(φ1 − φp) − d1(φ1' − φp')
    Jp φp'' = c1(φ1 − φp) + d1(φ1' − φp') − M_F,p − M_D,p
    Jg φg'' = −c2(φg − φ2) − d2(φg' − φ2') − M_F,g − M_D,g
    J2 φ2'' = M·z_g/z_p + c2(φg − φ2) + d2(φg' − φ2')

The master takes every parameter from the FMU (drive line, J_p, J_g, tooth numbers) and the
start state from the reference's first row (the static equilibrium at the nominal speed).
"""

import math
import subprocess

import numpy as np
import pytest

from conftest import RELEASE, Instance

EXE = RELEASE / "helical-gear"
STATE = ["phi_1", "phi_p", "phi_g", "phi_2", "w_1", "w_p", "w_g", "w_2"]
MESH = ["TE", "M_F_p", "M_F_g", "M_D_p", "M_D_g"]
STEPS_PER_MESH_PERIOD = 64
MESH_PERIODS = 20


def _simulate_available():
    if not EXE.exists():
        return f"{EXE} is not built (cargo build --release --bin helical-gear)"
    r = subprocess.run([str(EXE), "simulate", "--help"], capture_output=True, text=True)
    if r.returncode != 0:
        return "the `helical-gear simulate` subcommand is missing from this build"
    return None


def _column_key(name):
    """Maps the reference's CSV header to the names above; accepts both `phi_p` and
    `phi_p_rad`, `TE` and `te_m`, `M_F_p` and `m_f_p_nm`, `time` and `time_s`."""
    n = name.strip().lower()
    for suffix in ("_rad_s", "_rad", "_nm", "_s", "_m"):
        if n.endswith(suffix) and n[: -len(suffix)] in {
            "time", "te", "m_f_p", "m_f_g", "m_d_p", "m_d_g", *STATE
        }:
            n = n[: -len(suffix)]
            break
    return {"te": "TE", "m_f_p": "M_F_p", "m_f_g": "M_F_g", "m_d_p": "M_D_p",
            "m_d_g": "M_D_g"}.get(n, n)


def reference(omega_p, t_end, dt):
    r = subprocess.run(
        [str(EXE), "simulate", "--omega-p", repr(omega_p), "--t-end", repr(t_end),
         "--dt", repr(dt), "--csv"],
        capture_output=True, text=True, check=True,
    )
    lines = r.stdout.strip().splitlines()
    header = [_column_key(h) for h in lines[0].split(",")]
    data = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    return {h: data[:, i] for i, h in enumerate(header)}


class Master:
    """Fixed-step RK4 over Eqs. 1–4 with the mesh torques from the FMU."""

    def __init__(self, inst):
        self.inst = inst
        g = inst.slave.getReal
        v = inst.vr
        # The master's own drive line: Table 1's (the mesh element lists none of drive.*).
        (self.M, self.j1, self.j2, self.c1, self.c2, self.d1, self.d2) = (
            100.0, 0.62, 0.62, 984.0, 984.0, 0.04, 0.04)
        (self.jp, self.jg) = g([v[n] for n in ("J_p", "J_g")])
        z_p, z_g = inst.slave.getInteger([v["z_p"], v["z_g"]])
        self.brake = self.M * z_g / z_p
        self.inputs = [v["phi_p"], v["phi_g"], v["w_p"], v["w_g"]]
        self.outputs = [v[n] for n in MESH]

    def mesh(self, y):
        """TE and the four mesh torques at state y (set inputs, read outputs)."""
        self.inst.slave.setReal(self.inputs, [y[1], y[2], y[5], y[6]])
        return self.inst.slave.getReal(self.outputs)

    def f(self, y):
        _, m_f_p, m_f_g, m_d_p, m_d_g = self.mesh(y)
        shaft1 = self.c1 * (y[0] - y[1]) + self.d1 * (y[4] - y[5])
        shaft2 = self.c2 * (y[2] - y[3]) + self.d2 * (y[6] - y[7])
        return np.array([
            y[4], y[5], y[6], y[7],
            (self.M - shaft1) / self.j1,
            (shaft1 - m_f_p - m_d_p) / self.jp,
            (-shaft2 - m_f_g - m_d_g) / self.jg,
            (self.brake + shaft2) / self.j2,
        ])

    def run(self, y0, dt, n):
        y = np.array(y0, dtype=float)
        t = 0.0
        ys, outs = [y.copy()], [self.mesh(y)]
        for _ in range(n):
            k1 = self.f(y)
            k2 = self.f(y + 0.5 * dt * k1)
            k3 = self.f(y + 0.5 * dt * k2)
            k4 = self.f(y + dt * k3)
            y = y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            self.inst.slave.doStep(t, dt)
            t += dt
            ys.append(y.copy())
            outs.append(self.mesh(y))
        return np.array(ys), np.array(outs)


@pytest.mark.parametrize("omega_p", [150.0, 660.0], ids=["low speed", "near resonance"])
def test_rk4_master_matches_the_in_crate_reference(omega_p, md, unzipdir):
    reason = _simulate_available()
    if reason:
        pytest.skip(reason)
    inst = Instance(md, unzipdir, f"rk4 {omega_p}")
    try:
        inst.init()
        z_p = inst.slave.getInteger([inst.vr["z_p"]])[0]
        t_m = 2 * math.pi / (z_p * omega_p)
        dt = t_m / STEPS_PER_MESH_PERIOD
        n = STEPS_PER_MESH_PERIOD * MESH_PERIODS
        ref = reference(omega_p, n * dt, dt)
        assert len(ref["time"]) == n + 1
        assert np.allclose(ref["time"], dt * np.arange(n + 1), rtol=1e-12, atol=1e-15)

        y0 = [ref[s][0] for s in STATE]
        ys, outs = Master(inst).run(y0, dt, n)

        worst = {}
        for i, s in enumerate(STATE):
            worst[s] = np.max(np.abs(ys[:, i] - ref[s])) / np.max(np.abs(ref[s]))
        for i, m in enumerate(MESH):
            worst[m] = np.max(np.abs(outs[:, i] - ref[m])) / np.max(np.abs(ref[m]))
        print(f"ω_p = {omega_p} rad/s, {n} steps of {dt:.3e} s: largest relative deviations",
              {k: f"{v:.1e}" for k, v in worst.items()})
        # The run must be dynamic, not a trivial constant.
        assert np.ptp(ref["TE"]) > 1e-3 * np.max(np.abs(ref["TE"]))
        bad = {k: v for k, v in worst.items() if not v <= 1e-9}
        assert not bad, f"deviation above 1e-9 relative: {bad}"
    finally:
        inst.free()
