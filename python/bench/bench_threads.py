"""Throughput of one shared full-fidelity mesh model evaluated from one and from two Python
threads at once (the GIL is released during the evaluation; the model is shared, each call has
its own workspace). Prints the wall time of one call of N loaded states on one thread, of two
such calls on two threads, and the speed-up 2·t1/t2 (2 on two idle cores), with the
process's CPU time per wall second of each (at most 1 when the calls serialise).

    python python/bench/bench_threads.py [--states 400] [--repeat 3]
"""

import argparse
import os
import threading
import time

import numpy as np

import helical_gear as hg


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=400)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    pair = hg.GearPair()
    g = hg.geometry(pair)
    model = hg.MeshModel(pair, fidelity="full")
    n = a.states
    phi = np.linspace(0.0, 2 * np.pi / pair.z_p, n)
    # Loaded states: TE = 20 µm along one pinion pitch.
    phi_g = (20e-6 - phi * g.base_radius_p_m) / g.base_radius_g_m
    w_g = -300.0 * pair.z_p / pair.z_g

    def work():
        model.evaluate(phi, phi_g, 300.0, w_g)

    work()

    def timed(k):
        ts = [threading.Thread(target=work) for _ in range(k)]
        c = time.process_time()
        t = time.perf_counter()
        for x in ts:
            x.start()
        for x in ts:
            x.join()
        wall = time.perf_counter() - t
        return wall, (time.process_time() - c) / wall

    r1 = min(timed(1) for _ in range(a.repeat))
    r2 = min(timed(2) for _ in range(a.repeat))
    (t1, p1), (t2, p2) = r1, r2
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"one thread {n} states: {t1:.3f} s (CPU/wall {p1:.2f}); two threads {2 * n} states: "
          f"{t2:.3f} s (CPU/wall {p2:.2f}); speed-up {2 * t1 / t2:.2f}x")


if __name__ == "__main__":
    main()
