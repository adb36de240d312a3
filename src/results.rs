//! Result records: the one definition of every result the shells print (the CLI's `--json`,
//! the Python binding's JSON, the paper run's summary).
//!
//! Each record is a plain serde struct built from the library's own types. Field names are
//! snake_case and carry the unit as a suffix (`_m`, `_um`, `_rad`, `_rad_s`, `_nm`, `_pa`,
//! `_kgm2`, `_n_per_um`, `_s`); dimensionless quantities have none. Units are SI except where
//! the suffix says otherwise (µm for transmission errors, N/µm for mesh stiffness, the units
//! the paper reports them in). Signs follow the library: TE > 0 in normal drive (approach of
//! the driving flanks along the line of action), mesh torques M_F, M_D > 0 when they resist
//! the pinion's drive.
//!
//! JSON has no NaN or infinity (serde_json writes them as `null`), so a record is checked
//! before it leaves: [`GeometryRecord::check_finite`] and the like name the first non-finite
//! field, and the shells turn that into an error (CLI: exit status 1; Python: `SolverError`).
//! Quantities that are legitimately undefined (no tip relief, no mesh period at standstill) are
//! `Option`s, written as `null`, never as a non-finite number.
//!
//! Layering: `results` sits above `dynamics`; it reads geometry, contact, compliance, mesh,
//! dynamics and params and nothing reads it inside the library.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::compliance::data::ComplianceData;
use crate::compliance::fe::gear_mesh::GearMeshDensity;
use crate::compliance::stiffness::PairStiffness;
use crate::contact::{ContactPoint, FlankSide};
use crate::dynamics::model::{N_STATES, STATE_NAMES};
use crate::dynamics::{SteadyResponse, SweepResult, Trajectory};
use crate::geometry::PairGeometry;
use crate::iso6336::{IsoRootStress, nominal_root_stress};
use crate::mesh::outputs::real_fields;
#[cfg(doc)]
use crate::mesh::outputs::{MESH_OUTPUT_FIELDS, OutputField};
use crate::mesh::statics::StaticCurve;
use crate::params::GearPair;

/// Metres to micrometres.
const UM: f64 = 1e6;

/// `Err` naming `name` (and the index for arrays) if `v` is not finite.
fn finite(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() { Ok(()) } else { Err(format!("result field {name} = {v} is not finite")) }
}

/// `Err` naming `name[i]` for the first non-finite element of `v`.
fn finite_all(name: &str, v: &[f64]) -> Result<(), String> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!("result field {name}[{i}] = {} is not finite", v[i])),
    }
}

/// `Err` naming `name` if the optional `v` is present and not finite.
fn finite_opt(name: &str, v: Option<f64>) -> Result<(), String> {
    v.map_or(Ok(()), |x| finite(name, x))
}

/// The derived geometry of a gear pair (`helical-gear geometry --json`,
/// `helical_gear.geometry()`). Suffix `_p`: pinion, `_g`: gear.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeometryRecord {
    /// Transverse contact ratio ε_α (dimensionless).
    pub eps_alpha: f64,
    /// Overlap ratio ε_β (dimensionless).
    pub eps_beta: f64,
    /// Base radius of the pinion, m.
    pub base_radius_p_m: f64,
    /// Base radius of the gear, m.
    pub base_radius_g_m: f64,
    /// Tip radius of the pinion, m.
    pub tip_radius_p_m: f64,
    /// Tip radius of the gear, m.
    pub tip_radius_g_m: f64,
    /// Root radius of the pinion, m.
    pub root_radius_p_m: f64,
    /// Root radius of the gear, m.
    pub root_radius_g_m: f64,
    /// Reference (pitch) radius of the pinion, m.
    pub reference_radius_p_m: f64,
    /// Reference (pitch) radius of the gear, m.
    pub reference_radius_g_m: f64,
    /// Form radius of the pinion (start of the involute above the fillet), m.
    pub form_radius_p_m: f64,
    /// Form radius of the gear, m.
    pub form_radius_g_m: f64,
    /// Radius where the pinion's tip relief starts, m; `None` (null) without tip relief.
    pub relief_start_radius_p_m: Option<f64>,
    /// Radius where the gear's tip relief starts, m; `None` (null) without tip relief.
    pub relief_start_radius_g_m: Option<f64>,
    /// Radius where the pinion's tip rounding starts, m.
    pub rounding_start_radius_p_m: f64,
    /// Radius where the gear's tip rounding starts, m.
    pub rounding_start_radius_g_m: f64,
    /// Operating centre distance, m.
    pub center_distance_m: f64,
    /// Transverse pressure angle α_t at the reference circle, rad.
    pub transverse_pressure_angle_rad: f64,
    /// Transverse operating pressure angle α_wt, rad.
    pub operating_pressure_angle_rad: f64,
    /// Base helix angle β_b, rad (magnitude).
    pub base_helix_angle_rad: f64,
    /// Transverse base pitch, m.
    pub base_pitch_m: f64,
    /// Backlash expressed as TE (along the transverse line of action), m; the back flanks
    /// touch at TE = −backlash.
    pub backlash_te_m: f64,
    /// Angular pitch of the pinion 2π/z_p, rad.
    pub angular_pitch_p_rad: f64,
    /// Polar moment of inertia of the pinion body, kg·m².
    pub j_p_kgm2: f64,
    /// Polar moment of inertia of the gear body, kg·m².
    pub j_g_kgm2: f64,
    /// The modelling assumptions of the pair, one sentence each.
    pub assumptions: Vec<String>,
}

impl GeometryRecord {
    /// The record of `g`, the geometry derived from `p`.
    pub fn new(g: &PairGeometry, p: &GearPair) -> Self {
        Self {
            eps_alpha: g.eps_alpha,
            eps_beta: g.eps_beta,
            base_radius_p_m: g.pinion.rb,
            base_radius_g_m: g.gear.rb,
            tip_radius_p_m: g.pinion.ra,
            tip_radius_g_m: g.gear.ra,
            root_radius_p_m: g.pinion.rf,
            root_radius_g_m: g.gear.rf,
            reference_radius_p_m: g.pinion.r,
            reference_radius_g_m: g.gear.r,
            form_radius_p_m: g.pinion.r_form,
            form_radius_g_m: g.gear.r_form,
            relief_start_radius_p_m: g.pinion.r_relief_start,
            relief_start_radius_g_m: g.gear.r_relief_start,
            rounding_start_radius_p_m: g.pinion.r_rounding_start,
            rounding_start_radius_g_m: g.gear.r_rounding_start,
            center_distance_m: g.center_distance,
            transverse_pressure_angle_rad: g.alpha_t,
            operating_pressure_angle_rad: g.alpha_wt,
            base_helix_angle_rad: g.base_helix_angle,
            base_pitch_m: g.base_pitch,
            backlash_te_m: g.backlash_te,
            angular_pitch_p_rad: g.pinion.angular_pitch(),
            j_p_kgm2: g.j_p,
            j_g_kgm2: g.j_g,
            assumptions: p.assumptions(),
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        let scalars = [
            ("eps_alpha", self.eps_alpha),
            ("eps_beta", self.eps_beta),
            ("base_radius_p_m", self.base_radius_p_m),
            ("base_radius_g_m", self.base_radius_g_m),
            ("tip_radius_p_m", self.tip_radius_p_m),
            ("tip_radius_g_m", self.tip_radius_g_m),
            ("root_radius_p_m", self.root_radius_p_m),
            ("root_radius_g_m", self.root_radius_g_m),
            ("reference_radius_p_m", self.reference_radius_p_m),
            ("reference_radius_g_m", self.reference_radius_g_m),
            ("form_radius_p_m", self.form_radius_p_m),
            ("form_radius_g_m", self.form_radius_g_m),
            ("rounding_start_radius_p_m", self.rounding_start_radius_p_m),
            ("rounding_start_radius_g_m", self.rounding_start_radius_g_m),
            ("center_distance_m", self.center_distance_m),
            ("transverse_pressure_angle_rad", self.transverse_pressure_angle_rad),
            ("operating_pressure_angle_rad", self.operating_pressure_angle_rad),
            ("base_helix_angle_rad", self.base_helix_angle_rad),
            ("base_pitch_m", self.base_pitch_m),
            ("backlash_te_m", self.backlash_te_m),
            ("angular_pitch_p_rad", self.angular_pitch_p_rad),
            ("j_p_kgm2", self.j_p_kgm2),
            ("j_g_kgm2", self.j_g_kgm2),
        ];
        for (name, v) in scalars {
            finite(name, v)?;
        }
        finite_opt("relief_start_radius_p_m", self.relief_start_radius_p_m)?;
        finite_opt("relief_start_radius_g_m", self.relief_start_radius_g_m)
    }
}

/// The static transmission error curve (Eq. 16) and its summary: per-point arrays (one
/// element per pinion angle, uniform steps) and the extremes. STE > 0 in normal drive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticCurveRecord {
    /// Driving torque on the pinion M, N·m (> 0).
    pub torque_nm: f64,
    /// Pinion angle φp of each point, rad.
    pub phi_p_rad: Vec<f64>,
    /// Static transmission error at each point, µm.
    pub ste_um: Vec<f64>,
    /// Tooth pairs in contact at each point.
    pub n_pairs: Vec<u32>,
    /// Largest contact pressure at each point, Pa.
    pub p_max_pa: Vec<f64>,
    /// Loaded contact on a tip rounding or edge at each point.
    pub tip_contact: Vec<bool>,
    /// Total loaded contact length at each point, m.
    pub contact_length_m: Vec<f64>,
    /// Largest STE over the points, µm.
    pub ste_max_um: f64,
    /// Smallest STE over the points, µm.
    pub ste_min_um: f64,
    /// Mean STE over the points, µm.
    pub ste_mean_um: f64,
    /// Peak-to-peak STE (max − min), µm.
    pub ste_peak_to_peak_um: f64,
    /// Mean secant mesh stiffness along the transverse line of action, N/µm: the mean over
    /// the points of (M/r_b,p)/STE.
    pub mesh_stiffness_mean_n_per_um: f64,
    /// True if any point has a loaded contact on a tip rounding.
    pub tip_rounding_contact: bool,
    /// Force of the mesh on the pinion at each point (x, y, z), N, in the housing frame of
    /// `mesh::forces` (docs/loads.md); the gear's is its negative.
    pub force_p_n: Vec<[f64; 3]>,
    /// Tilting moment of that force about the pinion centre at mid-face (x, y), N·m.
    pub moment_p_nm: Vec<[f64; 2]>,
    /// Force of the mesh on the gear at each point (x, y, z), N (= −`force_p_n`).
    pub force_g_n: Vec<[f64; 3]>,
    /// Tilting moment about the gear centre at mid-face (x, y), N·m.
    pub moment_g_nm: Vec<[f64; 2]>,
    /// Mean of each component of the pinion force over the points, N.
    pub force_p_mean_n: [f64; 3],
    /// Peak-to-peak (max − min) of each component of the pinion force over the points, N.
    pub force_p_peak_to_peak_n: [f64; 3],
    /// Tooth-root stress of the pinion at each point, Pa (largest maximum principal stress at
    /// the tension-side fillet, [`crate::mesh::MeshOutputs::root_stress_p`]).
    pub root_stress_p_pa: Vec<f64>,
    /// Tooth-root stress of the gear at each point, Pa.
    pub root_stress_g_pa: Vec<f64>,
    /// Largest pinion root stress over the points, Pa.
    pub root_stress_max_p_pa: f64,
    /// Largest gear root stress over the points, Pa.
    pub root_stress_max_g_pa: f64,
}

