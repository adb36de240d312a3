//! `helical_gear._native`: the PyO3 glue between the `helical_gear` Python package and the
//! `helical_gear_mesh` library. No physics lives here: every function parses its arguments,
//! calls the library and converts the result.
//!
//! Conventions of the glue:
//! * Gear pairs cross the boundary as JSON text in the schema of
//!   [`helical_gear_mesh::GearPair`] (the Python `GearPair` keeps the JSON, so keys the Rust
//!   side learns later pass through unchanged).
//! * Every call runs through `run` (below): the GIL is released ([`Python::detach`]) for the Rust
//!   work, a panic is caught ([`std::panic::catch_unwind`]) and becomes
//!   `helical_gear.GearMeshError`, and library errors become a subclass of it carrying the
//!   library's message: `ParameterError` (invalid parameter or input),
//!   `ComplianceError` (FE compliance data), `SolverError` (load solve, equilibrium,
//!   integration).
//! * Structured results cross as JSON text (small) or numpy arrays (per-sample data).
//! * Units are SI (m, rad, rad/s, N·m, s) as in the library.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Arc;

use helical_gear_app::paper::{PaperOptions, run_paper};
use helical_gear_mesh::compliance::data::{CacheOptions, ComplianceData, ComplianceKey};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::compliance::influence_fe::DEFAULT_DEPTH_MN;
use helical_gear_mesh::dynamics::model::STATE_NAMES;
use helical_gear_mesh::dynamics::steady::steady_max_periods;
use helical_gear_mesh::dynamics::{
    DEFAULT_STEPS_PER_MESH_PERIOD, Dopri5Options, Drivetrain, DynamicsError, GearDynamics,
    MAX_TRAJECTORY_SAMPLES, SteadyMethod, SteadyRunOptions, Stepping, SweepOptions,
    default_rk4_step, simulate, sweep,
};
use helical_gear_mesh::iso6336::nominal_root_stress;
use helical_gear_mesh::mesh::bearings::BearingArrangement;
use helical_gear_mesh::mesh::outputs::{
    FieldAccess, MESH_OUTPUT_FIELDS, OutputKind, first_non_finite, real_fields,
};
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Fidelity, Friction, Mesh as RustMesh, MeshError, MeshOptions, MeshState,
    MeshTorques as _, static_curve_with,
};
use helical_gear_mesh::options::Integrator;
use helical_gear_mesh::results::{
    ComplianceRecord, GeometryRecord, IsoRootStressSummary, StaticCurveRecord,
    StaticFrictionSummary, SweepRecord,
};
use helical_gear_mesh::{DriveLine, GearPair, PairGeometry, ParamError};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;

create_exception!(
    _native,
    GearMeshError,
    PyException,
    "Base of every error of the helical_gear package; the message is the library's."
);
create_exception!(
    _native,
    ParameterError,
    GearMeshError,
    "An invalid gear-pair parameter, option or input (names the value and the limit)."
);
create_exception!(
    _native,
    ComplianceError,
    GearMeshError,
    "The FE compliance data could not be computed, read or used."
);
create_exception!(
    _native,
    SolverError,
    GearMeshError,
    "A load solve, static equilibrium, integration or steady-state run failed."
);

/// A library failure with the Python exception class it maps to.
enum Failure {
    Param(String),
    Compliance(String),
    Solver(String),
    Internal(String),
}

impl From<ParamError> for Failure {
    fn from(e: ParamError) -> Self {
        Failure::Param(e.to_string())
    }
}

impl From<MeshError> for Failure {
    fn from(e: MeshError) -> Self {
        match e {
            MeshError::Param(_)
            | MeshError::NonFinite { .. }
            | MeshError::AngleOutOfRange { .. } => Failure::Param(e.to_string()),
            MeshError::Compliance(_) => Failure::Compliance(e.to_string()),
            _ => Failure::Solver(e.to_string()),
        }
    }
}

impl From<DynamicsError> for Failure {
    fn from(e: DynamicsError) -> Self {
        match e {
            DynamicsError::Param(_)
            | DynamicsError::InvalidInput { .. }
            | DynamicsError::TooLarge(_) => Failure::Param(e.to_string()),
            _ => Failure::Solver(e.to_string()),
        }
    }
}

impl From<helical_gear_mesh::compliance::data::ComplianceError> for Failure {
    fn from(e: helical_gear_mesh::compliance::data::ComplianceError) -> Self {
        use helical_gear_mesh::compliance::data::ComplianceError as E;
        match e {
            E::Param(_) | E::Input(_) => Failure::Param(e.to_string()),
            _ => Failure::Compliance(e.to_string()),
        }
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> Self {
        match f {
            Failure::Param(m) => ParameterError::new_err(m),
            Failure::Compliance(m) => ComplianceError::new_err(m),
            Failure::Solver(m) => SolverError::new_err(m),
            Failure::Internal(m) => GearMeshError::new_err(m),
        }
    }
}

type Res<T> = Result<T, Failure>;

/// Runs `f` without the GIL, with panics caught and failures mapped to Python exceptions.
fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> Res<T> + Send) -> PyResult<T> {
    let r = py.detach(|| catch_unwind(AssertUnwindSafe(f)));
    match r {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(e.into()),
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic payload".into());
            Err(GearMeshError::new_err(format!("internal error (panic): {what}")))
        }
    }
}

/// The 3D force and moments handed to Python (the FMU output names), in order: F_p (x, y, z,
/// N), M_p (x, y, N·m), F_g, M_g, in the housing frame of the library's `mesh::forces`.
const FORCE_NAMES: [&str; 10] =
    ["F_p_x", "F_p_y", "F_p_z", "M_p_x", "M_p_y", "F_g_x", "F_g_y", "F_g_z", "M_g_x", "M_g_y"];

/// The one check on every number handed to Python: a non-finite value is a solver error naming
/// where (`at`) and which value, never a result.
/// Checks the nominal pinion speed `w_p` (rad/s) and the end time `t_end` (s) of a trajectory.
fn check_run(w_p: f64, t_end: f64) -> Res<()> {
    if !(w_p.is_finite() && w_p.abs() <= helical_gear_mesh::mesh::validity::MAX_SPEED_RAD_S) {
        return Err(Failure::Param(format!(
            "w_p = {w_p}: allowed finite, |w_p| <= 1e5 rad/s (the largest nominal speed; \
             negative: running backwards)"
        )));
    }
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(Failure::Param(format!("t_end = {t_end}: allowed finite and > 0 (s)")));
    }
    Ok(())
}

