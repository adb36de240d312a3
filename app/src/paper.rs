//! The paper run: the static and dynamic results of Andersson & Vedmar (2003) reproduced with
//! this model on one gear pair (by default the paper's Table 1), written as CSV files, a
//! machine-readable `summary.json` and a human-readable `summary.md`.
//!
//! Stages ([`run_paper`]):
//!
//! 1. **Static**: the static transmission error STE over one pinion pitch (Fig. 6 analogue) and
//!    the static pressure waterfall over the whole engagement of tooth pair 0 (Fig. 7), full
//!    fidelity. Then the **static onset of tip contact**
//!    ([`helical_gear_mesh::mesh::tip_contact_threshold_curve`]): at 40 pinion angles over one pitch the
//!    smallest TE at which a loaded contact reaches a tip rounding or tip edge
//!    (`tip_threshold.csv`; its minimum is `tip_contact_te_threshold_um` in the summary).
//! 2. **Sweeps**: steady TE_max/STE_max over the pinion speed for d_mesh = 100 and 200 N·s/m
//!    (Fig. 9), table fidelity, with the separation flags and the resonances. The main
//!    resonance ω_crit is the highest peak; the second and third are the peaks nearest
//!    ω_crit/2 and ω_crit/3 (each within ±20 %). Beside it, the dynamic factors of the loads
//!    (`dynamic_factors.csv/.png`): per speed the peak mesh force |F_p| and the peak
//!    tooth-root stress over the steady window, each over its static peak at the same torque.
//! 3. **Fig. 10**: TE over three mesh periods of the steady state at the 2nd and 3rd resonance.
//! 4. **Dynamic waterfalls** (Figs. 11–13): at the paper's speeds 220, 330, 570 rad/s and at
//!    this model's equivalents ω_crit/3, ω_crit/2, ω_crit·570/660 and at ω_crit, the steady
//!    trajectory (table fidelity) sampled 60 times per mesh period over two periods; every
//!    third sample is evaluated with the full model with per-slice detail. All samples give
//!    the steady TE max and its closest approach to the tip-contact threshold at the same
//!    phase ([`TipMargin`]).
//! 5. **Sensitivity**: ω_crit and STE_max under the alternatives the paper leaves open: the
//!    compliance referred to the rim instead of the hub (each body fixed just inside its rim,
//!    [`ComplianceData::compute_rim_fixed`], FE at run time: default mesh density, coarse in
//!    `--quick` runs; sweeps at d_mesh = 100 and 200 N·s/m, and its own tip-contact threshold
//!    and margins at 570 rad/s and at its ω_crit), other pinion/gear inertias (solid discs at
//!    the root and at the reference radius), no neighbour coupling between contact lines, and
//!    the other reading of d_mesh ([`DampingReading`]). Each case's short sweep is centred on
//!    ω_crit·ω_lin/ω_lin,default, ω_lin the linearised estimate.
//!
//! `summary.md` holds the comparison with the paper, the sweeps, the waterfalls, the
//! sensitivity table, the tip-contact thresholds against the steady TE, and a section
//! "Deviations beyond 10 % from the paper" written from the run's numbers: for each deviating
//! quantity the cases that move it and by how much. No parameter is tuned to the paper.
//!
//! Every figure's data goes through one function per figure (`figure_*`), which writes the CSV
//! file and draws the same data as PNG (axes with units, legends) with [`crate::plot`].

use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::plot;
use helical_gear_mesh::compliance::data::{CacheOptions, ComplianceData};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::dynamics::model::{PHI_G, PHI_P, W_G, W_P};
use helical_gear_mesh::dynamics::{
    Drivetrain, GearDynamics, SteadyMethod, SteadyRunOptions, Stepping, SweepOptions, SweepResult,
    mesh_stiffness, run_to_steady, simulate, sweep,
};
use helical_gear_mesh::geometry::Member;
use helical_gear_mesh::mesh::{
    Fidelity, GearCompliance, Mesh, MeshOptions, MeshState, TipThreshold, pressure_waterfall,
    static_curve, tip_contact_threshold_curve,
};
use helical_gear_mesh::results::{StaticCurveRecord, SweepRecord};
use helical_gear_mesh::{DriveLine, GearPair};

/// The paper's values (Andersson & Vedmar 2003) that the run is compared with.
pub mod reference {
    /// Largest static transmission error of the Table 1 gear at 100 N·m, µm.
    pub const STE_MAX_UM: f64 = 30.5;
    /// Main resonance ω_p,crit, rad/s.
    pub const OMEGA_CRIT_RAD_S: f64 = 660.0;
    /// Speed of the paper's Fig. 13 (tip rounding in contact), rad/s.
    pub const OMEGA_FIG13_RAD_S: f64 = 570.0;
    /// Speeds of the paper's dynamic pressure waterfalls (Figs. 11–13), rad/s.
    pub const WATERFALL_SPEEDS_RAD_S: [f64; 3] = [220.0, 330.0, 570.0];
}

/// How the mesh damping coefficient d_mesh (N·s/m) enters Eq. 14.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DampingReading {
    /// Eq. 14 literally: the damping force is d_mesh times the loaded axial extent
    /// Σ(ζ_e − ζ_b) (in units of m_n) times the relative velocity along the line of action, so
    /// the total viscous coefficient is d_mesh·Σ(ζ_e − ζ_b). The model's default.
    Eq14Literal,
    /// d_mesh is the total viscous coefficient of the mesh: the model is given
    /// d_mesh / mean Σ(ζ_e − ζ_b), the mean loaded extent over the static curve, so that the
    /// total coefficient equals d_mesh on average.
    TotalCoefficient,
}

/// Options of [`run_paper`].
#[derive(Debug, Clone, PartialEq)]
pub struct PaperOptions {
    /// Fewer speeds and refinement runs (a smoke run, for tests).
    pub quick: bool,
    /// Total slices over the simultaneous contact lines (the paper's 200).
    pub slices: usize,
    /// Worker threads of the sweeps; `None`: one per core.
    pub threads: Option<usize>,
    /// Progress lines on stderr, one per stage.
    pub progress: bool,
}

impl Default for PaperOptions {
    fn default() -> Self {
        Self { quick: false, slices: 200, threads: None, progress: true }
    }
}

/// Wall time of one stage of the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageTiming {
    /// Stage name.
    pub stage: String,
    /// Wall time of the stage, s.
    pub seconds: f64,
}

/// One speed of a sweep as recorded in the summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepRow {
    /// Pinion speed ω_p, rad/s.
    pub omega_p_rad_s: f64,
    /// Steady TE_max/STE_max (dimensionless).
    pub te_max_over_ste_max: f64,
    /// Steady TE_min/STE_max (dimensionless; negative means separation).
    pub te_min_over_ste_max: f64,
    /// Teeth separate in the steady state.
    pub separated: bool,
    /// Tip rounding or edge in contact in the steady state.
    pub tip_contact: bool,
    /// Steady state detected.
    pub steady: bool,
    /// Peak |F_p| over the steady window / the largest static |F_p| over a mesh cycle
    /// (the dynamic factor of the mesh force; `None` without contact geometry).
    pub mesh_force_max_over_static: Option<f64>,
    /// Peak tooth-root stress over the steady window / its static peak, the larger of pinion
    /// and gear (the dynamic factor of the root stress; `None` without FE data).
    pub root_stress_max_over_static: Option<f64>,
}

/// Summary of one speed sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSummary {
    /// d_mesh as given, N·s/m.
    pub d_mesh_n_s_per_m: f64,
    /// How d_mesh enters Eq. 14.
    pub damping_reading: DampingReading,
    /// The d_mesh value the model of Eq. 14 was given, N·s/m.
    pub d_mesh_model_n_s_per_m: f64,
    /// STE_max of the (table-fidelity) static curve that normalises the sweep, µm.
    pub ste_max_um: f64,
    /// Located resonances (refined peaks), rad/s, ascending.
    pub resonances_rad_s: Vec<f64>,
    /// TE_max/STE_max at each resonance.
    pub resonance_te_max_over_ste_max: Vec<f64>,
    /// Lowest and highest speed with separation (grid and refinement runs), rad/s; `None` if
    /// the teeth never separate.
    pub separation_rad_s: Option<[f64; 2]>,
    /// Runs that did not reach a detected steady state.
    pub not_steady: usize,
    /// Grid and refinement runs in speed order.
    pub rows: Vec<SweepRow>,
    /// Wall time, s.
    pub seconds: f64,
}

/// One case of the sensitivity study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensitivityCase {
    /// What was changed.
    pub case: String,
    /// Pinion inertia J_p, kg·m².
    pub j_p_kgm2: f64,
    /// Gear inertia J_g, kg·m².
    pub j_g_kgm2: f64,
    /// Main resonance found by the short sweep, rad/s (`None` if no peak in its range).
    pub omega_crit_rad_s: Option<f64>,
    /// Linearised cross-check: the pinion speed whose mesh frequency z_p·ω_p equals the
    /// linearised mesh mode (constant mesh stiffness of the static equilibrium at φp = 0),
    /// rad/s.
    pub omega_linear_rad_s: f64,
    /// STE_max of the case's static curve, µm.
    pub ste_max_um: f64,
    /// Linearised mesh stiffness at the static equilibrium at φp = 0 (the k of ω_lin), N/µm.
    pub mesh_stiffness_n_per_um: f64,
    /// Speed range with separation at d_mesh = 100 N·s/m within the short sweep, rad/s.
    pub separation_d100_rad_s: Option<[f64; 2]>,
    /// Speed range with separation at d_mesh = 200 N·s/m within the short sweep, rad/s (only
    /// where `d200_swept`).
    pub separation_d200_rad_s: Option<[f64; 2]>,
    /// A d_mesh = 200 N·s/m sweep was run for this case.
    pub d200_swept: bool,
    /// Peak TE_max/STE_max of the short sweep at d_mesh = 100 N·s/m.
    pub peak_te_max_over_ste_max: f64,
}

/// Tip contact in one dynamic pressure waterfall.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WaterfallSummary {
    /// Pinion speed, rad/s.
    pub omega_p_rad_s: f64,
    /// Why this speed (the paper's speed or this model's equivalent).
    pub label: String,
    /// A tip rounding or edge carries load at some sampled instant.
    pub tip_contact: bool,
    /// The teeth separate at some sampled instant.
    pub separated: bool,
    /// Largest Hertz pressure over the samples, Pa.
    pub p_max_pa: f64,
    /// Largest steady TE over the sampled periods, µm.
    pub te_max_um: f64,
    /// CSV file name.
    pub file: String,
}