impl StaticCurveRecord {
    /// The record of `curve`; `base_radius_p` (m) converts torque to force for the stiffness.
    pub fn new(curve: &StaticCurve, base_radius_p: f64) -> Self {
        let pts = &curve.points;
        Self {
            torque_nm: curve.torque,
            phi_p_rad: pts.iter().map(|e| e.phi_p).collect(),
            ste_um: pts.iter().map(|e| e.te * UM).collect(),
            n_pairs: pts.iter().map(|e| e.outputs.n_pairs).collect(),
            p_max_pa: pts.iter().map(|e| e.outputs.p_max).collect(),
            tip_contact: pts.iter().map(|e| e.outputs.tip_contact).collect(),
            contact_length_m: pts.iter().map(|e| e.outputs.contact_length).collect(),
            ste_max_um: curve.max() * UM,
            ste_min_um: curve.min() * UM,
            ste_mean_um: curve.mean() * UM,
            ste_peak_to_peak_um: (curve.max() - curve.min()) * UM,
            mesh_stiffness_mean_n_per_um: curve.mean_stiffness(base_radius_p) * 1e-6,
            tip_rounding_contact: curve.tip_rounding_contact(),
            force_p_n: pts.iter().map(|e| e.outputs.force_p).collect(),
            moment_p_nm: pts.iter().map(|e| e.outputs.moment_p).collect(),
            force_g_n: pts.iter().map(|e| e.outputs.force_g).collect(),
            moment_g_nm: pts.iter().map(|e| e.outputs.moment_g).collect(),
            force_p_mean_n: std::array::from_fn(|k| mean(pts.iter().map(|e| e.outputs.force_p[k]))),
            force_p_peak_to_peak_n: std::array::from_fn(|k| {
                peak_to_peak(pts.iter().map(|e| e.outputs.force_p[k]))
            }),
            root_stress_p_pa: pts.iter().map(|e| e.outputs.root_stress_p).collect(),
            root_stress_g_pa: pts.iter().map(|e| e.outputs.root_stress_g).collect(),
            root_stress_max_p_pa: pts.iter().map(|e| e.outputs.root_stress_p).fold(0.0, f64::max),
            root_stress_max_g_pa: pts.iter().map(|e| e.outputs.root_stress_g).fold(0.0, f64::max),
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite("torque_nm", self.torque_nm)?;
        finite_all("phi_p_rad", &self.phi_p_rad)?;
        finite_all("ste_um", &self.ste_um)?;
        finite_all("p_max_pa", &self.p_max_pa)?;
        finite_all("contact_length_m", &self.contact_length_m)?;
        finite("ste_max_um", self.ste_max_um)?;
        finite("ste_min_um", self.ste_min_um)?;
        finite("ste_mean_um", self.ste_mean_um)?;
        finite("ste_peak_to_peak_um", self.ste_peak_to_peak_um)?;
        finite("mesh_stiffness_mean_n_per_um", self.mesh_stiffness_mean_n_per_um)?;
        let flat3 = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<f64>>();
        let flat2 = |v: &[[f64; 2]]| v.iter().flatten().copied().collect::<Vec<f64>>();
        finite_all("force_p_n", &flat3(&self.force_p_n))?;
        finite_all("moment_p_nm", &flat2(&self.moment_p_nm))?;
        finite_all("force_g_n", &flat3(&self.force_g_n))?;
        finite_all("moment_g_nm", &flat2(&self.moment_g_nm))?;
        finite_all("force_p_mean_n", &self.force_p_mean_n)?;
        finite_all("force_p_peak_to_peak_n", &self.force_p_peak_to_peak_n)?;
        finite_all("root_stress_p_pa", &self.root_stress_p_pa)?;
        finite_all("root_stress_g_pa", &self.root_stress_g_pa)?;
        finite("root_stress_max_p_pa", self.root_stress_max_p_pa)?;
        finite("root_stress_max_g_pa", self.root_stress_max_g_pa)
    }
}

/// Mean of `v` (0 for none).
fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// max − min of `v` (0 for none).
fn peak_to_peak(v: impl Iterator<Item = f64>) -> f64 {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    if hi >= lo { hi - lo } else { 0.0 }
}

/// A speed sweep (the library's `dynamics::sweep`): per-speed arrays in the order of the
/// speeds, the located resonances and the normalisation. TE ratios are dynamic TE over the
/// static STE_max (dimensionless); a negative `te_min_over_ste_max` is a separation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRecord {
    /// Pinion speeds ω_p, rad/s.
    pub speeds_rad_s: Vec<f64>,
    /// Largest TE over the steady window / STE_max at each speed.
    pub te_max_over_ste_max: Vec<f64>,
    /// Smallest TE over the steady window / STE_max at each speed.
    pub te_min_over_ste_max: Vec<f64>,
    /// Teeth separated somewhere in the steady window.
    pub separated: Vec<bool>,
    /// Back flanks in contact somewhere in the steady window.
    pub back_contact: Vec<bool>,
    /// Tip rounding or edge in contact somewhere in the steady window.
    pub tip_contact: Vec<bool>,
    /// Steady state detected (otherwise see `warnings`).
    pub steady: Vec<bool>,
    /// Peak |F_p| of the mesh force over the steady window / the largest static |F_p| over a
    /// mesh cycle at the same torque, at each speed (the dynamic factor to compare with
    /// ISO 6336-1's K_v); null for a mesh without contact geometry.
    pub mesh_force_max_over_static: Vec<Option<f64>>,
    /// Peak tooth-root stress over the steady window / the largest static root stress over a
    /// mesh cycle at the same torque, the larger of pinion and gear (each against its own
    /// static peak), at each speed: the dynamic factor of the root stress; null for a mesh
    /// without FE data.
    pub root_stress_max_over_static: Vec<Option<f64>>,
    /// Mean mesh efficiency over the steady window at each speed, 1 − mean P_loss / mean
    /// mesh input power (M_F,p + M_D,p)·φ̇p (dimensionless; 1 without friction).
    pub mesh_efficiency_mean: Vec<f64>,
    /// Period of the steady TE in mesh periods.
    pub period_multiple: Vec<usize>,
    /// Mesh periods integrated at each speed.
    pub periods: Vec<f64>,
    /// Refined speeds of the resonance peaks, rad/s.
    pub resonances_rad_s: Vec<f64>,
    /// TE_max/STE_max at each resonance.
    pub resonance_te_max_over_ste_max: Vec<f64>,
    /// Grid bracket (low, high) of each resonance, rad/s.
    pub resonance_brackets_rad_s: Vec<[f64; 2]>,
    /// Largest TE_max/STE_max over every run (grid and refinement).
    pub peak_te_max_over_ste_max: f64,
    /// STE_max, the normalisation, µm.
    pub ste_max_um: f64,
    /// Mesh stiffness at the static equilibrium used for the step size, N/µm; `None` when a
    /// step was given.
    pub mesh_stiffness_n_per_um: Option<f64>,
    /// Largest RK4 step, s; `None` when not bounded by the sweep.
    pub max_step_s: Option<f64>,
    /// One line per run that is not a detected steady state.
    pub warnings: Vec<String>,
    /// Wall-clock time of the sweep, s.
    pub wall_seconds: f64,
}