fn finite(at: &str, names: &[&str], values: &[f64]) -> Res<()> {
    match names.iter().zip(values).find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some((name, v)) => Err(Failure::Solver(format!(
            "{at}: `{name}` = {v} is not finite (the model left its valid range)"
        ))),
    }
}

/// [`finite`] for a mesh result: a non-finite Real field (of the core's table of the mesh
/// outputs) is a solver error naming it by its interface name.
fn finite_outputs(at: &str, o: &helical_gear_mesh::mesh::MeshOutputs) -> Res<()> {
    match real_fields().find(|f| f.real(o).is_some_and(|v| !v.is_finite())) {
        None => Ok(()),
        Some(f) => finite(at, &[f.name], &[f.real(o).unwrap_or(f64::NAN)]),
    }
}

/// An input state within the stated ranges of the library (|angle| <= 1e15 rad, |speed| <=
/// 1e5 rad/s, `dynamics::unit::MAX_ANGLE_RAD`, `MAX_SPEED_RAD_S`).
fn check_state(i: usize, s: &MeshState) -> Res<()> {
    use helical_gear_mesh::dynamics::unit::{MAX_ANGLE_RAD, MAX_SPEED_RAD_S};
    for (name, v, max, range) in [
        ("phi_p", s.phi_p, MAX_ANGLE_RAD, "1e15 rad"),
        ("phi_g", s.phi_g, MAX_ANGLE_RAD, "1e15 rad"),
        ("w_p", s.w_p, MAX_SPEED_RAD_S, "1e5 rad/s"),
        ("w_g", s.w_g, MAX_SPEED_RAD_S, "1e5 rad/s"),
    ] {
        if !v.is_finite() {
            return Err(Failure::Param(format!("state {i}: input `{name}` = {v} is not finite")));
        }
        if v.abs() > max {
            return Err(Failure::Param(format!(
                "state {i}: input `{name}` = {}: allowed |{name}| <= {range}",
                helical_gear_mesh::error::short_num(v)
            )));
        }
    }
    Ok(())
}

/// Parses and validates gear-pair JSON.
fn parse_pair(text: &str) -> Res<GearPair> {
    let p = GearPair::from_json(text).map_err(Failure::Param)?;
    p.validate()?;
    Ok(p)
}

/// Parses and checks drive-line JSON (missing keys from Table 1).
fn parse_drive(text: &str) -> Res<DriveLine> {
    let d = DriveLine::from_json(text).map_err(Failure::Param)?;
    d.check()?;
    Ok(d)
}

fn to_json_text(v: &impl serde::Serialize) -> Res<String> {
    serde_json::to_string(v).map_err(|e| Failure::Internal(format!("JSON: {e}")))
}

fn density(name: &str) -> Res<GearMeshDensity> {
    match name {
        "coarse" => Ok(GearMeshDensity::coarse()),
        "default" => Ok(GearMeshDensity::default()),
        "conforming" => Ok(GearMeshDensity::conforming()),
        "refined" => Ok(GearMeshDensity::refined()),
        other => Err(Failure::Param(format!(
            "fe_density = {other:?}: allowed \"coarse\", \"default\", \"conforming\" or \"refined\""
        ))),
    }
}

fn fidelity(name: &str) -> Res<Fidelity> {
    name.parse::<Fidelity>().map_err(Failure::Param)
}

/// The range of every numeric gear-pair key: a list of (key, min, max, unit), the library's own
/// bounds (the same as the FMUs' `min`/`max`).
#[pyfunction]
fn parameter_bounds() -> Vec<(String, f64, f64, &'static str)> {
    helical_gear_mesh::params::parameter_bounds()
}

/// The bearing reactions (the library's `mesh::bearings`) to the force and moments
/// `columns` (the ten arrays of `FORCE_NAMES`, equally long) of a gear pair of face width
/// `face_width_m` (m) on the bearing arrangement `bearings_json`: a dict of arrays keyed
/// `<shaft>_<bearing>_<x|y|z>` (N, force of the bearing on the shaft). Raises `ParameterError`
/// naming the key and the limit.
#[pyfunction]
fn bearing_reactions<'py>(
    py: Python<'py>,
    bearings_json: &str,
    face_width_m: f64,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let cols: Vec<Vec<f64>> = columns.iter().map(|c| c.as_array().to_vec()).collect();
    let (labels, out) = run(py, || {
        let arrangement = BearingArrangement::from_json(bearings_json)
            .map_err(|e| Failure::Param(e.to_string()))?;
        if !(face_width_m.is_finite() && face_width_m > 0.0) {
            return Err(Failure::Param(format!(
                "face_width_m = {face_width_m:.3e} m: allowed finite and > 0"
            )));
        }
        if cols.len() != FORCE_NAMES.len() {
            return Err(Failure::Param(format!(
                "bearing_reactions: {} force columns given, {} needed ({})",
                cols.len(),
                FORCE_NAMES.len(),
                FORCE_NAMES.join(", ")
            )));
        }
        let n = cols[0].len();
        if cols.iter().any(|c| c.len() != n) {
            return Err(Failure::Param(
                "bearing_reactions: the force columns differ in length".into(),
            ));
        }
        let mut out: Vec<Vec<f64>> = (0..12).map(|_| Vec::with_capacity(n)).collect();
        for i in 0..n {
            let v: Vec<f64> = cols.iter().map(|c| c[i]).collect();
            finite(&format!("sample {i}"), &FORCE_NAMES, &v)?;
            let o = helical_gear_mesh::mesh::MeshOutputs {
                force_p: [v[0], v[1], v[2]],
                moment_p: [v[3], v[4]],
                force_g: [v[5], v[6], v[7]],
                moment_g: [v[8], v[9]],
                ..Default::default()
            };
            for (b, r) in arrangement.reactions(face_width_m, &o).iter().enumerate() {
                for (k, x) in r.iter().enumerate() {
                    out[3 * b + k].push(*x);
                }
            }
        }
        Ok((arrangement.labels(), out))
    })?;
    let d = PyDict::new(py);
    let mut cols = out.into_iter();
    for (shaft, bearing, _) in labels {
        for axis in ["x", "y", "z"] {
            d.set_item(
                format!("{shaft}_{bearing}_{axis}"),
                array(py, cols.next().unwrap_or_default()),
            )?;
        }
    }
    Ok(d)
}

/// The Table 1 gear pair of the paper as JSON.
#[pyfunction]
fn default_pair_json(py: Python<'_>) -> PyResult<String> {
    run(py, || to_json_text(&GearPair::paper_table1()))
}

