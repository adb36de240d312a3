"""The gear-pair parameters and the drive line: immutable, JSON-backed values with attribute
access.

`GearPair` holds the nested JSON object of the library's gear-pair schema (the output of
``helical-gear params``), SI units, basic-rack quantities in units of the normal module. It is
generic over that schema: every key, nested groups included (``material_p``,
``modifications``), is accepted and forwarded to the Rust side, which validates the whole pair
at construction and raises `ParameterError` naming the value and the limit.

`DriveLine` holds the drive line (torque, inertias, shafts of Eqs. 1–4; the output of
``helical-gear params --drive``) in the same way. It is not part of the pair: the calls that
need it take ``drive=`` (default: Table 1's drive line).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from . import _native

#: ISO 21771 / ISO 6336 symbols accepted as keyword aliases of the JSON keys.
ISO_SYMBOLS: Mapping[str, str] = MappingProxyType(
    {
        "z1": "z_p",
        "z2": "z_g",
        "m_n": "normal_module_m",
        "alpha_n": "pressure_angle_rad",
        "beta": "helix_angle_rad",
        "b": "face_width_m",
        "x1": "profile_shift_p",
        "x2": "profile_shift_g",
        "h_aP": "addendum_mn",
        "h_fP": "dedendum_mn",
        "rho_fP": "rack_fillet_radius_mn",
        "C_a": "tip_relief_depth_mn",
        "h_Ca": "tip_relief_height_mn",
        "rho_aP": "tip_rounding_radius_mn",
        "j_n": "normal_backlash_mn",
        "d_bore": "bore_diameter_m",
        "d_mesh": "d_mesh_n_s_per_m",
    }
)

#: Symbols accepted as keyword aliases of the drive-line JSON keys.
DRIVE_SYMBOLS: Mapping[str, str] = MappingProxyType({"T1": "torque_nm"})


def _freeze(value: Any) -> Any:
    if isinstance(value, Mapping):
        return Group({k: _freeze(v) for k, v in value.items()})
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    return value


def _thaw(value: Any) -> Any:
    if isinstance(value, Group):
        return {k: _thaw(v) for k, v in value.items()}
    if isinstance(value, tuple):
        return [_thaw(v) for v in value]
    return value


class Group(Mapping):
    """A read-only nested group of parameters (e.g. ``pair.material_p``): a mapping whose keys
    are also attributes."""

    __slots__ = ("_d",)

    def __init__(self, d: Mapping[str, Any]):
        object.__setattr__(self, "_d", dict(d))

    def __getitem__(self, k: str) -> Any:
        return self._d[k]

    def __iter__(self):
        return iter(self._d)

    def __len__(self) -> int:
        return len(self._d)

    def __getattr__(self, k: str) -> Any:
        try:
            return self._d[k]
        except KeyError:
            raise AttributeError(k) from None

    def __setattr__(self, k, v):
        raise AttributeError("parameter groups are immutable: use GearPair.replace")

    def __repr__(self) -> str:
        return f"Group({self._d!r})"


def _set_path(d: dict, path: str, value: Any) -> None:
    parts = path.split(".")
    for p in parts[:-1]:
        sub = d.get(p)
        if not isinstance(sub, dict):
            sub = {}
            d[p] = sub
        d = sub
    d[parts[-1]] = value


def _get_path(d: Mapping, path: str) -> Any:
    for p in path.split("."):
        d = d[p]
    return d


def _coerce(default: Any, value: Any) -> Any:
    """Integral floats become ints where the default is an int (tables read from CSV or pandas
    give 30.0 for 30); numpy scalars become Python numbers."""
    if hasattr(value, "item") and not isinstance(value, (list, dict)):
        value = value.item()
    if isinstance(default, int) and not isinstance(default, bool) and isinstance(value, float):
        if math.isfinite(value) and value == int(value):
            return int(value)
    return value


def _merge(base: dict, updates: Mapping[str, Any], symbols=None, default=None) -> dict:
    """`base` with `updates` applied: keys are JSON keys, dotted paths
    (``material_p.poisson_ratio``) or symbols (`symbols`, default `ISO_SYMBOLS`); a mapping
    value merges into the group. `default` gives the schema's defaults (for the types)."""
    symbols = ISO_SYMBOLS if symbols is None else symbols
    default_of = _default if default is None else default
    out = json.loads(json.dumps(base))
    for k, v in updates.items():
        k = symbols.get(k, k)
        v = _thaw(v)
        if isinstance(v, Mapping):
            for sk, sv in _flatten(v).items():
                _set_path(out, f"{k}.{sk}", sv)
            continue
        try:
            dv = _get_path(default_of(), k)  # for the type only (30.0 -> 30 for z_p)
        except (KeyError, TypeError):
            dv = None
        _set_path(out, k, _coerce(dv, v))
    return out