impl SweepRecord {
    /// The record of `r`, run at `speeds` (rad/s).
    pub fn new(r: &SweepResult, speeds: &[f64]) -> Self {
        let pts = &r.points;
        let all_runs = || pts.iter().chain(r.resonances.iter().flat_map(|x| x.refinement.iter()));
        Self {
            speeds_rad_s: speeds.to_vec(),
            te_max_over_ste_max: pts.iter().map(|p| p.te_max_over_ste_max).collect(),
            te_min_over_ste_max: pts.iter().map(|p| p.te_min_over_ste_max).collect(),
            separated: pts.iter().map(|p| p.separated).collect(),
            back_contact: pts.iter().map(|p| p.back_contact).collect(),
            tip_contact: pts.iter().map(|p| p.tip_contact).collect(),
            steady: pts.iter().map(|p| p.steady).collect(),
            mesh_force_max_over_static: pts.iter().map(|p| p.over_static.mesh_force).collect(),
            root_stress_max_over_static: pts.iter().map(|p| p.over_static.root_stress).collect(),
            mesh_efficiency_mean: pts.iter().map(|p| p.mesh_efficiency_mean).collect(),
            period_multiple: pts.iter().map(|p| p.period_multiple).collect(),
            periods: pts.iter().map(|p| p.periods).collect(),
            resonances_rad_s: r.resonances.iter().map(|x| x.omega_p).collect(),
            resonance_te_max_over_ste_max: r
                .resonances
                .iter()
                .map(|x| x.te_max_over_ste_max)
                .collect(),
            resonance_brackets_rad_s: r
                .resonances
                .iter()
                .map(|x| [x.bracket.0, x.bracket.1])
                .collect(),
            peak_te_max_over_ste_max: all_runs()
                .map(|p| p.te_max_over_ste_max)
                .fold(f64::NEG_INFINITY, f64::max),
            ste_max_um: r.ste.max() * UM,
            mesh_stiffness_n_per_um: r.mesh_stiffness.map(|k| k * 1e-6),
            max_step_s: r.max_step,
            warnings: all_runs()
                .filter_map(|p| p.warning.map(|w| format!("ω_p = {} rad/s: {w}", p.omega_p)))
                .collect(),
            wall_seconds: r.wall_seconds,
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite_all("speeds_rad_s", &self.speeds_rad_s)?;
        finite_all("te_max_over_ste_max", &self.te_max_over_ste_max)?;
        finite_all("te_min_over_ste_max", &self.te_min_over_ste_max)?;
        let ratios: Vec<f64> = self.mesh_force_max_over_static.iter().flatten().copied().collect();
        finite_all("mesh_force_max_over_static", &ratios)?;
        let ratios: Vec<f64> = self.root_stress_max_over_static.iter().flatten().copied().collect();
        finite_all("root_stress_max_over_static", &ratios)?;
        finite_all("mesh_efficiency_mean", &self.mesh_efficiency_mean)?;
        finite_all("periods", &self.periods)?;
        finite_all("resonances_rad_s", &self.resonances_rad_s)?;
        finite_all("resonance_te_max_over_ste_max", &self.resonance_te_max_over_ste_max)?;
        let brackets: Vec<f64> = self.resonance_brackets_rad_s.iter().flatten().copied().collect();
        finite_all("resonance_brackets_rad_s", &brackets)?;
        finite("peak_te_max_over_ste_max", self.peak_te_max_over_ste_max)?;
        finite("ste_max_um", self.ste_max_um)?;
        finite_opt("mesh_stiffness_n_per_um", self.mesh_stiffness_n_per_um)?;
        finite_opt("max_step_s", self.max_step_s)?;
        finite("wall_seconds", self.wall_seconds)
    }
}

/// One trajectory of Eqs. 1–4: per output time the eight states (names of
/// [`STATE_NAMES`]) and every Real mesh output, keyed by its result column of the core's one
/// table of the mesh outputs ([`MESH_OUTPUT_FIELDS`]: `te_m`, `m_f_p_nm`, … `force_p_x_n`,
/// … `root_stress_g_pa`). Angles in rad, speeds in rad/s, the outputs in the units of their
/// column suffix (M_F, M_D enter the pinion and gear equations with a minus sign).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryRecord {
    /// Output times, s.
    pub time_s: Vec<f64>,
    /// Drive-side inertia angle φ₁, rad.
    pub phi_1_rad: Vec<f64>,
    /// Pinion angle φp, rad.
    pub phi_p_rad: Vec<f64>,
    /// Gear angle φg, rad.
    pub phi_g_rad: Vec<f64>,
    /// Load-side inertia angle φ₂, rad.
    pub phi_2_rad: Vec<f64>,
    /// Drive-side inertia speed φ̇₁, rad/s.
    pub w_1_rad_s: Vec<f64>,
    /// Pinion speed φ̇p, rad/s.
    pub w_p_rad_s: Vec<f64>,
    /// Gear speed φ̇g, rad/s.
    pub w_g_rad_s: Vec<f64>,
    /// Load-side inertia speed φ̇₂, rad/s.
    pub w_2_rad_s: Vec<f64>,
    /// Every Real mesh output per output time, keyed by its result column
    /// ([`OutputField::column`] of [`MESH_OUTPUT_FIELDS`]; a flat part of the JSON object).
    #[serde(flatten)]
    pub mesh: BTreeMap<String, Vec<f64>>,
    /// Integration steps taken.
    pub steps: usize,
    /// Mesh evaluations.
    pub mesh_evaluations: usize,
    /// With the gear bodies on supports ([`crate::dynamics::bodies`]): per output time the
    /// poses and rates (`u_p_x` … `om_g_y`, m, rad, m/s, rad/s) and the support forces and
    /// moments on the bodies (`R_p_x` … `R_g_my`, N, N·m); empty (and absent from the JSON)
    /// on rigid bearings.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub bodies: BTreeMap<String, Vec<f64>>,
}

/// The statistics of one support force or moment over the last whole mesh periods of a run
/// ([`crate::dynamics::bodies::ForceStats`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SupportForceRecord {
    /// Mean, N (N·m for a moment).
    pub reaction_mean_n: f64,
    /// Peak to peak, N (N·m).
    pub reaction_peak_to_peak_n: f64,
    /// Amplitudes of mesh orders 1, 2, …, N (N·m); empty at standstill.
    pub orders: Vec<f64>,
}

/// `simulate --supports`: the coupled modes and the support-force statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SupportedRunRecord {
    /// Frequencies of the linearised coupled modes, Hz, ascending.
    pub modes_hz: Vec<f64>,
    /// Their damping ratios −Re λ/|λ|.
    pub modes_damping_ratio: Vec<f64>,
    /// Mesh periods the statistics are taken over (the last whole ones of the run; 0 at
    /// standstill: the whole run).
    pub window_mesh_periods: usize,
    /// Per support force and moment (`R_p_x` … `R_g_my`), its statistics.
    pub support_forces: BTreeMap<String, SupportForceRecord>,
    /// Per bearing of a shaft-form support, the statistics of its force on the shaft (x, y, z);
    /// empty (absent) without one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bearings: Vec<BearingForceRecord>,
}

/// The dynamic force of one bearing of a shaft-form support over the window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BearingForceRecord {
    /// `pinion` or `gear`.
    pub shaft: String,
    /// Index in the JSON's list of bearings.
    pub bearing: usize,
    /// Position along the axis, m.
    pub z_m: f64,
    /// Mean of the force on the shaft (x, y, z), N.
    pub reaction_mean_n: Vec<f64>,
    /// Peak to peak (x, y, z), N.
    pub reaction_peak_to_peak_n: Vec<f64>,
    /// Mesh-order amplitudes 1, 2, … of each component (x, y, z), N.
    pub orders: Vec<Vec<f64>>,
}

impl SupportedRunRecord {
    /// The record of the supported run `tr` with the coupled `modes`, on `supports`, with
    /// `samples_per_period` samples per mesh period (0 at standstill) and `orders` mesh orders.
    pub fn new(
        tr: &crate::dynamics::bodies::SupportedTrajectory,
        modes: &crate::dynamics::bodies::CoupledModes,
        supports: &crate::mesh::Supports,
        samples_per_period: usize,
        orders: usize,
    ) -> Self {
        use crate::dynamics::bodies::{REACTION_NAMES, bearing_force_stats, support_force_stats};
        let stats = support_force_stats(tr, samples_per_period, orders);
        let support_forces = stats
            .iter()
            .flat_map(|s| REACTION_NAMES.iter().zip(s.iter()))
            .map(|(name, s)| {
                let r = SupportForceRecord {
                    reaction_mean_n: s.mean,
                    reaction_peak_to_peak_n: s.peak_to_peak,
                    orders: s.orders.clone(),
                };
                (name.to_string(), r)
            })
            .collect();
        let bearings = bearing_force_stats(tr, supports, samples_per_period, orders)
            .into_iter()
            .map(|b| BearingForceRecord {
                shaft: b.shaft.to_string(),
                bearing: b.bearing,
                z_m: b.z_m,
                reaction_mean_n: b.components.iter().map(|c| c.mean).collect(),
                reaction_peak_to_peak_n: b.components.iter().map(|c| c.peak_to_peak).collect(),
                orders: b.components.iter().map(|c| c.orders.clone()).collect(),
            })
            .collect();
        Self {
            modes_hz: modes.frequencies_hz(),
            modes_damping_ratio: modes.eigenvalues.iter().map(|l| -l.re / l.norm()).collect(),
            window_mesh_periods: tr.drive.steps.checked_div(samples_per_period).unwrap_or(0),
            support_forces,
            bearings,
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite_all("modes_hz", &self.modes_hz)?;
        finite_all("modes_damping_ratio", &self.modes_damping_ratio)?;
        for (k, r) in &self.support_forces {
            finite(&format!("{k}.reaction_mean_n"), r.reaction_mean_n)?;
            finite(&format!("{k}.reaction_peak_to_peak_n"), r.reaction_peak_to_peak_n)?;
            finite_all(&format!("{k}.orders"), &r.orders)?;
        }
        for b in &self.bearings {
            let at = format!("bearings.{}[{}]", b.shaft, b.bearing);
            finite_all(&format!("{at}.reaction_mean_n"), &b.reaction_mean_n)?;
            finite_all(&format!("{at}.reaction_peak_to_peak_n"), &b.reaction_peak_to_peak_n)?;
            for o in &b.orders {
                finite_all(&format!("{at}.orders"), o)?;
            }
        }
        Ok(())
    }
}

impl TrajectoryRecord {
    /// The record of a supported trajectory: [`Self::new`] of its drive line with the bodies'
    /// columns.
    pub fn supported(tr: &crate::dynamics::bodies::SupportedTrajectory) -> Self {
        let mut r = Self::new(&tr.drive);
        for (k, name) in crate::mesh::pose::INPUT_NAMES.iter().enumerate() {
            r.bodies.insert(name.to_string(), tr.bodies.iter().map(|b| b[k]).collect());
        }
        for (k, name) in crate::dynamics::bodies::REACTION_NAMES.iter().enumerate() {
            r.bodies.insert(name.to_string(), tr.reactions.iter().map(|x| x.values()[k]).collect());
        }
        r
    }