/// The Table 1 drive line of the paper as JSON.
#[pyfunction]
fn default_drive_json(py: Python<'_>) -> PyResult<String> {
    run(py, || to_json_text(&DriveLine::paper_table1()))
}

/// Parses and checks drive-line JSON; returns it re-serialised with every key (missing keys
/// from Table 1). Raises `ParameterError` naming the value and the limit.
#[pyfunction]
fn normalize_drive(py: Python<'_>, drive_json: &str) -> PyResult<String> {
    run(py, || to_json_text(&parse_drive(drive_json)?))
}

/// Parses and validates gear-pair JSON; returns it re-serialised with every key (defaults of
/// optional keys filled in). Raises `ParameterError` naming the value and the limit.
#[pyfunction]
fn normalize_pair(py: Python<'_>, pair_json: &str) -> PyResult<String> {
    run(py, || to_json_text(&parse_pair(pair_json)?))
}

/// The modelling assumptions of the pair, one sentence each.
#[pyfunction]
fn assumptions(py: Python<'_>, pair_json: &str) -> PyResult<Vec<String>> {
    run(py, || Ok(parse_pair(pair_json)?.assumptions()))
}

/// Derived geometry of the pair as JSON: the library's `results::GeometryRecord`, the keys
/// and values of `helical-gear geometry --json`.
#[pyfunction]
fn geometry_json(py: Python<'_>, pair_json: &str) -> PyResult<String> {
    run(py, || {
        let p = parse_pair(pair_json)?;
        let g = PairGeometry::new(&p)?;
        let record = GeometryRecord::new(&g, &p);
        record.check_finite().map_err(Failure::Solver)?;
        to_json_text(&record)
    })
}

/// ISO 6336-3:2006 method B for the pair `pair_json` at the pinion torque `torque` (N·m; its
/// sign is ignored): JSON of the library's `iso6336::IsoRootStress` (`tangential_force_n`;
/// per gear `pinion`, `gear`: `y_f`, `y_s`, `y_beta`, `y_b`, `y_dt`, `s_fn_m`, `h_fe_m`,
/// `rho_f_m`, `alpha_fen_rad`, `z_n`, `sigma_f0_pa`). A pair the method cannot rate is a
/// `ParameterError` with the library's message.
#[pyfunction]
fn iso_root_stress_json(py: Python<'_>, pair_json: &str, torque: f64) -> PyResult<String> {
    run(py, || {
        let p = parse_pair(pair_json)?;
        let g = PairGeometry::new(&p)?;
        to_json_text(&nominal_root_stress(&p, &g, torque)?)
    })
}

/// The ISO 6336-3 keys of a static run at `torque` (N·m): JSON of the library's
/// `results::IsoRootStressSummary` (`root_stress_iso_p_pa`, `root_stress_iso_g_pa`,
/// `iso6336`, `iso6336_error`; the first three `null` and the reason in the last when the
/// method does not apply), the keys of `helical-gear static --json`.
#[pyfunction]
fn iso_root_stress_summary_json(py: Python<'_>, pair_json: &str, torque: f64) -> PyResult<String> {
    run(py, || {
        let p = parse_pair(pair_json)?;
        let g = PairGeometry::new(&p)?;
        let record = IsoRootStressSummary::new(&g, torque);
        record.check_finite().map_err(Failure::Solver)?;
        to_json_text(&record)
    })
}

/// 16 hex digits: the FNV-1a hash of the parameters that change the FE compliance
/// (`ComplianceKey`), the content key of the compliance data of a pair.
#[pyfunction]
fn compliance_key(py: Python<'_>, pair_json: &str) -> PyResult<String> {
    run(py, || Ok(format!("{:016x}", ComplianceKey::of(&parse_pair(pair_json)?).hash())))
}

/// FE compliance data of both gears of a pair (shared, immutable).
#[pyclass(module = "helical_gear._native", frozen)]
struct Compliance {
    data: Arc<ComplianceData>,
}

#[pymethods]
impl Compliance {
    /// Runs the FE model of both gears at mesh density `density` ("coarse", "default",
    /// "refined") and the default depth h, then the fits. Never reads or writes a cache.
    #[staticmethod]
    #[pyo3(signature = (pair_json, density = "default", progress = false))]
    fn compute(py: Python<'_>, pair_json: &str, density: &str, progress: bool) -> PyResult<Self> {
        run(py, || {
            let p = parse_pair(pair_json)?;
            let d = self::density(density)?;
            let data =
                ComplianceData::compute(&p, &d, DEFAULT_DEPTH_MN * p.normal_module_m, progress)?;
            Ok(Self { data: Arc::new(data) })
        })
    }

    /// The library's default source at the default density: the embedded Table 1 data when the
    /// pair matches, else the disk cache in `cache_dir` (default: `HELICAL_GEAR_CACHE_DIR`),
    /// else a fresh FE run (written to the cache directory when one is set).
    #[staticmethod]
    #[pyo3(signature = (pair_json, cache_dir = None, progress = false))]
    fn for_pair(
        py: Python<'_>,
        pair_json: &str,
        cache_dir: Option<PathBuf>,
        progress: bool,
    ) -> PyResult<Self> {
        run(py, || {
            let p = parse_pair(pair_json)?;
            let mut options = CacheOptions::default();
            if cache_dir.is_some() {
                options.dir = cache_dir;
            }
            options.progress = progress;
            Ok(Self { data: ComplianceData::for_pair(&p, &options)? })
        })
    }

    /// Lossless JSON of the data (every f64 exact), for pickling.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        let data = self.data.clone();
        run(py, move || to_json_text(&*data))
    }

    /// Data from [`Compliance::to_json`] (or a cache file), checked.
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        run(py, || Ok(Self { data: Arc::new(ComplianceData::from_json(text)?) }))
    }

    /// True iff the data belong to the pair (every compliance parameter bitwise equal).
    fn matches(&self, py: Python<'_>, pair_json: &str) -> PyResult<bool> {
        let data = self.data.clone();
        run(py, move || Ok(data.matches(&parse_pair(pair_json)?)))
    }

    /// Where the data came from: "computed", "embedded" or "disk".
    fn source(&self) -> &'static str {
        self.data.source().as_str()
    }

    /// FE wall time of both gears when the data were computed, s.
    fn fe_seconds(&self) -> f64 {
        self.data.fe_seconds()
    }

    /// Summary as JSON, the library's `results::ComplianceRecord` (the keys of
    /// `helical-gear compliance --json`): source, density, FE sizes and times, fit quality, and
    /// the tooth-pair stiffness at the pitch point of `pair_json` (200 slices) under `torque`
    /// N·m.
    #[pyo3(signature = (pair_json, torque = 100.0))]
    fn summary_json(&self, py: Python<'_>, pair_json: &str, torque: f64) -> PyResult<String> {
        let data = self.data.clone();
        run(py, move || {
            let p = parse_pair(pair_json)?;
            let geo = PairGeometry::new(&p)?;
            let st = data.pair_stiffness(&geo, 200, torque)?;
            let record = ComplianceRecord::new(&data, &st);
            record.check_finite().map_err(Failure::Solver)?;
            to_json_text(&record)
        })
    }
}

