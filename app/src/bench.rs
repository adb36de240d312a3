//! Work-precision benchmark: run time against error, every error measured against a converged
//! reference (the `helical-gear bench` command).
//!
//! * **Mesh evaluation.** The states sweep one pitch in 64 steps (phases (k + 0.37)/64 of the
//!   pitch, so they fall between the table's nodes) at each of three TE levels (0.53, 1.07 and
//!   1.61 × 30 µm, about the static TE at 100 N·m) at 300 rad/s, in that order, so the warm
//!   start works as along a trajectory. The reference is the full model with interpolated compliance at
//!   800 slices (the 200 → 400 change in STE is below 10⁻⁵). Each case reports the time per
//!   evaluation (the fastest of several passes over the states, single thread) and the largest
//!   relative error of M_F,p against the reference: full fidelity at 50…400 slices, with
//!   interpolated and fitted compliance, the general interpolation without the slice kernel
//!   (the assembly before [`helical_gear_mesh::compliance::interpolated::SliceInfluence`]), and the table
//!   fidelity at four sizes (with its build time), the default among them also sampled at
//!   the full model's 200 slices (the method before the table had its own sample slices).
//! * **Options**: what switching off pressure, damping or the neighbour coupling, or switching
//!   on the per-slice detail, costs or saves at 200 slices (and, for the coupling, the error
//!   it makes).
//! * **Dynamics**: from the static-equilibrium start at 500 rad/s (near the main resonance)
//!   over 30 mesh periods on the default table mesh, the maximum TE of the last five periods
//!   (sampled every T_m/16, the same instants in every run) and the largest TE difference
//!   against a 2048-steps-per-period RK4 reference: RK4 at 16…256 steps per mesh period and
//!   DOPRI5 at tolerances 10⁻⁶…10⁻¹².
//! * **Tooth deviations** ([`HuntingCase`]): the pair with the pitch errors and runouts of
//!   `docs/modifications/table1_pitch_errors.json` on the table fidelity (per-pair table,
//!   [`helical_gear_mesh::mesh::table`]): an RK4 run at 500 rad/s over a whole hunting period
//!   (z_p·z_g/gcd meshes, 1410 for Table 1; 30 in `--quick`) at 32 steps per mesh period, its
//!   wall time and mesh evaluations, the time per table evaluation at the run's states, and the
//!   torque error against full fidelity (same slices) at 200 states sampled evenly from the
//!   run (40 in `--quick`).
//! * **Drive-line units** ([`DriveUnitCase`]): the engine of the `HelicalGearDrive` FMU
//!   ([`helical_gear_mesh::dynamics::unit::DriveUnit`] of kind Drive, in-process, as the C API's
//!   `hgm_unit_advance` runs it) at 532 rad/s from its static equilibrium, communication step
//!   H = 10⁻⁴ s with the outputs read after every step: simulated seconds per wall second over
//!   1 s of drive-line time (0.01 s in `--quick`) at 32, 64, 96 and 128 RK4 sub-steps per
//!   mesh period and with DOPRI5 at rtol 1e-8 on the default table, with the TE error at the
//!   communication points against the same unit at 1024 sub-steps (largest difference over the
//!   largest |TE|); and at full
//!   fidelity (200 slices, 128 sub-steps) over 2 ms (speed only; the table's own error against
//!   the full model is `table_max_rel_err`).
//! * **A design** ([`DesignCase`]): what one design of a study costs, as
//!   `helical_gear.study.run` computes it at its defaults: the FE compliance of the pair
//!   computed afresh (both gears in parallel), the static TE, the default table (its phase
//!   rows on every core) and the speed sweep (one thread).
//!   With the cold and warm full evaluation, the table builds and the torques-only table
//!   evaluation, these are the figures a user waits for (`full_eval_us`,
//!   `full_eval_warm_us`, `table_build_s`, `table_deviation_build_s`, `fe_compliance_s`,
//!   `design_s`, `table_eval_torques_ns`); `table_back_build_s` is the default table's
//!   back-flank axis, sampled at the first state that needs it (not part of
//!   `table_build_s`); `full_eval_cold_from_zero_us` is the cold
//!   evaluation by the method before the coarse pre-solve (the load solver from q = 0),
//!   measured in the same run.
//! * **Paper run**: the wall time of the whole `paper` run, per stage.
//!
//! Timing is wall time on the calling thread; run it on an idle machine. An evaluation time is
//! the fastest of several passes; a build time (a table, the FE compliance, the design's FE and
//! table) the fastest of three builds (`build_runs`; one in `--quick`); the back-flank axis
//! (`table_back_build_s`) is sampled once, at its first use.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::paper::{PaperOptions, StageTiming, run_paper};
use crate::plot::{LineChart, Series, SeriesStyle, line_chart, write_csv};
use helical_gear_mesh::dynamics::integrators::{AbsTol, Dopri5Options};
use helical_gear_mesh::dynamics::model::{Drivetrain, GearDynamics};
use helical_gear_mesh::dynamics::simulate::{Stepping, simulate};
use helical_gear_mesh::mesh::statics::EquilibriumSettings;
use helical_gear_mesh::mesh::{
    ComplianceModel, Fidelity, Mesh, MeshOptions, MeshOutputs, MeshState, MeshTorques,
};
use helical_gear_mesh::params::{DriveLine, GearPair};

/// Options of [`run_bench`].
#[derive(Debug, Clone, PartialEq)]
pub struct BenchOptions {
    /// Small sizes and short runs (a smoke test of the benchmark, not a measurement).
    pub quick: bool,
    /// Also time the whole paper run (about a minute).
    pub paper: bool,
    /// Progress lines on stderr.
    pub progress: bool,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self { quick: false, paper: true, progress: true }
    }
}

/// One mesh-evaluation case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshCase {
    /// Family: `full interpolated`, `full interpolated, general assembly`, `full fitted` or
    /// `table`.
    pub family: String,
    /// Total slices over the simultaneous contact lines.
    pub slices: usize,
    /// Table size `phase × TE` nodes (table family only).
    pub table_size: Option<[usize; 2]>,
    /// Time per evaluation, µs.
    pub eval_us: f64,
    /// Largest |M_F,p − M_F,p,ref| / M_F,p,ref over the states.
    pub max_rel_err: f64,
    /// Mean Newton iterations per load solve (full fidelity).
    pub iterations_per_solve: Option<f64>,
    /// Mean matrix factorisations per load solve (full fidelity).
    pub factorizations_per_solve: Option<f64>,
    /// Table build time, s (table family only).
    pub build_s: Option<f64>,
    /// The slices the table sampled the full model at (`MeshOptions::table_sample_slices`;
    /// table families only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_slices: Option<usize>,
}