    /// The record of `tr`.
    pub fn new(tr: &Trajectory) -> Self {
        let s = |i: usize| tr.states.iter().map(|y| y[i]).collect::<Vec<f64>>();
        let mesh = real_fields()
            .map(|f| (f.column.to_string(), tr.outputs.iter().filter_map(|o| f.real(o)).collect()))
            .collect();
        Self {
            time_s: tr.time.clone(),
            phi_1_rad: s(0),
            phi_p_rad: s(1),
            phi_g_rad: s(2),
            phi_2_rad: s(3),
            w_1_rad_s: s(4),
            w_p_rad_s: s(5),
            w_g_rad_s: s(6),
            w_2_rad_s: s(7),
            mesh,
            steps: tr.steps,
            mesh_evaluations: tr.mesh_evaluations,
            bodies: BTreeMap::new(),
        }
    }

    /// The mesh-output column `column` (e.g. `te_m`); empty when the record has none.
    pub fn mesh_column(&self, column: &str) -> &[f64] {
        self.mesh.get(column).map_or(&[], Vec::as_slice)
    }

    /// The columns in output order with their names: `time_s`, the states in state order
    /// ([`STATE_NAMES`]), then every Real mesh output in the order of [`MESH_OUTPUT_FIELDS`]
    /// (`m_f_p_nm`, `m_f_g_nm`, `m_d_p_nm`, `m_d_g_nm`, `te_m`, `f_n_n`, `contact_length_m`,
    /// `p_max_pa`, the force and moments `force_p_x_n` … `moment_g_y_nm`,
    /// `root_stress_p_pa`, `root_stress_g_pa`), then with the bodies on supports the poses and
    /// rates (`u_p_x` … `om_g_y`) and the support forces (`R_p_x` … `R_g_my`).
    pub fn columns(&self) -> Vec<(&'static str, &[f64])> {
        let states: [&[f64]; N_STATES] = [
            &self.phi_1_rad,
            &self.phi_p_rad,
            &self.phi_g_rad,
            &self.phi_2_rad,
            &self.w_1_rad_s,
            &self.w_p_rad_s,
            &self.w_g_rad_s,
            &self.w_2_rad_s,
        ];
        let mut c: Vec<(&'static str, &[f64])> = vec![("time_s", &self.time_s)];
        c.extend(STATE_NAMES.iter().copied().zip(states));
        c.extend(real_fields().map(|f| (f.column, self.mesh_column(f.column))));
        let body_names =
            crate::mesh::pose::INPUT_NAMES.iter().chain(&crate::dynamics::bodies::REACTION_NAMES);
        for name in body_names {
            if let Some(v) = self.bodies.get(*name) {
                c.push((name, v.as_slice()));
            }
        }
        c
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        for (name, v) in self.columns() {
            finite_all(name, v)?;
        }
        Ok(())
    }
}

/// Name of a preset FE mesh density (`coarse`, `default`, `conforming`, `refined`), or
/// `custom`.
pub fn density_name(d: &GearMeshDensity) -> &'static str {
    [
        ("coarse", GearMeshDensity::coarse()),
        ("default", GearMeshDensity::default()),
        ("conforming", GearMeshDensity::conforming()),
        ("refined", GearMeshDensity::refined()),
    ]
    .into_iter()
    .find(|(_, v)| v == d)
    .map_or("custom", |(n, _)| n)
}

/// The FE compliance data of a pair and the tooth-pair stiffness at the pitch point
/// (`helical-gear compliance --json`, `helical_gear.Compliance.summary_json`). Suffix `_p`:
/// pinion, `_g`: gear. Times are wall-clock times of the run that computed the data (stored
/// with them), s; e_rel is the relative deviation of the fitted influence function (Eq. 9).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComplianceRecord {
    /// Where the data came from: `computed`, `embedded` or `disk`.
    pub source: String,
    /// Format version of the compliance data.
    pub format_version: u32,
    /// Version of the crate that computed the data.
    pub crate_version: String,
    /// Command that regenerates the data.
    pub command: String,
    /// FE mesh density: `coarse`, `default`, `refined` or `custom`.
    pub density: String,
    /// Depth h below the flank at which the influence is observed, m.
    pub depth_h_m: f64,
    /// Rows (profile positions) of the influence grid.
    pub grid_rows: usize,
    /// Columns (axial positions) of the influence grid.
    pub grid_columns: usize,
    /// Observed teeth relative to the loaded one (−1, 0, +1).
    pub grid_teeth: Vec<i32>,
    /// FE degrees of freedom of the pinion.
    pub fe_dofs_p: usize,
    /// FE degrees of freedom of the gear.
    pub fe_dofs_g: usize,
    /// FE wall time of both gears, s.
    pub fe_seconds: f64,
    /// Mesh generation of the pinion, s.
    pub fe_mesh_s_p: f64,
    /// Mesh generation of the gear, s.
    pub fe_mesh_s_g: f64,
    /// Assembly of the pinion, s.
    pub fe_assembly_s_p: f64,
    /// Assembly of the gear, s.
    pub fe_assembly_s_g: f64,
    /// Cholesky factorisation of the pinion, s.
    pub fe_factorisation_s_p: f64,
    /// Cholesky factorisation of the gear, s.
    pub fe_factorisation_s_g: f64,
    /// Load-case solves of the pinion, s.
    pub fe_solve_s_p: f64,
    /// Load-case solves of the gear, s.
    pub fe_solve_s_g: f64,
    /// Observation at depth h of the pinion, s.
    pub fe_observe_s_p: f64,
    /// Observation at depth h of the gear, s.
    pub fe_observe_s_g: f64,
    /// Unit load cases solved for the pinion.
    pub fe_load_cases_p: usize,
    /// Unit load cases solved for the gear.
    pub fe_load_cases_g: usize,
    /// Standard deviation of e_rel over the fitted pairs of the pinion (dimensionless).
    pub e_rel_std_p: f64,
    /// Standard deviation of e_rel over the fitted pairs of the gear (dimensionless).
    pub e_rel_std_g: f64,
    /// e_rel against the pinion's node grid over the fitted domain (dimensionless).
    pub e_rel_std_nodes_domain_p: f64,
    /// e_rel against the gear's node grid over the fitted domain (dimensionless).
    pub e_rel_std_nodes_domain_g: f64,
    /// e_rel against the pinion's node grid over all pairs of the fitted rows.
    pub e_rel_std_nodes_rows_p: f64,
    /// e_rel against the gear's node grid over all pairs of the fitted rows.
    pub e_rel_std_nodes_rows_g: f64,
    /// e_rel against the pinion's node grid over all same-tooth pairs.
    pub e_rel_std_nodes_all_p: f64,
    /// e_rel against the gear's node grid over all same-tooth pairs.
    pub e_rel_std_nodes_all_g: f64,
    /// Wall time of the pinion's fit, s.
    pub fit_seconds_p: f64,
    /// Wall time of the gear's fit, s.
    pub fit_seconds_g: f64,
    /// Wall time of both fits, s (`fit_seconds_p + fit_seconds_g`).
    pub fit_seconds: f64,
    /// Rows of the pinion with τ above this were not fitted, rad.
    pub fit_max_tau_p_rad: f64,
    /// Rows of the gear with τ above this were not fitted, rad.
    pub fit_max_tau_g_rad: f64,
    /// Reference compliance of the pinion (α* = α_ref·α), m/N.
    pub alpha_ref_p_m_per_n: f64,
    /// Reference compliance of the gear, m/N.
    pub alpha_ref_g_m_per_n: f64,
    /// Tooth-pair stiffness c′ at the pitch point, N/(mm·µm).
    pub pair_stiffness_n_per_mm_per_um: f64,
    /// Line load of the stiffness load case, N/m.
    pub pair_load_n_per_m: f64,
    /// Torque of the stiffness load case on one tooth pair, N·m.
    pub pair_torque_nm: f64,
    /// Transverse deflection along the line of action, µm.
    pub pair_deflection_t_um: f64,
    /// Global (bending, body) normal approach of the pinion, µm.
    pub pair_u_global_p_um: f64,
    /// Global normal approach of the gear, µm.
    pub pair_u_global_g_um: f64,
    /// Local (Hertzian) normal approach, µm.
    pub pair_u_local_um: f64,
    /// Share of the pinion's global approach in the total (dimensionless).
    pub pair_share_global_p: f64,
    /// Share of the gear's global approach in the total (dimensionless).
    pub pair_share_global_g: f64,
    /// Share of the local approach in the total (dimensionless).
    pub pair_share_local: f64,
}