/// The steady dynamic TE against the static onset of tip contact ([`TipThreshold`]) at one
/// speed (d_mesh = 100 N·s/m).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TipMargin {
    /// Which compliance: `"default"` or `"rim-fixed"`.
    pub compliance: String,
    /// Why this speed.
    pub label: String,
    /// Pinion speed, rad/s.
    pub omega_p_rad_s: f64,
    /// Largest steady TE over two mesh periods (60 samples per period), µm.
    pub te_max_um: f64,
    /// Smallest static tip-contact threshold over the mesh period of this compliance, µm
    /// (`None`: no tip contact up to the searched TE).
    pub threshold_min_um: Option<f64>,
    /// Closest approach: the smallest threshold(phase) − TE over the samples, µm; ≤ 0 means
    /// the TE reaches the onset of tip contact.
    pub margin_um: f64,
    /// The full model puts load on a tip rounding or edge at some sampled instant (20 per
    /// period).
    pub tip_contact: bool,
}

/// The result of [`run_paper`], written as `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperSummary {
    /// Largest static TE over one pitch (full fidelity), µm.
    pub ste_max_um: f64,
    /// Smallest static TE, µm.
    pub ste_min_um: f64,
    /// Mean static TE, µm.
    pub ste_mean_um: f64,
    /// A tip rounding or edge carries load somewhere on the static curve.
    pub tip_rounding_contact_static: bool,
    /// Mean mesh stiffness along the line of action, N/µm.
    pub mesh_stiffness_mean_n_per_um: f64,
    /// Mean loaded axial extent Σ(ζ_e − ζ_b) over the static curve (units of m_n).
    pub mean_loaded_extent_mn: f64,
    /// Main resonance (highest peak of the d_mesh = 100 N·s/m sweep), rad/s.
    pub omega_crit_rad_s: f64,
    /// The resonance nearest ω_crit/2 (within ±20 %), rad/s; `None` if there is none.
    pub omega_crit_2_rad_s: Option<f64>,
    /// The resonance nearest ω_crit/3 (within ±20 %, not the one of ω_crit/2), rad/s.
    pub omega_crit_3_rad_s: Option<f64>,
    /// Separation interval at d_mesh = 100 N·s/m, rad/s, or `None`.
    pub separation_d100_rad_s: Option<[f64; 2]>,
    /// Separation interval at d_mesh = 200 N·s/m, rad/s, or `None`.
    pub separation_d200_rad_s: Option<[f64; 2]>,
    /// Tip rounding in contact in the steady state at 570 rad/s (the paper's Fig. 13 speed).
    pub tip_rounding_contact_570: bool,
    /// Tip rounding in contact at this model's equivalent speed ω_crit·570/660.
    pub tip_rounding_contact_equivalent: bool,
    /// The equivalent speed ω_crit·570/660, rad/s.
    pub omega_equivalent_570_rad_s: f64,
    /// Static onset of tip contact: the smallest TE over one mesh period at which a loaded
    /// contact reaches a tip rounding or tip edge (default compliance, full model), µm; `None`
    /// if none up to `tip_contact_te_searched_um`.
    pub tip_contact_te_threshold_um: Option<f64>,
    /// Pinion angle (within one pitch from φp = 0) of that smallest threshold, rad.
    pub tip_contact_te_threshold_phi_p_rad: Option<f64>,
    /// Mean of the threshold over the mesh period, µm (angles without one count as the
    /// searched maximum).
    pub tip_contact_te_threshold_mean_um: f64,
    /// Share of the pinion angles over the mesh period at which tip contact is reached within
    /// the searched TE (default compliance).
    pub tip_contact_te_threshold_found_share: f64,
    /// The same minimum with the compliance referred to the rim (sensitivity case), µm.
    pub tip_contact_te_threshold_rim_um: Option<f64>,
    /// Largest TE searched for the thresholds, µm.
    pub tip_contact_te_searched_um: f64,
    /// Steady TE against the threshold at 570 rad/s and at ω_crit (default and rim-fixed).
    pub tip_margins: Vec<TipMargin>,
    /// The two sweeps (d_mesh = 100 and 200 N·s/m, Eq. 14 literally).
    pub sweeps: Vec<SweepSummary>,
    /// The dynamic pressure waterfalls.
    pub waterfalls: Vec<WaterfallSummary>,
    /// The sensitivity study.
    pub sensitivity: Vec<SensitivityCase>,
    /// Modelling assumptions ([`GearPair::assumptions`] and those of this run).
    pub assumptions: Vec<String>,
    /// Pinion inertia used, kg·m².
    pub j_p_kgm2: f64,
    /// Gear inertia used, kg·m².
    pub j_g_kgm2: f64,
    /// Depth h of the split between FE and local contact compliance, m.
    pub h_m: f64,
    /// Total slices over the simultaneous contact lines.
    pub slices: usize,
    /// Fidelity of the sweeps and the steady runs.
    pub fidelity_dynamics: String,
    /// Quick (smoke) run.
    pub quick: bool,
    /// Wall time per stage.
    pub stages: Vec<StageTiming>,
    /// Total wall time, s.
    pub runtime_s: f64,
    /// Peak resident memory of the process that ran it (the kernel's high-water mark,
    /// `VmHWM` of `/proc/self/status`), MB (10⁶ bytes); `None` where the system does not
    /// report it. The run's own peak, not that of a `cargo run` that also compiles (rustc's
    /// peak is larger).
    #[serde(default)]
    pub peak_memory_mb: Option<f64>,
}

/// The peak resident memory of this process so far, MB (10⁶ bytes), from `VmHWM` in
/// `/proc/self/status` (Linux); `None` elsewhere.
pub fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 =
        line.trim_start_matches("VmHWM:").trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kib * 1024.0 / 1e6)
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> String + '_ {
    move |e| format!("cannot write {}: {e}", path.display())
}

fn write_text(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(io_err(path))
}

struct Stages {
    t0: Instant,
    last: Instant,
    list: Vec<StageTiming>,
    progress: bool,
}

impl Stages {
    fn new(progress: bool) -> Self {
        let now = Instant::now();
        Self { t0: now, last: now, list: Vec::new(), progress }
    }

    fn done(&mut self, stage: &str, note: &str) {
        let now = Instant::now();
        let seconds = (now - self.last).as_secs_f64();
        self.last = now;
        if self.progress {
            eprintln!(
                "paper: {stage} done in {seconds:.1} s (total {:.1} s){}{note}",
                (now - self.t0).as_secs_f64(),
                if note.is_empty() { "" } else { ": " }
            );
        }
        self.list.push(StageTiming { stage: stage.to_string(), seconds });
    }
}

/// Inertia of a solid disc of radius `r` (m) with a bore of radius `r_bore` (m), face width
/// `b` (m) and density `rho` (kg/m³): ρ·b·π/2·(r⁴ − r_bore⁴), kg·m².
pub fn solid_disc_inertia(r: f64, r_bore: f64, b: f64, rho: f64) -> f64 {
    rho * b * std::f64::consts::PI / 2.0 * (r.powi(4) - r_bore.powi(4))
}

fn mesh_err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The data behind one sweep (kept for the figures and the summary).
struct SweepRun {
    summary: SweepSummary,
    result: SweepResult,
}

fn summarise(result: SweepResult, d: f64, reading: DampingReading, d_model: f64) -> SweepRun {
    let mut rows: Vec<SweepRow> = result
        .points
        .iter()
        .chain(result.resonances.iter().flat_map(|r| r.refinement.iter()))
        .map(|p| SweepRow {
            omega_p_rad_s: p.omega_p,
            te_max_over_ste_max: p.te_max_over_ste_max,
            te_min_over_ste_max: p.te_min_over_ste_max,
            separated: p.separated,
            tip_contact: p.tip_contact,
            steady: p.steady,
            mesh_force_max_over_static: p.over_static.mesh_force,
            root_stress_max_over_static: p.over_static.root_stress,
        })
        .collect();
    rows.sort_by(|a, b| a.omega_p_rad_s.total_cmp(&b.omega_p_rad_s));
    let sep: Vec<f64> = rows.iter().filter(|r| r.separated).map(|r| r.omega_p_rad_s).collect();
    let separation_rad_s = match (sep.first(), sep.last()) {
        (Some(&lo), Some(&hi)) => Some([lo, hi]),
        _ => None,
    };
    // The normalisation and the resonances are the shared sweep record's.
    let speeds: Vec<f64> = result.points.iter().map(|p| p.omega_p).collect();
    let record = SweepRecord::new(&result, &speeds);
    let mut res: Vec<(f64, f64)> = record
        .resonances_rad_s
        .iter()
        .copied()
        .zip(record.resonance_te_max_over_ste_max.iter().copied())
        .collect();
    res.sort_by(|a, b| a.0.total_cmp(&b.0));
    SweepRun {
        summary: SweepSummary {
            d_mesh_n_s_per_m: d,
            damping_reading: reading,
            d_mesh_model_n_s_per_m: d_model,
            ste_max_um: record.ste_max_um,
            resonances_rad_s: res.iter().map(|r| r.0).collect(),
            resonance_te_max_over_ste_max: res.iter().map(|r| r.1).collect(),
            separation_rad_s,
            not_steady: rows.iter().filter(|r| !r.steady).count(),
            rows,
            seconds: result.wall_seconds,
        },
        result,
    }
}

/// Main resonance (highest peak) and the peaks nearest ω/2 and ω/3 (each within ±20 %).
fn pick_resonances(s: &SweepSummary) -> Option<(f64, Option<f64>, Option<f64>)> {
    let (i, _) =
        s.resonance_te_max_over_ste_max.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    let w = s.resonances_rad_s[i];
    // A peak counts as the resonance at ω/n only within ±20 % of ω/n, and one peak is not
    // used twice.
    let nearest = |target: f64, not: Option<f64>| {
        s.resonances_rad_s
            .iter()
            .copied()
            .filter(|&x| (x - target).abs() < 0.2 * target && Some(x) != not)
            .min_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs()))
    };
    let w2 = nearest(w / 2.0, None);
    Some((w, w2, nearest(w / 3.0, w2)))
}