/// The cost of one option at 200 slices, full fidelity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OptionCase {
    /// What was changed against the defaults.
    pub option: String,
    /// Time per evaluation, µs.
    pub eval_us: f64,
    /// Time saved against the defaults, % (negative: extra cost).
    pub saving_percent: f64,
    /// Largest relative change of M_F,p against the defaults (0 for options that do not touch
    /// the torques).
    pub max_rel_change: f64,
}

/// One integration setting of the dynamics benchmark.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DynamicsCase {
    /// `rk4` or `dopri5`.
    pub integrator: String,
    /// RK4: steps per mesh period; DOPRI5: the relative tolerance.
    pub setting: f64,
    /// Wall time of the run, s.
    pub run_s: f64,
    /// Mesh evaluations.
    pub mesh_evaluations: usize,
    /// |max TE − max TE_ref| / max TE_ref over the last five mesh periods (sampled every
    /// T_m/16).
    pub max_te_rel_err: f64,
    /// max |TE − TE_ref| / max TE_ref over the same samples (the trajectory error).
    pub te_rel_err: f64,
}

/// The dynamic run over a hunting period with tooth deviations (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HuntingCase {
    /// Meshes in the run (the hunting period unless `--quick`).
    pub meshes: u64,
    /// RK4 steps per mesh period.
    pub steps_per_mesh: usize,
    /// Slices of both the table and the full reference.
    pub slices: usize,
    /// Wall time of the table build, s.
    pub build_s: f64,
    /// Wall time of the run, s.
    pub run_s: f64,
    /// Mesh evaluations of the run.
    pub mesh_evaluations: usize,
    /// Table evaluation at the sampled states of the run, ns per evaluation (the fastest of
    /// several passes).
    pub table_eval_ns: f64,
    /// Number of states sampled for the error.
    pub sampled_states: usize,
    /// max |M_F,p(table) − M_F,p(full)| / nominal torque at the sampled states.
    pub max_torque_err: f64,
    /// The same as an RMS over the sampled states.
    pub rms_torque_err: f64,
}

/// What a user waits for, measured once per run: one design of a study, split into its parts
/// (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignCase {
    /// FE compliance of both gears of a new pair (default mesh, no cache, fits included), s.
    pub fe_compliance_s: f64,
    /// Static TE over one pitch at 20 points, full fidelity, 200 slices, s.
    pub static_s: f64,
    /// Default table build (`MeshOptions`' default size) from the FE data, s.
    pub table_build_s: f64,
    /// Speed sweep of the study's defaults (12 speeds 100…1200 rad/s, RK4 at 128 steps per
    /// mesh period, 4 refinement runs per resonance, one thread), s.
    pub sweep_s: f64,
    /// The sum: one design of `helical_gear.study.run` with `static` and `sweep` at their
    /// defaults, s.
    pub design_s: f64,
}

/// Everything [`run_bench`] measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    /// Full fidelity, 200 slices, interpolated compliance, default options: µs per evaluation
    /// from a cold start (the warm start forgotten before each evaluation).
    pub full_eval_us: f64,
    /// The same along the benchmark's sweep of states, each warm-started from the one before
    /// (a trajectory's next state), µs per evaluation.
    pub full_eval_warm_us: f64,
    /// Largest relative M_F,p error of that evaluation (200 slices) against the reference.
    pub full_eval_max_rel_err: f64,
    /// Build time of the default table (200 slices, sampled at the default sample slices), s
    /// (fastest of `build_runs`).
    pub table_build_s: f64,
    /// The default table's size (phase points, TE points), `MeshOptions`' default.
    pub table_default_size: [usize; 2],
    /// Build time of the per-pair table with the hunting case's pitch deviations, s.
    pub table_deviation_build_s: f64,
    /// Sampling time of the default table's back-flank axis, done at the first state with
    /// TE < −j_t (not part of `table_build_s`), s.
    pub table_back_build_s: f64,
    /// FE compliance of a new pair (Table 1's macro-geometry, default mesh, no cache), s.
    pub fe_compliance_s: f64,
    /// One design of a study with the static and sweep analyses at their defaults, s
    /// ([`DesignCase`]).
    pub design_s: f64,
    /// Builds behind each build time (the tables, the FE compliance): the fastest of this many
    /// (`fastest_of`).
    pub build_runs: usize,
    /// The parts of that design.
    pub design: DesignCase,
    /// Table fidelity at the default size, only the torques and TE (the path of the
    /// right-hand side of Eqs. 1–4, which reads M_F,p, M_F,g, M_D,p, M_D,g and TE): ns per
    /// evaluation.
    pub table_eval_torques_ns: f64,
    /// The same with the general interpolation instead of the slice kernel, µs.
    pub full_eval_general_us: f64,
    /// The cold evaluation of `full_eval_us` with the load solver started from q = 0 instead
    /// of the coarse pre-solve (the method before it), µs.
    pub full_eval_cold_from_zero_us: f64,
    /// Table fidelity at the default size: ns per evaluation.
    pub table_eval_ns: f64,
    /// Table fidelity at the default size: largest relative M_F,p error against the reference.
    pub table_max_rel_err: f64,
    /// Wall time of the whole paper run, s (`None` when not run).
    pub paper_runtime_s: Option<f64>,
    /// The paper run's stages.
    pub paper_stages: Vec<StageTiming>,
    /// Slices of the converged reference.
    pub reference_slices: usize,
    /// Number of benchmark states.
    pub states: usize,
    /// Mesh-evaluation cases (the work-precision rows).
    pub mesh: Vec<MeshCase>,
    /// Options at 200 slices.
    pub options: Vec<OptionCase>,
    /// Dynamics cases.
    pub dynamics: Vec<DynamicsCase>,
    /// The dynamic run over a hunting period with tooth deviations.
    pub hunting: HuntingCase,
    /// Drive-line unit throughput (the Drive FMU's engine in-process).
    pub drive_units: Vec<DriveUnitCase>,
    /// Logical cores of the machine.
    pub cores: usize,
    /// CPU model (from /proc/cpuinfo where available).
    pub cpu: String,
    /// Crate version.
    pub version: String,
    /// The commit measured: `git rev-parse --short HEAD` in the working directory, with
    /// `-dirty` when tracked files had uncommitted changes ("unknown" without git).
    pub commit: String,
    /// When the run started (UTC), `YYYY-MM-DD HH:MM`.
    pub date_utc: String,
    /// The machine's load averages over 1, 5 and 15 minutes (`/proc/loadavg`) when the run
    /// started ("unknown" where it cannot be read): other work on the machine makes every time
    /// longer.
    pub load_average: String,
}