impl ComplianceRecord {
    /// The record of `data` and of the tooth-pair stiffness `st` it gives.
    pub fn new(data: &ComplianceData, st: &PairStiffness) -> Self {
        let (gp, gg, prov) = (&data.pinion, &data.gear, &data.provenance);
        let shares = st.shares();
        Self {
            source: data.source().as_str().into(),
            format_version: prov.format_version,
            crate_version: prov.crate_version.clone(),
            command: prov.command.clone(),
            density: density_name(&prov.density).into(),
            depth_h_m: prov.depth_h_m,
            grid_rows: gp.grid.profile.len(),
            grid_columns: gp.grid.zeta.len(),
            grid_teeth: gp.grid.teeth.clone(),
            fe_dofs_p: gp.fe.dofs,
            fe_dofs_g: gg.fe.dofs,
            fe_seconds: data.fe_seconds(),
            fe_mesh_s_p: gp.fe.mesh_s,
            fe_mesh_s_g: gg.fe.mesh_s,
            fe_assembly_s_p: gp.fe.assembly_s,
            fe_assembly_s_g: gg.fe.assembly_s,
            fe_factorisation_s_p: gp.fe.factorisation_s,
            fe_factorisation_s_g: gg.fe.factorisation_s,
            fe_solve_s_p: gp.fe.solve_s,
            fe_solve_s_g: gg.fe.solve_s,
            fe_observe_s_p: gp.fe.observe_s,
            fe_observe_s_g: gg.fe.observe_s,
            fe_load_cases_p: gp.fe.load_cases,
            fe_load_cases_g: gg.fe.load_cases,
            e_rel_std_p: gp.fit.report.sigma_e_rel,
            e_rel_std_g: gg.fit.report.sigma_e_rel,
            e_rel_std_nodes_domain_p: gp.fit.nodes_domain.std,
            e_rel_std_nodes_domain_g: gg.fit.nodes_domain.std,
            e_rel_std_nodes_rows_p: gp.fit.nodes_rows.std,
            e_rel_std_nodes_rows_g: gg.fit.nodes_rows.std,
            e_rel_std_nodes_all_p: gp.fit.nodes_all.std,
            e_rel_std_nodes_all_g: gg.fit.nodes_all.std,
            fit_seconds_p: gp.fit.fit_s,
            fit_seconds_g: gg.fit.fit_s,
            fit_seconds: gp.fit.fit_s + gg.fit.fit_s,
            fit_max_tau_p_rad: gp.fit.max_tau_rad,
            fit_max_tau_g_rad: gg.fit.max_tau_rad,
            alpha_ref_p_m_per_n: gp.fit.alpha_ref_m_per_n,
            alpha_ref_g_m_per_n: gg.fit.alpha_ref_m_per_n,
            pair_stiffness_n_per_mm_per_um: st.c_prime_n_per_mm_per_um,
            pair_load_n_per_m: st.load_n_per_m,
            pair_torque_nm: st.torque_nm,
            pair_deflection_t_um: st.delta_t_m * UM,
            pair_u_global_p_um: st.u_global_p_m * UM,
            pair_u_global_g_um: st.u_global_g_m * UM,
            pair_u_local_um: st.u_local_m * UM,
            pair_share_global_p: shares[0],
            pair_share_global_g: shares[1],
            pair_share_local: shares[2],
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        for (name, v) in [
            ("depth_h_m", self.depth_h_m),
            ("fe_seconds", self.fe_seconds),
            ("fe_mesh_s_p", self.fe_mesh_s_p),
            ("fe_mesh_s_g", self.fe_mesh_s_g),
            ("fe_assembly_s_p", self.fe_assembly_s_p),
            ("fe_assembly_s_g", self.fe_assembly_s_g),
            ("fe_factorisation_s_p", self.fe_factorisation_s_p),
            ("fe_factorisation_s_g", self.fe_factorisation_s_g),
            ("fe_solve_s_p", self.fe_solve_s_p),
            ("fe_solve_s_g", self.fe_solve_s_g),
            ("fe_observe_s_p", self.fe_observe_s_p),
            ("fe_observe_s_g", self.fe_observe_s_g),
            ("e_rel_std_p", self.e_rel_std_p),
            ("e_rel_std_g", self.e_rel_std_g),
            ("e_rel_std_nodes_domain_p", self.e_rel_std_nodes_domain_p),
            ("e_rel_std_nodes_domain_g", self.e_rel_std_nodes_domain_g),
            ("e_rel_std_nodes_rows_p", self.e_rel_std_nodes_rows_p),
            ("e_rel_std_nodes_rows_g", self.e_rel_std_nodes_rows_g),
            ("e_rel_std_nodes_all_p", self.e_rel_std_nodes_all_p),
            ("e_rel_std_nodes_all_g", self.e_rel_std_nodes_all_g),
            ("fit_seconds_p", self.fit_seconds_p),
            ("fit_seconds_g", self.fit_seconds_g),
            ("fit_seconds", self.fit_seconds),
            ("fit_max_tau_p_rad", self.fit_max_tau_p_rad),
            ("fit_max_tau_g_rad", self.fit_max_tau_g_rad),
            ("alpha_ref_p_m_per_n", self.alpha_ref_p_m_per_n),
            ("alpha_ref_g_m_per_n", self.alpha_ref_g_m_per_n),
            ("pair_stiffness_n_per_mm_per_um", self.pair_stiffness_n_per_mm_per_um),
            ("pair_load_n_per_m", self.pair_load_n_per_m),
            ("pair_torque_nm", self.pair_torque_nm),
            ("pair_deflection_t_um", self.pair_deflection_t_um),
            ("pair_u_global_p_um", self.pair_u_global_p_um),
            ("pair_u_global_g_um", self.pair_u_global_g_um),
            ("pair_u_local_um", self.pair_u_local_um),
            ("pair_share_global_p", self.pair_share_global_p),
            ("pair_share_global_g", self.pair_share_global_g),
            ("pair_share_local", self.pair_share_local),
        ] {
            finite(name, v)?;
        }
        Ok(())
    }
}

/// One slice of the instant line of contact (a [`ContactPoint`] as printed): the contact (or
/// gap) between a pinion and a gear flank in one transverse slice.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactSliceRecord {
    /// Axial coordinate ζ = z/m_n of the slice (dimensionless).
    pub zeta: f64,
    /// Tooth-pair number (the absolute index of the pinion tooth).
    pub pair: i64,
    /// Which flanks: `drive` or `back`.
    pub side: String,
    /// Surfaces in contact, `"<pinion surface>/<gear surface>"` (e.g. `involute/rounding`).
    pub kind: String,
    /// Signed overlap along the common normal, m (> 0: the teeth must deform).
    pub overlap_m: f64,
    /// Radius of curvature of the pinion flank (transverse), m.
    pub rho_p_m: f64,
    /// Radius of curvature of the gear flank (transverse), m.
    pub rho_g_m: f64,
    /// Moment arm of the normal force about the pinion axis, m (> 0 in normal drive).
    pub arm_p_m: f64,
    /// Moment arm of the normal force about the gear axis, m (> 0 in normal drive).
    pub arm_g_m: f64,
    /// Distance of the pinion's contact point from its axis, m.
    pub radius_p_m: f64,
    /// Distance of the gear's contact point from its axis, m.
    pub radius_g_m: f64,
    /// η* of the pinion's point, in units of m_n.
    pub eta_star_p: f64,
    /// τ of the pinion's point, rad.
    pub tau_p_rad: f64,
    /// η* of the gear's point, in units of m_n.
    pub eta_star_g: f64,
    /// τ of the gear's point, rad.
    pub tau_g_rad: f64,
    /// Angle of the pinion's outward normal in the fixed frame, rad.
    pub normal_angle_rad: f64,
}

/// The instant line of contact at a pinion angle and transmission error
/// (`helical-gear contact --json`): one record per slice and tooth pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactRecord {
    /// Pinion hub angle φp, rad.
    pub phi_p_rad: f64,
    /// Gear hub angle φg, rad (the one that gives the transmission error).
    pub phi_g_rad: f64,
    /// Transmission error TE = φp·g_p + φg·g_g (Eq. 16), m.
    pub te_m: f64,
    /// The contacts, slice by slice.
    pub slices: Vec<ContactSliceRecord>,
}

