//! The paper run: the static and dynamic results of Andersson & Vedmar (2003) reproduced with
//! this model on one gear pair (by default the paper's Table 1), written as CSV files, a
//! machine-readable `summary.json` and a human-readable `summary.md`.
//!
//! Stages ([`run_paper`]):
//!
//! 1. **Static**: the static transmission error STE over one pinion pitch (Fig. 6 analogue) and
//!    the static pressure waterfall over the whole engagement of tooth pair 0 (Fig. 7), full
//!    fidelity.
//! 2. **Sweeps**: steady TE_max/STE_max over the pinion speed for d_mesh = 100 and 200 N·s/m
//!    (Fig. 9), table fidelity, with the separation flags and the resonances. The main
//!    resonance ω_crit is the highest peak; the second and third are the peaks nearest
//!    ω_crit/2 and ω_crit/3 (each within ±20 %).
//! 3. **Fig. 10**: TE over three mesh periods of the steady state at the 2nd and 3rd resonance.
//! 4. **Dynamic waterfalls** (Figs. 11–13): at the paper's speeds 220, 330, 570 rad/s and at
//!    this model's equivalents ω_crit/3, ω_crit/2, ω_crit·570/660, the steady trajectory
//!    (table fidelity) sampled 20 times per mesh period over two periods; at each sampled
//!    state the full model is evaluated with per-slice detail.
//! 5. **Sensitivity**: ω_crit and STE_max under other pinion/gear inertias (solid discs at the
//!    root and at the reference radius), without the neighbour coupling between contact lines,
//!    and with the other reading of d_mesh ([`DampingReading`]).
//!
//! Every figure's data goes through one function per figure (`figure_*`), which writes the CSV
//! file and draws the same data as PNG (axes with units, legends) with [`crate::plot`].