/// Runs the benchmark on `pair` driven by `drive` (tables sized for its torque; the paper's
/// drive line is [`DriveLine::paper_table1`]), its compliance from the embedded data or the
/// cache.
pub fn run_bench(
    pair: &GearPair,
    drive: &DriveLine,
    opts: &BenchOptions,
) -> Result<BenchReport, String> {
    let say = |s: &str| {
        if opts.progress {
            eprintln!("bench: {s}");
        }
    };
    // The machine and the code as the run starts (later edits to the tree are not measured).
    let (commit, date_utc, load_average) = (git_commit(), utc_now(), load_average());
    let q = opts.quick;
    let err = |e: helical_gear_mesh::mesh::MeshError| e.to_string();
    let base = MeshOptions::default().sized_for(drive);
    let reference_slices = if q { 200 } else { 800 };
    let (n_phase, min_pass_s) = if q { (6, 0.02) } else { (64, 1.0) };

    let mut reference =
        Mesh::new(pair, MeshOptions { slices: reference_slices, ..base }).map_err(err)?;
    let states = bench_states(&reference, n_phase);
    say(&format!("reference: {reference_slices} slices, {} states", states.len()));
    let ref_out = states
        .iter()
        .map(|s| reference.evaluate_full(s).map(|o| o.m_f_p))
        .collect::<Result<Vec<_>, _>>()
        .map_err(err)?;
    let rel_err = |v: &[MeshOutputs]| {
        v.iter().zip(&ref_out).map(|(o, r)| ((o.m_f_p - r) / r).abs()).fold(0.0, f64::max)
    };

    let mut mesh = Vec::new();
    let full_slices: &[usize] = if q { &[50, 100] } else { &[50, 100, 200, 400] };
    let fitted_slices: &[usize] = if q { &[50] } else { &[50, 100, 200] };
    let mut full_eval_us = f64::NAN;
    let mut full_eval_warm_us = f64::NAN;
    let mut full_eval_max_rel_err = f64::NAN;
    let mut full_eval_general_us = f64::NAN;
    let mut full_eval_cold_from_zero_us = f64::NAN;
    let general_at = if q { 100 } else { 200 };
    for (family, compliance, list) in [
        ("full interpolated", ComplianceModel::Interpolated, full_slices),
        ("full fitted", ComplianceModel::Fitted, fitted_slices),
    ] {
        for &slices in list {
            let mut m = Mesh::new(pair, MeshOptions { slices, compliance, ..base }).map_err(err)?;
            let (us, out) = time_full(&mut m, &states, min_pass_s)?;
            let st = m.stats();
            let per = |x: usize| Some(x as f64 / st.solves.max(1) as f64);
            mesh.push(MeshCase {
                family: family.into(),
                slices,
                table_size: None,
                eval_us: us,
                max_rel_err: rel_err(&out),
                iterations_per_solve: per(st.iterations),
                factorizations_per_solve: per(st.factorizations),
                build_s: None,
                sample_slices: None,
            });
            say(&format!("{family}, {slices} slices: {us:.1} µs, error {:.2e}", rel_err(&out)));
            if compliance == ComplianceModel::Interpolated && slices == general_at {
                if slices == 200 || q {
                    full_eval_warm_us = us;
                    full_eval_max_rel_err = rel_err(&out);
                    let (cold, _) = time_with(&mut m, &states, min_pass_s, |m, s| {
                        m.forget_warm_start();
                        m.evaluate_full(s)
                    })?;
                    full_eval_us = cold;
                    say(&format!("full, {slices} slices, cold start: {cold:.1} µs"));
                    m.use_coarse_start(false);
                    let (zero, _) = time_with(&mut m, &states, min_pass_s, |m, s| {
                        m.forget_warm_start();
                        m.evaluate_full(s)
                    })?;
                    m.use_coarse_start(true);
                    full_eval_cold_from_zero_us = zero;
                    say(&format!("full, {slices} slices, cold start from q = 0: {zero:.1} µs"));
                }
                m.use_slice_kernel(false);
                m.reset_stats();
                let (us, out) = time_full(&mut m, &states, min_pass_s)?;
                full_eval_general_us = us;
                mesh.push(MeshCase {
                    family: "full interpolated, general assembly".into(),
                    slices,
                    table_size: None,
                    eval_us: us,
                    max_rel_err: rel_err(&out),
                    iterations_per_solve: None,
                    factorizations_per_solve: None,
                    build_s: None,
                    sample_slices: None,
                });
                say(&format!("general assembly, {slices} slices: {us:.1} µs"));
            }
        }
    }

    // Table fidelity.
    // The default size (`MeshOptions`) among them.
    let default_size = default_table_size();
    let mut sizes: Vec<[usize; 2]> =
        if q { vec![[16, 12]] } else { vec![[16, 12], [32, 24], [64, 48], [128, 96]] };
    // The default among them, in order of nodes.
    if !q && !sizes.contains(&default_size) {
        sizes.push(default_size);
        sizes.sort_by_key(|[p, t]| p * t);
    }
    let table_slices = if q { 50 } else { 200 };
    let mut table_eval_ns = f64::NAN;
    let mut table_max_rel_err = f64::NAN;
    let mut table_build_s = f64::NAN;
    let mut table_back_build_s = f64::NAN;
    let mut table_eval_torques_ns = f64::NAN;
    let mut default_table = None;
    // Each size at the default sample slices, and the default size sampled at the full
    // model's slices (the method before the table had its own sample slices), for the
    // side-by-side row.
    let default_samples = MeshOptions::default().table_slices;
    let mut cases: Vec<([usize; 2], usize, &str)> =
        sizes.iter().map(|&size| (size, default_samples, "table")).collect();
    if !q {
        cases.push((default_size, table_slices, "table, sampled at the full model's slices"));
    }
    for ([p, t], samples, family) in cases {
        let o = MeshOptions {
            fidelity: Fidelity::Table,
            slices: table_slices,
            table_phase_points: p,
            table_te_points: t,
            table_slices: samples,
            ..base
        };
        let (mut m, build_s) = fastest_of(build_runs(q), || Mesh::new(pair, o)).map_err(err)?;
        let (us, out) = time_eval(&mut m, &states, min_pass_s)?;
        let e = rel_err(&out);
        let sampled = o.table_sample_slices();
        say(&format!(
            "table {p}×{t} sampled at {sampled} slices: {:.0} ns, error {e:.2e}, built in \
             {build_s:.1} s",
            us * 1e3
        ));
        if family == "table" && ([p, t] == default_size || q) {
            table_eval_ns = us * 1e3;
            table_max_rel_err = e;
            table_build_s = build_s;
            // The back-flank axis, sampled now (the benchmark states are on the driving flanks).
            if let Some(t) = m.table() {
                t.te_range();
                table_back_build_s = t.back_build_seconds().unwrap_or(f64::NAN);
            }
            // What a right-hand side reads: the torques and TE (the other fields of the
            // outputs are not produced for it).
            let (us, _) = time_with(&mut m, &states, min_pass_s, |m, s| {
                m.torques(s).map(|(o, _)| [o.m_f_p, o.m_f_g, o.m_d_p, o.m_d_g, o.te])
            })?;
            table_eval_torques_ns = us * 1e3;
            say(&format!("table {p}×{t}, torques and TE only: {:.0} ns", us * 1e3));
            default_table = Some(m);
        }
        mesh.push(MeshCase {
            family: family.into(),
            slices: table_slices,
            table_size: Some([p, t]),
            eval_us: us,
            max_rel_err: e,
            iterations_per_solve: None,
            factorizations_per_solve: None,
            build_s: Some(build_s),
            sample_slices: Some(sampled),
        });
    }

    // Options.
    let opt_slices = if q { 50 } else { 200 };
    let mut options = Vec::new();
    let mut default_out = Vec::new();
    let mut default_us = 0.0;
    let cases: [(&str, MeshOptions); 5] = [
        ("defaults (pressure, damping on; detail off)", MeshOptions { slices: opt_slices, ..base }),
        ("pressure off", MeshOptions { slices: opt_slices, pressure: false, ..base }),
        ("damping off", MeshOptions { slices: opt_slices, damping: false, ..base }),
        ("per-slice detail on", MeshOptions { slices: opt_slices, detail: true, ..base }),
        (
            "neighbour coupling off (changes the model)",
            MeshOptions { slices: opt_slices, neighbour_coupling: false, ..base },
        ),
    ];
    for (k, (name, o)) in cases.into_iter().enumerate() {
        let mut m = Mesh::new(pair, o).map_err(err)?;
        let (us, out) = time_full(&mut m, &states, min_pass_s)?;
        if k == 0 {
            default_us = us;
            default_out = out.clone();
        }
        let change = out
            .iter()
            .zip(&default_out)
            .map(|(a, b)| ((a.m_f_p - b.m_f_p) / b.m_f_p).abs())
            .fold(0.0, f64::max);
        say(&format!("option {name}: {us:.1} µs"));
        options.push(OptionCase {
            option: name.into(),
            eval_us: us,
            saving_percent: 100.0 * (1.0 - us / default_us),
            max_rel_change: change,
        });
    }

    // Dynamics.
    let table = default_table.ok_or("no table model")?;
    let drive_units = drive_unit_cases(pair, drive, &table, q, &say)?;
    let dynamics = dynamics_cases(pair, drive, table, q, &say)?;
    let hunting = hunting_case(pair, drive, q, min_pass_s, &say)?;
    let design = design_case(pair, drive, q, &say)?;

    // Paper run.
    let (paper_runtime_s, paper_stages) = if opts.paper {
        say("paper run (quiet)");
        let dir = std::env::temp_dir().join(format!("helical-gear-bench-{}", std::process::id()));
        let po = PaperOptions { quick: q, progress: false, ..PaperOptions::default() };
        let s = run_paper(pair, drive, &dir, &po);
        let _ = std::fs::remove_dir_all(&dir);
        let s = s?;
        say(&format!("paper run: {:.1} s", s.runtime_s));
        (Some(s.runtime_s), s.stages)
    } else {
        (None, Vec::new())
    };

    Ok(BenchReport {
        full_eval_us,
        full_eval_warm_us,
        full_eval_max_rel_err,
        table_build_s,
        table_default_size: default_size,
        table_deviation_build_s: hunting.build_s,
        table_back_build_s,
        fe_compliance_s: design.fe_compliance_s,
        design_s: design.design_s,
        build_runs: build_runs(q),
        design,
        table_eval_torques_ns,
        full_eval_general_us,
        full_eval_cold_from_zero_us,
        table_eval_ns,
        table_max_rel_err,
        paper_runtime_s,
        paper_stages,
        reference_slices,
        states: states.len(),
        mesh,
        options,
        dynamics,
        hunting,
        drive_units,
        cores: cores(),
        cpu: cpu_model(),
        version: env!("CARGO_PKG_VERSION").into(),
        commit,
        date_utc,
        load_average,
    })
}

