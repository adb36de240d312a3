"""Design-study throughput: designs per hour on one core (serial) and on a two-process Dask
LocalCluster, and the split of the cost per design (FE and fits, table build, static
analysis, speed sweep), at the default FE density.

    python python/bench/bench_study.py [--designs N] [--workers 2] [--analyses static,sweep]
        [--out docs/bench/study.md]

Designs: a Latin hypercube over helix angle, face width and tip relief (none equals the
Table 1 pair, so every design runs its own FE; no disk cache is used). The same designs are
run serially and on the cluster; the tables must agree. Run it on an otherwise idle machine
(it prints the load average). With ``--out`` the figures are also written as a generated
page.
"""

import argparse
import os
import time

import numpy as np
import pandas as pd


def latin_hypercube(n: int, seed: int = 1) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    u = (np.argsort(rng.random((3, n)), axis=1) + rng.random((3, n))) / n
    return pd.DataFrame({
        "helix_angle_rad": np.radians(8.0 + 12.0 * u[0]),
        "face_width_m": 0.010 + 0.010 * u[1],
        "tip_relief_depth_mn": 0.005 + 0.025 * u[2],
    })


def main() -> None:
    import helical_gear as hg
    from distributed import Client, LocalCluster

    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--analyses", default="static,sweep")
    ap.add_argument("--out", default=None, help="write the figures as a Markdown page here")
    a = ap.parse_args()
    os.environ.pop("HELICAL_GEAR_CACHE_DIR", None)
    analyses = tuple(a.analyses.split(","))
    designs = latin_hypercube(a.designs)

    load_before = os.getloadavg()[0]
    # One core: the serial run (and the table build's threads, which follow the affinity mask)
    # on CPU 0 only; the cluster's worker processes are started with every core allowed.
    cores = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(cores)})
    t0, c0 = time.perf_counter(), time.process_time()
    serial = hg.study.run(designs, analyses=analyses, progress=False)
    t_serial, cpu_serial = time.perf_counter() - t0, time.process_time() - c0
    os.sched_setaffinity(0, cores)

    with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.run(lambda: __import__("helical_gear"))  # workers import the package first
        cpu0 = client.run(time.process_time)
        t0 = time.perf_counter()
        dist = hg.study.run(designs, analyses=analyses, client=client, progress=False)
        t_dist = time.perf_counter() - t0
        cpu1 = client.run(time.process_time)
    worker_cpu = [cpu1[w] - cpu0[w] for w in cpu0]

    cols = ["ste_max_um", "omega_crit_rad_s", "peak_te_ratio", "error"]
    same = serial[cols].equals(dist[cols])
    split = serial[["fe_s", "table_s", "static_s", "sweep_s"]].mean()
    n = len(designs)
    print(f"{n} designs, analyses {analyses}, default FE density; tables equal: {same}")
    print(f"serial (1 core):       {t_serial:8.1f} s  {3600 * n / t_serial:8.0f} designs/h")
    print(f"{a.workers} workers (LocalCluster): {t_dist:8.1f} s  {3600 * n / t_dist:8.0f} designs/h"
          f"  speed-up {t_serial / t_dist:.2f}x")
    # CPU seconds do not grow when other processes share the cores, wall seconds do: the
    # busiest worker's CPU time is the wall time the cluster would take with a core each.
    print(f"CPU: serial {cpu_serial:.1f} s; workers {', '.join(f'{c:.1f}' for c in worker_cpu)} s;"
          f" with a free core per process: {3600 * n / cpu_serial:.0f} designs/h serial, "
          f"{3600 * n / max(worker_cpu):.0f} designs/h on {a.workers} workers "
          f"(x{cpu_serial / max(worker_cpu):.2f})")
    print("mean cost per design, s: " + ", ".join(f"{k} {v:.2f}" for k, v in split.items()))
    for i, e in serial["error"].dropna().items():
        print(f"design {i} failed: {e}")
    print(f"load average (1 min) before {load_before:.1f}, after {os.getloadavg()[0]:.1f} "
          f"on {len(cores)} cores")
    if a.out:
        write_page(a, n, analyses, same, t_serial, cpu_serial, t_dist, worker_cpu, split,
                   load_before, len(cores), serial["error"].notna().sum())


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def write_page(a, n, analyses, same, t_serial, cpu_serial, t_dist, worker_cpu, split,
               load_before, cores, failed) -> None:
    """The figures of one run as a generated Markdown page."""
    cmd = (f"RAYON_NUM_THREADS=1 python python/bench/bench_study.py --designs {n} "
           f"--workers {a.workers} --analyses {','.join(analyses)} --out {a.out}")
    rows = [
        ("designs", f"{n} (Latin hypercube: helix angle 8–20°, face width 10–20 mm, tip relief "
                    f"0.005–0.03·m_n), analyses {', '.join(analyses)}, default FE density"),
        ("serial, one core: wall time", f"{t_serial:.1f} s, {3600 * n / t_serial:.0f} designs/h"),
        ("serial: CPU time", f"{cpu_serial:.1f} s, {cpu_serial / n:.2f} s per design, "
                             f"{3600 * n / cpu_serial:.0f} designs/h/core"),
        (f"LocalCluster, {a.workers} worker processes: wall time",
         f"{t_dist:.1f} s, {3600 * n / t_dist:.0f} designs/h (×{t_serial / t_dist:.2f})"),
        ("workers' CPU time", ", ".join(f"{c:.1f} s" for c in worker_cpu)),
        ("mean cost per design (serial)",
         ", ".join(f"{k.removesuffix('_s')} {v:.2f} s" for k, v in split.items())),
        ("serial and cluster tables equal", "yes" if same else "no"),
        ("designs that failed", str(failed)),
    ]
    lines = [
        "# Design-study throughput",
        "",
        "<!-- Generated file: do not edit; regenerate with the command below. -->",
        "",
        f"Generated by `{cmd}` on {time.strftime('%Y-%m-%d', time.gmtime())} (UTC), on a "
        f"machine with {cores} cores ({cpu_model()}); load average over the minute before the "
        f"run: {load_before:.2f}. Times are wall time of one run; other work on the machine "
        "makes them longer. The serial run is pinned to one core (its table builds included); "
        "the cluster's workers may use every core. CPU seconds do not grow when processes share "
        "a core, so the CPU time per design is the cost on a core of its own.",
        "",
        "| quantity | value |",
        "| --- | --- |",
        *[f"| {k} | {v} |" for k, v in rows],
        "",
    ]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