impl ContactRecord {
    /// The record of the contacts `cs` at (`phi_p`, `phi_g`) (rad) and transmission error
    /// `te` (m).
    pub fn new(phi_p: f64, phi_g: f64, te: f64, cs: &[ContactPoint]) -> Self {
        let slices = cs
            .iter()
            .map(|c| ContactSliceRecord {
                zeta: c.zeta,
                pair: c.pair,
                side: match c.side {
                    FlankSide::Drive => "drive".into(),
                    FlankSide::Back => "back".into(),
                },
                kind: c.kind_name(),
                overlap_m: c.overlap_m,
                rho_p_m: c.rho_p_m,
                rho_g_m: c.rho_g_m,
                arm_p_m: c.arm_p_m,
                arm_g_m: c.arm_g_m,
                radius_p_m: c.radius_p_m,
                radius_g_m: c.radius_g_m,
                eta_star_p: c.eta_star_p,
                tau_p_rad: c.tau_p,
                eta_star_g: c.eta_star_g,
                tau_g_rad: c.tau_g,
                normal_angle_rad: c.normal_angle,
            })
            .collect();
        Self { phi_p_rad: phi_p, phi_g_rad: phi_g, te_m: te, slices }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite("phi_p_rad", self.phi_p_rad)?;
        finite("phi_g_rad", self.phi_g_rad)?;
        finite("te_m", self.te_m)?;
        for (i, s) in self.slices.iter().enumerate() {
            for (name, v) in [
                ("zeta", s.zeta),
                ("overlap_m", s.overlap_m),
                ("rho_p_m", s.rho_p_m),
                ("rho_g_m", s.rho_g_m),
                ("arm_p_m", s.arm_p_m),
                ("arm_g_m", s.arm_g_m),
                ("radius_p_m", s.radius_p_m),
                ("radius_g_m", s.radius_g_m),
                ("eta_star_p", s.eta_star_p),
                ("tau_p_rad", s.tau_p_rad),
                ("eta_star_g", s.eta_star_g),
                ("tau_g_rad", s.tau_g_rad),
                ("normal_angle_rad", s.normal_angle_rad),
            ] {
                finite(&format!("slices[{i}].{name}"), v)?;
            }
        }
        Ok(())
    }
}

/// One flank-modification variant of a Harris map: its static STE peak to peak at each torque.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HarrisVariantRecord {
    /// Name of the variant (from the variants file).
    pub name: String,
    /// Peak-to-peak static TE at each torque of [`HarrisRecord::torques_nm`], µm.
    pub ste_peak_to_peak_um: Vec<f64>,
}

/// A Harris map (`helical-gear harris --json`): the static STE peak to peak over the torque
/// for each flank-modification variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HarrisRecord {
    /// Driving torques on the pinion, N·m.
    pub torques_nm: Vec<f64>,
    /// The variants, in the order of the variants file.
    pub variants: Vec<HarrisVariantRecord>,
}

impl HarrisRecord {
    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite_all("torques_nm", &self.torques_nm)?;
        for v in &self.variants {
            finite_all(&format!("{}.ste_peak_to_peak_um", v.name), &v.ste_peak_to_peak_um)?;
        }
        Ok(())
    }
}

/// The static TE over a whole hunting period and its amplitude spectrum in orders of the
/// pinion rotation (`helical-gear spectrum --json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpectrumRecord {
    /// Driving torque on the pinion, N·m.
    pub torque_nm: f64,
    /// Meshes in the hunting period (the length of the analysed record).
    pub hunting_meshes: usize,
    /// Pinion revolutions in the hunting period.
    pub pinion_revolutions: f64,
    /// Mean static TE, µm.
    pub ste_mean_um: f64,
    /// Peak-to-peak static TE, µm.
    pub ste_peak_to_peak_um: f64,
    /// Orders of the pinion rotation of the lines (dimensionless, from 0).
    pub orders: Vec<f64>,
    /// Amplitude of each line, µm.
    pub amplitudes_um: Vec<f64>,
    /// Wall time of the run, s.
    pub seconds: f64,
}

impl SpectrumRecord {
    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite("torque_nm", self.torque_nm)?;
        finite("pinion_revolutions", self.pinion_revolutions)?;
        finite("ste_mean_um", self.ste_mean_um)?;
        finite("ste_peak_to_peak_um", self.ste_peak_to_peak_um)?;
        finite_all("orders", &self.orders)?;
        finite_all("amplitudes_um", &self.amplitudes_um)?;
        finite("seconds", self.seconds)
    }
}

/// The steady dynamic run behind a dynamic spectrum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SteadyRunRecord {
    /// Pinion speed, rad/s.
    pub speed_rad_s: f64,
    /// True if the response reached the steady state.
    pub steady: bool,
    /// Mesh periods integrated (fractional for DOPRI5).
    pub mesh_periods_integrated: f64,
    /// Largest dynamic TE over the analysed window, µm.
    pub te_max_um: f64,
    /// Smallest dynamic TE over the analysed window, µm (< 0 with separation possible).
    pub te_min_um: f64,
    /// True if the teeth separated in the window.
    pub separated: bool,
}

impl SteadyRunRecord {
    /// The record of the steady response `r` at pinion speed `speed` (rad/s).
    pub fn new(speed: f64, r: &SteadyResponse) -> Self {
        Self {
            speed_rad_s: speed,
            steady: r.steady,
            mesh_periods_integrated: r.periods,
            te_max_um: r.te_max * UM,
            te_min_um: r.te_min * UM,
            separated: r.separated,
        }
    }
}

/// The dynamic TE over one period of the steady response and its amplitude spectrum in orders
/// of the pinion rotation (`helical-gear spectrum --dynamic --json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DynamicSpectrumRecord {
    /// The steady run.
    pub dynamic: SteadyRunRecord,
    /// Meshes in the analysed period.
    pub period_meshes: usize,
    /// Pinion revolutions in the analysed period.
    pub pinion_revolutions: f64,
    /// Mean dynamic TE, µm.
    pub te_mean_um: f64,
    /// Peak-to-peak dynamic TE, µm.
    pub te_peak_to_peak_um: f64,
    /// Orders of the pinion rotation of the lines (dimensionless, from 0).
    pub orders: Vec<f64>,
    /// Amplitude of each line, µm.
    pub amplitudes_um: Vec<f64>,
    /// Wall time of the run, s.
    pub seconds: f64,
}

impl DynamicSpectrumRecord {
    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        let d = &self.dynamic;
        finite("dynamic.speed_rad_s", d.speed_rad_s)?;
        finite("dynamic.mesh_periods_integrated", d.mesh_periods_integrated)?;
        finite("dynamic.te_max_um", d.te_max_um)?;
        finite("dynamic.te_min_um", d.te_min_um)?;
        finite("pinion_revolutions", self.pinion_revolutions)?;
        finite("te_mean_um", self.te_mean_um)?;
        finite("te_peak_to_peak_um", self.te_peak_to_peak_um)?;
        finite_all("orders", &self.orders)?;
        finite_all("amplitudes_um", &self.amplitudes_um)?;
        finite("seconds", self.seconds)
    }
}

/// One point of `helical-gear static --json`'s `points`: the static state at one pinion angle
/// with its face load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticPointRecord {
    /// Pinion angle φp, rad.
    pub phi_p_rad: f64,
    /// Static transmission error, µm (> 0 in normal drive).
    pub ste_um: f64,
    /// Tooth pairs in contact.
    pub n_pairs: u32,
    /// Largest contact pressure, Pa.
    pub p_max_pa: f64,
    /// Loaded contact on a tip rounding or edge.
    pub tip_contact: bool,
    /// Total loaded contact length, m.
    pub contact_length_m: f64,
    /// Face load factor K_Hβ (largest over mean line load, dimensionless).
    pub k_h_beta: f64,
    /// Largest line load across the face, N/mm.
    pub line_load_max_n_per_mm: f64,
    /// Mean line load across the face, N/mm.
    pub line_load_mean_n_per_mm: f64,
    /// Force of the mesh on the pinion (x, y, z), N (housing frame of `mesh::forces`).
    pub force_p_n: [f64; 3],
    /// Tilting moment on the pinion about its centre at mid-face (x, y), N·m.
    pub moment_p_nm: [f64; 2],
    /// Force of the mesh on the gear (x, y, z), N.
    pub force_g_n: [f64; 3],
    /// Tilting moment on the gear about its centre at mid-face (x, y), N·m.
    pub moment_g_nm: [f64; 2],
    /// Tooth-root stress of the pinion, Pa.
    pub root_stress_p_pa: f64,
    /// Tooth-root stress of the gear, Pa.
    pub root_stress_g_pa: f64,
    /// Mesh friction power loss P_loss at the run's pinion speed, W (0 without friction and
    /// at standstill; [`crate::mesh::MeshOutputs::p_loss`]).
    pub p_loss_w: f64,
    /// Instantaneous mesh efficiency 1 − P_loss/P_in, dimensionless (1 without friction).
    pub eta_mesh: f64,
    /// Friction torque on the pinion M_R,p, N·m (part of the elastic-plus-friction torque
    /// M_F,p, which equals the run's torque).
    pub m_r_p_nm: f64,
    /// Friction torque on the gear M_R,g, N·m.
    pub m_r_g_nm: f64,
    /// Friction heat into the pinion's flanks Q_p, W.
    pub q_p_w: f64,
    /// Friction heat into the gear's flanks Q_g, W.
    pub q_g_w: f64,
    /// With supports (`static --supports`): the pinion body's pose at the equilibrium
    /// (u_x, u_y, u_z in m, θ_x, θ_y in rad; [`crate::mesh::pose`]); absent without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_p: Option<[f64; 5]>,
    /// With supports: the gear body's pose at the equilibrium.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_g: Option<[f64; 5]>,
}