/// Uniform grid of `n` (≥ 2) speeds from `lo` to `hi`, rad/s.
fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect()
}

struct Ctx<'a> {
    opts: &'a PaperOptions,
    drive: Drivetrain,
    table: Mesh,
}

impl Ctx<'_> {
    fn sweep_opts(&self, refine_runs: usize) -> SweepOptions {
        SweepOptions {
            run: SteadyRunOptions {
                keep_window: false,
                ..SteadyRunOptions::for_pair(self.table.pair())
            },
            threads: self.opts.threads,
            refine_runs,
            ..SweepOptions::default()
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn run_sweep(
        &self,
        mesh: &Mesh,
        drive: &Drivetrain,
        d: f64,
        reading: DampingReading,
        extent: f64,
        speeds: &[f64],
        refine_runs: usize,
    ) -> Result<SweepRun, String> {
        let d_model = match reading {
            DampingReading::Eq14Literal => d,
            DampingReading::TotalCoefficient => d / extent,
        };
        let mut m = mesh.clone();
        m.set_d_mesh(d_model).map_err(mesh_err)?;
        let r = sweep(&m, drive, speeds, &self.sweep_opts(refine_runs)).map_err(mesh_err)?;
        Ok(summarise(r, d, reading, d_model))
    }
}

/// A steady trajectory at `omega_p` sampled over `periods` mesh periods, `per_period` samples
/// per period: (t, state) pairs, t from the start of the sampled stretch.
fn steady_samples(
    mesh: &Mesh,
    drive: &Drivetrain,
    omega_p: f64,
    max_step: Option<f64>,
    periods: usize,
    per_period: usize,
) -> Result<Vec<(f64, [f64; 8])>, String> {
    let mut model = GearDynamics::new(mesh.clone(), *drive).map_err(mesh_err)?;
    let run = SteadyRunOptions {
        keep_window: false,
        max_step,
        ..SteadyRunOptions::for_pair(mesh.pair())
    };
    let r = run_to_steady(&mut model, omega_p, &run).map_err(mesh_err)?;
    let t_m = drive.mesh_period(omega_p);
    let base = match &run.method {
        SteadyMethod::Rk4 { steps_per_period } => *steps_per_period,
        SteadyMethod::Dopri5 { .. } => 128,
    };
    let mut sub = base.div_ceil(per_period).max(1);
    if let Some(h) = max_step {
        while t_m / (per_period * sub) as f64 > h {
            sub += 1;
        }
    }
    let dt = t_m / (per_period * sub) as f64;
    let n = periods * per_period * sub;
    let tr =
        simulate(&mut model, &r.y_end, dt * n as f64, &Stepping::Rk4 { dt }).map_err(mesh_err)?;
    Ok(tr.time.iter().zip(&tr.states).step_by(sub).map(|(&t, &y)| (t, y)).collect())
}

fn state_of(y: &[f64; 8]) -> MeshState {
    MeshState { phi_p: y[PHI_P], phi_g: y[PHI_G], w_p: y[W_P], w_g: y[W_G], ..Default::default() }
}

/// Runs the paper job for `pair` driven by the drive line `drive` (the paper's:
/// [`DriveLine::paper_table1`]) into the directory `out` (created if missing); see the module
/// doc. Returns the summary that is also written to `out/summary.json`.
pub fn run_paper(
    pair: &GearPair,
    drive: &DriveLine,
    out: &Path,
    opts: &PaperOptions,
) -> Result<PaperSummary, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut st = Stages::new(opts.progress);

    // Stage 0: FE compliance (the embedded Table 1 data, a disk cache or a fresh FE run),
    // shared by every mesh model of the run.
    let cache = CacheOptions { progress: opts.progress, ..CacheOptions::default() };
    let data = ComplianceData::for_pair(pair, &cache).map_err(|e| e.to_string())?;
    let interp = |m: Member| -> Result<GearCompliance, String> {
        let c = data.interpolated(m).map_err(|e| e.to_string())?;
        Ok(GearCompliance::Interpolated(std::sync::Arc::new(c)))
    };
    let (cp, cg) = (interp(Member::Pinion)?, interp(Member::Gear)?);
    let h_m = cp.depth();
    st.done("FE compliance", data.source().as_str());

    // Stage 1: static analysis (full fidelity).
    let full_opts = MeshOptions { slices: opts.slices, ..MeshOptions::default() }.sized_for(drive);
    // From the data, so the mesh also carries the FE root-stress influence (the dynamic
    // factor of the root stress beside Fig. 9); the compliances are those of `cp`, `cg`.
    let build = |o: MeshOptions| Mesh::from_data(pair, o, &data).map_err(mesh_err);
    let mut full = build(full_opts)?;
    let geo = full.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let torque = drive.torque_nm;
    let curve = static_curve(&mut full, torque, 0.0, pitch, 40, 1).map_err(mesh_err)?;
    // The static summary is the shared static record's.
    let static_record = StaticCurveRecord::new(&curve, geo.pinion.rb);
    static_record.check_finite()?;
    let cos_b = geo.base_helix_angle.cos();
    let extent = curve.points.iter().map(|e| e.outputs.contact_length).sum::<f64>()
        / curve.points.len() as f64
        * cos_b
        / pair.normal_module_m;
    figure_static_te(out, &curve)?;
    let rows = pressure_waterfall(&mut full, torque, 0, -1.5 * pitch, 1.5 * pitch, 20)
        .map_err(mesh_err)?;
    figure_7(out, &rows)?;
    st.done(
        "static (STE curve, Fig. 7)",
        &format!("STE max {:.2} µm, mean extent {extent:.2} m_n", curve.max() * 1e6),
    );
    // Static onset of tip contact over one mesh period (full model).
    let (thr_points, thr_steps) = if opts.quick { (8, 40) } else { (40, 100) };
    let te_search = TIP_SEARCH_STE_MULTIPLE * curve.max();
    let threshold =
        tip_contact_threshold_curve(&full, 0.0, pitch, thr_points, te_search, thr_steps)
            .map_err(mesh_err)?;
    st.done(
        "static onset of tip contact",
        &format!(
            "smallest TE with tip contact {}",
            threshold.min().map_or("none".into(), |(_, t)| format!("{:.2} µm", t * 1e6))
        ),
    );

    // Stage 2: table model and the two sweeps.
    let table_opts = MeshOptions { fidelity: Fidelity::Table, ..full_opts };
    let table = build(table_opts)?;
    let drive = Drivetrain::new(table.geometry(), drive).map_err(mesh_err)?;
    let ctx = Ctx { opts, drive, table };
    st.done("table surrogate", "");
    let (n_grid, refine) = if opts.quick { (12, 2) } else { (80, 6) };
    let speeds = grid(120.0, 950.0, n_grid);
    let lit = DampingReading::Eq14Literal;
    let s100 = ctx.run_sweep(&ctx.table, &ctx.drive, 100.0, lit, extent, &speeds, refine)?;
    st.done("sweep d_mesh = 100 N·s/m", &format!("{} runs", s100.summary.rows.len()));
    let s200 = ctx.run_sweep(&ctx.table, &ctx.drive, 200.0, lit, extent, &speeds, refine)?;
    st.done("sweep d_mesh = 200 N·s/m", &format!("{} runs", s200.summary.rows.len()));
    figure_9(out, &[&s100.summary, &s200.summary])?;
    figure_dynamic_factors(out, &[&s100.summary, &s200.summary])?;
    let (w_crit, w2, w3) =
        pick_resonances(&s100.summary).ok_or("the d_mesh = 100 N·s/m sweep found no resonance")?;
    let max_step = s100.result.max_step;

    // Stage 3: Fig. 10, TE over three mesh periods at the 2nd and 3rd resonance.
    let mut t100 = ctx.table.clone();
    t100.set_d_mesh(100.0).map_err(mesh_err)?;
    let fig10_speeds: Vec<(String, f64)> = [("omega_crit_2", w2), ("omega_crit_3", w3)]
        .into_iter()
        .filter_map(|(n, w)| w.map(|w| (n.to_string(), w)))
        .collect();
    let fig10: Vec<TeRun> = fig10_speeds
        .par_iter()
        .map(|(n, w)| {
            let s = steady_samples(&t100, &ctx.drive, *w, max_step, 3, 64)?;
            let mut m = t100.clone();
            let te = s
                .iter()
                .map(|(t, y)| Ok((*t, m.evaluate(&state_of(y)).map_err(mesh_err)?.te)))
                .collect::<Result<Vec<_>, String>>()?;
            Ok((n.clone(), *w, te))
        })
        .collect::<Result<_, String>>()?;
    figure_10(out, &fig10, curve.max())?;
    st.done("Fig. 10 (TE at the 2nd and 3rd resonance)", "");

    // Stage 4: dynamic pressure waterfalls (Figs. 11–13), full model at steady states.
    let w_eq = w_crit * reference::OMEGA_FIG13_RAD_S / reference::OMEGA_CRIT_RAD_S;
    let mut cases: Vec<(String, f64)> = reference::WATERFALL_SPEEDS_RAD_S
        .iter()
        .map(|&w| (format!("paper speed {w} rad/s"), w))
        .collect();
    if let Some(w) = w3 {
        cases.push(("this model's omega_crit/3 resonance".into(), w));
    }
    if let Some(w) = w2 {
        cases.push(("this model's omega_crit/2 resonance".into(), w));
    }
    cases.push(("this model's omega_crit*570/660".into(), w_eq));
    cases.push((LABEL_OMEGA_CRIT.into(), w_crit));
    let mut full100 = full.clone();
    full100.set_d_mesh(100.0).map_err(mesh_err)?;
    full100.set_detail(true);
    let runs: Vec<(WaterfallSummary, TipMargin)> = cases
        .par_iter()
        .enumerate()
        .map(|(i, (label, w))| {
            let samples = steady_samples(&t100, &ctx.drive, *w, max_step, 2, 60)?;
            let (te_max, margin) = te_against_threshold(&samples, &geo, &threshold);
            let mut m = full100.clone();
            m.set_detail(true);
            let mut rows = Vec::new();
            let (mut tip, mut sep, mut p_max) = (false, false, 0.0f64);
            for (t, y) in samples.iter().step_by(3) {
                let o = m.evaluate_full(&state_of(y)).map_err(mesh_err)?;
                tip |= o.tip_contact;
                sep |= o.separated;
                p_max = p_max.max(o.p_max);
                for s in m.slices() {
                    rows.push(DynRow {
                        t: *t,
                        phi_p: y[PHI_P],
                        pair: s.pair,
                        zeta: s.zeta,
                        pressure: s.pressure_pa,
                        kind: s.kind,
                    });
                }
            }
            let file = format!("waterfall_dynamic_{}_{:.0}.csv", i + 1, w);
            figure_11_13(out, &file, label, *w, &rows)?;
            let summary = WaterfallSummary {
                omega_p_rad_s: *w,
                label: label.clone(),
                tip_contact: tip,
                separated: sep,
                p_max_pa: p_max,
                te_max_um: te_max * 1e6,
                file,
            };
            let margin = TipMargin {
                compliance: "default".into(),
                label: label.clone(),
                omega_p_rad_s: *w,
                te_max_um: te_max * 1e6,
                threshold_min_um: threshold.min().map(|m| m.1 * 1e6),
                margin_um: margin * 1e6,
                tip_contact: tip,
            };
            Ok((summary, margin))
        })
        .collect::<Result<_, String>>()?;
    let mut tip_margins: Vec<TipMargin> = runs
        .iter()
        .filter(|(w, _)| {
            w.omega_p_rad_s == reference::OMEGA_FIG13_RAD_S || w.label == LABEL_OMEGA_CRIT
        })
        .map(|(_, m)| m.clone())
        .collect();
    let waterfalls: Vec<WaterfallSummary> = runs.into_iter().map(|(w, _)| w).collect();
    let tip_at =
        |w: f64| waterfalls.iter().any(|x| (x.omega_p_rad_s - w).abs() < 1e-9 && x.tip_contact);
    let tip_570 = tip_at(reference::OMEGA_FIG13_RAD_S);
    let tip_eq = tip_at(w_eq);
    st.done("dynamic waterfalls (Figs. 11–13)", &format!("tip contact at 570: {tip_570}"));

    // Stage 5: sensitivity.
    let mut sensitivity = sensitivity(&ctx, pair, &cp, &cg, w_crit, extent, &s100, &mut st, out)?;
    let rim = rim_fixed_case(&ctx, pair, h_m, w_crit, &sensitivity[0], te_search, &mut st)?;
    sensitivity.insert(1, rim.case);
    tip_margins.extend(rim.margins);
    figure_tip_threshold(out, &threshold, &rim.threshold)?;

    let mut assumptions = pair.assumptions();
    assumptions.push(format!(
        "depth h = {:.3} mm separates the FE (global) and the local contact compliance",
        h_m * 1e3
    ));
    assumptions.push(format!(
        "{} slices over the simultaneous contact lines; static results at full fidelity, sweeps \
         and steady runs with the (phase, TE) table surrogate, dynamic waterfalls evaluated \
         with the full model at the steady states",
        opts.slices
    ));
    assumptions.push(
        "d_mesh enters Eq. 14 literally (times the loaded extent Σ(ζ_e − ζ_b) in units of m_n)"
            .into(),
    );
    assumptions.push(
        "resonances: the main one is the highest peak of the d_mesh = 100 N·s/m sweep; the 2nd \
         and 3rd are the peaks nearest ω_crit/2 and ω_crit/3"
            .into(),
    );

    let summary = PaperSummary {
        ste_max_um: static_record.ste_max_um,
        ste_min_um: static_record.ste_min_um,
        ste_mean_um: static_record.ste_mean_um,
        tip_rounding_contact_static: static_record.tip_rounding_contact,
        mesh_stiffness_mean_n_per_um: static_record.mesh_stiffness_mean_n_per_um,
        mean_loaded_extent_mn: extent,
        omega_crit_rad_s: w_crit,
        omega_crit_2_rad_s: w2,
        omega_crit_3_rad_s: w3,
        separation_d100_rad_s: s100.summary.separation_rad_s,
        separation_d200_rad_s: s200.summary.separation_rad_s,
        tip_rounding_contact_570: tip_570,
        tip_rounding_contact_equivalent: tip_eq,
        omega_equivalent_570_rad_s: w_eq,
        tip_contact_te_threshold_um: threshold.min().map(|m| m.1 * 1e6),
        tip_contact_te_threshold_phi_p_rad: threshold.min().map(|m| m.0),
        tip_contact_te_threshold_mean_um: threshold
            .te
            .iter()
            .map(|t| t.unwrap_or(threshold.te_max))
            .sum::<f64>()
            / threshold.te.len().max(1) as f64
            * 1e6,
        tip_contact_te_threshold_found_share: threshold.te.iter().filter(|t| t.is_some()).count()
            as f64
            / threshold.te.len().max(1) as f64,
        tip_contact_te_threshold_rim_um: rim.threshold.min().map(|m| m.1 * 1e6),
        tip_contact_te_searched_um: te_search * 1e6,
        tip_margins,
        sweeps: vec![s100.summary, s200.summary],
        waterfalls,
        sensitivity,
        assumptions,
        j_p_kgm2: ctx.drive.j_p,
        j_g_kgm2: ctx.drive.j_g,
        h_m,
        slices: opts.slices,
        fidelity_dynamics: "table".into(),
        quick: opts.quick,
        runtime_s: 0.0,
        peak_memory_mb: None,
        stages: Vec::new(),
    };
    let mut summary = summary;
    st.done("sensitivity", "");
    summary.stages = st.list.clone();
    summary.runtime_s = st.t0.elapsed().as_secs_f64();
    summary.peak_memory_mb = peak_memory_mb();
    let json = serde_json::to_string_pretty(&summary).map_err(mesh_err)?;
    write_text(&out.join("summary.json"), &json)?;
    write_text(&out.join("summary.md"), &summary_markdown(&summary))?;
    Ok(summary)
}