/// The mesh model of a pair (the library's `Mesh` at a fidelity), never evaluated itself:
/// every call works on a copy that shares the immutable model and table (`Arc`) and has its
/// own workspace and a cold warm start. Calls from several Python threads run in parallel
/// (the GIL is released), and each call's results depend on its arguments only.
#[pyclass(module = "helical_gear._native", frozen)]
struct MeshModel {
    model: RustMesh,
}

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

#[pymethods]
impl MeshModel {
    /// Builds the model of `pair_json` at `fidelity` ("full" or "table") with `slices` slices
    /// over the simultaneous contact lines, from `compliance` when given (it must belong to the
    /// pair) or from the library's default source ([`Compliance::for_pair`]). The table
    /// fidelity's resolution: `table_phase_points` per mesh period × `table_te_points` along TE
    /// (the library's defaults 96 × 24), its TE range sized for `table_design_torque` N·m
    /// (default 100, Table 1's torque), its samples at min(`slices`, `table_slices`) slices
    /// (default 100). `friction`: the mesh friction option as JSON text
    /// (the library's `mesh::Friction::from_json`: `{"model": …, "mu": …, …}`, `none` or
    /// None for the paper's frictionless model).
    #[new]
    #[pyo3(signature = (pair_json, fidelity, slices, compliance, table_phase_points, table_te_points, table_design_torque, friction, table_slices))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        pair_json: &str,
        fidelity: &str,
        slices: usize,
        compliance: Option<&Compliance>,
        table_phase_points: usize,
        table_te_points: usize,
        table_design_torque: f64,
        friction: Option<&str>,
        table_slices: usize,
    ) -> PyResult<Self> {
        let data = compliance.map(|c| c.data.clone());
        run(py, move || {
            let p = parse_pair(pair_json)?;
            let friction = match friction {
                None => Friction::none(),
                Some(text) => Friction::from_json(text).map_err(Failure::Param)?,
            };
            let options = MeshOptions {
                fidelity: self::fidelity(fidelity)?,
                slices,
                table_phase_points,
                table_te_points,
                table_design_torque_nm: table_design_torque,
                table_slices,
                friction,
                ..MeshOptions::default()
            };
            let model = match data {
                Some(d) => RustMesh::from_data(&p, options, &d)?,
                None => RustMesh::new(&p, options)?,
            };
            Ok(Self { model })
        })
    }

    /// Evaluates the mesh at every state (φp, φg, φ̇p, φ̇g) of four equally long float64 arrays
    /// (rad, rad/s), in order, exactly as the library's `Mesh::evaluate` does one after
    /// another from a cold start (each state warm-started from the one before; the first
    /// cold); returns a dict of arrays keyed like the FMU outputs. `pose`, when given, is an
    /// (n, 20) float64 array of the gear bodies' poses and rates per state, columns in the order
    /// of the library's `mesh::pose::INPUT_NAMES` (m, rad, m/s, rad/s). `outputs`, when
    /// given, names the outputs to compute and return (keys of the FMU outputs, each once, in
    /// the order given): when every one is a torques output of the library's
    /// `mesh::outputs::MESH_OUTPUT_FIELDS` the evaluation takes the torques path
    /// (`MeshTorques::torques`), whose values are bit for bit those of the complete one.
    #[pyo3(signature = (phi_p, phi_g, w_p, w_g, pose = None, outputs = None))]
    #[allow(clippy::too_many_arguments)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        phi_p: PyReadonlyArray1<'py, f64>,
        phi_g: PyReadonlyArray1<'py, f64>,
        w_p: PyReadonlyArray1<'py, f64>,
        w_g: PyReadonlyArray1<'py, f64>,
        pose: Option<PyReadonlyArray2<'py, f64>>,
        outputs: Option<Vec<String>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let fields: Vec<usize> = match &outputs {
            None => (0..MESH_OUTPUT_FIELDS.len()).collect(),
            Some(names) => {
                let mut fields = Vec::with_capacity(names.len().min(MESH_OUTPUT_FIELDS.len()));
                for name in names {
                    let Some(k) = helical_gear_mesh::mesh::outputs::field_index(name) else {
                        let all: Vec<_> = MESH_OUTPUT_FIELDS.iter().map(|f| f.name).collect();
                        return Err(ParameterError::new_err(format!(
                            "evaluate: no mesh output is named {name:?}; the outputs: {}",
                            all.join(", ")
                        )));
                    };
                    if !fields.contains(&k) {
                        fields.push(k);
                    }
                }
                fields
            }
        };
        let torques_only = outputs.is_some()
            && helical_gear_mesh::mesh::outputs::torques_cover(fields.iter().copied());
        let inputs = [phi_p.as_array(), phi_g.as_array(), w_p.as_array(), w_g.as_array()];
        let n = inputs[0].len();
        if inputs.iter().any(|a| a.len() != n) {
            return Err(ParameterError::new_err(format!(
                "evaluate: the four state arrays must have one length (got {}, {}, {}, {})",
                inputs[0].len(),
                inputs[1].len(),
                inputs[2].len(),
                inputs[3].len()
            )));
        }
        let pose = pose.as_ref().map(|p| p.as_array());
        if let Some(p) = &pose
            && p.shape() != [n, 20]
        {
            return Err(ParameterError::new_err(format!(
                "evaluate: the pose array must have shape ({n}, 20) (got {:?})",
                p.shape()
            )));
        }
        // State i, built where it is evaluated (not all n first: 192 bytes each).
        let state = |i: usize| {
            let mut s = MeshState {
                phi_p: inputs[0][i],
                phi_g: inputs[1][i],
                w_p: inputs[2][i],
                w_g: inputs[3][i],
                ..Default::default()
            };
            if let Some(p) = &pose {
                let v: [f64; 20] = std::array::from_fn(|k| p[[i, k]]);
                helical_gear_mesh::mesh::pose::set_inputs(&mut s, &v);
            }
            s
        };
        // One column per field of the core's table of the mesh outputs, in its order.
        enum Column {
            Real(Vec<f64>),
            Integer(Vec<u32>),
            Boolean(Vec<bool>),
        }
        let cols = run(py, || {
            let mut m = self.model.clone();
            let mut cols: Vec<Column> = fields
                .iter()
                .map(|&k| match MESH_OUTPUT_FIELDS[k].kind() {
                    OutputKind::Real => Column::Real(Vec::with_capacity(n)),
                    OutputKind::Integer => Column::Integer(Vec::with_capacity(n)),
                    OutputKind::Boolean => Column::Boolean(Vec::with_capacity(n)),
                })
                .collect();
            for i in 0..n {
                let s = &state(i);
                check_state(i, s)?;
                let o = if torques_only { m.torques(s).map(|(o, _)| o) } else { m.evaluate(s) };
                let o = o.map_err(|e| match Failure::from(e) {
                    Failure::Param(msg) => Failure::Param(format!("state {i}: {msg}")),
                    Failure::Solver(msg) => Failure::Solver(format!("state {i}: {msg}")),
                    other => other,
                })?;
                if first_non_finite(&o).is_some() {
                    finite_outputs(&format!("state {i}"), &o)?;
                }
                for (c, &k) in cols.iter_mut().zip(&fields) {
                    match (c, MESH_OUTPUT_FIELDS[k].access) {
                        (Column::Real(c), FieldAccess::Real { get, .. }) => c.push(get(&o)),
                        (Column::Integer(c), FieldAccess::Integer { get }) => c.push(get(&o)),
                        (Column::Boolean(c), FieldAccess::Boolean { get }) => c.push(get(&o)),
                        _ => unreachable!("columns follow the table's kinds"),
                    }
                }
            }
            Ok(cols)
        })?;
        let d = PyDict::new(py);
        for (&k, c) in fields.iter().zip(cols) {
            let f = &MESH_OUTPUT_FIELDS[k];
            match c {
                Column::Real(c) => d.set_item(f.name, array(py, c))?,
                Column::Integer(c) => d.set_item(f.name, PyArray1::from_vec(py, c))?,
                Column::Boolean(c) => d.set_item(f.name, PyArray1::from_vec(py, c))?,
            }
        }
        Ok(d)
    }

    /// Static transmission error (Eq. 16) at torque `torque` (N·m) on `points_per_pitch`
    /// pinion angles per pitch over `pitches` pitches from φp = 0: JSON of the library's
    /// `results::StaticCurveRecord` (per-point arrays `phi_p_rad`, `ste_um`, `n_pairs`,
    /// `p_max_pa`, `tip_contact`, `contact_length_m`, `force_p_n`, `moment_p_nm`, `force_g_n`,
    /// `moment_g_nm`, `root_stress_p_pa`, `root_stress_g_pa`; summary `ste_max_um`,
    /// `ste_min_um`, `ste_mean_um`, `ste_peak_to_peak_um`, `mesh_stiffness_mean_n_per_um`,
    /// `force_p_mean_n`, `force_p_peak_to_peak_n`, `root_stress_max_p_pa`,
    /// `root_stress_max_g_pa`), with the mesh friction at pinion speed `w_p` (rad/s; the
    /// states run at it when the model has friction, at rest otherwise): the keys of the
    /// library's `results::StaticFrictionSummary` (`omega_p_rad_s`, `mesh_loss_mean_w`,
    /// `mesh_efficiency_mean`, `loss_factor_h_v`, `mu_mean`) and the per-point arrays
    /// `p_loss_w`, `eta_mesh`, `m_r_p_nm`, `m_r_g_nm`, `q_p_w`, `q_g_w` (W, N·m).
    #[pyo3(signature = (torque, points_per_pitch = 20, pitches = 1, w_p = 0.0))]
    fn static_curve_json(
        &self,
        py: Python<'_>,
        torque: f64,
        points_per_pitch: usize,
        pitches: usize,
        w_p: f64,
    ) -> PyResult<String> {
        run(py, || {
            if !(w_p.is_finite() && w_p.abs() <= helical_gear_mesh::mesh::validity::MAX_SPEED_RAD_S)
            {
                return Err(Failure::Param(format!(
                    "w_p = {w_p}: allowed finite, |w_p| <= 1e5 rad/s (0: standstill, negative: \
                     running backwards)"
                )));
            }
            if !(torque.is_finite() && torque > 0.0) {
                return Err(Failure::Param(format!(
                    "torque = {torque} N·m: allowed > 0 and finite"
                )));
            }
            if !(1..=10_000).contains(&points_per_pitch) || !(1..=100).contains(&pitches) {
                return Err(Failure::Param(format!(
                    "points_per_pitch = {points_per_pitch} (allowed 1 … 10000), pitches = \
                     {pitches} (allowed 1 … 100)"
                )));
            }
            let mut m = self.model.clone();
            let geo = m.geometry().clone();
            let pitch = geo.pinion.angular_pitch();
            let friction = m.options().friction;
            // Without friction the speed changes nothing: the states at rest, bit for bit.
            let settings = EquilibriumSettings {
                w_p: if friction.is_on() { w_p } else { 0.0 },
                ..EquilibriumSettings::default()
            };
            let c = static_curve_with(
                &mut m,
                torque,
                0.0,
                pitch,
                points_per_pitch,
                pitches,
                &settings,
            )?;
            let record = StaticCurveRecord::new(&c, geo.pinion.rb);
            record.check_finite().map_err(Failure::Solver)?;
            for (k, e) in c.points.iter().enumerate() {
                finite_outputs(&format!("static point {k}"), &e.outputs)?;
            }
            let summary = StaticFrictionSummary::new(&c, &geo, friction, w_p);
            summary.check_finite().map_err(Failure::Solver)?;
            let mut v =
                serde_json::to_value(&record).map_err(|e| Failure::Solver(e.to_string()))?;
            let s = serde_json::to_value(&summary).map_err(|e| Failure::Solver(e.to_string()))?;
            if let (Value::Object(o), Value::Object(s)) = (&mut v, s) {
                o.extend(s);
                type Get = fn(&helical_gear_mesh::mesh::MeshOutputs) -> f64;
                let per_point: [(&str, Get); 6] = [
                    ("p_loss_w", |o| o.p_loss),
                    ("eta_mesh", |o| o.eta_mesh),
                    ("m_r_p_nm", |o| o.m_r_p),
                    ("m_r_g_nm", |o| o.m_r_g),
                    ("q_p_w", |o| o.q_p),
                    ("q_g_w", |o| o.q_g),
                ];
                for (key, get) in per_point {
                    let values: Vec<f64> = c.points.iter().map(|e| get(&e.outputs)).collect();
                    o.insert(key.into(), values.into());
                }
            }
            to_json_text(&v)
        })
    }

    /// One trajectory of Eqs. 1–4 from the static equilibrium at nominal pinion speed `w_p`
    /// (rad/s, ≥ 0) to `t_end` (s), with RK4 steps `dt` (default: the library's step rule,
    /// `dynamics::default_rk4_step`, shortened to divide `t_end`) or adaptive DOPRI5 (`method="dopri5"`, `dt` = output interval); the
    /// mesh damping from `pair_json`, the drivetrain from `pair_json` and the drive line
    /// `drive_json`. Returns a dict of arrays: `time`, the eight states, `TE`, `M_F_p`,
    /// `M_F_g`, `M_D_p`, `M_D_g`, the force and moments `F_p_x` … `M_g_y`, `sigma_F_p`,
    /// `sigma_F_g` (tooth-root stresses, Pa), the friction outputs `M_R_p`, `M_R_g` (N·m),
    /// `P_loss`, `eta_mesh`, `Q_p`, `Q_g` (W) of the model's friction option (the start is
    /// the quasi-static state at `w_p` with friction, at rest without); and `steps`,
    /// `mesh_evaluations`.
    #[pyo3(signature = (pair_json, drive_json, w_p, t_end, dt = None, method = "rk4", phi_p0 = 0.0, rtol = 1e-8, atol = 1e-12))]
    #[allow(clippy::too_many_arguments)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        pair_json: &str,
        drive_json: &str,
        w_p: f64,
        t_end: f64,
        dt: Option<f64>,
        method: &str,
        phi_p0: f64,
        rtol: f64,
        atol: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (tr_time, states, outs, steps, evals) = run(py, || {
            check_run(w_p, t_end)?;
            if let Some(dt) = dt
                && !(dt.is_finite() && dt > 0.0 && dt <= t_end)
            {
                return Err(Failure::Param(format!(
                    "dt = {dt}: allowed finite, > 0 and <= t_end (s)"
                )));
            }
            if !phi_p0.is_finite() {
                return Err(Failure::Param(format!("phi_p0 = {phi_p0}: allowed finite (rad)")));
            }
            let pair = parse_pair(pair_json)?;
            let drive = Drivetrain::from_pair(&pair, &parse_drive(drive_json)?)?;
            let t_m = drive.mesh_period(w_p);
            let mut mesh = self.model.clone();
            mesh.set_d_mesh(pair.d_mesh_n_s_per_m)?;
            let mut model = GearDynamics::new(mesh, drive)?;
            let method =
                method.parse::<Integrator>().map_err(|e| Failure::Param(format!("method: {e}")))?;
            let stepping = match method {
                Integrator::Rk4 => {
                    let dt = match dt {
                        Some(dt) => {
                            let n = (t_end / dt).round();
                            if (n * dt - t_end).abs() > 1e-9 * t_end {
                                return Err(Failure::Param(format!(
                                    "t_end = {t_end} is not a whole number of RK4 steps dt = \
                                     {dt} (within 1e-9)"
                                )));
                            }
                            dt
                        }
                        // The step rule of dynamics::limits (mesh period and fastest mode).
                        None => default_rk4_step(&mut model, w_p, phi_p0, t_end)?,
                    };
                    Stepping::Rk4 { dt }
                }
                Integrator::Dopri5 => {
                    let mut options = Dopri5Options::with_tolerances(rtol, atol);
                    options.h_max = t_m.is_finite().then_some(t_m);
                    options.max_steps = MAX_TRAJECTORY_SAMPLES;
                    Stepping::Dopri5 { options, output_dt: dt }
                }
            };
            // With friction the start is the quasi-static state at the nominal speed; without,
            // the state at rest (the speed changes nothing).
            let settings = EquilibriumSettings {
                w_p: if self.model.options().friction.is_on() { w_p } else { 0.0 },
                ..EquilibriumSettings::default()
            };
            let start = model
                .static_start(phi_p0, w_p, &settings)
                .map_err(|e| Failure::Solver(format!("static start: {e}")))?;
            let tr = simulate(&mut model, &start.y, t_end, &stepping)?;
            for (k, (y, o)) in tr.states.iter().zip(&tr.outputs).enumerate() {
                let at = format!("sample {k} (t = {:.6e} s)", tr.time[k]);
                finite(&at, &STATE_NAMES, &y[..STATE_NAMES.len()])?;
                finite_outputs(&at, o)?;
            }
            Ok((tr.time, tr.states, tr.outputs, tr.steps, tr.mesh_evaluations))
        })?;
        let d = PyDict::new(py);
        d.set_item("time", array(py, tr_time))?;
        for (i, name) in STATE_NAMES.iter().enumerate() {
            d.set_item(*name, array(py, states.iter().map(|y| y[i]).collect()))?;
        }
        // Every Real mesh output of the core's table, keyed by its interface name.
        for f in real_fields() {
            d.set_item(f.name, array(py, outs.iter().filter_map(|o| f.real(o)).collect()))?;
        }
        d.set_item("steps", steps)?;
        d.set_item("mesh_evaluations", evals)?;
        Ok(d)
    }

    /// One trajectory with both gear bodies on the supports of `supports_json` (the library's
    /// `dynamics::bodies`, as the CLI's `simulate --supports`): the columns of `simulate`, the
    /// poses and rates (`u_p_x` … `om_g_y`) and the support forces (`R_p_x` … `R_g_my`), and
    /// under `"supports"` the JSON of `results::SupportedRunRecord` (modes, statistics over
    /// the last whole mesh periods with `orders` mesh orders).
    #[allow(clippy::too_many_arguments)]
    fn simulate_supported<'py>(
        &self,
        py: Python<'py>,
        pair_json: &str,
        drive_json: &str,
        supports_json: &str,
        w_p: f64,
        t_end: f64,
        phi_p0: f64,
        orders: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        use helical_gear_mesh::dynamics::bodies::{
            REACTION_NAMES, SupportedDynamics, simulate_supported, supported_rk4_step,
        };
        use helical_gear_mesh::mesh::pose::INPUT_NAMES;
        use helical_gear_mesh::results::SupportedRunRecord;
        let (tr, summary) = run(py, || {
            check_run(w_p, t_end)?;
            if !phi_p0.is_finite() {
                return Err(Failure::Param(format!("phi_p0 = {phi_p0}: allowed finite (rad)")));
            }
            if orders > 64 {
                return Err(Failure::Param(format!("orders = {orders}: allowed 0 … 64")));
            }
            let pair = parse_pair(pair_json)?;
            let supports =
                helical_gear_mesh::mesh::Supports::from_json_for(supports_json, pair.face_width_m)?;
            let drive = Drivetrain::from_pair(&pair, &parse_drive(drive_json)?)?;
            let mut mesh = self.model.clone();
            mesh.set_d_mesh(pair.d_mesh_n_s_per_m)?;
            let mut model = SupportedDynamics::new(mesh, drive, supports)?;
            let start = model
                .static_start(phi_p0, w_p, &EquilibriumSettings::default())
                .map_err(|e| Failure::Solver(format!("static start: {e}")))?;
            let modes = model.linear_modes(&start)?;
            let dt = supported_rk4_step(&drive, &modes, w_p);
            let t_m = drive.mesh_period(w_p);
            let spp = if t_m.is_finite() { (t_m / dt).round() as usize } else { 0 };
            let n = (t_end / dt).ceil().max(1.0);
            if n + 1.0 > MAX_TRAJECTORY_SAMPLES as f64 {
                return Err(Failure::Param(format!(
                    "t_end = {t_end}: {n:.3e} steps of {dt:.3e} s, more than the {:.0e} samples \
                     a trajectory may hold; lower t_end",
                    MAX_TRAJECTORY_SAMPLES as f64
                )));
            }
            let tr = simulate_supported(&mut model, &start.y, dt, n as usize, &modes)?;
            for (k, o) in tr.drive.outputs.iter().enumerate() {
                let at = format!("sample {k} (t = {:.6e} s)", tr.drive.time[k]);
                finite(&at, &STATE_NAMES, &tr.drive.states[k][..STATE_NAMES.len()])?;
                finite(&at, &INPUT_NAMES, &tr.bodies[k])?;
                finite(&at, &REACTION_NAMES, &tr.reactions[k].values())?;
                finite_outputs(&at, o)?;
            }
            let summary = SupportedRunRecord::new(&tr, &modes, model.supports(), spp, orders);
            summary.check_finite().map_err(Failure::Solver)?;
            Ok((tr, to_json_text(&summary)?))
        })?;
        let d = PyDict::new(py);
        d.set_item("time", array(py, tr.drive.time.clone()))?;
        for (i, name) in STATE_NAMES.iter().enumerate() {
            d.set_item(*name, array(py, tr.drive.states.iter().map(|y| y[i]).collect()))?;
        }
        for f in real_fields() {
            d.set_item(
                f.name,
                array(py, tr.drive.outputs.iter().filter_map(|o| f.real(o)).collect()),
            )?;
        }
        for (i, name) in INPUT_NAMES.iter().enumerate() {
            d.set_item(*name, array(py, tr.bodies.iter().map(|b| b[i]).collect()))?;
        }
        for (i, name) in REACTION_NAMES.iter().enumerate() {
            d.set_item(*name, array(py, tr.reactions.iter().map(|r| r.values()[i]).collect()))?;
        }
        d.set_item("steps", tr.drive.steps)?;
        d.set_item("mesh_evaluations", tr.drive.mesh_evaluations)?;
        d.set_item("supports", summary)?;
        Ok(d)
    }

    /// Steady-state TE_max/STE_max at every speed of `speeds` (rad/s, > 0, ascending) with the
    /// mesh damping of `pair_json`, the drivetrain of `pair_json` and the drive line
    /// `drive_json`, and the located resonances (the library's
    /// `dynamics::sweep`): JSON of the library's `results::SweepRecord` (per-speed arrays,
    /// among them `mesh_efficiency_mean` of the model's friction option, `resonances_rad_s`, `resonance_te_max_over_ste_max`, `ste_max_um`,
    /// `mesh_stiffness_n_per_um`, `warnings`).
    #[pyo3(signature = (pair_json, drive_json, speeds, steps_per_period = DEFAULT_STEPS_PER_MESH_PERIOD, max_periods = 3000, refine_runs = 6, min_prominence = 0.005, threads = None))]
    #[allow(clippy::too_many_arguments)]
    fn sweep_json(
        &self,
        py: Python<'_>,
        pair_json: &str,
        drive_json: &str,
        speeds: Vec<f64>,
        steps_per_period: usize,
        max_periods: usize,
        refine_runs: usize,
        min_prominence: f64,
        threads: Option<usize>,
    ) -> PyResult<String> {
        run(py, || {
            let pair = parse_pair(pair_json)?;
            let drive = Drivetrain::from_pair(&pair, &parse_drive(drive_json)?)?;
            let mut mesh = self.model.clone();
            mesh.set_d_mesh(pair.d_mesh_n_s_per_m)?;
            let period = pair.modifications.period_meshes(pair.z_p, pair.z_g) as usize;
            let opts = SweepOptions {
                run: SteadyRunOptions {
                    method: SteadyMethod::Rk4 { steps_per_period },
                    max_periods: steady_max_periods(max_periods, period),
                    period_meshes: period,
                    keep_window: false,
                    ..SteadyRunOptions::default()
                },
                threads,
                refine_runs,
                min_prominence,
                progress: false,
                ..SweepOptions::default()
            };
            let r = sweep(&mesh, &drive, &speeds, &opts)?;
            let record = SweepRecord::new(&r, &speeds);
            record.check_finite().map_err(Failure::Solver)?;
            to_json_text(&record)
        })
    }

    /// The steady response at every speed of `speeds` (rad/s) with both gear bodies on the
    /// supports of `supports_json` (the library's `dynamics::supported_sweep`, as the CLI's
    /// `sweep --supports`): JSON of `results::SupportedSweepRecord`.
    #[pyo3(signature = (pair_json, drive_json, supports_json, speeds, max_periods = 2000, min_prominence = 0.005, threads = None))]
    #[allow(clippy::too_many_arguments)]
    fn sweep_supported_json(
        &self,
        py: Python<'_>,
        pair_json: &str,
        drive_json: &str,
        supports_json: &str,
        speeds: Vec<f64>,
        max_periods: usize,
        min_prominence: f64,
        threads: Option<usize>,
    ) -> PyResult<String> {
        use helical_gear_mesh::dynamics::supported_sweep::{
            SupportedSweepOptions, sweep_supported,
        };
        use helical_gear_mesh::results::SupportedSweepRecord;
        run(py, || {
            let pair = parse_pair(pair_json)?;
            let supports =
                helical_gear_mesh::mesh::Supports::from_json_for(supports_json, pair.face_width_m)?;
            let drive = Drivetrain::from_pair(&pair, &parse_drive(drive_json)?)?;
            if self.model.options().friction.is_on() {
                return Err(Failure::Param(
                    "supports with friction: not supported yet (the friction forces' pose \
                     sensitivities are not derived)"
                        .into(),
                ));
            }
            let mut mesh = self.model.clone();
            mesh.set_d_mesh(pair.d_mesh_n_s_per_m)?;
            let opts = SupportedSweepOptions {
                max_periods: max_periods.max(1),
                threads,
                ..SupportedSweepOptions::default()
            };
            let sw = sweep_supported(&mesh, &drive, &supports, &speeds, &opts)?;
            let record = SupportedSweepRecord::new(&sw, drive.z_p, min_prominence);
            record.check_finite().map_err(Failure::Solver)?;
            to_json_text(&record)
        })
    }

    /// Seconds spent building the table (0 for the full fidelity).
    fn table_build_seconds(&self, py: Python<'_>) -> PyResult<f64> {
        run(py, || Ok(self.model.table().map_or(0.0, |t| t.build_seconds())))
    }
}