/// The short hash of `HEAD`, with `-dirty` when tracked files differ from it ("unknown" when
/// git or the repository is missing).
pub fn git_commit() -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short", "HEAD"]) {
        Some(hash) if !hash.is_empty() => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty { format!("{hash}-dirty") } else { hash }
        }
        _ => "unknown".into(),
    }
}

/// The current time (UTC) as `YYYY-MM-DD HH:MM`, from the system clock (civil from days).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let z = secs.div_euclid(86_400) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    let (hh, mm) = (secs.rem_euclid(86_400) / 3600, secs.rem_euclid(3600) / 60);
    format!("{y:04}-{m:02}-{d:02} {hh:02}:{mm:02}")
}

/// The load averages over 1, 5 and 15 minutes from `/proc/loadavg`, or "unknown".
/// The 1-minute load average of `load_average` (the format of [`load_average`]: three numbers
/// or "unknown") when it exceeds half of `cores`: more than half the cores were busy with other
/// work, so wall-clock times measure that work too. `None` when the machine was quieter or the
/// load is unknown.
pub fn loaded(load_average: &str, cores: f64) -> Option<f64> {
    let load1: f64 = load_average.split_whitespace().next()?.parse().ok()?;
    (load1 > 0.5 * cores).then_some(load1)
}