#[allow(clippy::too_many_arguments)]
fn sensitivity(
    ctx: &Ctx,
    pair: &GearPair,
    cp: &GearCompliance,
    cg: &GearCompliance,
    w_crit: f64,
    extent: f64,
    s100: &SweepRun,
    st: &mut Stages,
    out: &Path,
) -> Result<Vec<SensitivityCase>, String> {
    let quick = ctx.opts.quick;
    let (n, refine) = short_sweep_size(quick);
    let mut t = ctx.table.clone();
    let k = mesh_stiffness(&mut t, 0.0, ctx.drive.torque).map_err(mesh_err)?;
    let w_lin = |d: &Drivetrain, k: f64| linear_mesh_speed(ctx.table.geometry(), d, k);
    let w_lin0 = w_lin(&ctx.drive, k);
    let mut cases = Vec::new();
    cases.push(SensitivityCase {
        case: "default: toothed bodies to the bore, neighbour coupling on, Eq. 14 literal".into(),
        j_p_kgm2: ctx.drive.j_p,
        j_g_kgm2: ctx.drive.j_g,
        omega_crit_rad_s: Some(w_crit),
        omega_linear_rad_s: w_lin0,
        ste_max_um: s100.summary.ste_max_um,
        mesh_stiffness_n_per_um: k * 1e-6,
        separation_d100_rad_s: s100.summary.separation_rad_s,
        separation_d200_rad_s: None,
        d200_swept: false,
        peak_te_max_over_ste_max: peak_value(&s100.summary),
    });
    let lit = DampingReading::Eq14Literal;

    // (a) inertias.
    let geo = ctx.table.geometry();
    let r_bore = pair.bore_diameter_m / 2.0;
    let b = pair.face_width_m;
    for (name, rp, rg) in [
        ("solid discs at the root radius", geo.pinion.rf, geo.gear.rf),
        ("solid discs at the reference radius", geo.pinion.r, geo.gear.r),
    ] {
        let mut d = ctx.drive;
        d.j_p = solid_disc_inertia(rp, r_bore, b, pair.material_p.density_kg_m3);
        d.j_g = solid_disc_inertia(rg, r_bore, b, pair.material_g.density_kg_m3);
        let wl = w_lin(&d, k);
        let centre = w_crit * wl / w_lin0;
        let speeds = grid(0.85 * centre, 1.15 * centre, n);
        let s = ctx.run_sweep(&ctx.table, &d, 100.0, lit, extent, &speeds, refine)?;
        cases.push(SensitivityCase {
            case: format!("J_p, J_g: {name}"),
            j_p_kgm2: d.j_p,
            j_g_kgm2: d.j_g,
            omega_crit_rad_s: peak(&s.summary).map(|p| p.0),
            omega_linear_rad_s: wl,
            ste_max_um: s.summary.ste_max_um,
            mesh_stiffness_n_per_um: k * 1e-6,
            separation_d100_rad_s: s.summary.separation_rad_s,
            separation_d200_rad_s: None,
            d200_swept: false,
            peak_te_max_over_ste_max: peak_value(&s.summary),
        });
        st.done(&format!("sensitivity: {name}"), "");
    }

    // (b) neighbour coupling off.
    let o = MeshOptions { neighbour_coupling: false, ..*ctx.table.options() };
    let nc = Mesh::with_compliance(pair, o, cp.clone(), cg.clone()).map_err(mesh_err)?;
    let mut nc_probe = nc.clone();
    let k_nc = mesh_stiffness(&mut nc_probe, 0.0, ctx.drive.torque).map_err(mesh_err)?;
    let wl = w_lin(&ctx.drive, k_nc);
    let centre = w_crit * wl / w_lin0;
    let speeds = grid(0.85 * centre, 1.15 * centre, n);
    let s = ctx.run_sweep(&nc, &ctx.drive, 100.0, lit, extent, &speeds, refine)?;
    cases.push(SensitivityCase {
        case: "neighbour coupling between contact lines off".into(),
        j_p_kgm2: ctx.drive.j_p,
        j_g_kgm2: ctx.drive.j_g,
        omega_crit_rad_s: peak(&s.summary).map(|p| p.0),
        omega_linear_rad_s: wl,
        ste_max_um: s.summary.ste_max_um,
        mesh_stiffness_n_per_um: k_nc * 1e-6,
        separation_d100_rad_s: s.summary.separation_rad_s,
        separation_d200_rad_s: None,
        d200_swept: false,
        peak_te_max_over_ste_max: peak_value(&s.summary),
    });
    st.done("sensitivity: neighbour coupling off", "");

    // (c) d_mesh as the total coefficient.
    let speeds = grid(0.7 * w_crit, 1.3 * w_crit, if quick { 6 } else { 18 });
    let tot = DampingReading::TotalCoefficient;
    let a = ctx.run_sweep(&ctx.table, &ctx.drive, 100.0, tot, extent, &speeds, refine)?;
    let c = ctx.run_sweep(&ctx.table, &ctx.drive, 200.0, tot, extent, &speeds, refine)?;
    cases.push(SensitivityCase {
        case: format!("d_mesh as the total coefficient (model given d_mesh/{extent:.2})"),
        j_p_kgm2: ctx.drive.j_p,
        j_g_kgm2: ctx.drive.j_g,
        omega_crit_rad_s: peak(&a.summary).map(|p| p.0),
        omega_linear_rad_s: w_lin0,
        ste_max_um: a.summary.ste_max_um,
        mesh_stiffness_n_per_um: k * 1e-6,
        separation_d100_rad_s: a.summary.separation_rad_s,
        separation_d200_rad_s: c.summary.separation_rad_s,
        d200_swept: true,
        peak_te_max_over_ste_max: peak_value(&a.summary),
    });
    figure_9_named(out, "sweep_total_coefficient.csv", &[&a.summary, &c.summary])?;
    st.done("sensitivity: d_mesh as the total coefficient", "");
    Ok(cases)
}