/// The mesh friction summary of a static run at a running speed (`helical-gear static
/// --json`, Python's `static_curve`): the loss and efficiency averaged over the points, the
/// ISO/TR 14179-2 loss factor of the geometry and the coefficient of friction used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticFrictionSummary {
    /// Pinion speed of the quasi-static states ω_p, rad/s (the gear at the rigid ratio).
    pub omega_p_rad_s: f64,
    /// Mean friction power loss P_loss over the points, W (0 without friction).
    pub mesh_loss_mean_w: f64,
    /// Mean mesh efficiency 1 − `mesh_loss_mean_w`/(M·|ω_p|) with M the run's torque,
    /// dimensionless; 1 at standstill.
    pub mesh_efficiency_mean: f64,
    /// Gear loss factor H_V of ISO/TR 14179-2 from the geometry (dimensionless; always given,
    /// with or without friction): the mean loss of that method is μ·H_V·P_in.
    pub loss_factor_h_v: f64,
    /// Coefficient of friction μ, dimensionless: the option's μ for `constant`, the mean over
    /// the points of μ_mz at each point's elastic torque and ω_p for `iso_tr_14179_2`, null
    /// without friction.
    pub mu_mean: Option<f64>,
}

impl StaticFrictionSummary {
    /// The summary of `curve` (equilibria at pinion speed `omega_p`, rad/s) on the pair of
    /// geometry `geo` with the friction option `friction`.
    pub fn new(
        curve: &StaticCurve,
        geo: &PairGeometry,
        friction: crate::mesh::Friction,
        omega_p: f64,
    ) -> Self {
        use crate::mesh::FrictionModel;
        use crate::mesh::friction::{FrictionConst, loss_factor_h_v};
        let pts = &curve.points;
        let loss = mean(pts.iter().map(|e| e.outputs.p_loss));
        let p_in = (curve.torque * omega_p).abs();
        let fc = FrictionConst::new(geo, friction);
        let mu_mean = match friction.model {
            FrictionModel::None => None,
            FrictionModel::Constant => Some(friction.mu),
            FrictionModel::IsoTr14179_2 => {
                Some(mean(pts.iter().map(|e| fc.mu(e.outputs.m_f_p - e.outputs.m_r_p, omega_p))))
            }
        };
        Self {
            omega_p_rad_s: omega_p,
            mesh_loss_mean_w: loss,
            mesh_efficiency_mean: if p_in > 0.0 { 1.0 - loss / p_in } else { 1.0 },
            loss_factor_h_v: loss_factor_h_v(geo),
            mu_mean,
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite("omega_p_rad_s", self.omega_p_rad_s)?;
        finite("mesh_loss_mean_w", self.mesh_loss_mean_w)?;
        finite("mesh_efficiency_mean", self.mesh_efficiency_mean)?;
        finite("loss_factor_h_v", self.loss_factor_h_v)?;
        finite_opt("mu_mean", self.mu_mean)
    }
}

/// `helical-gear static --json`: the static curve ([`StaticCurveRecord`], its keys at the top
/// level), the face load summary against ISO 6336-1 and the per-point table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticRunRecord {
    /// The static curve and its summary.
    #[serde(flatten)]
    pub curve: StaticCurveRecord,
    /// Axial slices per contact line of the model.
    pub slices: usize,
    /// Largest K_Hβ over the points (dimensionless).
    pub k_h_beta_max: f64,
    /// K_Hβ of the line load averaged over the points (dimensionless).
    pub k_h_beta_cycle: f64,
    /// K_Hβ of ISO 6336-1 method C (dimensionless).
    pub k_h_beta_iso: f64,
    /// Effective misalignment F_βy of the ISO method, µm.
    pub f_beta_y_um: f64,
    /// Mesh stiffness per unit face width of the aligned pair, N/(mm·µm).
    pub c_gamma_n_per_mm_per_um: f64,
    /// Wall time of the model build, s.
    pub model_build_s: f64,
    /// Wall time of the run, s.
    pub seconds: f64,
    /// ISO 6336-3 method B at the run's torque ([`IsoRootStressSummary`], its keys at the top
    /// level).
    #[serde(flatten)]
    pub iso: IsoRootStressSummary,
    /// The mesh friction at the run's speed ([`StaticFrictionSummary`], its keys at the top
    /// level).
    #[serde(flatten)]
    pub friction: StaticFrictionSummary,
    /// The points with their face load.
    pub points: Vec<StaticPointRecord>,
    /// The bearing loads over the points (with `--bearings`; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bearings: Option<Vec<BearingLoadRecord>>,
}

/// The load of one bearing over a static curve (`helical-gear static --bearings`): the
/// reaction of the bearing on its shaft (x, y, z, N; z only at the locating bearing) in the
/// housing frame of `mesh::forces`, from `mesh::bearings`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BearingLoadRecord {
    /// `pinion` or `gear`.
    pub shaft: String,
    /// `locating` or `floating`.
    pub bearing: String,
    /// Axial position of the bearing, m.
    pub z_m: f64,
    /// Mean reaction over the points, N.
    pub reaction_mean_n: [f64; 3],
    /// Peak-to-peak (max − min) of each component over the points, N.
    pub reaction_peak_to_peak_n: [f64; 3],
    /// Single-sided amplitude of each component at the mesh orders 1, 2, … (one entry per
    /// order up to the points' Nyquist limit, at most 10), N.
    pub reaction_order_amplitudes_n: Vec<[f64; 3]>,
}

impl BearingLoadRecord {
    /// The records of the four bearings of `arrangement` over the mesh outputs `outs` (uniform
    /// pinion angles over `pitches` whole pinion pitches), face width `face_width_m` (m).
    pub fn over_cycle(
        arrangement: &crate::mesh::bearings::BearingArrangement,
        face_width_m: f64,
        outs: &[crate::mesh::MeshOutputs],
        pitches: usize,
    ) -> Vec<Self> {
        use crate::mesh::bearings::order_amplitudes;
        let reactions: Vec<[[f64; 3]; 4]> =
            outs.iter().map(|o| arrangement.reactions(face_width_m, o)).collect();
        arrangement
            .labels()
            .iter()
            .enumerate()
            .map(|(b, &(shaft, bearing, z))| {
                let comp = |k: usize| reactions.iter().map(move |r| r[b][k]);
                let amps: [Vec<f64>; 3] = std::array::from_fn(|k| {
                    order_amplitudes(&comp(k).collect::<Vec<_>>(), pitches.max(1), 10)
                });
                Self {
                    shaft: shaft.into(),
                    bearing: bearing.into(),
                    z_m: z,
                    reaction_mean_n: std::array::from_fn(|k| mean(comp(k))),
                    reaction_peak_to_peak_n: std::array::from_fn(|k| peak_to_peak(comp(k))),
                    reaction_order_amplitudes_n: (0..amps[0].len())
                        .map(|j| [amps[0][j], amps[1][j], amps[2][j]])
                        .collect(),
                }
            })
            .collect()
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite("z_m", self.z_m)?;
        finite_all("reaction_mean_n", &self.reaction_mean_n)?;
        finite_all("reaction_peak_to_peak_n", &self.reaction_peak_to_peak_n)?;
        let a: Vec<f64> = self.reaction_order_amplitudes_n.iter().flatten().copied().collect();
        finite_all("reaction_order_amplitudes_n", &a)
    }
}

impl StaticRunRecord {
    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        self.curve.check_finite()?;
        for (name, v) in [
            ("k_h_beta_max", self.k_h_beta_max),
            ("k_h_beta_cycle", self.k_h_beta_cycle),
            ("k_h_beta_iso", self.k_h_beta_iso),
            ("f_beta_y_um", self.f_beta_y_um),
            ("c_gamma_n_per_mm_per_um", self.c_gamma_n_per_mm_per_um),
            ("model_build_s", self.model_build_s),
            ("seconds", self.seconds),
        ] {
            finite(name, v)?;
        }
        self.iso.check_finite()?;
        self.friction.check_finite()?;
        for (i, p) in self.points.iter().enumerate() {
            for (name, v) in [
                ("phi_p_rad", p.phi_p_rad),
                ("ste_um", p.ste_um),
                ("p_max_pa", p.p_max_pa),
                ("contact_length_m", p.contact_length_m),
                ("k_h_beta", p.k_h_beta),
                ("line_load_max_n_per_mm", p.line_load_max_n_per_mm),
                ("line_load_mean_n_per_mm", p.line_load_mean_n_per_mm),
                ("root_stress_p_pa", p.root_stress_p_pa),
                ("root_stress_g_pa", p.root_stress_g_pa),
                ("p_loss_w", p.p_loss_w),
                ("eta_mesh", p.eta_mesh),
                ("m_r_p_nm", p.m_r_p_nm),
                ("m_r_g_nm", p.m_r_g_nm),
                ("q_p_w", p.q_p_w),
                ("q_g_w", p.q_g_w),
            ] {
                finite(&format!("points[{i}].{name}"), v)?;
            }
            let f = p.force_p_n.iter().chain(&p.moment_p_nm).chain(&p.force_g_n);
            for (k, v) in f.chain(&p.moment_g_nm).enumerate() {
                finite(&format!("points[{i}].force_moment[{k}]"), *v)?;
            }
        }
        for b in self.bearings.iter().flatten() {
            b.check_finite().map_err(|e| format!("bearings ({} {}): {e}", b.shaft, b.bearing))?;
        }
        Ok(())
    }
}