/// The logical cores of this machine (1 where they cannot be read).
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// The benchmark states: three TE levels, each a sweep of `n_phase` phases over one pitch (a
/// warm-started sequence like a trajectory's).
fn bench_states(m: &Mesh, n_phase: usize) -> Vec<MeshState> {
    let geo = m.geometry();
    let pitch = geo.pinion.angular_pitch();
    let w_p = 300.0;
    let w_g = -w_p * geo.pinion.rb / geo.gear.rb;
    let mut v = Vec::new();
    for f in [0.53, 1.07, 1.61] {
        for k in 0..n_phase {
            let phi_p = (k as f64 + 0.37) / n_phase as f64 * pitch;
            let phi_g = geo.phi_g_for_te(phi_p, f * 30e-6);
            v.push(MeshState { phi_p, phi_g, w_p, w_g, ..Default::default() });
        }
    }
    v
}

/// µs per [`Mesh::evaluate_full`] (fastest pass of several lasting together at least
/// `min_s`), and the outputs of the first pass.
fn time_full(
    m: &mut Mesh,
    states: &[MeshState],
    min_s: f64,
) -> Result<(f64, Vec<MeshOutputs>), String> {
    time_with(m, states, min_s, |m, s| m.evaluate_full(s))
}

/// µs per [`Mesh::evaluate`] (the configured fidelity), as [`time_full`].
fn time_eval(
    m: &mut Mesh,
    states: &[MeshState],
    min_s: f64,
) -> Result<(f64, Vec<MeshOutputs>), String> {
    time_with(m, states, min_s, |m, s| m.evaluate(s))
}

/// µs per call of `f` (fastest pass of several lasting together at least `min_s`), and the
/// results of the first pass. Each timed result is handed to `black_box` by reference, so the
/// time is that of producing it, without copies of it made by the measurement.
fn time_with<T>(
    m: &mut Mesh,
    states: &[MeshState],
    min_s: f64,
    f: impl Fn(&mut Mesh, &MeshState) -> Result<T, helical_gear_mesh::mesh::MeshError>,
) -> Result<(f64, Vec<T>), String> {
    let out = states.iter().map(|s| f(m, s)).collect::<Result<Vec<_>, _>>();
    let out = out.map_err(|e| e.to_string())?;
    m.reset_stats();
    let (mut best, mut total, mut passes) = (f64::INFINITY, 0.0, 0);
    while (total < min_s || passes < 3) && passes < 10_000 {
        let t = Instant::now();
        for s in states {
            let r = f(m, s);
            if let Err(e) = &r {
                return Err(e.to_string());
            }
            std::hint::black_box(&r);
        }
        let dt = t.elapsed().as_secs_f64();
        best = best.min(dt);
        total += dt;
        passes += 1;
    }
    Ok((best / states.len() as f64 * 1e6, out))
}

/// Builds with `build` `runs` times (at least once) and returns the last result and the
/// fastest build's wall time, s: the time of an undisturbed build, as the evaluation timings
/// are the fastest of several passes (a single build on a machine with other work reads
/// whatever that work took from it).
fn fastest_of<T, E>(runs: usize, mut build: impl FnMut() -> Result<T, E>) -> Result<(T, f64), E> {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let r = build()?;
        best = best.min(t0.elapsed().as_secs_f64());
        last = Some(r);
    }
    Ok((last.expect("at least one build"), best))
}

/// Builds per timed build figure ([`fastest_of`]): 3, one in `--quick`.
fn build_runs(quick: bool) -> usize {
    if quick { 1 } else { 3 }
}

/// The dynamics cases on the table mesh `table` (see the module docs).
fn dynamics_cases(
    pair: &GearPair,
    drive: &DriveLine,
    table: Mesh,
    quick: bool,
    say: &dyn Fn(&str),
) -> Result<Vec<DynamicsCase>, String> {
    let drive = Drivetrain::from_pair(pair, drive).map_err(|e| e.to_string())?;
    let mut dynm = GearDynamics::new(table, drive).map_err(|e| e.to_string())?;
    let omega = 500.0;
    let start = dynm
        .static_start(0.0, omega, &EquilibriumSettings::default())
        .map_err(|e| e.to_string())?;
    let tm = dynm.drive().mesh_period(omega);
    let periods = if quick { 6.0 } else { 30.0 };
    let t_end = periods * tm;
    let window = t_end - 5.0 * tm;
    // Every run is sampled on the common grid t_i = i·T_m/16 of the last five mesh periods
    // (RK4 steps and the DOPRI5 output interval divide T_m/16), so the discrete maximum does
    // not depend on the sampling of the run.
    let grid = |t: f64| (t / tm * 16.0 - (t / tm * 16.0).round()).abs() < 1e-6;
    let mut run = |stepping: &Stepping| -> Result<(Vec<f64>, f64, usize), String> {
        let e0 = dynm.mesh_evaluations();
        let t = Instant::now();
        let tr = simulate(&mut dynm, &start.y, t_end, stepping).map_err(|e| e.to_string())?;
        let secs = t.elapsed().as_secs_f64();
        let te = tr
            .time
            .iter()
            .zip(&tr.outputs)
            .filter(|(t, _)| **t >= window * (1.0 - 1e-12) && grid(**t))
            .map(|(_, o)| o.te)
            .collect();
        Ok((te, secs, dynm.mesh_evaluations() - e0))
    };
    let max_of = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let n_ref = if quick { 256 } else { 2048 };
    let (te_ref, ..) = run(&Stepping::Rk4 { dt: tm / n_ref as f64 })?;
    let max_ref = max_of(&te_ref);
    let errors = |te: &[f64]| -> Result<(f64, f64), String> {
        if te.len() != te_ref.len() {
            return Err(format!(
                "dynamics: {} samples against {} of the reference",
                te.len(),
                te_ref.len()
            ));
        }
        let traj = te.iter().zip(&te_ref).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        Ok((((max_of(te) - max_ref) / max_ref).abs(), traj / max_ref))
    };
    say(&format!("dynamics reference: RK4 {n_ref} steps per mesh period"));
    let mut cases = Vec::new();
    let steps: &[usize] = if quick { &[16, 64] } else { &[16, 32, 64, 128, 256] };
    for &n in steps {
        let (te, secs, evals) = run(&Stepping::Rk4 { dt: tm / n as f64 })?;
        let (max_te_rel_err, te_rel_err) = errors(&te)?;
        cases.push(DynamicsCase {
            integrator: "rk4".into(),
            setting: n as f64,
            run_s: secs,
            mesh_evaluations: evals,
            max_te_rel_err,
            te_rel_err,
        });
    }
    let tols: &[f64] = if quick { &[1e-6] } else { &[1e-6, 1e-8, 1e-10, 1e-12] };
    for &tol in tols {
        let options =
            Dopri5Options { rtol: tol, atol: AbsTol::Scalar(tol * 1e-3), ..Default::default() };
        let stepping = Stepping::Dopri5 { options, output_dt: Some(tm / 256.0) };
        let (te, secs, evals) = run(&stepping)?;
        let (max_te_rel_err, te_rel_err) = errors(&te)?;
        cases.push(DynamicsCase {
            integrator: "dopri5".into(),
            setting: tol,
            run_s: secs,
            mesh_evaluations: evals,
            max_te_rel_err,
            te_rel_err,
        });
    }
    for c in &cases {
        say(&format!(
            "dynamics {} {:e}: {:.2} ms, error of max TE {:.2e}, of TE {:.2e}",
            c.integrator,
            c.setting,
            c.run_s * 1e3,
            c.max_te_rel_err,
            c.te_rel_err
        ));
    }
    Ok(cases)
}