def _flatten(d: Mapping, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.update(_flatten(v, key + "."))
        else:
            out[key] = v
    return out


BOUNDS: Mapping[str, tuple[float, float, str]] = MappingProxyType(
    {k: (lo, hi, unit) for k, lo, hi, unit in _native.parameter_bounds()}
)
"""Inclusive range of every numeric gear-pair key (dotted for nested keys) and drive-line key
(``drive.`` and the `DriveLine` key, the FMU parameter names): ``(min, max, unit)``, the
library's own bounds, the same as the FMUs' ``min``/``max``. A value inside may still be
refused in combination with others (undercut, pointed tooth, contact ratio …)."""


_DEFAULT: dict | None = None


def _default() -> dict:
    global _DEFAULT
    if _DEFAULT is None:
        _DEFAULT = json.loads(_native.default_pair_json())
    return _DEFAULT


class GearPair:
    """Parameters of a helical gear pair (defaults: Table 1 of Andersson & Vedmar 2003).

    ``GearPair(**kw)`` starts from the defaults and applies ``kw``: JSON keys
    (``helix_angle_rad=0.2``), ISO symbols (``beta=0.2``, see `ISO_SYMBOLS`), nested groups as
    mappings (``material_p={"poisson_ratio": 0.29}``) or dotted paths through
    ``**{"material_p.poisson_ratio": 0.29}``. The drive line is not part of the pair: see
    `DriveLine` (a ``drive`` key is refused with a message saying so).
    SI units: m, rad, Pa, N·s/m; basic-rack quantities (``*_mn``) in units of m_n.
    Every key with its ISO alias, unit, default, range and meaning: ``docs/parameters.md`` of
    the repository.
    The pair is validated by the library at construction (`ParameterError` names the value and
    the limit), is immutable and hashable, compares by value, and pickles as its JSON.
    """

    __slots__ = ("_json", "_data")

    def __init__(self, **kw: Any):
        # Only the given keys: the library fills the rest from Table 1.
        self._init(json.dumps(_merge({}, kw)))

    def _init(self, text: str) -> None:
        norm = _native.normalize_pair(text)
        object.__setattr__(self, "_json", norm)
        object.__setattr__(self, "_data", _freeze(json.loads(norm)))

    @classmethod
    def from_json(cls, text: str) -> "GearPair":
        """The pair of a JSON text in the library's schema (unknown keys are the library's to
        accept or reject)."""
        self = cls.__new__(cls)
        self._init(text)
        return self

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "GearPair":
        """The pair of a nested mapping in the JSON schema."""
        return cls.from_json(json.dumps(_thaw(d) if isinstance(d, Group) else d))

    def to_json(self, indent: int | None = None) -> str:
        """JSON in the library's schema (every key present)."""
        if indent is None:
            return self._json
        return json.dumps(json.loads(self._json), indent=indent)

    def to_dict(self) -> dict:
        """A nested (mutable) dict copy of the parameters."""
        return json.loads(self._json)

    def flat(self) -> dict:
        """Flat dict keyed by dotted paths (``material_p.poisson_ratio``): the design-table
        columns."""
        return _flatten(json.loads(self._json))

    def replace(self, **kw: Any) -> "GearPair":
        """A copy with `kw` applied (the same keys as the constructor)."""
        return GearPair.from_json(json.dumps(_merge(json.loads(self._json), kw)))

    def __getattr__(self, k: str) -> Any:
        if k.startswith("_"):
            raise AttributeError(k)
        try:
            return _get_path(self._data, ISO_SYMBOLS.get(k, k))
        except KeyError:
            raise AttributeError(k) from None

    def __getitem__(self, k: str) -> Any:
        return _get_path(self._data, ISO_SYMBOLS.get(k, k))

    def __setattr__(self, k, v):
        raise AttributeError("GearPair is immutable: use GearPair.replace(...)")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GearPair) and other._json == self._json

    def __hash__(self) -> int:
        return hash(self._json)

    def __reduce__(self):
        return (GearPair.from_json, (self._json,))

    def __repr__(self) -> str:
        d = self.flat()
        default = _flatten(_default())
        changed = {k: v for k, v in d.items() if default.get(k) != v}
        args = ", ".join(f"{k}={v!r}" for k, v in changed.items())
        return f"GearPair({args})" if args else "GearPair()  # Table 1"

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(json.loads(self._json)) | set(ISO_SYMBOLS))

    def assumptions(self) -> list[str]:
        """The modelling assumptions the library makes for this pair, one sentence each."""
        return _native.assumptions(self._json)

    def compliance_key(self) -> str:
        """16 hex digits identifying every parameter that changes the FE compliance."""
        return _native.compliance_key(self._json)