/// The nominal tooth-root stress of ISO 6336-3:2006 method B ([`crate::iso6336`]) beside a
/// static run (`helical-gear static --json`, Python's `static_curve`): σ_F0 of both gears at
/// the run's pinion torque and the factors behind it. When the method cannot rate the pair
/// (ε_αn < 1, a rim thinner than half a tooth depth, …) the three are `null` and
/// `iso6336_error` says why; the run itself is not refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IsoRootStressSummary {
    /// Nominal tooth-root stress σ_F0 of the pinion, Pa (≥ 0).
    pub root_stress_iso_p_pa: Option<f64>,
    /// Nominal tooth-root stress σ_F0 of the gear, Pa (≥ 0).
    pub root_stress_iso_g_pa: Option<f64>,
    /// F_t (N) and, per gear (`pinion`, `gear`), Y_F, Y_S, Y_β, Y_B, Y_DT, s_Fn (m), h_Fe (m),
    /// ρ_F (m), α_Fen (rad), z_n and σ_F0 (Pa): [`IsoRootStress`].
    pub iso6336: Option<IsoRootStress>,
    /// Why the method does not apply (the library's message), `null` when it does.
    pub iso6336_error: Option<String>,
}

impl IsoRootStressSummary {
    /// The rating of `geometry`'s pair at the pinion torque `torque_nm` (N·m; |T| is used).
    pub fn new(geometry: &PairGeometry, torque_nm: f64) -> Self {
        match nominal_root_stress(&geometry.params, geometry, torque_nm) {
            Ok(r) => Self {
                root_stress_iso_p_pa: Some(r.pinion.sigma_f0_pa),
                root_stress_iso_g_pa: Some(r.gear.sigma_f0_pa),
                iso6336: Some(r),
                iso6336_error: None,
            },
            Err(e) => Self {
                root_stress_iso_p_pa: None,
                root_stress_iso_g_pa: None,
                iso6336: None,
                iso6336_error: Some(e.to_string()),
            },
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite_opt("root_stress_iso_p_pa", self.root_stress_iso_p_pa)?;
        finite_opt("root_stress_iso_g_pa", self.root_stress_iso_g_pa)?;
        let Some(r) = &self.iso6336 else { return Ok(()) };
        finite("iso6336.tangential_force_n", r.tangential_force_n)?;
        for (gear, g) in [("pinion", &r.pinion), ("gear", &r.gear)] {
            for (name, v) in [
                ("y_f", g.y_f),
                ("y_s", g.y_s),
                ("y_beta", g.y_beta),
                ("y_b", g.y_b),
                ("y_dt", g.y_dt),
                ("s_fn_m", g.s_fn_m),
                ("h_fe_m", g.h_fe_m),
                ("rho_f_m", g.rho_f_m),
                ("alpha_fen_rad", g.alpha_fen_rad),
                ("z_n", g.z_n),
                ("sigma_f0_pa", g.sigma_f0_pa),
            ] {
                finite(&format!("iso6336.{gear}.{name}"), v)?;
            }
        }
        Ok(())
    }
}

/// `helical-gear dynamics --json`: the trajectory ([`TrajectoryRecord`], its keys at the top
/// level) and the run's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryRunRecord {
    /// The trajectory.
    #[serde(flatten)]
    pub trajectory: TrajectoryRecord,
    /// Nominal pinion speed, rad/s.
    pub omega_p_rad_s: f64,
    /// End time of the run, s.
    pub t_end_s: f64,
    /// Integrator: `rk4` or `dopri5`.
    pub method: String,
    /// Step (RK4) or output interval (DOPRI5), s; `None` (null): DOPRI5's accepted steps.
    pub dt_s: Option<f64>,
    /// Mesh fidelity: `full` or `table`.
    pub fidelity: String,
    /// Mesh period at the nominal speed, s; `None` (null) at standstill (infinite).
    pub mesh_period_s: Option<f64>,
    /// Static TE of the start, m.
    pub te_static_start_m: f64,
    /// Names of the trajectory's columns, in the order of the CSV output.
    pub columns: Vec<String>,
    /// With `--supports`: the coupled modes and the support-force statistics.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supports: Option<SupportedRunRecord>,
}

impl TrajectoryRunRecord {
    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        self.trajectory.check_finite()?;
        finite("omega_p_rad_s", self.omega_p_rad_s)?;
        finite("t_end_s", self.t_end_s)?;
        finite_opt("dt_s", self.dt_s)?;
        finite_opt("mesh_period_s", self.mesh_period_s)?;
        if let Some(s) = &self.supports {
            s.check_finite()?;
        }
        finite("te_static_start_m", self.te_static_start_m)
    }
}

/// `helical-gear sweep --json`: the sweep ([`SweepRecord`], its keys at the top level) and the
/// run's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRunRecord {
    /// The sweep.
    #[serde(flatten)]
    pub sweep: SweepRecord,
    /// Mesh damping coefficient d_mesh of Eq. 14, N·s/m.
    pub d_mesh_n_s_per_m: f64,
    /// Mesh fidelity: `full` or `table`.
    pub fidelity: String,
    /// RK4 steps per mesh period.
    pub steps_per_period: usize,
    /// With `--supports`: the same speeds with both gear bodies on their supports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supports: Option<SupportedSweepRecord>,
}

impl SweepRunRecord {
    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        self.sweep.check_finite()?;
        if let Some(s) = &self.supports {
            s.check_finite()?;
        }
        finite("d_mesh_n_s_per_m", self.d_mesh_n_s_per_m)
    }
}

/// Per-speed statistics of one support force over the steady window of a supported sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SupportForceSweepRecord {
    /// Mean per speed, N (N·m for a moment).
    pub reaction_mean_n: Vec<f64>,
    /// Peak to peak per speed, N (N·m).
    pub reaction_peak_to_peak_n: Vec<f64>,
    /// Amplitude of the first mesh order per speed, N (N·m).
    pub order_1_n: Vec<f64>,
}

/// `sweep --supports`: the sweep with both gear bodies on their supports
/// ([`crate::dynamics::supported_sweep`]), at the speeds of the rigid sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SupportedSweepRecord {
    /// Largest static TE of the mesh on its supports, µm.
    pub ste_max_um: f64,
    /// Steady TE_max/STE_max per speed (STE_max of the supported mesh).
    pub te_max_over_ste_max: Vec<f64>,
    /// Steady TE_min/STE_max per speed.
    pub te_min_over_ste_max: Vec<f64>,
    /// Whether each run passed the period check.
    pub steady: Vec<bool>,
    /// Mesh periods run before each window.
    pub periods: Vec<usize>,
    /// Peaks of `te_max_over_ste_max` (rad/s, grid speeds; prominence as the rigid sweep's).
    pub resonances_rad_s: Vec<f64>,
    /// Frequencies of the coupled modes linearised at rest, Hz.
    pub modes_hz: Vec<f64>,
    /// The speeds at which the first mesh order meets each mode, 2π·f/z_p, rad/s.
    pub mode_speeds_rad_s: Vec<f64>,
    /// Per support force (`R_p_x` … `R_g_my`), its statistics per speed.
    pub support_forces: BTreeMap<String, SupportForceSweepRecord>,
}

impl SupportedSweepRecord {
    /// The record of the supported sweep `sw` for a pinion of `z_p` teeth; peaks of at least
    /// `prominence` ([`crate::dynamics::find_peaks`]).
    pub fn new(
        sw: &crate::dynamics::supported_sweep::SupportedSweep,
        z_p: u32,
        prominence: f64,
    ) -> Self {
        use crate::dynamics::bodies::{ForceStats, REACTION_NAMES};
        let ratio: Vec<f64> = sw.points.iter().map(|p| p.te_max / sw.ste_max).collect();
        let speeds: Vec<f64> = sw.points.iter().map(|p| p.speed).collect();
        let modes_hz = sw.modes.frequencies_hz();
        let support_forces = REACTION_NAMES
            .iter()
            .enumerate()
            .map(|(c, name)| {
                let get = |f: &dyn Fn(&ForceStats) -> f64| {
                    sw.points.iter().map(|p| p.forces.get(c).map_or(f64::NAN, f)).collect()
                };
                let rec = SupportForceSweepRecord {
                    reaction_mean_n: get(&|s| s.mean),
                    reaction_peak_to_peak_n: get(&|s| s.peak_to_peak),
                    order_1_n: get(&|s| s.orders.first().copied().unwrap_or(0.0)),
                };
                (name.to_string(), rec)
            })
            .collect();
        let peaks = crate::dynamics::find_peaks(&ratio, prominence);
        Self {
            ste_max_um: sw.ste_max * 1e6,
            te_min_over_ste_max: sw.points.iter().map(|p| p.te_min / sw.ste_max).collect(),
            steady: sw.points.iter().map(|p| p.steady).collect(),
            periods: sw.points.iter().map(|p| p.periods).collect(),
            resonances_rad_s: peaks.iter().map(|(i, _)| speeds[*i]).collect(),
            mode_speeds_rad_s: modes_hz
                .iter()
                .map(|f| 2.0 * std::f64::consts::PI * f / z_p as f64)
                .collect(),
            modes_hz,
            te_max_over_ste_max: ratio,
            support_forces,
        }
    }

    /// `Err` naming the first non-finite number.
    pub fn check_finite(&self) -> Result<(), String> {
        finite("supports.ste_max_um", self.ste_max_um)?;
        finite_all("supports.te_max_over_ste_max", &self.te_max_over_ste_max)?;
        finite_all("supports.te_min_over_ste_max", &self.te_min_over_ste_max)?;
        finite_all("supports.modes_hz", &self.modes_hz)?;
        for (k, r) in &self.support_forces {
            finite_all(&format!("supports.{k}.reaction_mean_n"), &r.reaction_mean_n)?;
            finite_all(
                &format!("supports.{k}.reaction_peak_to_peak_n"),
                &r.reaction_peak_to_peak_n,
            )?;
            finite_all(&format!("supports.{k}.order_1_n"), &r.order_1_n)?;
        }
        Ok(())
    }
}