use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::GearPair;
use crate::compliance::data::{CacheOptions, ComplianceData};
use crate::dynamics::model::{PHI_G, PHI_P, W_G, W_P};
use crate::dynamics::{
    Drivetrain, GearDynamics, SteadyMethod, SteadyRunOptions, Stepping, SweepOptions, SweepResult,
    mesh_stiffness, run_to_steady, simulate, sweep,
};
use crate::geometry::Member;
use crate::mesh::{
    Fidelity, GearCompliance, MeshModel, MeshOptions, MeshState, pressure_waterfall, static_curve,
};
use crate::plot;

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
    /// Speed range with separation at d_mesh = 100 N·s/m within the short sweep, rad/s.
    pub separation_d100_rad_s: Option<[f64; 2]>,
    /// Speed range with separation at d_mesh = 200 N·s/m within the short sweep, rad/s (only
    /// for the damping cases).
    pub separation_d200_rad_s: Option<[f64; 2]>,
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
    /// CSV file name.
    pub file: String,
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
        })
        .collect();
    rows.sort_by(|a, b| a.omega_p_rad_s.total_cmp(&b.omega_p_rad_s));
    let sep: Vec<f64> = rows.iter().filter(|r| r.separated).map(|r| r.omega_p_rad_s).collect();
    let separation_rad_s = match (sep.first(), sep.last()) {
        (Some(&lo), Some(&hi)) => Some([lo, hi]),
        _ => None,
    };
    let mut res: Vec<(f64, f64)> =
        result.resonances.iter().map(|r| (r.omega_p, r.te_max_over_ste_max)).collect();
    res.sort_by(|a, b| a.0.total_cmp(&b.0));
    SweepRun {
        summary: SweepSummary {
            d_mesh_n_s_per_m: d,
            damping_reading: reading,
            d_mesh_model_n_s_per_m: d_model,
            ste_max_um: result.ste.max() * 1e6,
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
    table: MeshModel,
}

impl Ctx<'_> {
    fn sweep_opts(&self, refine_runs: usize) -> SweepOptions {
        SweepOptions {
            run: SteadyRunOptions { keep_window: false, ..SteadyRunOptions::default() },
            threads: self.opts.threads,
            refine_runs,
            ..SweepOptions::default()
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn run_sweep(
        &self,
        mesh: &MeshModel,
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
    mesh: &MeshModel,
    drive: &Drivetrain,
    omega_p: f64,
    max_step: Option<f64>,
    periods: usize,
    per_period: usize,
) -> Result<Vec<(f64, [f64; 8])>, String> {
    let mut model = GearDynamics::new(mesh.clone(), *drive).map_err(mesh_err)?;
    let run = SteadyRunOptions { keep_window: false, max_step, ..SteadyRunOptions::default() };
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
    MeshState { phi_p: y[PHI_P], phi_g: y[PHI_G], w_p: y[W_P], w_g: y[W_G] }
}

/// Runs the paper job for `pair` into the directory `out` (created if missing); see the module
/// doc. Returns the summary that is also written to `out/summary.json`.
pub fn run_paper(pair: &GearPair, out: &Path, opts: &PaperOptions) -> Result<PaperSummary, String> {
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
    let full_opts = MeshOptions { slices: opts.slices, ..MeshOptions::default() };
    let build = |o: MeshOptions, p: &GearCompliance, g: &GearCompliance| {
        MeshModel::with_compliance(pair, o, p.clone(), g.clone()).map_err(mesh_err)
    };
    let mut full = build(full_opts, &cp, &cg)?;
    let geo = full.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let torque = pair.drive.torque_nm;
    let curve = static_curve(&mut full, torque, 0.0, pitch, 40, 1).map_err(mesh_err)?;
    let k_mean = curve.mean_stiffness(geo.pinion.rb);
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

    // Stage 2: table model and the two sweeps.
    let table_opts = MeshOptions { fidelity: Fidelity::Table, ..full_opts };
    let table = build(table_opts, &cp, &cg)?;
    let drive = Drivetrain::from_pair(pair).map_err(mesh_err)?;
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
    let mut full100 = full.clone();
    full100.set_d_mesh(100.0).map_err(mesh_err)?;
    full100.set_detail(true);
    let waterfalls: Vec<WaterfallSummary> = cases
        .par_iter()
        .enumerate()
        .map(|(i, (label, w))| {
            let samples = steady_samples(&t100, &ctx.drive, *w, max_step, 2, 20)?;
            let mut m = full100.clone();
            m.set_detail(true);
            let mut rows = Vec::new();
            let (mut tip, mut sep, mut p_max) = (false, false, 0.0f64);
            for (t, y) in &samples {
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
            Ok(WaterfallSummary {
                omega_p_rad_s: *w,
                label: label.clone(),
                tip_contact: tip,
                separated: sep,
                p_max_pa: p_max,
                file,
            })
        })
        .collect::<Result<_, String>>()?;
    let tip_at =
        |w: f64| waterfalls.iter().any(|x| (x.omega_p_rad_s - w).abs() < 1e-9 && x.tip_contact);
    let tip_570 = tip_at(reference::OMEGA_FIG13_RAD_S);
    let tip_eq = tip_at(w_eq);
    st.done("dynamic waterfalls (Figs. 11–13)", &format!("tip contact at 570: {tip_570}"));

    // Stage 5: sensitivity.
    let sensitivity = sensitivity(&ctx, pair, &cp, &cg, w_crit, extent, &s100, &mut st, out)?;

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
        ste_max_um: curve.max() * 1e6,
        ste_min_um: curve.min() * 1e6,
        ste_mean_um: curve.mean() * 1e6,
        tip_rounding_contact_static: curve.tip_rounding_contact(),
        mesh_stiffness_mean_n_per_um: k_mean * 1e-6,
        mean_loaded_extent_mn: extent,
        omega_crit_rad_s: w_crit,
        omega_crit_2_rad_s: w2,
        omega_crit_3_rad_s: w3,
        separation_d100_rad_s: s100.summary.separation_rad_s,
        separation_d200_rad_s: s200.summary.separation_rad_s,
        tip_rounding_contact_570: tip_570,
        tip_rounding_contact_equivalent: tip_eq,
        omega_equivalent_570_rad_s: w_eq,
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
        stages: Vec::new(),
    };
    let mut summary = summary;
    st.done("sensitivity", "");
    summary.stages = st.list.clone();
    summary.runtime_s = st.t0.elapsed().as_secs_f64();
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
    let (n, refine) = if quick { (6, 1) } else { (14, 4) };
    let mut t = ctx.table.clone();
    let k = mesh_stiffness(&mut t, 0.0, ctx.drive.torque).map_err(mesh_err)?;
    let (gp, gg) = (ctx.table.geometry().pinion.rb, ctx.table.geometry().gear.rb);
    // The mesh mode of the linearised system (the highest of the four) is excited when the
    // mesh frequency z_p·ω_p meets it: as a pinion speed, ω_mode/z_p.
    let z_p = ctx.drive.z_p as f64;
    let w_lin = |d: &Drivetrain, k: f64| d.linear_frequencies(k, gp, gg)[3] / z_p;
    let w_lin0 = w_lin(&ctx.drive, k);
    let peak = |s: &SweepSummary| {
        s.resonance_te_max_over_ste_max
            .iter()
            .zip(&s.resonances_rad_s)
            .max_by(|a, b| a.0.total_cmp(b.0))
            .map(|(p, w)| (*w, *p))
    };
    let peak_value = |s: &SweepSummary| {
        s.rows.iter().map(|r| r.te_max_over_ste_max).fold(f64::NEG_INFINITY, f64::max)
    };
    let mut cases = Vec::new();
    cases.push(SensitivityCase {
        case: "default: toothed bodies to the bore, neighbour coupling on, Eq. 14 literal".into(),
        j_p_kgm2: ctx.drive.j_p,
        j_g_kgm2: ctx.drive.j_g,
        omega_crit_rad_s: Some(w_crit),
        omega_linear_rad_s: w_lin0,
        ste_max_um: s100.summary.ste_max_um,
        separation_d100_rad_s: s100.summary.separation_rad_s,
        separation_d200_rad_s: None,
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
            separation_d100_rad_s: s.summary.separation_rad_s,
            separation_d200_rad_s: None,
            peak_te_max_over_ste_max: peak_value(&s.summary),
        });
        st.done(&format!("sensitivity: {name}"), "");
    }

    // (b) neighbour coupling off.
    let o = MeshOptions { neighbour_coupling: false, ..*ctx.table.options() };
    let nc = MeshModel::with_compliance(pair, o, cp.clone(), cg.clone()).map_err(mesh_err)?;
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
        separation_d100_rad_s: s.summary.separation_rad_s,
        separation_d200_rad_s: None,
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
        separation_d100_rad_s: a.summary.separation_rad_s,
        separation_d200_rad_s: c.summary.separation_rad_s,
        peak_te_max_over_ste_max: peak_value(&a.summary),
    });
    figure_9_named(out, "sweep_total_coefficient.csv", &[&a.summary, &c.summary])?;
    st.done("sensitivity: d_mesh as the total coefficient", "");
    Ok(cases)
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
pub fn figure_static_te(dir: &Path, curve: &crate::mesh::StaticCurve) -> Result<(), String> {
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
pub fn figure_7(dir: &Path, rows: &[crate::mesh::WaterfallRow]) -> Result<(), String> {
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
    m.push_str("\n## Sensitivity\n\nShort sweeps (d_mesh = 100 N·s/m) around the peak each case predicts; ω_lin is the pinion speed whose mesh frequency meets the linearised mesh mode (constant stiffness at φp = 0), a cross-check only.\n\n| case | J_p (kg·m²) | J_g (kg·m²) | ω_crit (rad/s) | ω_lin (rad/s) | STE max (µm) | peak TE_max/STE_max | separation d = 100 | separation d = 200 |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for c in &s.sensitivity {
        m.push_str(&format!(
            "| {} | {:.4e} | {:.4e} | {} | {:.0} | {:.1} | {:.3} | {} | {} |\n",
            c.case,
            c.j_p_kgm2,
            c.j_g_kgm2,
            opt_w(c.omega_crit_rad_s),
            c.omega_linear_rad_s,
            c.ste_max_um,
            c.peak_te_max_over_ste_max,
            opt_iv(c.separation_d100_rad_s),
            if c.case.starts_with("d_mesh") {
                opt_iv(c.separation_d200_rad_s)
            } else {
                "—".into()
            }
        ));
    }
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

fn yes_no(b: bool) -> String {
    if b { "yes".into() } else { "no".into() }
}

/// The files [`run_paper`] writes into its output directory (the dynamic waterfalls are named
/// `waterfall_dynamic_<n>_<speed>.csv`).
pub const OUTPUT_FILES: [&str; 7] = [
    "summary.json",
    "summary.md",
    "static_te.csv",
    "waterfall_static.csv",
    "sweep.csv",
    "fig10_te.csv",
    "sweep_total_coefficient.csv",
];