/// The pitch errors and runouts of the benchmark with tooth deviations (the file
/// `docs/modifications/table1_pitch_errors.json`, scaled to the pair's tooth numbers: the
/// 30 pinion values repeated, the runouts kept).
fn bench_deviations(pair: &GearPair) -> helical_gear_mesh::modifications::Modifications {
    let sample =
        GearPair::from_json(include_str!("../../docs/modifications/table1_pitch_errors.json"))
            .map(|p| p.modifications)
            .unwrap_or_default();
    let mut m = pair.modifications.clone();
    let e = &sample.pinion.pitch_deviations_m;
    if !e.is_empty() {
        m.pinion.pitch_deviations_m = (0..pair.z_p as usize).map(|i| e[i % e.len()]).collect();
    }
    m.pinion.runout_m = sample.pinion.runout_m;
    m.pinion.runout_phase_rad = sample.pinion.runout_phase_rad;
    m.gear.runout_m = sample.gear.runout_m;
    m.gear.runout_phase_rad = sample.gear.runout_phase_rad;
    m
}

/// One drive-line unit row (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveUnitCase {
    /// Mesh fidelity: `table` or `full`.
    pub fidelity: &'static str,
    /// Integrator inside the unit: `rk4` or `dopri5`.
    pub integrator: &'static str,
    /// RK4 sub-steps per mesh period (0 for DOPRI5).
    pub steps_per_mesh_period: u32,
    /// DOPRI5 relative tolerance (absolute 1e-6 of it); `None` for RK4.
    pub rtol: Option<f64>,
    /// Simulated drive-line time, s.
    pub simulated_s: f64,
    /// Wall time, s.
    pub wall_s: f64,
    /// Simulated seconds per wall-clock second.
    pub realtime_factor: f64,
    /// TE error against the unit at 1024 sub-steps per mesh period (table rows).
    pub te_rel_err: Option<f64>,
}

/// The drive-line unit rows (see the module docs).
fn drive_unit_cases(
    pair: &GearPair,
    drive: &DriveLine,
    table: &Mesh,
    quick: bool,
    say: &dyn Fn(&str),
) -> Result<Vec<DriveUnitCase>, String> {
    use helical_gear_mesh::dynamics::unit::{DriveUnit, UnitKind, UnitStepping};
    let drive = Drivetrain::from_pair(pair, drive).map_err(|e| e.to_string())?;
    let (omega, h) = (532.0, 1e-4);
    let run = |mesh: Mesh, stepping: UnitStepping, n: usize| -> Result<(Vec<f64>, f64), String> {
        let e = |e: helical_gear_mesh::dynamics::DynamicsError| e.to_string();
        let mut u = DriveUnit::new(UnitKind::Drive, mesh, drive, stepping).map_err(e)?;
        u.start_static(0.0, omega, &EquilibriumSettings::default()).map_err(e)?;
        let mut te = Vec::with_capacity(n);
        let t = Instant::now();
        for _ in 0..n {
            u.advance(h).map_err(e)?;
            te.push(u.outputs().map_err(e)?.mesh.te);
        }
        Ok((te, t.elapsed().as_secs_f64()))
    };
    let n = if quick { 100 } else { 10_000 };
    say("drive-line units: reference (1024 sub-steps per mesh period)");
    let rk4 = |steps| UnitStepping::Rk4 { steps_per_mesh_period: steps };
    let (te_ref, _) = run(table.clone(), rk4(1024), n)?;
    let scale = te_ref.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut cases = Vec::new();
    let rows = [32, 64, 96, 128].map(|n| (rk4(n), n, None)).into_iter().chain([(
        UnitStepping::Dopri5 { rtol: 1e-8, atol: 1e-14 },
        0,
        Some(1e-8),
    )]);
    for (stepping, steps, rtol) in rows {
        let (te, wall) = run(table.clone(), stepping, n)?;
        let err = te.iter().zip(&te_ref).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale;
        let label = rtol.map_or(format!("RK4 {steps} sub-steps"), |r| format!("DOPRI5 rtol {r:e}"));
        say(&format!(
            "drive-line unit, table, {label}: {:.2}× real time, TE error {err:.1e}",
            n as f64 * h / wall
        ));
        cases.push(DriveUnitCase {
            fidelity: "table",
            integrator: if rtol.is_some() { "dopri5" } else { "rk4" },
            steps_per_mesh_period: steps,
            rtol,
            simulated_s: n as f64 * h,
            wall_s: wall,
            realtime_factor: n as f64 * h / wall,
            te_rel_err: Some(err),
        });
    }
    let full = Mesh::new(pair, MeshOptions::default()).map_err(|e| e.to_string())?;
    let n_full = if quick { 2 } else { 20 };
    let (_, wall) = run(full, rk4(128), n_full)?;
    say(&format!("drive-line unit, full: {:.5}× real time", n_full as f64 * h / wall));
    cases.push(DriveUnitCase {
        fidelity: "full",
        integrator: "rk4",
        steps_per_mesh_period: 128,
        rtol: None,
        simulated_s: n_full as f64 * h,
        wall_s: wall,
        realtime_factor: n_full as f64 * h / wall,
        te_rel_err: None,
    });
    Ok(cases)
}