/// Grid points and refinement runs of a sensitivity case's short sweep.
fn short_sweep_size(quick: bool) -> (usize, usize) {
    if quick { (6, 1) } else { (14, 4) }
}

/// The pinion speed (rad/s) at which the mesh frequency z_p·ω_p meets the mesh mode (the
/// highest of the four) of Eqs. 1–4 linearised with the constant mesh stiffness `k` (N/m).
fn linear_mesh_speed(
    geo: &helical_gear_mesh::geometry::PairGeometry,
    d: &Drivetrain,
    k: f64,
) -> f64 {
    d.linear_frequencies(k, geo.pinion.rb, geo.gear.rb)[3] / d.z_p as f64
}

/// The highest refined peak of a sweep: (ω in rad/s, TE_max/STE_max).
fn peak(s: &SweepSummary) -> Option<(f64, f64)> {
    s.resonance_te_max_over_ste_max
        .iter()
        .zip(&s.resonances_rad_s)
        .max_by(|a, b| a.0.total_cmp(b.0))
        .map(|(p, w)| (*w, *p))
}

/// The largest TE_max/STE_max over all runs of a sweep.
fn peak_value(s: &SweepSummary) -> f64 {
    s.rows.iter().map(|r| r.te_max_over_ste_max).fold(f64::NEG_INFINITY, f64::max)
}

/// TE search range of the tip-contact threshold, in multiples of the default STE_max.
const TIP_SEARCH_STE_MULTIPLE: f64 = 6.0;

/// Waterfall label of this model's main resonance.
const LABEL_OMEGA_CRIT: &str = "this model's omega_crit resonance";

/// Largest TE (m) over `samples` and the closest approach min(threshold(φp) − TE) (m).
fn te_against_threshold(
    samples: &[(f64, [f64; 8])],
    geo: &helical_gear_mesh::geometry::PairGeometry,
    threshold: &TipThreshold,
) -> (f64, f64) {
    let (mut te_max, mut margin) = (f64::NEG_INFINITY, f64::INFINITY);
    for (_, y) in samples {
        let te = y[PHI_P] * geo.pinion.rb + y[PHI_G] * geo.gear.rb;
        te_max = te_max.max(te);
        margin = margin.min(threshold.at(y[PHI_P]) - te);
    }
    (te_max, margin)
}

/// The sensitivity case "compliance referred to the rim" and its tip-contact evidence.
struct RimCase {
    case: SensitivityCase,
    threshold: TipThreshold,
    margins: Vec<TipMargin>,
}

