"""Design studies: many gear designs, each with its own FE compliance, analysed serially or on
any ``dask.distributed`` cluster, written incrementally to Parquet.

``run(designs, analyses=("static", "sweep"), client=None, out=None, fe_density="default")``

* `designs`: a pandas DataFrame, one row per design. Columns are parameters named like the
  FMU parameters, i.e. the `GearPair` JSON keys with nested keys joined by a dot
  (``helix_angle_rad``, ``face_width_m``, ``tip_relief_depth_mn``, ``modifications.…``) and
  the drive line's `DriveLine` keys prefixed ``drive.`` (``drive.torque_nm``, routed to the
  design's drive line, not the pair); a missing column or an empty cell (NaN) keeps the
  Table 1 default. The sweep's speed range can be set per design by the columns
  ``omega_from_rad_s``, ``omega_to_rad_s``, ``omega_points`` (else the `sweep` argument). Any
  other column is forwarded to the library as a parameter (an unknown one gives that design an
  error row), except columns whose name starts with ``_`` (labels, kept as they are).
* Analyses: ``"static"`` — static TE over one pinion pitch at ``drive.torque_nm``
  (``static_points`` angles, full fidelity): ``ste_max_um``, ``ste_peak_to_peak_um``,
  ``mesh_stiffness_mean_n_per_um`` (mean mesh stiffness along the line of action);
  ``"sweep"`` — steady-state runs over the speed range with the table fidelity and the
  resonance search of the library's ``dynamics::sweep``: ``omega_crit_rad_s`` (the resonance
  with the largest TE_max/STE_max; NaN when none is found) and ``peak_te_ratio`` (the largest
  TE_max/STE_max of every run).
* The result: the input rows in input order, input columns kept, then the result columns,
  ``error`` (None, or the message of the exception that stopped this design), the seconds
  ``fe_s`` (the FE run and fits that produced the design's compliance data, reported by every
  design sharing them; 0 when they came from the embedded Table 1 data or the disk cache),
  ``table_s`` (building the sweep's table), ``static_s``, ``sweep_s``, and ``design_key``
  (a hash of the design's parameters and the study settings).

The FE compliance of a design is computed once and shared by its analyses and by every design
with the same compliance parameters: the task is keyed by the content (the library's compliance
key of the pair and the FE density), so Dask computes it once per key and the serial run keeps
it while designs still need it. The compliance data cross between processes losslessly, so the
distributed table equals the serial one.

With `out`, finished rows are appended as small Parquet files to the journal directory
``<out>.parts`` as they arrive (at most `flush_seconds` apart); the complete table is written
to `out` at the end and the journal removed. A study run again with the same `out` reads
`out` and the journal and computes only the designs whose ``design_key`` has no row yet.

FE mesh density: the library computes compliance at ``GearMeshDensity::default()``, with the
embedded data of the Table 1 pair and the disk cache (``HELICAL_GEAR_CACHE_DIR``, or
`cache_dir`) used when they match; ``fe_density="coarse"`` runs the FE at
``GearMeshDensity::coarse()`` (about 20k–30k DOFs per gear, well under a second; for tests),
never cached.

When the environment variable ``HELICAL_GEAR_STUDY_EVENTS`` names a file, every FE compliance
task and every design analysis appends one JSON line to it (``{"event": "fe", "key": …}``,
``{"event": "design", "key": …}``), in whichever process it runs: the counter the tests use.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import time
import warnings
from collections import defaultdict
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from ._api import (
    _SLICES,
    DEFAULT_TABLE_SIZE,
    Compliance,
    MeshModel,
    _design_torque,
    _friction_text,
    compliance,
    static_curve,
    sweep,
)
from ._pair import DriveLine, GearPair

#: Result columns of the contract, in order.
RESULT_COLUMNS = (
    "ste_max_um",
    "ste_peak_to_peak_um",
    "mesh_stiffness_mean_n_per_um",
    "omega_crit_rad_s",
    "peak_te_ratio",
    "error",
)
#: Cost split of each design, s.
TIMING_COLUMNS = ("fe_s", "table_s", "static_s", "sweep_s")
#: Per-design speed-range columns.
SPEED_COLUMNS = ("omega_from_rad_s", "omega_to_rad_s", "omega_points")
ANALYSES = ("static", "sweep")
EVENTS_ENV = "HELICAL_GEAR_STUDY_EVENTS"


@dataclass(frozen=True)
class Settings:
    """Study settings shared by every design (see `run`)."""

    analyses: tuple
    fe_density: str
    static_points: int
    slices: int
    steps_per_period: int
    max_periods: int
    refine_runs: int
    table_size: tuple
    cache_dir: str | None
    #: The mesh friction option as JSON text (None: the paper's frictionless model).
    friction: str | None = None


def _event(kind: str, key: str) -> None:
    path = os.environ.get(EVENTS_ENV)
    if path:
        line = json.dumps({"event": kind, "key": key, "pid": os.getpid()}) + "\n"
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, line.encode())
        finally:
            os.close(fd)


def _is_missing(v: Any) -> bool:
    if v is None:
        return True
    try:
        return isinstance(v, float) and math.isnan(v)
    except TypeError:
        return False


def _plain(v: Any) -> Any:
    return v.item() if hasattr(v, "item") else v


def _speed_range(rec: dict, default: tuple) -> tuple | str:
    """The design's speed range (from, to, points) from its speed columns (else `default`), or
    the message naming the column and the value that is not one: a speed must be a finite real
    number, the number of points an integer. Nothing is coerced (no text parsed as a number,
    no 2.5 points rounded, no boolean taken as 0 or 1)."""
    out = []
    for c, d in zip(SPEED_COLUMNS, default):
        v = _plain(rec[c]) if c in rec and not _is_missing(rec[c]) else d
        integral = c == "omega_points"
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return f"column `{c}` = {v!r}: allowed a number"
        if not math.isfinite(v):
            return f"column `{c}` = {v!r}: allowed a finite number"
        if integral:
            if v != int(v):
                return f"column `{c}` = {v!r}: allowed a whole number of points"
            out.append(int(v))
        else:
            out.append(float(v))
    w_from, w_to, points = out
    if not 0.0 < w_from <= MAX_SPEED_RAD_S:
        return f"column `omega_from_rad_s` = {w_from!r}: allowed 0 < speed <= 1e5 rad/s"
    if not w_from <= w_to <= MAX_SPEED_RAD_S:
        return (
            f"column `omega_to_rad_s` = {w_to!r}: allowed omega_from_rad_s = {w_from!r} <= "
            "speed <= 1e5 rad/s"
        )
    if w_from == w_to and points != 1:
        return f"column `omega_points` = {points!r}: allowed 1 when omega_from = omega_to"
    if w_from < w_to and not 2 <= points <= MAX_SWEEP_SPEEDS:
        return (
            f"column `omega_points` = {points!r}: allowed a whole number in [2, "
            f"{MAX_SWEEP_SPEEDS}] when omega_from < omega_to"
        )
    return tuple(out)


#: Largest speed of a sweep, rad/s (the library's largest nominal speed).
MAX_SPEED_RAD_S = 1e5
#: Most speeds of one sweep (the library's ``MAX_SWEEP_SPEEDS``).
MAX_SWEEP_SPEEDS = 100_000


#: Prefix of the design-table columns of the drive line (the FMU parameter names).
DRIVE_PREFIX = "drive."


def design_pair(params: dict) -> GearPair:
    """The gear pair of one design row (dotted keys, missing values keep the default; the
    ``drive.*`` columns belong to `design_drive`)."""
    return GearPair(
        **{
            k: v
            for k, v in params.items()
            if not _is_missing(v) and not str(k).startswith(DRIVE_PREFIX)
        }
    )


def design_drive(params: dict) -> DriveLine:
    """The drive line of one design row: its ``drive.*`` columns (missing values keep Table
    1's)."""
    return DriveLine(
        **{
            str(k)[len(DRIVE_PREFIX):]: v
            for k, v in params.items()
            if not _is_missing(v) and str(k).startswith(DRIVE_PREFIX)
        }
    )


class _Failed:
    """A failed compliance task (the message reaches every design that needed it)."""

    def __init__(self, message: str):
        self.message = message


def _message(e: BaseException) -> str:
    return f"{type(e).__name__}: {e}"


def compliance_task(pair: GearPair, fe_density: str, cache_dir: str | None, key: str):
    """The FE compliance of `pair` (a `Compliance`), or `_Failed` with the message."""
    _event("fe", key)
    t0 = time.perf_counter()
    try:
        c = compliance(pair, fe_density=fe_density, cache_dir=cache_dir)
    except Exception as e:  # noqa: BLE001 - every failure becomes the design's error row
        return _Failed(_message(e))
    return (c, time.perf_counter() - t0)


def design_task(
    pair: GearPair,
    comp,
    speeds: tuple,
    settings: Settings,
    key: str,
    drive: DriveLine | None = None,
) -> dict:
    """The analyses of one design with its compliance `comp` and drive line `drive` (default
    Table 1's): a dict of result columns."""
    drive = DriveLine() if drive is None else drive
    _event("design", key)
    row: dict[str, Any] = {c: math.nan for c in RESULT_COLUMNS + TIMING_COLUMNS}
    row["error"] = None
    if isinstance(comp, _Failed):
        row["error"] = comp.message
        return row
    c, seconds = comp
    row["fe_s"] = seconds if c.source == "computed" else 0.0
    try:
        if "static" in settings.analyses:
            t0 = time.perf_counter()
            m = MeshModel(pair, "full", settings.slices, c, friction=settings.friction)
            s = static_curve(m, points_per_pitch=settings.static_points, drive=drive)
            row["ste_max_um"] = s.ste_max * 1e6
            row["ste_peak_to_peak_um"] = s.ste_peak_to_peak * 1e6
            row["mesh_stiffness_mean_n_per_um"] = s.mesh_stiffness_mean * 1e-6
            row["static_s"] = time.perf_counter() - t0
        if "sweep" in settings.analyses:
            t0 = time.perf_counter()
            m = MeshModel(
                pair,
                "table",
                settings.slices,
                c,
                settings.table_size,
                _design_torque(drive),
                friction=settings.friction,
            )
            t1 = time.perf_counter()
            row["table_s"] = t1 - t0
            w_from, w_to, points = speeds
            r = sweep(
                m,
                w_from=w_from,
                w_to=w_to,
                points=points,
                steps_per_period=settings.steps_per_period,
                max_periods=settings.max_periods,
                refine_runs=settings.refine_runs,
                threads=1,
                drive=drive,
            )
            row["omega_crit_rad_s"] = r.omega_crit
            row["peak_te_ratio"] = r.peak_te_ratio
            row["sweep_s"] = time.perf_counter() - t1
    except Exception as e:  # noqa: BLE001 - a failing design gives an error row
        row["error"] = _message(e)
    return row


def _key(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:24]


class _Journal:
    """The Parquet output: finished rows in ``<out>.parts``, the complete table in `out`."""

    def __init__(self, out: str | os.PathLike | None, flush_seconds: float):
        self.out = None if out is None else Path(out)
        self.parts = None if out is None else Path(str(out) + ".parts")
        self.flush_seconds = flush_seconds
        self.pending: list[dict] = []
        self.last = 0.0

    def done(self) -> dict[str, dict]:
        """Rows already on disk, by design key."""
        import pandas as pd

        found: dict[str, dict] = {}
        if self.out is None:
            return found
        files = []
        if self.out.exists():
            files.append(self.out)
        if self.parts.exists():
            files += sorted(self.parts.glob("part-*.parquet"))
        for f in files:
            try:
                df = pd.read_parquet(f)
            except Exception as e:  # noqa: BLE001 - any unreadable file: its designs rerun
                warnings.warn(
                    f"study journal: {f} cannot be read ({type(e).__name__}: {e}); "
                    "its designs are computed again",
                    stacklevel=2,
                )
                continue
            if "design_key" not in df.columns:
                continue
            for rec in df.to_dict("records"):
                found[rec["design_key"]] = {
                    c: _plain(rec.get(c)) for c in RESULT_COLUMNS + TIMING_COLUMNS
                }
        for r in found.values():
            if _is_missing(r["error"]):
                r["error"] = None
        return found

    def add(self, key: str, row: dict) -> None:
        if self.out is None:
            return
        self.pending.append({"design_key": key, **row})
        if time.monotonic() - self.last >= self.flush_seconds:
            self.flush()

    def flush(self) -> None:
        if self.out is None or not self.pending:
            return
        import pandas as pd

        self.parts.mkdir(parents=True, exist_ok=True)
        df = pd.DataFrame(self.pending)
        df["error"] = df["error"].astype(object)
        name = f"part-{time.time_ns():020d}-{os.getpid()}.parquet"
        tmp = self.parts / (name + ".tmp")
        df.to_parquet(tmp, index=False)
        os.replace(tmp, self.parts / name)
        self.pending = []
        self.last = time.monotonic()

    def finish(self, table) -> None:
        if self.out is None:
            return
        self.flush()
        tmp = self.out.with_name(self.out.name + ".tmp")
        table.to_parquet(tmp)
        os.replace(tmp, self.out)
        if self.parts.exists():
            for f in self.parts.iterdir():
                f.unlink()
            self.parts.rmdir()


def run(
    designs,
    analyses=("static", "sweep"),
    client=None,
    out: str | os.PathLike | None = None,
    fe_density: str = "default",
    *,
    sweep: tuple = (100.0, 1200.0, 12),
    static_points: int = 20,
    slices: int = _SLICES,
    steps_per_period: int = 128,
    max_periods: int = 3000,
    refine_runs: int = 4,
    table_size: tuple = DEFAULT_TABLE_SIZE,
    cache_dir: str | os.PathLike | None = None,
    progress: bool = True,
    flush_seconds: float = 2.0,
    friction=None,
):
    """Runs `analyses` on every design of the DataFrame `designs` and returns the table (see
    the module doc). `client`: None (serial, in this process), a ``distributed.Client``, or a
    scheduler address (a client is opened and closed here). `sweep`: default speed range
    (from, to, points), rad/s. `refine_runs`: extra runs per resonance (golden section).
    `static_points`: pinion angles of the static TE curve; `slices`: axial slices of the mesh
    model; `table_size`: the sweep's table resolution (see `MeshModel`); `max_periods`,
    `steps_per_period`: the steady-state runs (as the CLI's ``sweep``). `friction`: the mesh
    friction option of every design's models (a dict, JSON text or None; see `MeshModel`),
    the static curve then at its default running speed of 300 rad/s."""
    import pandas as pd

    if isinstance(analyses, str):
        analyses = (analyses,)
    analyses = tuple(analyses)
    bad = [a for a in analyses if a not in ANALYSES]
    if bad:
        raise ValueError(f"analyses {bad}: allowed {ANALYSES}")
    if fe_density not in ("coarse", "default", "refined"):
        raise ValueError(f"fe_density = {fe_density!r}: allowed 'coarse', 'default', 'refined'")
    if not isinstance(designs, pd.DataFrame):
        designs = pd.DataFrame(designs)
    settings = Settings(
        analyses=analyses,
        fe_density=fe_density,
        static_points=int(static_points),
        slices=int(slices),
        steps_per_period=int(steps_per_period),
        max_periods=int(max_periods),
        refine_runs=int(refine_runs),
        table_size=(int(table_size[0]), int(table_size[1])),
        cache_dir=None if cache_dir is None else os.fspath(cache_dir),
        friction=_friction_text(friction),
    )

    # Parse every design here (cheap): its pair, speed range and content key.
    n = len(designs)
    records = designs.to_dict("records")
    keys: list[str] = []
    jobs: dict[str, tuple] = {}  # design key -> (pair or error message, speeds, drive)
    for rec in records:
        params = {
            k: _plain(v)
            for k, v in rec.items()
            if not str(k).startswith("_") and k not in SPEED_COLUMNS
        }
        speeds = _speed_range(rec, sweep)
        key = _key({"params": {k: v for k, v in params.items() if not _is_missing(v)},
                    "speeds": speeds if isinstance(speeds, tuple) else repr(
                        [_plain(rec.get(c)) for c in SPEED_COLUMNS]),
                    "settings": asdict(settings)})
        keys.append(key)
        if key not in jobs:
            if isinstance(speeds, str):
                jobs[key] = (speeds, None, None)
                continue
            try:
                jobs[key] = (design_pair(params), speeds, design_drive(params))
            except Exception as e:  # noqa: BLE001 - invalid design: an error row
                jobs[key] = (_message(e), speeds, None)

    journal = _Journal(out, flush_seconds)
    results = journal.done()
    todo = [k for k in jobs if k not in results]

    from tqdm.auto import tqdm

    bar = tqdm(total=len(jobs), initial=len(jobs) - len(todo), disable=not progress,
               desc="designs", unit="design")

    def finished(key: str, row: dict) -> None:
        results[key] = row
        journal.add(key, row)
        bar.update(1)

    # Designs that failed to parse need no computation.
    for key in list(todo):
        pair, _, _ = jobs[key]
        if isinstance(pair, str):
            row = {c: math.nan for c in RESULT_COLUMNS + TIMING_COLUMNS}
            row["error"] = pair
            finished(key, row)
            todo.remove(key)

    # Compliance key of each remaining design; how many designs still need each.
    ckey = {k: f"{fe_density}-{jobs[k][0].compliance_key()}" for k in todo}
    needed = defaultdict(int)
    for k in todo:
        needed[ckey[k]] += 1

    own_client = None
    try:
        if client is None:
            cache: dict[str, Any] = {}
            for k in sorted(todo, key=lambda k: ckey[k]):
                pair, speeds, drive = jobs[k]
                ck = ckey[k]
                if ck not in cache:
                    cache[ck] = compliance_task(pair, fe_density, settings.cache_dir, ck)
                finished(k, design_task(pair, cache[ck], speeds, settings, k, drive))
                needed[ck] -= 1
                if needed[ck] == 0:
                    del cache[ck]
        else:
            from distributed import Client, as_completed

            if isinstance(client, str):
                own_client = client = Client(client)
            comp_futures: dict[str, Any] = {}
            futures = {}
            for k in todo:
                pair, speeds, drive = jobs[k]
                ck = ckey[k]
                if ck not in comp_futures:
                    comp_futures[ck] = client.submit(
                        compliance_task, pair, fe_density, settings.cache_dir, ck,
                        key=f"helical-gear-compliance-{ck}", pure=False,
                    )
                f = client.submit(
                    design_task, pair, comp_futures[ck], speeds, settings, k, drive,
                    key=f"helical-gear-design-{k}", pure=False,
                )
                futures[f] = k
            for f in as_completed(list(futures)):
                k = futures.pop(f)
                try:
                    row = f.result()
                except Exception as e:  # noqa: BLE001 - a lost worker etc.: an error row
                    row = {c: math.nan for c in RESULT_COLUMNS + TIMING_COLUMNS}
                    row["error"] = _message(e)
                finished(k, row)
                ck = ckey[k]
                needed[ck] -= 1
                if needed[ck] == 0:
                    comp_futures.pop(ck).release()
                f.release()
    finally:
        journal.flush()
        bar.close()
        if own_client is not None:
            own_client.close()

    table = designs.copy()
    for c in RESULT_COLUMNS + TIMING_COLUMNS:
        table[c] = [results[k][c] for k in keys]
    table["error"] = table["error"].astype(object).where(table["error"].notna(), None)
    table["design_key"] = keys
    journal.finish(table)
    return table


def main(argv: list[str] | None = None) -> int:
    """The command line: ``python -m helical_gear study designs.csv --out results.parquet
    [--scheduler ADDRESS] [--workers N]``."""
    p = argparse.ArgumentParser(prog="python -m helical_gear")
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("study", help="run a design study from a CSV table of designs")
    s.add_argument("designs", help="CSV, one row per design, columns named like GearPair keys")
    s.add_argument("--out", required=True, help="Parquet output (resumed when it exists)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--scheduler", help="address of a running Dask scheduler")
    g.add_argument("--workers", type=int, help="start a local Dask cluster of N processes")
    s.add_argument("--analyses", default="static,sweep", help="comma list of static, sweep")
    s.add_argument("--fe-density", default="default", choices=("coarse", "default", "refined"))
    s.add_argument("--sweep", nargs=3, type=float, metavar=("FROM", "TO", "POINTS"),
                   default=(100.0, 1200.0, 12), help="default speed range, rad/s")
    s.add_argument("--refine-runs", type=int, default=4)
    s.add_argument("--max-periods", type=int, default=3000)
    s.add_argument("--no-progress", action="store_true")
    a = p.parse_args(argv)

    import pandas as pd

    designs = pd.read_csv(a.designs)
    kw = dict(
        analyses=tuple(x.strip() for x in a.analyses.split(",") if x.strip()),
        out=a.out,
        fe_density=a.fe_density,
        sweep=(a.sweep[0], a.sweep[1], int(a.sweep[2])),
        refine_runs=a.refine_runs,
        max_periods=a.max_periods,
        progress=not a.no_progress,
    )
    if a.workers:
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            table = run(designs, client=client, **kw)
    else:
        table = run(designs, client=a.scheduler, **kw)
    errors = int(table["error"].notna().sum())
    print(f"{len(table)} designs, {errors} with errors, written to {a.out}")
    return 0