/// The default table's size (phase points, TE points) of [`MeshOptions`].
pub fn default_table_size() -> [usize; 2] {
    let o = MeshOptions::default();
    [o.table_phase_points, o.table_te_points]
}

/// The hunting-period case (see the module docs).
fn hunting_case(
    pair: &GearPair,
    drive: &DriveLine,
    quick: bool,
    min_pass_s: f64,
    say: &dyn Fn(&str),
) -> Result<HuntingCase, String> {
    let err = |e: helical_gear_mesh::mesh::MeshError| e.to_string();
    let p = GearPair { modifications: bench_deviations(pair), ..pair.clone() };
    let slices = if quick { 50 } else { 200 };
    let o = MeshOptions { fidelity: Fidelity::Table, slices, ..MeshOptions::default() }
        .sized_for(drive);
    let (table, build_s) = fastest_of(build_runs(quick), || Mesh::new(&p, o)).map_err(err)?;
    let mut full = Mesh::new(&p, MeshOptions { slices, ..MeshOptions::default() }).map_err(err)?;
    let meshes = if quick {
        30
    } else {
        helical_gear_mesh::modifications::Modifications::hunting_meshes(p.z_p, p.z_g)
    };
    let line = drive;
    let drive = Drivetrain::from_pair(&p, line).map_err(|e| e.to_string())?;
    let mut dynm = GearDynamics::new(table, drive).map_err(|e| e.to_string())?;
    let omega = 500.0;
    let start = dynm
        .static_start(0.0, omega, &EquilibriumSettings::default())
        .map_err(|e| e.to_string())?;
    let tm = dynm.drive().mesh_period(omega);
    let steps_per_mesh = 32;
    let e0 = dynm.mesh_evaluations();
    let t = Instant::now();
    let tr = simulate(
        &mut dynm,
        &start.y,
        meshes as f64 * tm,
        &Stepping::Rk4 { dt: tm / steps_per_mesh as f64 },
    )
    .map_err(|e| e.to_string())?;
    let run_s = t.elapsed().as_secs_f64();
    let mesh_evaluations = dynm.mesh_evaluations() - e0;
    let n_samples = if quick { 40 } else { 200 };
    let stride = (tr.states.len() / n_samples).max(1);
    let states: Vec<MeshState> = tr
        .states
        .iter()
        .step_by(stride)
        .take(n_samples)
        .map(|y| MeshState { phi_p: y[1], phi_g: y[2], w_p: y[5], w_g: y[6], ..Default::default() })
        .collect();
    let mut table = dynm.into_mesh();
    let (us, out) = time_eval(&mut table, &states, min_pass_s)?;
    let nominal = line.torque_nm.abs().max(1.0);
    let (mut max_err, mut sq) = (0.0f64, 0.0);
    for (s, o) in states.iter().zip(&out) {
        let f = full.evaluate_full(s).map_err(err)?;
        let e = (o.m_f_p - f.m_f_p).abs() / nominal;
        max_err = max_err.max(e);
        sq += e * e;
    }
    let case = HuntingCase {
        meshes,
        steps_per_mesh,
        slices,
        build_s,
        run_s,
        mesh_evaluations,
        table_eval_ns: us * 1e3,
        sampled_states: states.len(),
        max_torque_err: max_err,
        rms_torque_err: (sq / states.len().max(1) as f64).sqrt(),
    };
    say(&format!(
        "hunting period with pitch errors: {} meshes in {:.2} s ({} evaluations), table {:.0} \
         ns/eval, torque error max {:.2e}, rms {:.2e} of nominal",
        case.meshes,
        case.run_s,
        case.mesh_evaluations,
        case.table_eval_ns,
        case.max_torque_err,
        case.rms_torque_err
    ));
    Ok(case)
}

/// One design as `helical_gear.study.run` computes it at its defaults (see [`DesignCase`]): the
/// FE compliance of `pair` computed afresh (default mesh; `--quick`: coarse), the static TE at
/// 20 points over one pitch (full fidelity, 200 slices; `--quick`: 50), the default table
/// (`--quick`: 16 × 12) and the sweep over 12 speeds from 100 to 1200 rad/s (`--quick`: 3) at
/// 128 RK4 steps per mesh period, 4 refinement runs, on one thread.
fn design_case(
    pair: &GearPair,
    drive: &DriveLine,
    q: bool,
    say: &dyn Fn(&str),
) -> Result<DesignCase, String> {
    use helical_gear_mesh::compliance::data::ComplianceData;
    use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
    use helical_gear_mesh::compliance::influence_fe::DEFAULT_DEPTH_MN;
    use helical_gear_mesh::dynamics::simulate::{SteadyMethod, SteadyRunOptions};
    use helical_gear_mesh::dynamics::steady::steady_max_periods;
    use helical_gear_mesh::dynamics::sweep::{SweepOptions, sweep};
    use helical_gear_mesh::mesh::statics::static_curve;
    let err = |e: helical_gear_mesh::mesh::MeshError| e.to_string();
    let density = if q { GearMeshDensity::coarse() } else { GearMeshDensity::default() };
    let h = DEFAULT_DEPTH_MN * pair.normal_module_m;
    let (data, fe_compliance_s) =
        fastest_of(build_runs(q), || ComplianceData::compute(pair, &density, h, false))
            .map_err(|e| e.to_string())?;
    say(&format!("design: FE compliance {fe_compliance_s:.2} s"));

    let slices = if q { 50 } else { 200 };
    let base = MeshOptions { slices, ..MeshOptions::default() }.sized_for(drive);
    let t0 = Instant::now();
    let mut full = Mesh::from_data(pair, base, &data).map_err(err)?;
    let pitch = full.geometry().pinion.angular_pitch();
    static_curve(&mut full, drive.torque_nm, 0.0, pitch, 20, 1).map_err(err)?;
    let static_s = t0.elapsed().as_secs_f64();

    let size = if q { [16, 12] } else { default_table_size() };
    let o = MeshOptions {
        fidelity: Fidelity::Table,
        table_phase_points: size[0],
        table_te_points: size[1],
        ..base
    };
    let (mut table, table_build_s) =
        fastest_of(build_runs(q), || Mesh::from_data(pair, o, &data)).map_err(err)?;
    table.set_d_mesh(pair.d_mesh_n_s_per_m).map_err(err)?;

    let n = if q { 3 } else { 12 };
    let speeds: Vec<f64> = (0..n).map(|i| 100.0 + 1100.0 * i as f64 / (n - 1) as f64).collect();
    let period = pair.modifications.period_meshes(pair.z_p, pair.z_g) as usize;
    let opts = SweepOptions {
        run: SteadyRunOptions {
            method: SteadyMethod::Rk4 { steps_per_period: 128 },
            max_periods: steady_max_periods(if q { 300 } else { 3000 }, period),
            period_meshes: period,
            keep_window: false,
            ..SteadyRunOptions::default()
        },
        threads: Some(1),
        refine_runs: if q { 0 } else { 4 },
        progress: false,
        ..SweepOptions::default()
    };
    let train = Drivetrain::from_pair(pair, drive).map_err(|e| e.to_string())?;
    let t0 = Instant::now();
    sweep(&table, &train, &speeds, &opts).map_err(|e| e.to_string())?;
    let sweep_s = t0.elapsed().as_secs_f64();
    let design_s = fe_compliance_s + static_s + table_build_s + sweep_s;
    say(&format!(
        "design: static {static_s:.2} s, table {table_build_s:.2} s, sweep {sweep_s:.2} s, \
         total {design_s:.2} s"
    ));
    Ok(DesignCase { fe_compliance_s, static_s, table_build_s, sweep_s, design_s })
}

