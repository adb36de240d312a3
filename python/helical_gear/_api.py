"""The main calls: geometry, compliance, the mesh model, static TE, simulation, speed sweep and
the paper run. Every call is a thin wrapper of the Rust library (`helical_gear._native`); the
Rust work runs with the GIL released.

Units are SI: angles rad, speeds rad/s, torques N·m, TE m, times s. Angles φp, φg are hub
rotations in one absolute sense (the pinion drives in the positive sense); the transmission
error is TE = φp·g_p + φg·g_g (Eq. 16; > 0 when the teeth must deform). The mesh torques are
positive in normal drive and enter the equations of motion with a minus sign.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _native
from ._pair import DriveLine, GearPair

#: Keys of `MeshModel.evaluate`'s result: the FMU's output names, from the library's one table
#: of the mesh outputs (`_native.MESH_OUTPUTS`: name, SI unit, kind, meaning), in its order.
OUTPUT_NAMES = tuple(name for name, _unit, _kind, _meaning in _native.MESH_OUTPUTS)

#: The outputs `MeshModel.evaluate` computes on its own when asked only for them
#: (``outputs=``): the mesh torques, TE, the loaded contact length and the friction torques and
#: loss, from the library's table (`_native.TORQUES_OUTPUTS`).
TORQUES_OUTPUTS = tuple(_native.TORQUES_OUTPUTS)

#: Keywords of `MeshModel.evaluate` for the gear bodies off their bearing axes: each body's
#: translation ``u_*_x``, ``u_*_y``, ``u_*_z`` (m) and tilts ``th_*_x``, ``th_*_y`` (rad) at its
#: centre at mid-face, then their rates ``v_*`` (m/s) and ``om_*`` (rad/s), pinion ``p`` then
#: gear ``g``: the FMU's input names, from the library (`_native.POSE_INPUTS`).
POSE_NAMES = tuple(_native.POSE_INPUTS)

#: The library's default mesh options (`_native.MESH_OPTION_DEFAULTS`, from its
#: `MeshOptions::default()`): ``slices``, ``table_phase_points``, ``table_te_points``,
#: ``table_design_torque`` (N·m) and ``table_slices``; every default below is read from here.
MESH_OPTION_DEFAULTS = dict(_native.MESH_OPTION_DEFAULTS)
_SLICES = MESH_OPTION_DEFAULTS["slices"]
#: The table's default points per mesh period × points along TE.
DEFAULT_TABLE_SIZE = (
    MESH_OPTION_DEFAULTS["table_phase_points"],
    MESH_OPTION_DEFAULTS["table_te_points"],
)

#: SI unit of each output of `OUTPUT_NAMES` ("" for counts and flags).
OUTPUT_UNITS = {name: unit for name, unit, _kind, _meaning in _native.MESH_OUTPUTS}

#: The 3D force and moments (the FMU output names): the force of the mesh on the pinion
#: ``F_p_*`` and on the gear ``F_g_* = -F_p_*`` (N), the tilting moments about each gear's
#: centre at mid-face ``M_p_*``, ``M_g_*`` (N·m), in the housing frame of docs/loads.md
#: (x from the pinion axis to the gear axis, z along the pinion axis, y = z × x).
FORCE_NAMES = OUTPUT_NAMES[OUTPUT_NAMES.index("F_p_x") : OUTPUT_NAMES.index("M_g_y") + 1]

#: The mesh friction outputs (the FMU output names): the loss ``P_loss`` (W), the mesh
#: efficiency ``eta_mesh``, the friction torques ``M_R_p``, ``M_R_g`` (N·m) and the heat into
#: each gear ``Q_p``, ``Q_g`` (W).
LOSS_NAMES = ("P_loss", "eta_mesh", "M_R_p", "M_R_g", "Q_p", "Q_g")

FE_DENSITIES = ("coarse", "default", "refined")


def _drive(drive: DriveLine | None) -> DriveLine:
    if drive is None:
        return DriveLine()
    if not isinstance(drive, DriveLine):
        raise TypeError(f"expected a DriveLine, got {type(drive).__name__}")
    return drive


def _design_torque(drive: DriveLine) -> float:
    """The table's design torque for `drive`: max(|M|, 1 N·m) (the library's rule)."""
    return max(abs(float(drive.torque_nm)), 1.0)


def _pair(pair: GearPair | None) -> GearPair:
    if pair is None:
        return GearPair()
    if not isinstance(pair, GearPair):
        raise TypeError(f"expected a GearPair, got {type(pair).__name__}")
    return pair


class _Result:
    """Base of the result objects: numpy arrays, `to_dataframe()` and `plot()`."""

    _columns: tuple[str, ...] = ()

    def to_dataframe(self):
        """The per-sample arrays as a pandas DataFrame (pandas is imported here)."""
        import pandas as pd

        return pd.DataFrame({c: np.asarray(getattr(self, c)) for c in self._columns})

    def _axes(self, ax):
        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots()
        return ax


class Mapping_(Mapping):
    """A read-only mapping with attribute access (geometry, summaries)."""

    def __init__(self, d: Mapping[str, Any]):
        self.__dict__["_d"] = dict(d)

    def __getitem__(self, k):
        return self._d[k]

    def __iter__(self):
        return iter(self._d)

    def __len__(self):
        return len(self._d)

    def __getattr__(self, k):
        try:
            return self._d[k]
        except KeyError:
            raise AttributeError(k) from None

    def __repr__(self):
        return f"{type(self).__name__}({self._d!r})"


class Geometry(Mapping_):
    """Derived geometry of a pair (the keys and values of ``helical-gear geometry --json``,
    the library's ``results::GeometryRecord``): contact ratios ``eps_alpha``, ``eps_beta``;
    radii ``*_radius_p_m``/``*_g_m`` (``relief_start_radius_*_m`` None without tip relief);
    ``center_distance_m``; angles ``*_rad`` (``angular_pitch_p_rad``); ``base_pitch_m``;
    ``backlash_te_m``; inertias ``j_p_kgm2``, ``j_g_kgm2``; ``assumptions`` (sentences)."""


def geometry(pair: GearPair | None = None) -> Geometry:
    """Derived geometry of `pair` (default Table 1)."""
    return Geometry(json.loads(_native.geometry_json(_pair(pair).to_json())))


class Compliance:
    """FE compliance data of both gears of a pair (influence grids and fitted constants of
    Eqs. 5–8). Pickles losslessly (every float exact), so a model rebuilt from unpickled data
    equals the original bit for bit."""

    __slots__ = ("pair", "_c", "fe_density")

    def __init__(self, pair: GearPair, native, fe_density: str):
        self.pair = pair
        self._c = native
        self.fe_density = fe_density

    @property
    def source(self) -> str:
        """Where the data came from: ``computed``, ``embedded`` (Table 1) or ``disk`` (cache)."""
        return self._c.source()

    def summary(self, drive: DriveLine | None = None) -> Mapping_:
        """Source (``computed``, ``embedded``, ``disk``), density, FE sizes and seconds, fit
        quality σ(e_rel) and the tooth-pair stiffness c′ at the pitch point, N/(mm·µm), under
        the torque of `drive` (default Table 1's, 100 N·m)."""
        t = float(_drive(drive).torque_nm)
        return Mapping_(json.loads(self._c.summary_json(self.pair.to_json(), t)))

    def __reduce__(self):
        return (_compliance_from_json, (self.pair, self._c.to_json(), self.fe_density))

    def __repr__(self):
        s = self.summary()
        return (
            f"Compliance({s['source']}, {s['density']} density, {s['fe_dofs_p']}/"
            f"{s['fe_dofs_g']} DOFs, c′ = {s['pair_stiffness_n_per_mm_per_um']:.3f} N/(mm·µm))"
        )


def _compliance_from_json(pair: GearPair, text: str, fe_density: str) -> Compliance:
    return Compliance(pair, _native.Compliance.from_json(text), fe_density)


def compliance(
    pair: GearPair | None = None,
    fe_density: str = "default",
    cache_dir: str | os.PathLike | None = None,
    progress: bool = False,
) -> Compliance:
    """FE compliance data of `pair`.

    ``fe_density="default"`` takes the library's default source: the embedded data of the
    Table 1 pair when the compliance parameters match, else the disk cache in `cache_dir`
    (default: the environment variable ``HELICAL_GEAR_CACHE_DIR``), else a fresh FE run at the
    default mesh density (``fe_compliance_s`` in docs/performance.md; written to the cache
    when a directory is set).
    ``"coarse"`` (for tests; about 3 % stiffer) and ``"refined"`` always run the FE at that
    density and never touch the cache.
    """
    pair = _pair(pair)
    if fe_density not in FE_DENSITIES:
        raise _native.ParameterError(
            f"fe_density = {fe_density!r}: allowed {', '.join(map(repr, FE_DENSITIES))}"
        )
    if fe_density == "default":
        c = _native.Compliance.for_pair(
            pair.to_json(), None if cache_dir is None else os.fspath(cache_dir), progress
        )
    else:
        c = _native.Compliance.compute(pair.to_json(), fe_density, progress)
    return Compliance(pair, c, fe_density)


_MAX_COUNT = 2**63 - 1


def _count(name: str, value, lo: int = 0) -> int:
    """`value` as a whole number >= `lo` for a count argument (slices, threads, table points,
    runs): anything else is a ``ParameterError`` naming the argument, its value and the range,
    never Python's OverflowError from the conversion to an unsigned integer."""
    try:
        v = int(value)
        whole = v == value and not isinstance(value, bool)
    except (TypeError, ValueError, OverflowError):
        whole = False
    if not whole or v < lo or v > _MAX_COUNT:
        raise _native.ParameterError(
            f"`{name}` = {value!r}: allowed a whole number in [{lo}, {_MAX_COUNT}]"
        )
    return v


def _friction_text(friction) -> str | None:
    """JSON text of the `friction` option: a mapping (its non-finite values named by key), a
    JSON string (or ``"none"``), or None (no friction); anything else is a
    ``ParameterError``. The keys and values are checked by the library."""
    if friction is None:
        return None
    if isinstance(friction, Mapping):
        _finite_keys(friction, "friction")
        return json.dumps(dict(friction))
    if isinstance(friction, str):
        return friction
    raise _native.ParameterError(
        f"friction = {friction!r}: allowed a dict, JSON text, \"none\" or None"
    )


class MeshModel:
    """The Andersson–Vedmar mesh model of a pair.

    ``fidelity="full"`` does the contact search and load solve at every evaluation;
    ``"table"`` interpolates in a (mesh phase, TE) table built once from the full model (under
    a second for Table 1) and falls back to the full model outside it. `slices`: total axial
    slices over the simultaneous contact lines (the paper's 200). `compliance`: FE data of this
    pair (default: `compliance(pair)`). `table_size`: the table's points per mesh period ×
    points along TE (96 × 24: 2.0·10⁻⁴ relative error; 16 × 12 builds 4–6× faster at 6·10⁻³);
    each 8 … 4096 and their product at most 65 536 (about a minute of build), else
    `ParameterError`.
    `table_design_torque`: the torque (N·m, 1 … 1e9) whose static TE sizes the table's TE range
    (default 100, Table 1's; `simulate` and `sweep` size a table they build themselves for
    their ``drive``); a torque the pair cannot carry within the model's overlap limit (Table 1:
    about 2.2 kN·m) is a ``ParameterError`` naming it. `table_slices`: the table samples the
    full model at min(`slices`, `table_slices`) slices (default 100: the table's error is
    unchanged, its build three times faster than at 200; 10 … 4000). `slices`, `table_size` and
    `table_slices` are whole numbers (else ``ParameterError`` naming them); the table's points ×
    sample slices are at most 65 536 × 100 (about a minute of build). `friction`: the mesh
    friction option, a dict or JSON text ``{"model": "none" | "constant" | "iso_tr_14179_2",
    "mu": …, "oil_viscosity_pa_s": …, "roughness_ra_m": …, "lubricant_factor": …,
    "regularisation_speed_m_s": …}`` (every key optional, SI units; an unknown key or a value
    out of range is a ``ParameterError`` naming it), or None (default) for the paper's
    frictionless model; with friction the torques include the friction torques ``M_R_p``,
    ``M_R_g`` and the outputs ``P_loss`` (W), ``eta_mesh``, ``Q_p``, ``Q_g`` (W) are filled.
    Pickles as pair + options (+ the compliance when given) and is rebuilt on unpickling.
    """

    def __init__(
        self,
        pair: GearPair | None = None,
        fidelity: str = "full",
        slices: int = _SLICES,
        compliance: Compliance | None = None,
        table_size: tuple[int, int] = DEFAULT_TABLE_SIZE,
        table_design_torque: float = MESH_OPTION_DEFAULTS["table_design_torque"],
        friction: Mapping[str, Any] | str | None = None,
        table_slices: int = MESH_OPTION_DEFAULTS["table_slices"],
    ):
        self.pair = _pair(pair)
        self.friction = _friction_text(friction)
        self.fidelity = fidelity
        self.slices = _count("slices", slices, 1)
        self.compliance = compliance
        self.table_size = (
            _count("table_size[0]", table_size[0]),
            _count("table_size[1]", table_size[1]),
        )
        self.table_design_torque = float(table_design_torque)
        self.table_slices = _count("table_slices", table_slices, 1)
        self._m = _native.MeshModel(
            self.pair.to_json(),
            fidelity,
            self.slices,
            None if compliance is None else compliance._c,
            *self.table_size,
            self.table_design_torque,
            self.friction,
            self.table_slices,
        )

    def __reduce__(self):
        return (
            MeshModel,
            (
                self.pair,
                self.fidelity,
                self.slices,
                self.compliance,
                self.table_size,
                self.table_design_torque,
                self.friction,
                self.table_slices,
            ),
        )

    def __repr__(self):
        return f"MeshModel({self.pair!r}, fidelity={self.fidelity!r}, slices={self.slices})"

    @property
    def table_build_seconds(self) -> float:
        """Seconds the table took to build (0 for the full fidelity)."""
        return self._m.table_build_seconds()

    def evaluate(
        self, phi_p, phi_g, w_p=0.0, w_g=0.0, outputs=None, **pose
    ) -> dict[str, np.ndarray]:
        """Mesh outputs at the states (φp, φg, φ̇p, φ̇g) (rad, rad/s); the four arguments are
        broadcast against each other (numpy rules) and evaluated in C order, each exactly as
        the library's ``Mesh::evaluate`` (the first state from a cold start, each next one
        warm-started from the one before: a call's results depend on its arguments only).
        Calls from several threads on one model run in parallel. Returns a dict of arrays of
        the broadcast shape:
        ``M_F_p``, ``M_F_g``, ``M_D_p``, ``M_D_g`` (N·m), ``TE`` (m), ``F_n`` (N),
        ``contact_length`` (m), ``p_max`` (Pa), ``sigma_F_p``, ``sigma_F_g`` (tooth-root
        stresses, Pa), ``n_pairs``, ``tip_contact``, ``separated``, ``back_contact``, the
        friction torques ``M_R_p``, ``M_R_g`` (N·m, inside ``M_F_p``, ``M_F_g``), the loss
        ``P_loss`` (W), the mesh efficiency ``eta_mesh`` and the heat ``Q_p``, ``Q_g`` (W)
        (0, 1, 0 without friction), and every other name of `OUTPUT_NAMES`.

        ``outputs``: the names of `OUTPUT_NAMES` to compute and return (each once, in the order
        given; default all). When they are all torques outputs (`TORQUES_OUTPUTS`: ``M_F_p``,
        ``M_F_g``, ``M_D_p``, ``M_D_g``, ``TE``, ``contact_length``, ``M_R_p``, ``M_R_g``,
        ``P_loss``) the evaluation computes only those, bit for bit as the complete one: at
        table fidelity 3 of the table's 13 node values are interpolated. An unknown name raises
        `ParameterError` naming it.

        The gear bodies off their bearing axes (``docs/gear-bodies.md``): the keywords of
        `POSE_NAMES`, each broadcast like the angles, all 0 by default (the rigid-bearing
        model): ``u_p_x``, ``u_p_y``, ``u_p_z`` (m), ``th_p_x``, ``th_p_y`` (rad), the pinion
        body's translation and tilts at its centre at mid-face; ``v_p_x`` … ``om_p_y`` their
        rates (m/s, rad/s); the same with ``_g_`` for the gear. A pose beyond its bound
        (0.05·m_n, tilts 0.05·m_n/b) raises `ParameterError` naming it."""
        unknown = sorted(set(pose) - set(POSE_NAMES))
        if unknown:
            raise _native.ParameterError(
                f"evaluate: unknown keyword(s) {', '.join(unknown)}; the pose keywords are "
                + ", ".join(POSE_NAMES)
            )
        names = [k for k in POSE_NAMES if k in pose]
        arrays = np.broadcast_arrays(
            *(np.asarray(a, dtype=np.float64) for a in (phi_p, phi_g, w_p, w_g)),
            *(np.asarray(pose[k], dtype=np.float64) for k in names),
        )
        shape = arrays[0].shape
        flat = [np.ascontiguousarray(a.ravel()) for a in arrays]
        poses = None
        if names:
            poses = np.zeros((flat[0].size, len(POSE_NAMES)))
            for k, a in zip(names, flat[4:]):
                poses[:, POSE_NAMES.index(k)] = a
        if outputs is not None:
            outputs = [outputs] if isinstance(outputs, str) else [str(k) for k in outputs]
        out = self._m.evaluate(*flat[:4], poses, outputs)
        return {k: v.reshape(shape) for k, v in out.items()}


def _model(
    pair_or_model,
    fidelity: str,
    slices: int,
    compliance: Compliance | None,
    drive: DriveLine | None = None,
    friction: Mapping[str, Any] | str | None = None,
) -> MeshModel:
    if isinstance(pair_or_model, MeshModel):
        if friction is not None:
            raise _native.ParameterError(
                "friction= applies to a model built here; a MeshModel carries its own "
                "(MeshModel(..., friction=...))"
            )
        return pair_or_model
    torque = _design_torque(_drive(drive))
    return MeshModel(
        _pair(pair_or_model), fidelity, slices, compliance, DEFAULT_TABLE_SIZE, torque, friction
    )


@dataclass(frozen=True)
class StaticCurve(_Result):
    """Static transmission error over pinion angles (Eq. 16) at one torque."""

    #: Driving torque on the pinion, N·m.
    torque_nm: float
    #: Pinion angles, rad.
    phi_p: np.ndarray
    #: Static TE, m.
    ste: np.ndarray
    #: Loaded tooth pairs.
    n_pairs: np.ndarray
    #: Largest Hertz pressure, Pa.
    p_max: np.ndarray
    #: Loaded contact on the tip rounding.
    tip_contact: np.ndarray
    #: Loaded contact length, m.
    contact_length: np.ndarray
    #: max, min, mean STE, m; peak to peak, m.
    ste_max: float
    ste_min: float
    ste_mean: float
    #: Mean mesh stiffness along the line of action, N/m.
    mesh_stiffness_mean: float
    #: Tooth-root stress of pinion and gear (largest maximum principal stress at the
    #: tension-side fillet), Pa.
    sigma_F_p: np.ndarray
    sigma_F_g: np.ndarray
    #: Largest tooth-root stress over the points, Pa.
    sigma_F_max_p: float
    sigma_F_max_g: float
    #: ISO 6336-3 method B nominal tooth-root stress σ_F0 of pinion and gear at `torque_nm`,
    #: Pa (None when the method does not apply; the reason in ``iso6336_error``).
    root_stress_iso_p_pa: float | None = None
    root_stress_iso_g_pa: float | None = None
    #: The factors behind them (`iso_root_stress`'s dict), or None.
    iso6336: dict | None = None
    #: Why ISO 6336-3 method B does not apply to the pair, or None.
    iso6336_error: str | None = None
    #: The force and moments per point (`FORCE_NAMES`: N, N·m), keyed by name; also
    #: attributes (``curve.F_p_x``) and columns of `to_dataframe()`.
    forces: dict = field(default_factory=dict, repr=False)
    #: Pinion speed of the quasi-static states, rad/s (the gear at the rigid ratio; the
    #: states run at it with friction, at rest without).
    w_p: float = 0.0
    #: Mean mesh friction loss over the points, W (0 without friction or at standstill).
    mesh_loss_mean: float = 0.0
    #: Mean mesh efficiency 1 − `mesh_loss_mean`/(M·|w_p|) (1 at standstill).
    mesh_efficiency_mean: float = 1.0
    #: Gear loss factor H_V of ISO/TR 14179-2 from the geometry.
    loss_factor_h_v: float = float("nan")
    #: Coefficient of friction: the option's μ (``constant``), the mean μ_mz over the points
    #: (``iso_tr_14179_2``), None without friction.
    mu_mean: float | None = None
    #: The friction outputs per point (`LOSS_NAMES`: ``P_loss`` W, ``eta_mesh``, ``M_R_p``,
    #: ``M_R_g`` N·m, ``Q_p``, ``Q_g`` W), keyed by name; also attributes (``curve.P_loss``)
    #: and columns of `to_dataframe()`.
    losses: dict = field(default_factory=dict, repr=False)
    #: The gear pair the curve was computed for (its face width places the gear centres of
    #: `bearing_loads`).
    pair: GearPair | None = field(default=None, repr=False, compare=False)
    _columns = (
        "phi_p",
        "ste",
        "n_pairs",
        "p_max",
        "tip_contact",
        "contact_length",
        "sigma_F_p",
        "sigma_F_g",
    ) + FORCE_NAMES + LOSS_NAMES

    def __getattr__(self, k):
        for group in ("forces", "losses"):
            values = self.__dict__.get(group, {})
            if k in values:
                return values[k]
        raise AttributeError(k)

    @property
    def ste_peak_to_peak(self) -> float:
        """STE max − min, m."""
        return self.ste_max - self.ste_min

    def plot(self, ax=None):
        """STE (µm) over the pinion angle (rad) on `ax` (a new figure when None)."""
        ax = self._axes(ax)
        ax.plot(self.phi_p, self.ste * 1e6, marker=".")
        ax.set_xlabel("pinion angle φp (rad)")
        ax.set_ylabel("static TE (µm)")
        ax.set_title(f"Static transmission error, M = {self.torque_nm:g} N·m")
        return ax


def static_curve(
    pair: GearPair | MeshModel | None = None,
    torque: float | None = None,
    points_per_pitch: int = 20,
    pitches: int = 1,
    slices: int = _SLICES,
    compliance: Compliance | None = None,
    drive: DriveLine | None = None,
    friction: Mapping[str, Any] | str | None = None,
    w_p: float = 300.0,
) -> StaticCurve:
    """Static TE of `pair` (or of a `MeshModel`, full fidelity recommended) at `torque` N·m
    (default: the torque of `drive`, default Table 1's 100 N·m) on `points_per_pitch` angles
    per pinion pitch over `pitches` pitches from φp = 0 (the library's ``mesh::static_curve``,
    as the CLI's ``static``), with the ISO 6336-3 method B root stress at that torque
    (``root_stress_iso_p_pa``, ``root_stress_iso_g_pa``, ``iso6336``: the keys of
    ``helical-gear static --json``). `friction`: the mesh friction option (see `MeshModel`;
    a `MeshModel` passed as `pair` carries its own). `w_p`: the pinion speed of the
    quasi-static states, rad/s (default 300, as the CLI's ``--omega-p``; 0: standstill,
    negative: running backwards), which sets the sliding speeds, the loss and the ISO μ; the
    result's ``P_loss``, ``eta_mesh``, ``M_R_p``, ``M_R_g``, ``Q_p``, ``Q_g`` per point and
    ``mesh_loss_mean``, ``mesh_efficiency_mean``, ``loss_factor_h_v``, ``mu_mean``."""
    drive = _drive(drive)
    m = _model(pair, "full", slices, compliance, drive, friction)
    t = drive.torque_nm if torque is None else float(torque)
    d = json.loads(
        m._m.static_curve_json(t, int(points_per_pitch), int(pitches), float(w_p))
    )
    iso = json.loads(_native.iso_root_stress_summary_json(m.pair.to_json(), t))
    return StaticCurve(
        torque_nm=d["torque_nm"],
        phi_p=np.array(d["phi_p_rad"]),
        ste=np.array(d["ste_um"]) * 1e-6,
        n_pairs=np.array(d["n_pairs"], dtype=np.uint32),
        p_max=np.array(d["p_max_pa"]),
        tip_contact=np.array(d["tip_contact"], dtype=bool),
        contact_length=np.array(d["contact_length_m"]),
        ste_max=d["ste_max_um"] * 1e-6,
        ste_min=d["ste_min_um"] * 1e-6,
        ste_mean=d["ste_mean_um"] * 1e-6,
        mesh_stiffness_mean=d["mesh_stiffness_mean_n_per_um"] * 1e6,
        root_stress_iso_p_pa=iso["root_stress_iso_p_pa"],
        root_stress_iso_g_pa=iso["root_stress_iso_g_pa"],
        iso6336=iso["iso6336"],
        iso6336_error=iso["iso6336_error"],
        forces=_force_columns(d),
        sigma_F_p=np.array(d["root_stress_p_pa"]),
        sigma_F_g=np.array(d["root_stress_g_pa"]),
        sigma_F_max_p=d["root_stress_max_p_pa"],
        sigma_F_max_g=d["root_stress_max_g_pa"],
        pair=m.pair,
        w_p=d["omega_p_rad_s"],
        mesh_loss_mean=d["mesh_loss_mean_w"],
        mesh_efficiency_mean=d["mesh_efficiency_mean"],
        loss_factor_h_v=d["loss_factor_h_v"],
        mu_mean=d["mu_mean"],
        losses={
            name: np.array(d[key], dtype=float)
            for name, key in zip(
                LOSS_NAMES, ("p_loss_w", "eta_mesh", "m_r_p_nm", "m_r_g_nm", "q_p_w", "q_g_w")
            )
        },
    )


def iso_root_stress(pair: GearPair | None = None, torque: float = 100.0) -> dict:
    """Nominal tooth-root stress of ISO 6336-3:2006 method B for `pair` (default Table 1) at
    the pinion torque `torque` N·m (its sign is ignored), as the library's ``iso6336``
    computes it: a dict with ``tangential_force_n`` (N) and, for ``"pinion"`` and ``"gear"``,
    the factors ``y_f``, ``y_s``, ``y_beta``, ``y_b``, ``y_dt``, the section ``s_fn_m``,
    ``h_fe_m``, ``rho_f_m`` (m), ``alpha_fen_rad``, ``z_n`` and ``sigma_f0_pa`` (Pa). A pair the
    method cannot rate (virtual contact ratio below 1, a rim under half a tooth depth, …)
    raises `ParameterError` naming the key to change."""
    return json.loads(_native.iso_root_stress_json(_pair(pair).to_json(), float(torque)))


def _force_columns(d: Mapping[str, Any]) -> dict:
    """`FORCE_NAMES` → arrays from a static record's ``force_p_n``, ``moment_p_nm``,
    ``force_g_n``, ``moment_g_nm`` (per-point lists of components)."""
    out = {}
    for key, prefix, axes in (
        ("force_p_n", "F_p", "xyz"),
        ("moment_p_nm", "M_p", "xy"),
        ("force_g_n", "F_g", "xyz"),
        ("moment_g_nm", "M_g", "xy"),
    ):
        a = np.array(d[key], dtype=float).reshape(-1, len(axes))
        for k, ax in enumerate(axes):
            out[f"{prefix}_{ax}"] = a[:, k]
    return out


@dataclass(frozen=True)
class BearingLoads(_Result):
    """The reactions of the four bearings (force of each bearing on its shaft, N, in the housing
    frame of docs/loads.md) per sample of a static curve or trajectory, keyed
    ``<shaft>_<bearing>_<x|y|z>`` (``pinion_locating_x`` …, ``gear_floating_z``), as
    attributes (numpy arrays) and in ``arrays``; `mean()` and `peak_to_peak()` per key."""

    arrays: dict = field(repr=False)

    def __getattr__(self, k):
        try:
            return self.__dict__["arrays"][k]
        except KeyError:
            raise AttributeError(k) from None

    @property
    def _columns(self):
        return tuple(self.arrays)

    def mean(self) -> dict:
        """Mean of each reaction component over the samples, N."""
        return {k: float(np.mean(v)) for k, v in self.arrays.items()}

    def peak_to_peak(self) -> dict:
        """max − min of each reaction component over the samples, N."""
        return {k: float(np.ptp(v)) for k, v in self.arrays.items()}


#: Largest JSON file read for parameters (bearings), bytes: 16 MiB, far above any
#: parameter file (a few kB), far below a runaway read (``/dev/zero`` has no end).
MAX_JSON_FILE_BYTES = 16 * 1024 * 1024


def _finite_keys(value, path: str) -> None:
    """Raises ``ParameterError`` naming the key of the first non-finite float in `value`."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            _finite_keys(v, f"{path}.{k}" if path else str(k))
    elif isinstance(value, float) and not np.isfinite(value):
        raise _native.ParameterError(f"`{path}` = {value}: allowed a finite number")


def _read_json_file(path) -> str:
    """The text of the JSON file `path`, as ``ParameterError`` naming the path when it is no
    file, a directory, larger than `MAX_JSON_FILE_BYTES` or not UTF-8."""
    p = os.fspath(path)
    if os.path.isdir(p):
        raise _native.ParameterError(f"{p!r} is a directory, not a JSON file")
    try:
        with open(p, "rb") as f:
            data = f.read(MAX_JSON_FILE_BYTES + 1)
    except OSError as e:
        raise _native.ParameterError(f"cannot read {p!r}: {e.strerror}") from None
    if len(data) > MAX_JSON_FILE_BYTES:
        raise _native.ParameterError(
            f"{p!r} holds more than {MAX_JSON_FILE_BYTES} bytes (16 MiB), the most read for a "
            "parameter file"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise _native.ParameterError(
            f"{p!r} is not UTF-8 text (byte {e.start}); a JSON file is UTF-8"
        ) from None


def _bearings_text(bearings) -> str:
    """JSON text of `bearings`: a mapping (its non-finite values named by key), a path to an
    existing file, or a JSON string; a string that is neither is "no such file"."""
    if isinstance(bearings, Mapping):
        _finite_keys(bearings, "")
        return json.dumps(dict(bearings))
    if isinstance(bearings, os.PathLike):
        if not os.path.exists(bearings):
            raise _native.ParameterError(f"no such file: {os.fspath(bearings)!r}")
        return _read_json_file(bearings)
    if isinstance(bearings, str):
        if os.path.exists(bearings):
            return _read_json_file(bearings)
        if not bearings.lstrip().startswith(("{", "[")):
            raise _native.ParameterError(
                f"no such file: {bearings!r} (and not JSON text: a bearing arrangement is a "
                "dict, JSON text or the path of a JSON file)"
            )
        return bearings
    raise _native.ParameterError(
        f"bearings = {bearings!r}: allowed a dict, JSON text or the path of a JSON file"
    )


def bearing_loads(result, bearings, pair: GearPair | None = None) -> BearingLoads:
    """Bearing loads along a `StaticCurve` or a `Trajectory` (its force and moment columns
    ``F_p_x`` … ``M_g_y``): each shaft rigid on a locating bearing (radial and axial load) and a
    floating one (radial), at the axial positions of `bearings` (a dict, a JSON string or a path
    to a JSON file: ``{"pinion": {"locating_z_m": …, "floating_z_m": …}, "gear": {…}}``, z in
    m from the end face ζ = 0); the gears' centres at z = b/2 with b the face width of the
    pair the result was computed for (``result.pair``). `pair` is needed only for a result
    that carries none; one that differs from ``result.pair`` is a ``ParameterError`` (the
    centres would sit at another face width's b/2). The statics are the library's
    (``mesh::bearings``)."""
    own = getattr(result, "__dict__", {}).get("pair")
    if own is None and pair is None:
        raise _native.ParameterError(
            "bearing_loads: the result carries no gear pair; pass pair= (the face width places "
            "the gear centres at b/2)"
        )
    if own is not None and pair is not None and _pair(pair) != own:
        raise _native.ParameterError(
            "bearing_loads: pair= differs from the pair the result was computed for "
            f"(face width {_pair(pair).face_width_m} m against {own.face_width_m} m); "
            "leave pair= out"
        )
    text = _bearings_text(bearings)
    b = json.loads((own if own is not None else _pair(pair)).to_json())["face_width_m"]
    cols = [np.ascontiguousarray(getattr(result, n), dtype=float) for n in FORCE_NAMES]
    return BearingLoads(arrays=dict(_native.bearing_reactions(text, float(b), cols)))


#: The eight states of Eqs. 1–4 as `Trajectory` keys (the library's names: angles rad, rates
#: rad/s): φ₁, φp, φg, φ₂, φ̇₁, φ̇p, φ̇g, φ̇₂.
STATE_NAMES = (
    "phi_1_rad",
    "phi_p_rad",
    "phi_g_rad",
    "phi_2_rad",
    "w_1_rad_s",
    "w_p_rad_s",
    "w_g_rad_s",
    "w_2_rad_s",
)


@dataclass(frozen=True)
class Trajectory(_Result):
    """One solution of Eqs. 1–4: ``time`` (s), the eight states (`STATE_NAMES`) and every real
    mesh output of `OUTPUT_NAMES` (units in `OUTPUT_UNITS`: ``TE`` in m, the mesh torques
    ``M_F_p`` … ``M_D_g`` in N·m, the force and moments ``F_p_x`` … ``M_g_y``, the tooth-root
    stresses ``sigma_F_p``, ``sigma_F_g`` in Pa, …) per output time, as attributes (numpy
    arrays) and in ``arrays``."""

    arrays: dict = field(repr=False)
    steps: int
    mesh_evaluations: int
    #: The gear pair the trajectory was computed for (its face width places the gear centres
    #: of `bearing_loads`).
    pair: GearPair | None = field(default=None, repr=False, compare=False)
    #: With ``simulate(..., supports=...)``: the coupled modes and the support-force
    #: statistics (``modes_hz``, ``modes_damping_ratio``, ``window_mesh_periods``,
    #: ``support_forces``); None on rigid bearings.
    supports: dict | None = field(default=None, repr=False, compare=False)

    def __getattr__(self, k):
        try:
            return self.__dict__["arrays"][k]
        except KeyError:
            raise AttributeError(k) from None

    @property
    def _columns(self):
        return tuple(self.arrays)

    def plot(self, ax=None):
        """TE (µm) over time (s)."""
        ax = self._axes(ax)
        ax.plot(self.arrays["time"], self.arrays["TE"] * 1e6)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("TE (µm)")
        return ax


def simulate(
    pair: GearPair | MeshModel | None,
    w_p: float,
    t_end: float,
    dt: float | None = None,
    method: str = "rk4",
    fidelity: str = "full",
    phi_p0: float = 0.0,
    rtol: float = 1e-8,
    atol: float = 1e-12,
    slices: int = _SLICES,
    compliance: Compliance | None = None,
    drive: DriveLine | None = None,
    friction: Mapping[str, Any] | str | None = None,
    supports: Mapping[str, Any] | str | None = None,
    orders: int = 3,
) -> Trajectory:
    """One trajectory of Eqs. 1–4 from the static equilibrium at nominal pinion speed `w_p`
    (rad/s, |w_p| ≤ 1e5; standstill and low speed are normal operation, a negative speed runs
    backwards on the same driving flanks) to `t_end` (s), as the CLI's
    ``simulate``: RK4 with fixed step `dt` or adaptive ``method="dopri5"`` (`dt` is then the
    output interval). The default RK4 step is the library's step rule: the smaller of the mesh
    period / 128 and the period of the fastest linearised mode / 32, shortened to divide
    `t_end`. An explicit `dt` outside RK4's stability region for that mode, or a trajectory of
    more than 2·10⁶ samples, raises `ParameterError` before anything runs. Mesh damping and
    gear bodies from the pair, the drive line (torque, inertias, shafts) from `drive`
    (default Table 1's). `friction`: the mesh friction option (see `MeshModel`; a `MeshModel`
    passed as `pair` carries its own); the trajectory's ``P_loss``, ``eta_mesh``, ``M_R_p``,
    ``M_R_g``, ``Q_p``, ``Q_g`` carry it.

    `supports`: both gear bodies on elastic supports (a dict or JSON text of
    docs/gear-bodies.md), as the CLI's ``simulate --supports``: RK4 with a whole number of
    steps per mesh period chosen from the coupled modes (`dt`, ``method="dopri5"`` and friction
    raise `ParameterError`; at ``fidelity="table"`` the table adds its pose sensitivities), the
    run ending at the first step at or after `t_end`. The trajectory then also holds the poses and rates ``u_p_x`` … ``om_g_y`` (m,
    rad, m/s, rad/s) and the support forces on the bodies ``R_p_x`` … ``R_g_my`` (N, N·m), and
    ``supports`` holds ``modes_hz``, ``modes_damping_ratio``, ``window_mesh_periods`` and per
    support force ``reaction_mean_n``, ``reaction_peak_to_peak_n`` and ``orders`` (mesh-order
    amplitudes 1 … `orders`) over the last whole mesh periods."""
    drive = _drive(drive)
    if supports is not None:
        if dt is not None or method != "rk4":
            raise _native.ParameterError(
                "supports: the step is chosen from the coupled modes (leave dt out), RK4 only "
                "(method='rk4')"
            )
        if friction not in (None, "none"):
            raise _native.ParameterError(
                "supports with friction: not supported yet (the friction forces' pose "
                "sensitivities are not derived)"
            )
        text = supports if isinstance(supports, str) else json.dumps(supports)
        m = _model(pair, fidelity, slices, compliance, drive, friction)
        d = m._m.simulate_supported(
            m.pair.to_json(), drive.to_json(), text, float(w_p), float(t_end), float(phi_p0),
            int(orders),
        )
        steps = d.pop("steps")
        evals = d.pop("mesh_evaluations")
        summary = json.loads(d.pop("supports"))
        return Trajectory(arrays=dict(d), steps=steps, mesh_evaluations=evals, pair=m.pair,
                          supports=summary)
    m = _model(pair, fidelity, slices, compliance, drive, friction)
    d = m._m.simulate(
        m.pair.to_json(),
        drive.to_json(),
        float(w_p),
        float(t_end),
        dt,
        method,
        float(phi_p0),
        rtol,
        atol,
    )
    steps = d.pop("steps")
    evals = d.pop("mesh_evaluations")
    return Trajectory(arrays=dict(d), steps=steps, mesh_evaluations=evals, pair=m.pair)


@dataclass(frozen=True)
class SweepResult(_Result):
    """Steady-state TE_max/STE_max per pinion speed and the located resonances."""

    #: Pinion speeds, rad/s.
    speeds: np.ndarray
    #: Steady TE max and min over STE max (dynamic factor of TE).
    te_max_over_ste_max: np.ndarray
    te_min_over_ste_max: np.ndarray
    separated: np.ndarray
    back_contact: np.ndarray
    tip_contact: np.ndarray
    steady: np.ndarray
    #: Dynamic factors of the mesh force and of the tooth-root stress per speed: the steady
    #: maximum over the static maximum (NaN where the run has none), as the CLI's
    #: ``mesh_force_max_over_static`` and ``root_stress_max_over_static``.
    mesh_force_max_over_static: np.ndarray
    root_stress_max_over_static: np.ndarray
    #: Mean mesh efficiency over the steady window per speed, 1 − mean P_loss / mean mesh
    #: input power (1 without friction), as the CLI's ``mesh_efficiency_mean``.
    mesh_efficiency_mean: np.ndarray
    #: Resonance speeds (rad/s) and their TE_max/STE_max (refined by golden section).
    resonances: np.ndarray
    resonance_te_max_over_ste_max: np.ndarray
    #: Largest TE_max/STE_max over every run (grid and refinement).
    peak_te_ratio: float
    #: STE max of the sweep's static pass, m; mean mesh stiffness, N/m.
    ste_max: float
    mesh_stiffness: float | None
    warnings: tuple
    wall_seconds: float
    #: With ``sweep(..., supports=...)``: the same speeds with both gear bodies on their
    #: supports (``te_max_over_ste_max``, ``steady``, ``resonances_rad_s``, ``modes_hz``,
    #: ``mode_speeds_rad_s``, ``support_forces``); None on rigid bearings.
    supports: dict | None = field(default=None, repr=False, compare=False)
    _columns = (
        "speeds",
        "te_max_over_ste_max",
        "te_min_over_ste_max",
        "separated",
        "back_contact",
        "tip_contact",
        "steady",
        "mesh_force_max_over_static",
        "root_stress_max_over_static",
        "mesh_efficiency_mean",
    )

    @property
    def omega_crit(self) -> float:
        """The main resonance: the resonance speed with the largest TE_max/STE_max, rad/s
        (NaN when the sweep found none)."""
        if len(self.resonances) == 0:
            return float("nan")
        return float(self.resonances[int(np.argmax(self.resonance_te_max_over_ste_max))])

    def plot(self, ax=None):
        """TE_max/STE_max over the pinion speed, resonances marked."""
        ax = self._axes(ax)
        ax.plot(self.speeds, self.te_max_over_ste_max, marker=".", label="TE max / STE max")
        ax.plot(self.resonances, self.resonance_te_max_over_ste_max, "rv", label="resonance")
        ax.set_xlabel("pinion speed ω_p (rad/s)")
        ax.set_ylabel("TE max / STE max")
        ax.legend()
        return ax


def sweep(
    pair: GearPair | MeshModel | None = None,
    speeds=None,
    *,
    w_from: float = 100.0,
    w_to: float = 1200.0,
    points: int = 23,
    fidelity: str = "table",
    steps_per_period: int = 128,
    max_periods: int = 3000,
    refine_runs: int = 6,
    min_prominence: float = 0.005,
    threads: int | None = None,
    slices: int = _SLICES,
    compliance: Compliance | None = None,
    drive: DriveLine | None = None,
    friction: Mapping[str, Any] | str | None = None,
    supports: Mapping[str, Any] | str | None = None,
) -> SweepResult:
    """Steady-state runs at every speed (rad/s; default a uniform grid of `points` from
    `w_from` to `w_to`) and the resonances, as the CLI's ``sweep`` (the library's
    ``dynamics::sweep``; `threads` worker threads, default one per core). Work is bounded
    before anything runs: at most 64 `refine_runs`, and per run at most 10⁸ RK4 steps
    (`max_periods` × steps per mesh period, raised at low speed to resolve the mesh mode), so
    a sweep at 0.01 rad/s raises at once instead of running for hours. The drive line
    (torque, inertias, shafts) is `drive` (default Table 1's). The speeds (non-empty, in
    (0, 1e5] rad/s, ascending), `threads`, `min_prominence` and `refine_runs` are checked
    before the model is built. The result carries the dynamic factors of the mesh force and the
    root stress per speed (``mesh_force_max_over_static``, ``root_stress_max_over_static``)
    and, with `friction` (the mesh friction option, see `MeshModel`; a `MeshModel` passed as
    `pair` carries its own), the mean mesh efficiency per speed
    (``mesh_efficiency_mean``).

    `supports` (a dict or JSON text of docs/gear-bodies.md): the same speeds are also run with
    both gear bodies on elastic supports, as the CLI's ``sweep --supports``
    (``SweepResult.supports``: ``te_max_over_ste_max``, ``steady``, ``resonances_rad_s``,
    ``modes_hz``, ``mode_speeds_rad_s`` and per support force ``reaction_mean_n``,
    ``reaction_peak_to_peak_n``, ``order_1_n`` per speed; not with friction)."""
    drive = _drive(drive)
    if supports is not None and friction not in (None, "none"):
        raise _native.ParameterError(
            "supports with friction: not supported yet (the friction forces' pose "
            "sensitivities are not derived)"
        )
    if speeds is None:
        speeds = np.linspace(w_from, w_to, int(points)) if points > 1 else np.array([w_from])
    sp = [float(s) for s in np.asarray(speeds, dtype=float).ravel()]
    # The arguments are checked before the model (a table build takes up to a minute).
    _native.check_sweep_request(
        sp,
        _count("refine_runs", refine_runs),
        float(min_prominence),
        None if threads is None else _count("threads", threads),
    )
    m = _model(pair, fidelity, slices, compliance, drive, friction)
    d = json.loads(
        m._m.sweep_json(
            m.pair.to_json(),
            drive.to_json(),
            sp,
            _count("steps_per_period", steps_per_period),
            _count("max_periods", max_periods),
            _count("refine_runs", refine_runs),
            float(min_prominence),
            threads,
        )
    )
    supported = None
    if supports is not None:
        text = supports if isinstance(supports, str) else json.dumps(supports)
        supported = json.loads(
            m._m.sweep_supported_json(
                m.pair.to_json(), drive.to_json(), text, sp, _count("max_periods", max_periods),
                float(min_prominence), threads,
            )
        )
    return SweepResult(
        supports=supported,
        speeds=np.array(d["speeds_rad_s"]),
        te_max_over_ste_max=np.array(d["te_max_over_ste_max"]),
        te_min_over_ste_max=np.array(d["te_min_over_ste_max"]),
        separated=np.array(d["separated"], dtype=bool),
        back_contact=np.array(d["back_contact"], dtype=bool),
        tip_contact=np.array(d["tip_contact"], dtype=bool),
        steady=np.array(d["steady"], dtype=bool),
        mesh_force_max_over_static=np.array(
            [np.nan if v is None else v for v in d["mesh_force_max_over_static"]], dtype=float
        ),
        root_stress_max_over_static=np.array(
            [np.nan if v is None else v for v in d["root_stress_max_over_static"]], dtype=float
        ),
        mesh_efficiency_mean=np.array(d["mesh_efficiency_mean"], dtype=float),
        resonances=np.array(d["resonances_rad_s"], dtype=float),
        resonance_te_max_over_ste_max=np.array(d["resonance_te_max_over_ste_max"], dtype=float),
        peak_te_ratio=d["peak_te_max_over_ste_max"],
        ste_max=d["ste_max_um"] * 1e-6,
        mesh_stiffness=(
            None if d["mesh_stiffness_n_per_um"] is None else d["mesh_stiffness_n_per_um"] * 1e6
        ),
        warnings=tuple(d["warnings"]),
        wall_seconds=d["wall_seconds"],
    )


def paper(
    out_dir: str | os.PathLike,
    pair: GearPair | None = None,
    quick: bool = False,
    slices: int = _SLICES,
    threads: int | None = None,
    progress: bool = True,
    drive: DriveLine | None = None,
) -> dict:
    """The whole paper run (static TE and Fig. 7, the sweeps of Fig. 9, Figs. 10–13, the
    resonances, separation, tip contact, sensitivity study) into `out_dir`, as the CLI's
    ``paper``; returns the summary (also in ``out_dir/summary.json``). `quick`: a smoke run.
    `drive`: the drive line (default Table 1's, the paper's)."""
    return json.loads(
        _native.paper_json(
            _pair(pair).to_json(),
            _drive(drive).to_json(),
            os.fspath(out_dir),
            quick,
            int(slices),
            threads,
            progress,
        )
    )