/// Checks a sweep's arguments before any model is built (the library's
/// `dynamics::check_sweep_request`): `speeds` (rad/s) non-empty, finite, in (0, 1e5],
/// strictly ascending, at most 100 000; `refine_runs` ≤ 64; `min_prominence` finite and
/// ≥ 0; `threads` ≥ 1. A bad one is a `ParameterError` naming it, its value and its range.
#[pyfunction]
#[pyo3(signature = (speeds, refine_runs, min_prominence, threads = None))]
fn check_sweep_request(
    py: Python<'_>,
    speeds: Vec<f64>,
    refine_runs: usize,
    min_prominence: f64,
    threads: Option<usize>,
) -> PyResult<()> {
    run(py, || {
        let opts = SweepOptions { refine_runs, min_prominence, threads, ..SweepOptions::default() };
        helical_gear_mesh::dynamics::check_sweep_request(&speeds, &opts)
            .map_err(|e| Failure::Param(e.to_string()))
    })
}

/// The whole paper run into `out_dir` (summary.json, summary.md, the CSV and PNG figures);
/// returns the summary as JSON. `quick`: coarse speed grids, a smoke run. The pair is driven
/// by the drive line `drive_json`.
#[pyfunction]
#[pyo3(signature = (pair_json, drive_json, out_dir, quick = false, slices = 200, threads = None, progress = true))]
#[allow(clippy::too_many_arguments)]
fn paper_json(
    py: Python<'_>,
    pair_json: &str,
    drive_json: &str,
    out_dir: PathBuf,
    quick: bool,
    slices: usize,
    threads: Option<usize>,
    progress: bool,
) -> PyResult<String> {
    run(py, || {
        if threads == Some(0) {
            return Err(Failure::Param("threads = 0: allowed >= 1".into()));
        }
        let pair = parse_pair(pair_json)?;
        let drive = parse_drive(drive_json)?;
        let opts = PaperOptions { quick, slices, threads, progress };
        let s = run_paper(&pair, &drive, &out_dir, &opts).map_err(Failure::Solver)?;
        let v: Value = serde_json::to_value(&s).map_err(|e| Failure::Internal(e.to_string()))?;
        to_json_text(&v)
    })
}