/// The CPU's model name from `/proc/cpuinfo` ("unknown" where it cannot be read).
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Writes `bench_mesh.csv`, `bench_options.csv`, `bench_dynamics.csv`, `bench.json` and the
/// log–log plots `bench_mesh.png` (error against time per evaluation) and
/// `bench_dynamics.png` (error in max TE against run time) into `dir`; returns the paths.
pub fn write_bench_files(r: &BenchReport, dir: &Path) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let e = |e: crate::plot::PlotError| e.to_string();
    let mut files = Vec::new();
    let family_code = |f: &str| match f {
        "full interpolated" => 0.0,
        "full interpolated, general assembly" => 1.0,
        "full fitted" => 2.0,
        "table" => 3.0,
        _ => 4.0,
    };
    let p = dir.join("bench_mesh.csv");
    write_csv(
        &p,
        &["family_code", "slices", "table_phase", "table_te", "eval_us", "max_rel_err", "build_s"],
        r.mesh.iter().map(|c| {
            let [tp, tt] = c.table_size.unwrap_or([0, 0]);
            vec![
                family_code(&c.family),
                c.slices as f64,
                tp as f64,
                tt as f64,
                c.eval_us,
                c.max_rel_err,
                c.build_s.unwrap_or(0.0),
            ]
        }),
    )
    .map_err(e)?;
    files.push(p);
    let p = dir.join("bench_dynamics.csv");
    write_csv(
        &p,
        &["rk4_1_dopri5_2", "setting", "run_s", "mesh_evaluations", "max_te_rel_err", "te_rel_err"],
        r.dynamics.iter().map(|c| {
            vec![
                if c.integrator == "rk4" { 1.0 } else { 2.0 },
                c.setting,
                c.run_s,
                c.mesh_evaluations as f64,
                c.max_te_rel_err,
                c.te_rel_err,
            ]
        }),
    )
    .map_err(e)?;
    files.push(p);
    let p = dir.join("bench.json");
    let json = serde_json::to_string_pretty(r).map_err(|e| e.to_string())?;
    std::fs::write(&p, json).map_err(|e| format!("cannot write {}: {e}", p.display()))?;
    files.push(p);

    // Errors of 0 (exact agreement) cannot be drawn on a log axis: floor them at 1e-16.
    let pt = |x: f64, y: f64| (x, y.max(1e-16));
    let series = |name: &str, family: &str| Series {
        name: name.into(),
        points: r
            .mesh
            .iter()
            .filter(|c| c.family == family)
            .map(|c| pt(c.eval_us, c.max_rel_err))
            .collect(),
        style: SeriesStyle::LinePoints,
    };
    let chart = LineChart {
        title: "Mesh evaluation: error of M_F,p against time per evaluation".into(),
        x_label: "time per evaluation (µs)".into(),
        y_label: format!("max relative error vs {} slices", r.reference_slices),
        series: vec![
            series("full, interpolated compliance (50…400 slices)", "full interpolated"),
            series("full, fitted compliance (50…200 slices)", "full fitted"),
            series(
                "full, general interpolation (no slice kernel)",
                "full interpolated, general assembly",
            ),
            series("table (16×12 … 128×96 nodes)", "table"),
        ],
        x_log: true,
        y_log: true,
        // Room above the data for the legend.
        y_range: headroom(r.mesh.iter().map(|c| c.max_rel_err)),
        ..LineChart::default()
    };
    let p = dir.join("bench_mesh.png");
    line_chart(&p, &chart, (1000, 700)).map_err(e)?;
    files.push(p);
    let dseries = |name: &str, integ: &str| Series {
        name: name.into(),
        points: r
            .dynamics
            .iter()
            .filter(|c| c.integrator == integ)
            .map(|c| pt(c.run_s, c.max_te_rel_err))
            .collect(),
        style: SeriesStyle::LinePoints,
    };
    let chart = LineChart {
        title: "Dynamics at 500 rad/s (table mesh): error of max TE against run time".into(),
        x_label: "run time, 30 mesh periods (s)".into(),
        y_label: "relative error of max TE".into(),
        series: vec![
            dseries("RK4, 16…256 steps per mesh period", "rk4"),
            dseries("DOPRI5, rtol 1e-6…1e-12", "dopri5"),
        ],
        x_log: true,
        y_log: true,
        y_range: headroom(r.dynamics.iter().map(|c| c.max_te_rel_err)),
        ..LineChart::default()
    };
    let p = dir.join("bench_dynamics.png");
    line_chart(&p, &chart, (1000, 700)).map_err(e)?;
    files.push(p);
    Ok(files)
}

/// A logarithmic y range from half the smallest to 30 times the largest positive value (room
/// for the legend above the data); `None` without positive values.
fn headroom(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    (hi > 0.0).then(|| (0.5 * lo.max(1e-16), 30.0 * hi))
}
