"""HelicalGearMesh as a force element: a Python master holds the drive line of Eqs. 1–4 and both
gear bodies on elastic supports of its own (28 states, RK4) and asks the FMU, at every stage,
for the mesh torques and the force and moments on each body at the displaced state. From the
library's start, with the library's step, its trajectory is the library's
``simulate(..., supports=...)`` step for step: the FMU is the library's mesh and the master's
equations of motion are the library's (docs/gear-bodies.md)."""

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import Instance

hg = pytest.importorskip("helical_gear")

# The guide's example supports (the file its figures were made with).
SUPPORTS = json.loads(
    (Path(__file__).resolve().parents[2] / "docs" / "gear-bodies" / "supports.json").read_text()
)


def diagonal(d, keys):
    r, a, t = (d[k] for k in keys)
    return np.diag([r, r, a, t, t])


class Master:
    """The drive line and both bodies, with the mesh from the FMU `fmu`."""

    OUT = ("M_F_p", "M_F_g", "M_D_p", "M_D_g", "F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y",
           "F_g_x", "F_g_y", "F_g_z", "M_g_x", "M_g_y")

    def __init__(self, fmu):
        self.fmu = fmu
        pair, drive, geo = hg.GearPair(), hg.DriveLine(), hg.geometry()
        self.torque, self.j1, self.j2 = drive.torque_nm, drive.j1_kgm2, drive.j2_kgm2
        self.c1, self.c2 = drive.c1_nm_per_rad, drive.c2_nm_per_rad
        self.d1, self.d2 = drive.d1_nms_per_rad, drive.d2_nms_per_rad
        self.jp, self.jg = geo["j_p_kgm2"], geo["j_g_kgm2"]
        self.brake = self.torque * pair.z_g / pair.z_p
        self.bodies = []
        for name in ("pinion", "gear"):
            s = SUPPORTS[name]
            k = diagonal(s["stiffness"], ("radial_n_per_m", "axial_n_per_m", "tilt_nm_per_rad"))
            c = diagonal(s["damping"], ("radial_ns_per_m", "axial_ns_per_m", "tilt_nms_per_rad"))
            m = np.array([s["mass_kg"]] * 3 + [s["j_transverse_kgm2"]] * 2)
            self.bodies.append((k, c, m))
        self.inputs = ["phi_p", "phi_g", "w_p", "w_g"] + list(hg.POSE_NAMES)

    def rhs(self, y):
        # The FMU's inputs: angles, speeds, then poses and rates in the order of POSE_NAMES.
        values = [y[1], y[2], y[5], y[6]] + list(y[8:28])
        self.fmu.set(**dict(zip(self.inputs, values)))
        o = dict(zip(self.OUT, self.fmu.get(*self.OUT)))
        d = np.empty(28)
        shaft1 = self.c1 * (y[0] - y[1]) + self.d1 * (y[4] - y[5])
        shaft2 = self.c2 * (y[2] - y[3]) + self.d2 * (y[6] - y[7])
        d[0:4] = y[4:8]
        d[4] = (self.torque - shaft1) / self.j1
        d[5] = (shaft1 - o["M_F_p"] - o["M_D_p"]) / self.jp
        d[6] = (-shaft2 - o["M_F_g"] - o["M_D_g"]) / self.jg
        d[7] = (self.brake + shaft2) / self.j2
        for b, (side, j_z, spin) in enumerate((("p", self.jp, y[5]), ("g", self.jg, y[6]))):
            k, c, m = self.bodies[b]
            p, v = y[8 + 5 * b:13 + 5 * b], y[18 + 5 * b:23 + 5 * b]
            w = np.array([o[f"F_{side}_x"], o[f"F_{side}_y"], o[f"F_{side}_z"],
                          o[f"M_{side}_x"], o[f"M_{side}_y"]])
            a = w - k @ p - c @ v
            # Gyroscopic moments of the spinning body.
            a[3] -= j_z * spin * v[4]
            a[4] += j_z * spin * v[3]
            d[8 + 5 * b:13 + 5 * b] = v
            d[18 + 5 * b:23 + 5 * b] = a / m
        return d


def test_a_python_master_with_its_own_bodies_reproduces_the_library(md, unzipdir):
    ref = hg.simulate(None, 300.0, 1.5e-3, slices=60, supports=SUPPORTS)
    start = list(hg.STATE_NAMES) + list(hg.POSE_NAMES)
    y = np.array([ref.arrays[n][0] for n in start])
    dt = ref.time[1] - ref.time[0]

    fmu = Instance(md, unzipdir, "force-element")
    fmu.slave.setInteger([fmu.vr["slices"]], [60])
    fmu.init()
    master = Master(fmu)
    te = []
    for _ in range(ref.time.size - 1):
        k1 = master.rhs(y)
        k2 = master.rhs(y + 0.5 * dt * k1)
        k3 = master.rhs(y + 0.5 * dt * k2)
        k4 = master.rhs(y + dt * k3)
        y = y + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        master.rhs(y)
        te.append(fmu.get("TE")[0])
    fmu.free()
    te = np.array(te)
    dev = np.max(np.abs(te - ref.TE[1:])) / np.max(np.abs(ref.TE))
    pose = np.array(y[8:28])
    end = np.array([ref.arrays[n][-1] for n in hg.POSE_NAMES])
    pdev = np.max(np.abs(pose[:10] - end[:10])) / np.max(np.abs(end[:10]))
    print(f"{ref.time.size - 1} steps: max |ΔTE| {dev:.2e} of TE, poses at the end {pdev:.2e}")
    assert dev < 1e-9 and pdev < 1e-9


def test_table_fidelity_takes_poses(md, unzipdir):
    """At fidelity 1 the FMU's table evaluates a pose with its pose sensitivities (built at the
    first posed call): the torque and the force on the pinion agree with fidelity 0 within
    10⁻³ of 100 N·m and of the force (the table's stated error with poses)."""
    state = {"phi_p": 0.01, "phi_g": -0.0060851, "w_p": 300.0, "w_g": -191.49,
             "u_g_x": 4e-6, "u_g_y": 2e-6, "u_p_z": -1e-6, "th_g_y": -1.5e-5, "th_p_x": 3e-6}
    out = ("M_F_p", "F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y")
    values = []
    for fidelity in (0, 1):
        fmu = Instance(md, unzipdir, f"posed-{fidelity}")
        fmu.slave.setInteger([fmu.vr["fidelity"]], [fidelity])
        fmu.init()
        fmu.set(**state)
        values.append(np.array(fmu.get(*out)))
        assert not fmu.errors(), fmu.errors()
        fmu.free()
    full, table = values
    force = np.linalg.norm(full[1:4])
    assert abs(table[0] - full[0]) < 1e-3 * 100.0, (table, full)
    assert np.max(np.abs(table[1:4] - full[1:4])) < 1e-3 * force, (table, full)