/// Sensitivity case: each gear body fixed just inside its rim
/// ([`ComplianceData::compute_rim_fixed`]; coarse FE mesh in quick runs), the same mesh
/// options as the default case; short sweeps at d_mesh = 100 and 200 N·s/m around
/// ω_crit·ω_lin/ω_lin,default, the static onset of tip contact and the steady TE against it
/// at 570 rad/s and at this case's ω_crit.
fn rim_fixed_case(
    ctx: &Ctx,
    pair: &GearPair,
    h_m: f64,
    w_crit: f64,
    default: &SensitivityCase,
    te_search: f64,
    st: &mut Stages,
) -> Result<RimCase, String> {
    let quick = ctx.opts.quick;
    // The mesh of the embedded bore-fixed data this case is compared with.
    let density = if quick { GearMeshDensity::coarse() } else { GearMeshDensity::conforming() };
    let data = ComplianceData::compute_rim_fixed(pair, &density, h_m, ctx.opts.progress)
        .map_err(|e| e.to_string())?;
    let interp = |m: Member| -> Result<GearCompliance, String> {
        let c = data.interpolated(m).map_err(|e| e.to_string())?;
        Ok(GearCompliance::Interpolated(std::sync::Arc::new(c)))
    };
    let (cp, cg) = (interp(Member::Pinion)?, interp(Member::Gear)?);
    st.done(
        "sensitivity: rim-fixed FE compliance",
        &format!(
            "{} + {} DOFs, {:.1} s of FE ({} density)",
            data.pinion.fe.dofs,
            data.gear.fe.dofs,
            data.fe_seconds(),
            if quick { "coarse" } else { "default" }
        ),
    );
    let table_opts = *ctx.table.options();
    let table =
        Mesh::with_compliance(pair, table_opts, cp.clone(), cg.clone()).map_err(mesh_err)?;
    let full_opts = MeshOptions { fidelity: Fidelity::Full, ..table_opts };
    let full = Mesh::with_compliance(pair, full_opts, cp, cg).map_err(mesh_err)?;
    let mut probe = table.clone();
    let k = mesh_stiffness(&mut probe, 0.0, ctx.drive.torque).map_err(mesh_err)?;
    let wl = linear_mesh_speed(table.geometry(), &ctx.drive, k);
    let centre = w_crit * wl / default.omega_linear_rad_s;
    let (n, refine) = short_sweep_size(quick);
    let speeds = grid(0.85 * centre, 1.15 * centre, n);
    let lit = DampingReading::Eq14Literal;
    // Eq. 14 literally: the loaded extent does not enter.
    let s100 = ctx.run_sweep(&table, &ctx.drive, 100.0, lit, 1.0, &speeds, refine)?;
    let s200 = ctx.run_sweep(&table, &ctx.drive, 200.0, lit, 1.0, &speeds, refine)?;
    let w_rim = peak(&s100.summary).map(|p| p.0);
    let case = SensitivityCase {
        case: "compliance referred to the rim (each body fixed just inside its rim)".into(),
        j_p_kgm2: ctx.drive.j_p,
        j_g_kgm2: ctx.drive.j_g,
        omega_crit_rad_s: w_rim,
        omega_linear_rad_s: wl,
        ste_max_um: s100.summary.ste_max_um,
        mesh_stiffness_n_per_um: k * 1e-6,
        separation_d100_rad_s: s100.summary.separation_rad_s,
        separation_d200_rad_s: s200.summary.separation_rad_s,
        d200_swept: true,
        peak_te_max_over_ste_max: peak_value(&s100.summary),
    };
    st.done(
        "sensitivity: compliance referred to the rim",
        &format!("ω_crit {}, STE max {:.2} µm", opt_w(w_rim), s100.summary.ste_max_um),
    );

    // Tip contact: static onset and the steady TE at 570 rad/s and at this case's ω_crit.
    let pitch = full.geometry().pinion.angular_pitch();
    let (points, steps) = if quick { (8, 40) } else { (40, 100) };
    let threshold = tip_contact_threshold_curve(&full, 0.0, pitch, points, te_search, steps)
        .map_err(mesh_err)?;
    let mut t100 = table.clone();
    t100.set_d_mesh(100.0).map_err(mesh_err)?;
    let mut f100 = full.clone();
    f100.set_d_mesh(100.0).map_err(mesh_err)?;
    let mut speeds = vec![(format!("paper speed {} rad/s", reference::OMEGA_FIG13_RAD_S), 570.0)];
    if let Some(w) = w_rim {
        speeds.push(("this case's omega_crit resonance".into(), w));
    }
    let geo = full.geometry().clone();
    let max_step = s100.result.max_step;
    let margins = speeds
        .par_iter()
        .map(|(label, w)| {
            let samples = steady_samples(&t100, &ctx.drive, *w, max_step, 2, 60)?;
            let (te_max, margin) = te_against_threshold(&samples, &geo, &threshold);
            let mut m = f100.clone();
            let mut tip = false;
            for (_, y) in samples.iter().step_by(3) {
                tip |= m.evaluate_full(&state_of(y)).map_err(mesh_err)?.tip_contact;
            }
            Ok(TipMargin {
                compliance: "rim-fixed".into(),
                label: label.clone(),
                omega_p_rad_s: *w,
                te_max_um: te_max * 1e6,
                threshold_min_um: threshold.min().map(|m| m.1 * 1e6),
                margin_um: margin * 1e6,
                tip_contact: tip,
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    st.done(
        "sensitivity: rim-fixed tip contact",
        &format!(
            "smallest TE with tip contact {}",
            threshold.min().map_or("none".into(), |(_, t)| format!("{:.2} µm", t * 1e6))
        ),
    );
    Ok(RimCase { case, threshold, margins })
}

/// The static onset of tip contact over one mesh period, default and rim-fixed compliance:
/// `tip_threshold.csv` (empty where there is none up to the searched TE) and `.png` (drawn at
/// the searched TE there) in `dir`.
fn figure_tip_threshold(
    dir: &Path,
    default: &TipThreshold,
    rim: &TipThreshold,
) -> Result<(), String> {
    let um = |t: Option<f64>| t.map_or(String::new(), |t| format!("{:e}", t * 1e6));
    let mut csv = String::from("case,phi_p_rad,te_threshold_um\n");
    for (name, thr) in [("default", default), ("rim_fixed", rim)] {
        for (p, t) in thr.phi_p.iter().zip(&thr.te) {
            csv.push_str(&format!("{name},{p:e},{}\n", um(*t)));
        }
    }
    write_text(&dir.join("tip_threshold.csv"), &csv)?;
    let series = [("default (bodies fixed at the bore)", default), ("rim-fixed", rim)]
        .into_iter()
        .map(|(name, thr)| {
            let pts = thr
                .phi_p
                .iter()
                .zip(&thr.te)
                .map(|(p, t)| (*p, t.unwrap_or(thr.te_max) * 1e6))
                .collect();
            (name.to_string(), pts)
        })
        .collect();
    line_png(
        dir,
        "tip_threshold.png",
        format!(
            "Static onset of tip contact (none up to {:.0} µm: drawn at {:.0} µm)",
            default.te_max * 1e6,
            default.te_max * 1e6
        ),
        "pinion angle φp (rad)",
        "TE (µm)",
        series,
    )
}

/// A named steady TE record: (case, ω_p in rad/s, (t in s, TE in m) samples).
type TeRun = (String, f64, Vec<(f64, f64)>);

/// One loaded or unloaded slice of a dynamic pressure waterfall.
struct DynRow {
    t: f64,
    phi_p: f64,
    pair: i64,
    zeta: f64,
    pressure: f64,
    kind: &'static str,
}

// ---- Figures: one function per figure; each writes the figure's data as CSV and draws it as
// PNG with the `plot` module.

fn png_err(e: crate::plot::PlotError) -> String {
    e.to_string()
}

/// A line chart of named series into `dir/file`.
fn line_png(
    dir: &Path,
    file: &str,
    title: String,
    x_label: &str,
    y_label: &str,
    series: Vec<(String, Vec<(f64, f64)>)>,
) -> Result<(), String> {
    let chart = plot::LineChart {
        title,
        x_label: x_label.into(),
        y_label: y_label.into(),
        series: series
            .into_iter()
            .map(|(name, points)| plot::Series { name, points, style: plot::SeriesStyle::Line })
            .collect(),
        ..plot::LineChart::default()
    };
    plot::line_chart(&dir.join(file), &chart, (1000, 600)).map_err(png_err)
}

/// Static TE over one pitch (Fig. 6 analogue): `static_te.csv` and `.png` in `dir`.
pub fn figure_static_te(
    dir: &Path,
    curve: &helical_gear_mesh::mesh::StaticCurve,
) -> Result<(), String> {
    let mut csv = String::from("phi_p_rad,ste_um,n_pairs,p_max_pa,tip_contact\n");
    for e in &curve.points {
        csv.push_str(&format!(
            "{:e},{:e},{},{:e},{}\n",
            e.phi_p,
            e.te * 1e6,
            e.outputs.n_pairs,
            e.outputs.p_max,
            e.outputs.tip_contact as u8
        ));
    }
    write_text(&dir.join("static_te.csv"), &csv)?;
    line_png(
        dir,
        "static_te.png",
        format!("Static transmission error, M = {} N·m", curve.torque),
        "pinion angle φp (rad)",
        "STE (µm)",
        vec![("STE".into(), curve.points.iter().map(|e| (e.phi_p, e.te * 1e6)).collect())],
    )
}

/// Static pressure waterfall of tooth pair 0 (Fig. 7): `waterfall_static.csv` and `.png` in `dir`.
pub fn figure_7(dir: &Path, rows: &[helical_gear_mesh::mesh::WaterfallRow]) -> Result<(), String> {
    let mut csv = String::from("phi_p_rad,ste_um,zeta,pressure_pa,tip_contact\n");
    for r in rows {
        for (z, p) in r.zeta.iter().zip(&r.pressure) {
            csv.push_str(&format!(
                "{:e},{:e},{:e},{:e},{}\n",
                r.phi_p,
                r.te * 1e6,
                z,
                p,
                r.tip_contact as u8
            ));
        }
    }
    write_text(&dir.join("waterfall_static.csv"), &csv)?;
    let w = plot::Waterfall {
        title: "Static contact pressure of tooth pair 0 (Fig. 7)".into(),
        x_label: "ζ = z/m_n".into(),
        y_label: "φp (rad)".into(),
        z_label: "contact pressure (MPa)".into(),
        curves: rows
            .iter()
            .map(|r| {
                (r.phi_p, r.zeta.iter().zip(&r.pressure).map(|(&z, &p)| (z, p * 1e-6)).collect())
            })
            .collect(),
    };
    plot::waterfall(&dir.join("waterfall_static.png"), &w, (1000, 800)).map_err(png_err)
}

/// TE_max/STE_max over the speed for the two dampings (Fig. 9): `sweep.csv`.
fn figure_9(dir: &Path, sweeps: &[&SweepSummary]) -> Result<(), String> {
    figure_9_named(dir, "sweep.csv", sweeps)
}

fn figure_9_named(dir: &Path, name: &str, sweeps: &[&SweepSummary]) -> Result<(), String> {
    let mut csv = String::from(
        "d_mesh_n_s_per_m,damping_reading,omega_p_rad_s,te_max_over_ste_max,\
         te_min_over_ste_max,separated,tip_contact,steady\n",
    );
    for s in sweeps {
        let reading = match s.damping_reading {
            DampingReading::Eq14Literal => "eq14_literal",
            DampingReading::TotalCoefficient => "total_coefficient",
        };
        for r in &s.rows {
            csv.push_str(&format!(
                "{},{reading},{:e},{:e},{:e},{},{},{}\n",
                s.d_mesh_n_s_per_m,
                r.omega_p_rad_s,
                r.te_max_over_ste_max,
                r.te_min_over_ste_max,
                r.separated as u8,
                r.tip_contact as u8,
                r.steady as u8
            ));
        }
    }
    write_text(&dir.join(name), &csv)?;
    let series = sweeps
        .iter()
        .map(|s| {
            let mut pts: Vec<(f64, f64)> =
                s.rows.iter().map(|r| (r.omega_p_rad_s, r.te_max_over_ste_max)).collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            (format!("d_mesh = {} N·s/m", s.d_mesh_n_s_per_m), pts)
        })
        .collect();
    line_png(
        dir,
        &name.replace(".csv", ".png"),
        "Maximum dynamic TE over maximum static TE (Fig. 9)".into(),
        "pinion speed ω_p (rad/s)",
        "TE_max / STE_max",
        series,
    )
}

/// The dynamic factors of the loads beside Fig. 9: per speed, the peak mesh force |F_p| and
/// the peak tooth-root stress over the steady window, each over its static peak at the same
/// torque (the quantities engineers compare with ISO 6336-1's K_v), for both dampings:
/// `dynamic_factors.csv/.png`.
fn figure_dynamic_factors(dir: &Path, sweeps: &[&SweepSummary]) -> Result<(), String> {
    let mut csv = String::from(
        "d_mesh_n_s_per_m,omega_p_rad_s,te_max_over_ste_max,mesh_force_max_over_static,\
         root_stress_max_over_static\n",
    );
    let opt = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    let mut series = Vec::new();
    for s in sweeps {
        let mut rows: Vec<&SweepRow> = s.rows.iter().collect();
        rows.sort_by(|a, b| a.omega_p_rad_s.total_cmp(&b.omega_p_rad_s));
        for r in &rows {
            csv.push_str(&format!(
                "{},{:e},{:e},{},{}\n",
                s.d_mesh_n_s_per_m,
                r.omega_p_rad_s,
                r.te_max_over_ste_max,
                opt(r.mesh_force_max_over_static),
                opt(r.root_stress_max_over_static)
            ));
        }
        let pick = |f: fn(&SweepRow) -> Option<f64>| -> Vec<(f64, f64)> {
            rows.iter().filter_map(|r| f(r).map(|v| (r.omega_p_rad_s, v))).collect()
        };
        series.push((
            format!("mesh force, d_mesh = {} N·s/m", s.d_mesh_n_s_per_m),
            pick(|r| r.mesh_force_max_over_static),
        ));
        series.push((
            format!("root stress, d_mesh = {} N·s/m", s.d_mesh_n_s_per_m),
            pick(|r| r.root_stress_max_over_static),
        ));
    }
    write_text(&dir.join("dynamic_factors.csv"), &csv)?;
    series.retain(|(_, pts)| !pts.is_empty());
    line_png(
        dir,
        "dynamic_factors.png",
        "Peak mesh force and root stress over their static peaks".into(),
        "pinion speed ω_p (rad/s)",
        "dynamic / static peak",
        series,
    )
}

/// TE over three mesh periods at the 2nd and 3rd resonance (Fig. 10): `fig10_te.csv`.
fn figure_10(dir: &Path, runs: &[TeRun], ste_max: f64) -> Result<(), String> {
    let mut csv = String::from("case,omega_p_rad_s,t_s,te_um,te_over_ste_max\n");
    for (name, w, te) in runs {
        for (t, x) in te {
            csv.push_str(&format!("{name},{w:e},{t:e},{:e},{:e}\n", x * 1e6, x / ste_max));
        }
    }
    write_text(&dir.join("fig10_te.csv"), &csv)?;
    let series = runs
        .iter()
        .map(|(name, w, te)| {
            let t0 = te.first().map_or(0.0, |p| p.0);
            (
                format!("{name}, ω_p = {w:.0} rad/s"),
                te.iter().map(|(t, x)| ((t - t0) * 1e3, x / ste_max)).collect(),
            )
        })
        .collect();
    line_png(
        dir,
        "fig10_te.png",
        "TE over three mesh periods at the 2nd and 3rd resonance (Fig. 10)".into(),
        "time from the window start (ms)",
        "TE / STE_max",
        series,
    )
}

/// Dynamic pressure waterfall at one speed (Figs. 11–13): `file`.
fn figure_11_13(
    dir: &Path,
    file: &str,
    label: &str,
    omega_p: f64,
    rows: &[DynRow],
) -> Result<(), String> {
    let mut csv = format!("# {label}, omega_p = {omega_p} rad/s, d_mesh = 100 N*s/m\n");
    csv.push_str("t_s,phi_p_rad,pair,zeta,pressure_pa,kind\n");
    for r in rows {
        csv.push_str(&format!(
            "{:e},{:e},{},{:e},{:e},{}\n",
            r.t, r.phi_p, r.pair, r.zeta, r.pressure, r.kind
        ));
    }
    write_text(&dir.join(file), &csv)?;
    // One curve per instant: pressure along ζ of the loaded slices (MPa).
    let mut curves: Vec<(f64, Vec<(f64, f64)>)> = Vec::new();
    for r in rows {
        match curves.last_mut() {
            Some((t, pts)) if *t == r.t => pts.push((r.zeta, r.pressure * 1e-6)),
            _ => curves.push((r.t, vec![(r.zeta, r.pressure * 1e-6)])),
        }
    }
    let t0 = curves.first().map_or(0.0, |c| c.0);
    for c in &mut curves {
        c.0 = (c.0 - t0) * 1e3;
        c.1.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Several pairs at one ζ: draw the largest pressure.
        c.1.dedup_by(|b, a| {
            let same = a.0 == b.0;
            if same {
                a.1 = a.1.max(b.1);
            }
            same
        });
    }
    let w = plot::Waterfall {
        title: format!("Contact pressure at ω_p = {omega_p:.0} rad/s ({label})"),
        x_label: "ζ = z/m_n".into(),
        y_label: "time (ms)".into(),
        z_label: "contact pressure (MPa)".into(),
        curves,
    };
    plot::waterfall(&dir.join(file.replace(".csv", ".png")), &w, (1000, 800)).map_err(png_err)
}

fn opt_w(w: Option<f64>) -> String {
    w.map_or("none".into(), |w| format!("{w:.0} rad/s"))
}

fn opt_iv(iv: Option<[f64; 2]>) -> String {
    iv.map_or("none".into(), |[lo, hi]| format!("{lo:.0} … {hi:.0} rad/s"))
}

/// `summary.md`: the paper against this model, the assumptions and the sensitivity table.
pub fn summary_markdown(s: &PaperSummary) -> String {
    use reference::*;
    let mut m = String::new();
    m.push_str("# Paper run: Andersson & Vedmar (2003), Table 1 gear pair\n\n");
    if s.quick {
        m.push_str("**Quick run** (coarse speed grid): indicative only.\n\n");
    }
    m.push_str("| quantity | paper | this model |\n| --- | --- | --- |\n");
    let row = |m: &mut String, a: &str, b: String, c: String| {
        m.push_str(&format!("| {a} | {b} | {c} |\n"));
    };
    row(&mut m, "max static TE", format!("{STE_MAX_UM} µm"), format!("{:.1} µm", s.ste_max_um));
    row(
        &mut m,
        "main resonance ω_crit",
        format!("{OMEGA_CRIT_RAD_S} rad/s"),
        opt_w(Some(s.omega_crit_rad_s)),
    );
    row(
        &mut m,
        "second resonance",
        format!("ω_crit/2 = {:.0} rad/s", OMEGA_CRIT_RAD_S / 2.0),
        format!("{} (ω_crit/2 = {:.0})", opt_w(s.omega_crit_2_rad_s), s.omega_crit_rad_s / 2.0),
    );
    row(
        &mut m,
        "third resonance",
        format!("ω_crit/3 = {:.0} rad/s", OMEGA_CRIT_RAD_S / 3.0),
        format!("{} (ω_crit/3 = {:.0})", opt_w(s.omega_crit_3_rad_s), s.omega_crit_rad_s / 3.0),
    );
    row(
        &mut m,
        "separation, d_mesh = 100 N·s/m",
        "an interval near ω_crit".into(),
        opt_iv(s.separation_d100_rad_s),
    );
    row(&mut m, "separation, d_mesh = 200 N·s/m", "none".into(), opt_iv(s.separation_d200_rad_s));
    row(
        &mut m,
        "tip rounding in contact, static",
        "no".into(),
        yes_no(s.tip_rounding_contact_static),
    );
    row(
        &mut m,
        "tip rounding in contact at 570 rad/s",
        "yes".into(),
        yes_no(s.tip_rounding_contact_570),
    );
    row(
        &mut m,
        "tip rounding at ω_crit·570/660",
        "yes (570 rad/s)".into(),
        format!(
            "{} ({:.0} rad/s)",
            yes_no(s.tip_rounding_contact_equivalent),
            s.omega_equivalent_570_rad_s
        ),
    );
    row(&mut m, "run time", "not given".into(), format!("{:.0} s", s.runtime_s));
    if let Some(mb) = s.peak_memory_mb {
        row(&mut m, "peak memory", "not given".into(), format!("{mb:.0} MB"));
    }
    m.push_str(&format!(
        "\nMean mesh stiffness {:.1} N/µm; mean loaded extent Σ(ζ_e − ζ_b) = {:.2} (units of \
         m_n); J_p = {:.4e} kg·m², J_g = {:.4e} kg·m²; h = {:.3} mm; {} slices.\n",
        s.mesh_stiffness_mean_n_per_um,
        s.mean_loaded_extent_mn,
        s.j_p_kgm2,
        s.j_g_kgm2,
        s.h_m * 1e3,
        s.slices
    ));
    m.push_str("\n## Sweeps\n\n| d_mesh (N·s/m) | resonances (rad/s) | peak TE_max/STE_max | separation | runs not steady |\n| --- | --- | --- | --- | --- |\n");
    for w in &s.sweeps {
        let peak = w.rows.iter().map(|r| r.te_max_over_ste_max).fold(f64::NEG_INFINITY, f64::max);
        let res: Vec<String> = w.resonances_rad_s.iter().map(|x| format!("{x:.0}")).collect();
        m.push_str(&format!(
            "| {} | {} | {peak:.3} | {} | {} |\n",
            w.d_mesh_n_s_per_m,
            res.join(", "),
            opt_iv(w.separation_rad_s),
            w.not_steady
        ));
    }
    m.push_str("\n## Dynamic pressure waterfalls (d_mesh = 100 N·s/m)\n\n| speed (rad/s) | case | tip contact | separation | p_max (MPa) | file |\n| --- | --- | --- | --- | --- | --- |\n");
    for w in &s.waterfalls {
        m.push_str(&format!(
            "| {:.0} | {} | {} | {} | {:.0} | `{}` |\n",
            w.omega_p_rad_s,
            w.label,
            yes_no(w.tip_contact),
            yes_no(w.separated),
            w.p_max_pa * 1e-6,
            w.file
        ));
    }
    m.push_str("\n## Sensitivity\n\nShort sweeps (d_mesh = 100 N·s/m) around the peak each case predicts; ω_lin is the pinion speed whose mesh frequency meets the linearised mesh mode (constant stiffness at φp = 0), a cross-check only.\n\n| case | J_p (kg·m²) | J_g (kg·m²) | ω_crit (rad/s) | ω_lin (rad/s) | k at φp = 0 (N/µm) | STE max (µm) | peak TE_max/STE_max | separation d = 100 | separation d = 200 |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for c in &s.sensitivity {
        m.push_str(&format!(
            "| {} | {:.4e} | {:.4e} | {} | {:.0} | {:.1} | {:.1} | {:.3} | {} | {} |\n",
            c.case,
            c.j_p_kgm2,
            c.j_g_kgm2,
            opt_w(c.omega_crit_rad_s),
            c.omega_linear_rad_s,
            c.mesh_stiffness_n_per_um,
            c.ste_max_um,
            c.peak_te_max_over_ste_max,
            opt_iv(c.separation_d100_rad_s),
            if c.d200_swept { opt_iv(c.separation_d200_rad_s) } else { "—".into() }
        ));
    }
    tip_contact_markdown(&mut m, s);
    deviations_markdown(&mut m, s);
    m.push_str("\n## Assumptions\n\n");
    for a in &s.assumptions {
        m.push_str(&format!("- {a}\n"));
    }
    m.push_str("\n## Stage timings\n\n| stage | s |\n| --- | --- |\n");
    for t in &s.stages {
        m.push_str(&format!("| {} | {:.1} |\n", t.stage, t.seconds));
    }
    m
}

fn opt_um(v: Option<f64>) -> String {
    v.map_or("none".into(), |v| format!("{v:.1} µm"))
}

/// Relative deviation of `ours` from `paper`, %.
fn dev_pct(ours: f64, paper: f64) -> f64 {
    100.0 * (ours / paper - 1.0)
}

/// The section of `summary.md` on the static onset of tip contact against the steady TE.
fn tip_contact_markdown(m: &mut String, s: &PaperSummary) {
    m.push_str("\n## Tip contact: static onset against the steady dynamic TE\n\n");
    m.push_str(&format!(
        "The static model (full fidelity, no damping) puts load on a tip rounding or tip edge once \
         TE reaches a threshold that depends on the mesh phase (`tip_threshold.csv`, TE searched \
         up to {:.0} µm). Default compliance: smallest threshold {} at φp = {}; reached within \
         the searched TE at {:.0} % of the mesh period, mean over the period {:.1} µm (angles \
         without it counted at the searched maximum); compliance referred to the rim: smallest \
         {}. The static TE stays below it (STE max {:.1} µm), so there is no static tip \
         contact, as in the paper.\n\n",
        s.tip_contact_te_searched_um,
        opt_um(s.tip_contact_te_threshold_um),
        s.tip_contact_te_threshold_phi_p_rad.map_or("—".into(), |p| format!("{p:.4} rad")),
        100.0 * s.tip_contact_te_threshold_found_share,
        s.tip_contact_te_threshold_mean_um,
        opt_um(s.tip_contact_te_threshold_rim_um),
        s.ste_max_um,
    ));
    m.push_str("Steady state at d_mesh = 100 N·s/m, TE sampled 60 times per mesh period over two periods; the margin is the smallest threshold(phase) − TE over the samples (≤ 0: the onset is reached); tip contact is the full model's flag at 20 samples per period.\n\n| compliance | speed (rad/s) | case | steady TE max (µm) | smallest threshold (µm) | margin (µm) | tip contact |\n| --- | --- | --- | --- | --- | --- | --- |\n");
    for t in &s.tip_margins {
        m.push_str(&format!(
            "| {} | {:.0} | {} | {:.1} | {} | {:+.1} | {} |\n",
            t.compliance,
            t.omega_p_rad_s,
            t.label,
            t.te_max_um,
            t.threshold_min_um.map_or("none".into(), |v| format!("{v:.1}")),
            t.margin_um,
            yes_no(t.tip_contact)
        ));
    }
}

/// The section of `summary.md` that explains, from this run's numbers, every result that
/// deviates from the paper by more than 10 % (or qualitatively).
fn deviations_markdown(m: &mut String, s: &PaperSummary) {
    use reference::*;
    m.push_str("\n## Deviations beyond 10 % from the paper\n\n");
    m.push_str("Generated from this run's numbers; no parameter is tuned to the paper.\n\n");
    let default = s.sensitivity.first();
    let find = |prefix: &str| s.sensitivity.iter().find(|c| c.case.starts_with(prefix));
    let rim = find("compliance referred to the rim");
    let mut listed = 0;

    // Static TE.
    let d_ste = dev_pct(s.ste_max_um, STE_MAX_UM);
    if d_ste.abs() > 10.0 {
        listed += 1;
        m.push_str(&format!(
            "- **STE max** {:.1} µm against {STE_MAX_UM} µm ({d_ste:+.0} %).\n",
            s.ste_max_um
        ));
    }

    // Main resonance.
    let w = s.omega_crit_rad_s;
    let d_w = dev_pct(w, OMEGA_CRIT_RAD_S);
    if d_w.abs() > 10.0 {
        listed += 1;
        m.push_str(&format!(
            "- **ω_crit** {w:.0} rad/s against {OMEGA_CRIT_RAD_S} rad/s ({d_w:+.0} %). The \
             static TE agrees ({:.1} against {STE_MAX_UM} µm, {d_ste:+.1} %), so the mesh \
             stiffness is not far from the paper's. Each alternative the paper leaves open \
             (short sweeps, d_mesh = 100 N·s/m; k the linearised mesh stiffness at φp = 0):\n",
            s.ste_max_um
        ));
        if let Some(d0) = default {
            for c in &s.sensitivity {
                let Some(wc) = c.omega_crit_rad_s else {
                    m.push_str(&format!("  - {}: no peak in its short sweep.\n", c.case));
                    continue;
                };
                m.push_str(&format!(
                    "  - {}: ω_crit {wc:.0} rad/s ({:+.1} % from the default, {:+.1} % from \
                     the paper), STE max {:.1} µm ({:+.0} % from the paper), k {:.1} N/µm \
                     (×{:.2}), J_p {:.3e}, J_g {:.3e} kg·m² (×{:.2}, ×{:.2}).\n",
                    c.case,
                    dev_pct(wc, w),
                    dev_pct(wc, OMEGA_CRIT_RAD_S),
                    c.ste_max_um,
                    dev_pct(c.ste_max_um, STE_MAX_UM),
                    c.mesh_stiffness_n_per_um,
                    c.mesh_stiffness_n_per_um / d0.mesh_stiffness_n_per_um,
                    c.j_p_kgm2,
                    c.j_g_kgm2,
                    c.j_p_kgm2 / d0.j_p_kgm2,
                    c.j_g_kgm2 / d0.j_g_kgm2,
                ));
            }
            let need = (OMEGA_CRIT_RAD_S / w).powi(2);
            m.push_str(&format!(
                "  - Linear estimate (ω_crit² ∝ k/J_eff): reaching {OMEGA_CRIT_RAD_S} rad/s takes \
                 a mesh stiffness ×{need:.2} with this model's inertias (STE max near \
                 {:.1} µm, {:+.0} % from the paper's), or an effective inertia ×{:.2} with this \
                 model's stiffness.\n",
                s.ste_max_um / need,
                dev_pct(s.ste_max_um / need, STE_MAX_UM),
                1.0 / need
            ));
            if let (Some(r), Some(wr)) = (rim, rim.and_then(|r| r.omega_crit_rad_s)) {
                m.push_str(&format!(
                    "  - Compliance: referring it to the rim removes the bodies' twist between \
                     bore and rim (k ×{:.2}); ω_crit moves to {wr:.0} rad/s ({:+.0} % from the \
                     paper) and the STE max to {:.1} µm ({:+.0} % from the paper).\n",
                    r.mesh_stiffness_n_per_um / d0.mesh_stiffness_n_per_um,
                    dev_pct(wr, OMEGA_CRIT_RAD_S),
                    r.ste_max_um,
                    dev_pct(r.ste_max_um, STE_MAX_UM)
                ));
            }
            // The case closest to the paper's ω_crit among those that keep the STE max within
            // 10 % of the paper's.
            let best = s
                .sensitivity
                .iter()
                .filter(|c| dev_pct(c.ste_max_um, STE_MAX_UM).abs() <= 10.0)
                .filter_map(|c| c.omega_crit_rad_s.map(|wc| (c, wc)))
                .min_by(|a, b| {
                    (a.1 - OMEGA_CRIT_RAD_S).abs().total_cmp(&(b.1 - OMEGA_CRIT_RAD_S).abs())
                });
            if let Some((c, wc)) = best {
                m.push_str(&format!(
                    "  - Of the cases whose STE max stays within 10 % of the paper's, \"{}\" \
                     comes closest to the paper's ω_crit: {wc:.0} rad/s ({:+.1} %).{}\n",
                    c.case,
                    dev_pct(wc, OMEGA_CRIT_RAD_S),
                    if dev_pct(wc, OMEGA_CRIT_RAD_S).abs() <= 10.0 {
                        " The paper's STE and ω_crit are both matched within 10 % by an \
                         inertia assumption, not by a stiffer compliance; the paper does not \
                         publish J_p, J_g."
                    } else {
                        ""
                    }
                ));
            }
        }
    }

    // Second and third resonance.
    for (name, paper_w, ours, n) in [
        ("ω_crit/2", OMEGA_CRIT_RAD_S / 2.0, s.omega_crit_2_rad_s, 2.0),
        ("ω_crit/3", OMEGA_CRIT_RAD_S / 3.0, s.omega_crit_3_rad_s, 3.0),
    ] {
        match ours {
            Some(x) if dev_pct(x, paper_w).abs() > 10.0 => {
                listed += 1;
                m.push_str(&format!(
                    "- **Resonance at {name}** {x:.0} rad/s against {paper_w:.0} rad/s \
                     ({:+.0} %); relative to this model's ω_crit it lies at {:.3}·ω_crit \
                     (paper {:.3}), so its deviation is that of ω_crit.\n",
                    dev_pct(x, paper_w),
                    x / w,
                    1.0 / n
                ));
            }
            None => {
                listed += 1;
                m.push_str(&format!(
                    "- **Resonance at {name}**: no peak within ±20 % of {:.0} rad/s.\n",
                    w / n
                ));
            }
            _ => {}
        }
    }

    // Separation.
    let te_min = |d: f64| {
        s.sweeps
            .iter()
            .find(|x| x.d_mesh_n_s_per_m == d)
            .and_then(|x| {
                x.rows.iter().min_by(|a, b| a.te_min_over_ste_max.total_cmp(&b.te_min_over_ste_max))
            })
            .map(|r| (r.te_min_over_ste_max, r.omega_p_rad_s))
    };
    let sep_cases = |d200: bool| {
        s.sensitivity
            .iter()
            .map(|c| {
                let iv = if d200 { c.separation_d200_rad_s } else { c.separation_d100_rad_s };
                if d200 && !c.d200_swept {
                    String::new()
                } else {
                    format!("{}: {}", c.case, opt_iv(iv))
                }
            })
            .filter(|x| !x.is_empty())
            .collect::<Vec<_>>()
            .join("; ")
    };
    if s.separation_d100_rad_s.is_none() {
        listed += 1;
        let closest = te_min(100.0).map_or("—".into(), |(v, w)| {
            format!("the smallest TE_min/STE_max of the sweep is {v:.3} at {w:.0} rad/s")
        });
        m.push_str(&format!(
            "- **Separation at d_mesh = 100 N·s/m**: the paper has an interval near ω_crit, this \
             model none with Eq. 14 taken literally ({closest}; separation needs < 0). By \
             case: {}.\n",
            sep_cases(false)
        ));
    }
    if let Some(iv) = s.separation_d200_rad_s {
        listed += 1;
        m.push_str(&format!(
            "- **Separation at d_mesh = 200 N·s/m**: the paper has none, this model {}. By \
             case: {}.\n",
            opt_iv(Some(iv)),
            sep_cases(true)
        ));
    }

    // Tip contact at 570 rad/s.
    if !s.tip_rounding_contact_570 {
        listed += 1;
        let at = |c: &str, lbl: &dyn Fn(&str) -> bool| {
            s.tip_margins.iter().find(|t| t.compliance == c && lbl(&t.label))
        };
        let is570 = |l: &str| l.starts_with("paper speed 570");
        let is_crit = |l: &str| l.contains("omega_crit resonance");
        let describe = |t: Option<&TipMargin>| {
            t.map_or("not run".into(), |t| {
                format!(
                    "TE max {:.1} µm, closest approach {:+.1} µm{}",
                    t.te_max_um,
                    t.margin_um,
                    if t.tip_contact { ", tip contact" } else { ", no tip contact" }
                )
            })
        };
        m.push_str(&format!(
            "- **Tip rounding in contact at 570 rad/s**: the paper has it (Fig. 13), this model \
             not. The static onset of tip contact lies at TE ≥ {} (default compliance), {:.1} × \
             the STE max. Default compliance at 570 rad/s: {}; at ω_crit = {w:.0} rad/s: {}. \
             Compliance referred to the rim (threshold {}): at 570 rad/s {}; at its ω_crit {}. \
             At this model's equivalent speed ω_crit·570/660 = {:.0} rad/s: {}.\n",
            opt_um(s.tip_contact_te_threshold_um),
            s.tip_contact_te_threshold_um.unwrap_or(f64::NAN) / s.ste_max_um,
            describe(at("default", &is570)),
            describe(at("default", &is_crit)),
            opt_um(s.tip_contact_te_threshold_rim_um),
            describe(at("rim-fixed", &is570)),
            describe(at("rim-fixed", &is_crit)),
            s.omega_equivalent_570_rad_s,
            if s.tip_rounding_contact_equivalent { "tip contact" } else { "no tip contact" }
        ));
    }
    if listed == 0 {
        m.push_str("None.\n");
    }
}

fn yes_no(b: bool) -> String {
    if b { "yes".into() } else { "no".into() }
}

/// The files [`run_paper`] writes into its output directory (the dynamic waterfalls are named
/// `waterfall_dynamic_<n>_<speed>.csv`).
pub const OUTPUT_FILES: [&str; 8] = [
    "summary.json",
    "summary.md",
    "static_te.csv",
    "waterfall_static.csv",
    "sweep.csv",
    "fig10_te.csv",
    "sweep_total_coefficient.csv",
    "tip_threshold.csv",
];
