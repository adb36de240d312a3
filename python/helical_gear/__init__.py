"""helical_gear: the Andersson–Vedmar helical-gear mesh model from Python.

Contact outside the plane of action, FE tooth compliance, the non-linear load distribution
along the contact lines, mesh torques and the torsional dynamics of Eqs. 1–4 (A. Andersson,
L. Vedmar, J. Sound Vib. 260 (2003) 195–212), computed by the Rust library ``helical_gear_mesh``.

>>> import helical_gear as hg
>>> pair = hg.GearPair(beta=0.2)             # Table 1 with a 0.2 rad helix angle
>>> curve = hg.static_curve(pair)            # static TE over one pinion pitch
>>> curve.ste_max                            # m
>>> drive = hg.DriveLine(torque_nm=50.0)     # Table 1's drive line at 50 N·m
>>> tr = hg.simulate(pair, 300.0, 0.01, drive=drive)

SI units throughout. Errors derive from `GearMeshError` and carry the library's message.
Design studies: `helical_gear.study.run`.
"""

from ._native import (
    ComplianceError,
    GearMeshError,
    LIBRARY_VERSION,
    ParameterError,
    SolverError,
)
from ._pair import BOUNDS, DRIVE_SYMBOLS, ISO_SYMBOLS, DriveLine, GearPair, Group
from ._api import (
    FORCE_NAMES,
    LOSS_NAMES,
    OUTPUT_NAMES,
    OUTPUT_UNITS,
    POSE_NAMES,
    STATE_NAMES,
    TORQUES_OUTPUTS,
    Compliance,
    Geometry,
    MeshModel,
    BearingLoads,
    StaticCurve,
    SweepResult,
    Trajectory,
    bearing_loads,
    compliance,
    geometry,
    iso_root_stress,
    paper,
    simulate,
    static_curve,
    sweep,
)

from . import study  # noqa: E402  (pandas, dask, tqdm are imported when a study runs)

__version__ = LIBRARY_VERSION

__all__ = [
    "BOUNDS",
    "BearingLoads",
    "Compliance",
    "ComplianceError",
    "DRIVE_SYMBOLS",
    "DriveLine",
    "FORCE_NAMES",
    "GearMeshError",
    "GearPair",
    "Geometry",
    "Group",
    "ISO_SYMBOLS",
    "LOSS_NAMES",
    "MeshModel",
    "OUTPUT_NAMES",
    "OUTPUT_UNITS",
    "POSE_NAMES",
    "ParameterError",
    "STATE_NAMES",
    "SolverError",
    "StaticCurve",
    "SweepResult",
    "TORQUES_OUTPUTS",
    "Trajectory",
    "bearing_loads",
    "compliance",
    "geometry",
    "iso_root_stress",
    "paper",
    "simulate",
    "static_curve",
    "sweep",
]
