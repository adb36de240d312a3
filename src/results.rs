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
//! Layering: `results` sits above `dynamics`; it reads geometry, mesh, dynamics and params
//! and nothing reads it inside the library.

use serde::{Deserialize, Serialize};

use crate::dynamics::model::{N_STATES, STATE_NAMES};
use crate::dynamics::{SweepResult, Trajectory};
use crate::geometry::PairGeometry;
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
        finite("mesh_stiffness_mean_n_per_um", self.mesh_stiffness_mean_n_per_um)
    }
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
/// [`STATE_NAMES`]), TE and the four mesh torques. Angles in rad, speeds in rad/s, torques in
/// N·m (M_F, M_D enter the pinion and gear equations with a minus sign).
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
    /// Transmission error, m (> 0 in normal drive).
    pub te_m: Vec<f64>,
    /// Elastic mesh torque on the pinion M_F,p (Eq. 13), N·m.
    pub m_f_p_nm: Vec<f64>,
    /// Elastic mesh torque on the gear M_F,g (Eq. 13), N·m.
    pub m_f_g_nm: Vec<f64>,
    /// Mesh damping torque on the pinion M_D,p (Eq. 14), N·m.
    pub m_d_p_nm: Vec<f64>,
    /// Mesh damping torque on the gear M_D,g (Eq. 14), N·m.
    pub m_d_g_nm: Vec<f64>,
    /// Integration steps taken.
    pub steps: usize,
    /// Mesh evaluations.
    pub mesh_evaluations: usize,
}

impl TrajectoryRecord {
    /// The record of `tr`.
    pub fn new(tr: &Trajectory) -> Self {
        let s = |i: usize| tr.states.iter().map(|y| y[i]).collect::<Vec<f64>>();
        let o = |f: fn(&crate::mesh::MeshOutputs) -> f64| tr.outputs.iter().map(f).collect();
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
            te_m: o(|x| x.te),
            m_f_p_nm: o(|x| x.m_f_p),
            m_f_g_nm: o(|x| x.m_f_g),
            m_d_p_nm: o(|x| x.m_d_p),
            m_d_g_nm: o(|x| x.m_d_g),
            steps: tr.steps,
            mesh_evaluations: tr.mesh_evaluations,
        }
    }

    /// The columns in output order with their names: `time_s`, the states in state order
    /// ([`STATE_NAMES`]), `te_m`, `m_f_p_nm`, `m_f_g_nm`, `m_d_p_nm`, `m_d_g_nm`.
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
        c.extend([
            ("te_m", self.te_m.as_slice()),
            ("m_f_p_nm", &self.m_f_p_nm),
            ("m_f_g_nm", &self.m_f_g_nm),
            ("m_d_p_nm", &self.m_d_p_nm),
            ("m_d_g_nm", &self.m_d_g_nm),
        ]);
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