_DEFAULT_DRIVE: dict | None = None


def _default_drive() -> dict:
    global _DEFAULT_DRIVE
    if _DEFAULT_DRIVE is None:
        _DEFAULT_DRIVE = json.loads(_native.default_drive_json())
    return _DEFAULT_DRIVE


class DriveLine:
    """The drive line of a gear pair (Eqs. 1–4; defaults: Table 1 of Andersson & Vedmar 2003):
    driving torque ``torque_nm`` (N·m on J₁; the load on J₂ is M·z_g/z_p), inertias
    ``j1_kgm2``, ``j2_kgm2`` (kg·m²), shaft stiffnesses ``c1_nm_per_rad``, ``c2_nm_per_rad``
    (N·m/rad) and dampings ``d1_nms_per_rad``, ``d2_nms_per_rad`` (N·m·s/rad).

    ``DriveLine(**kw)`` starts from the defaults and applies ``kw`` (JSON keys, or ``T1`` for
    the torque, see `DRIVE_SYMBOLS`). The library checks every value against its range at
    construction (`ParameterError` names the value and the limit). Immutable, hashable,
    compares by value, pickles as its JSON. Pass it as ``drive=`` to the calls that need it.
    """

    __slots__ = ("_json", "_data")

    def __init__(self, **kw: Any):
        self._init(json.dumps(_merge({}, kw, DRIVE_SYMBOLS, _default_drive)))

    def _init(self, text: str) -> None:
        norm = _native.normalize_drive(text)
        object.__setattr__(self, "_json", norm)
        object.__setattr__(self, "_data", json.loads(norm))

    @classmethod
    def from_json(cls, text: str) -> "DriveLine":
        """The drive line of a JSON text in the library's schema (missing keys from Table 1,
        unknown keys refused by the library)."""
        self = cls.__new__(cls)
        self._init(text)
        return self

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "DriveLine":
        """The drive line of a mapping in the JSON schema."""
        return cls.from_json(json.dumps(dict(d)))

    def to_json(self, indent: int | None = None) -> str:
        """JSON in the library's schema (every key present)."""
        if indent is None:
            return self._json
        return json.dumps(json.loads(self._json), indent=indent)

    def to_dict(self) -> dict:
        """A (mutable) dict copy of the values."""
        return json.loads(self._json)

    def replace(self, **kw: Any) -> "DriveLine":
        """A copy with `kw` applied (the same keys as the constructor)."""
        return DriveLine.from_json(
            json.dumps(_merge(json.loads(self._json), kw, DRIVE_SYMBOLS, _default_drive))
        )

    def __getattr__(self, k: str) -> Any:
        if k.startswith("_"):
            raise AttributeError(k)
        try:
            return self._data[DRIVE_SYMBOLS.get(k, k)]
        except KeyError:
            raise AttributeError(k) from None

    def __getitem__(self, k: str) -> Any:
        return self._data[DRIVE_SYMBOLS.get(k, k)]

    def __setattr__(self, k, v):
        raise AttributeError("DriveLine is immutable: use DriveLine.replace(...)")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, DriveLine) and other._json == self._json

    def __hash__(self) -> int:
        return hash(self._json)

    def __reduce__(self):
        return (DriveLine.from_json, (self._json,))

    def __repr__(self) -> str:
        default = _default_drive()
        changed = {k: v for k, v in self._data.items() if default.get(k) != v}
        args = ", ".join(f"{k}={v!r}" for k, v in changed.items())
        return f"DriveLine({args})" if args else "DriveLine()  # Table 1"

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self._data) | set(DRIVE_SYMBOLS))
