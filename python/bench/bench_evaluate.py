"""Cost per state of `MeshModel.evaluate` on arrays: N random loaded states of Table 1 (one
pinion pitch, TE 5 … 50 µm, 300 rad/s) in one call, at table or full fidelity, for every
output, the five outputs of a right-hand side (`M_F_p`, `M_F_g`, `M_D_p`, `M_D_g`, `TE`: the
torques path) and `M_F_p` alone; the fastest of R calls each, in ns per state.

    python python/bench/bench_evaluate.py [--states 200000] [--repeat 5] [--fidelity table]
"""

import argparse
import os
import time

import numpy as np

import helical_gear as hg


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=200_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--fidelity", choices=("table", "full"), default="table")
    a = ap.parse_args()
    pair = hg.GearPair()
    g = hg.geometry(pair)
    gp, gg = g.base_radius_p_m, g.base_radius_g_m
    rng = np.random.default_rng(1)
    phi_p = rng.uniform(0.0, g.angular_pitch_p_rad, a.states)
    phi_g = (rng.uniform(5e-6, 50e-6, a.states) - phi_p * gp) / gg
    w_g = -300.0 * pair.z_p / pair.z_g
    model = hg.MeshModel(pair, fidelity=a.fidelity)
    print(f"{a.states} states, {a.fidelity} fidelity, load average {os.getloadavg()[0]:.2f}")
    for name, ask in [("every output", None), ("right-hand side", list(hg.TORQUES_OUTPUTS[:5])),
                      ("M_F_p", ["M_F_p"])]:
        best = float("inf")
        for _ in range(a.repeat):
            t = time.perf_counter()
            model.evaluate(phi_p, phi_g, 300.0, w_g, outputs=ask)
            best = min(best, time.perf_counter() - t)
        print(f"{name:>16}: {best / a.states * 1e9:7.0f} ns per state")


if __name__ == "__main__":
    main()