/// Raises a Rust panic inside [`run`] (tests check that it arrives as `GearMeshError`).
#[pyfunction]
fn _panic_for_test(py: Python<'_>) -> PyResult<()> {
    run(py, || -> Res<()> { panic!("deliberate panic for the boundary test") })
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GearMeshError", py.get_type::<GearMeshError>())?;
    m.add("ParameterError", py.get_type::<ParameterError>())?;
    m.add("ComplianceError", py.get_type::<ComplianceError>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    m.add("LIBRARY_VERSION", env!("CARGO_PKG_VERSION"))?;
    // The core's one table of the mesh outputs: (name, unit, kind, description) in order.
    let outputs: Vec<(&str, &str, &str, &str)> = MESH_OUTPUT_FIELDS
        .iter()
        .map(|f| {
            let kind = match f.kind() {
                OutputKind::Real => "real",
                OutputKind::Integer => "integer",
                OutputKind::Boolean => "boolean",
            };
            (f.name, f.unit, kind, f.description)
        })
        .collect();
    m.add("MESH_OUTPUTS", outputs)?;
    // The outputs the torques path gives (`OutputField::torques`).
    let torques: Vec<&str> =
        MESH_OUTPUT_FIELDS.iter().filter(|f| f.torques).map(|f| f.name).collect();
    m.add("TORQUES_OUTPUTS", torques)?;
    m.add("POSE_INPUTS", helical_gear_mesh::mesh::pose::INPUT_NAMES.to_vec())?;
    // The library's default mesh options: the one source of the Python shell's defaults.
    let d = MeshOptions::default();
    let defaults = PyDict::new(py);
    defaults.set_item("slices", d.slices)?;
    defaults.set_item("table_phase_points", d.table_phase_points)?;
    defaults.set_item("table_te_points", d.table_te_points)?;
    defaults.set_item("table_design_torque", d.table_design_torque_nm)?;
    defaults.set_item("table_slices", d.table_slices)?;
    m.add("MESH_OPTION_DEFAULTS", defaults)?;
    m.add_class::<Compliance>()?;
    m.add_class::<MeshModel>()?;
    m.add_function(wrap_pyfunction!(default_pair_json, m)?)?;
    m.add_function(wrap_pyfunction!(default_drive_json, m)?)?;
    m.add_function(wrap_pyfunction!(normalize_drive, m)?)?;
    m.add_function(wrap_pyfunction!(parameter_bounds, m)?)?;
    m.add_function(wrap_pyfunction!(normalize_pair, m)?)?;
    m.add_function(wrap_pyfunction!(assumptions, m)?)?;
    m.add_function(wrap_pyfunction!(geometry_json, m)?)?;
    m.add_function(wrap_pyfunction!(iso_root_stress_json, m)?)?;
    m.add_function(wrap_pyfunction!(iso_root_stress_summary_json, m)?)?;
    m.add_function(wrap_pyfunction!(compliance_key, m)?)?;
    m.add_function(wrap_pyfunction!(paper_json, m)?)?;
    m.add_function(wrap_pyfunction!(bearing_reactions, m)?)?;
    m.add_function(wrap_pyfunction!(check_sweep_request, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    Ok(())
}
