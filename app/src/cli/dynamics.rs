//! The `simulate` and `sweep` subcommands: the 4-DOF model of Eqs. 1–4 driven by the mesh
//! model of the gear pair.
//!
//! `simulate` prints one trajectory from the static-equilibrium start at the nominal speed
//! (see `helical_gear_mesh::dynamics::model`): per output time the eight states, TE and the
//! four mesh torques. With `--dt` and `--method rk4` (the default) it takes fixed RK4 steps of
//! exactly that size with the mesh evaluated at every stage state: the reference that a
//! co-simulation master running RK4 over the FMU reproduces.
//!
//! `sweep` runs the speeds of a uniform grid to the steady state in parallel and prints
//! TE_max/STE_max per speed, the separation flags and the located resonances. Progress goes to
//! stderr, one line per run.

use std::io::Write;

use clap::{Args, ValueEnum};
use helical_gear_mesh::dynamics::bodies::ForceStats;
use helical_gear_mesh::dynamics::bodies::{
    REACTION_NAMES, SupportedDynamics, simulate_supported, support_force_stats, supported_rk4_step,
};
use helical_gear_mesh::dynamics::simulate::{check_samples, default_rk4_step};
use helical_gear_mesh::dynamics::steady::steady_max_periods;
use helical_gear_mesh::dynamics::supported_sweep::{SupportedSweepOptions, sweep_supported};
use helical_gear_mesh::dynamics::{
    DEFAULT_STEPS_PER_MESH_PERIOD, Dopri5Options, Drivetrain, GearDynamics, MAX_REFINE_RUNS,
    MAX_TRAJECTORY_SAMPLES, SteadyMethod, SteadyRunOptions, Stepping, SweepOptions, simulate,
    sweep,
};
use helical_gear_mesh::mesh::Supports;
use helical_gear_mesh::mesh::{
    EquilibriumSettings, Fidelity, Friction, Mesh, MeshError, MeshOptions, MeshTorques,
};
use helical_gear_mesh::results::{
    SupportedRunRecord, SupportedSweepRecord, SweepRecord, SweepRunRecord, TrajectoryRecord,
    TrajectoryRunRecord,
};
use helical_gear_mesh::{DriveLine, GearPair};

use super::{Common, DriveArg, FrictionArg, load_drive, load_friction, load_params};

/// Mesh evaluation fidelity on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CliFidelity {
    /// Contact search and load solve at every evaluation.
    Full,
    /// Interpolation in a (mesh phase, TE) table built once from the full model.
    Table,
}

impl CliFidelity {
    fn fidelity(self) -> Fidelity {
        match self {
            CliFidelity::Full => Fidelity::Full,
            CliFidelity::Table => Fidelity::Table,
        }
    }

    fn name(self) -> &'static str {
        match self {
            CliFidelity::Full => "full",
            CliFidelity::Table => "table",
        }
    }
}

/// Integrator of `simulate`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CliMethod {
    /// Classical RK4, fixed step.
    Rk4,
    /// Adaptive Dormand–Prince 5(4).
    Dopri5,
}

/// Arguments of `helical-gear simulate`.
#[derive(Args, Clone)]
pub struct SimulateArgs {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    drive: DriveArg,
    /// Nominal pinion speed ω_p, rad/s (|ω_p| ≤ 1e5, negative: running backwards; low speeds are integrated with the step of the
    /// fastest mode); the gear turns at −ω_p·z_p/z_g.
    #[arg(long)]
    omega_p: f64,
    /// End time, s (> 0). With `--dt` and RK4 a whole number of steps.
    #[arg(long)]
    t_end: f64,
    /// RK4: the fixed step, s (default: the smaller of the mesh period / 128 and the period of
    /// the fastest linearised mode / 32, shortened to divide --t-end; a step outside RK4's
    /// stability region is refused).
    /// DOPRI5: the output interval (default: every accepted step).
    #[arg(long)]
    dt: Option<f64>,
    /// Integrator.
    #[arg(long, value_enum, default_value_t = CliMethod::Rk4)]
    method: CliMethod,
    /// Print CSV (one header line, one row per output time) instead of text.
    #[arg(long, conflicts_with = "json")]
    csv: bool,
    /// Pinion angle φp at t = 0, rad.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    phi_p0: f64,
    /// Mesh damping d_mesh, N·s/m (default: the parameters' `d_mesh_n_s_per_m`).
    #[arg(long)]
    d_mesh: Option<f64>,
    /// Mesh evaluation fidelity.
    #[arg(long, value_enum, default_value_t = CliFidelity::Full)]
    fidelity: CliFidelity,
    #[command(flatten)]
    friction: FrictionArg,
    /// DOPRI5 relative tolerance.
    #[arg(long, default_value_t = 1e-8)]
    rtol: f64,
    /// DOPRI5 absolute tolerance, for every component of the relative state (φp, the shaft
    /// twists and TE and their rates: rad, m, rad/s, m/s).
    #[arg(long, default_value_t = 1e-12)]
    atol: f64,
    /// Elastic supports of the gear bodies (JSON of docs/gear-bodies.md): both bodies move on
    /// them, coupled to Eqs. 1–4 (RK4 with a whole number of steps per mesh period from the
    /// coupled modes; at table fidelity the table adds its pose sensitivities); adds the
    /// poses, the support forces and their mesh-order amplitudes.
    #[arg(long, value_name = "FILE")]
    supports: Option<std::path::PathBuf>,
    /// Mesh orders of the support-force amplitudes (with --supports).
    #[arg(long, default_value_t = 3)]
    orders: usize,
    /// With --supports: write the support-force spectrum (`support_spectrum.csv`,
    /// `support_spectrum.png`: the mesh-order amplitudes of the six support forces) into DIR.
    #[arg(long, value_name = "DIR", requires = "supports")]
    out: Option<std::path::PathBuf>,
}

/// Arguments of `helical-gear sweep`.
#[derive(Args, Clone)]
pub struct SweepArgs {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    drive: DriveArg,
    /// Lowest pinion speed, rad/s (> 0).
    #[arg(long)]
    from: f64,
    /// Highest pinion speed, rad/s (≥ --from).
    #[arg(long)]
    to: f64,
    /// Number of speeds, uniformly spaced from --from to --to.
    #[arg(long)]
    points: usize,
    /// Mesh damping d_mesh, N·s/m (default: the parameters' `d_mesh_n_s_per_m`).
    #[arg(long)]
    d_mesh: Option<f64>,
    /// Mesh evaluation fidelity (the table is built once and shared by all workers).
    #[arg(long, value_enum, default_value_t = CliFidelity::Table)]
    fidelity: CliFidelity,
    #[command(flatten)]
    friction: FrictionArg,
    /// RK4 steps per mesh period (raised at low speeds to resolve the fastest mode).
    #[arg(long, default_value_t = DEFAULT_STEPS_PER_MESH_PERIOD)]
    steps_per_period: usize,
    /// Cap on the mesh periods of one run; a run that reaches it is reported as not steady.
    #[arg(long, default_value_t = 3000)]
    max_periods: usize,
    /// Extra runs per resonance peak (golden-section refinement).
    #[arg(long, default_value_t = 6)]
    refine_runs: usize,
    /// Smallest prominence of a TE_max/STE_max peak that counts as a resonance.
    #[arg(long, default_value_t = 0.005)]
    min_prominence: f64,
    /// Worker threads (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Elastic supports of the gear bodies (JSON of docs/gear-bodies.md): the same speeds are
    /// also run with both bodies on them (`supports` in the JSON: TE_max/STE_max, the support
    /// forces, the coupled modes and the speeds where the mesh meets them).
    #[arg(long, value_name = "FILE")]
    supports: Option<std::path::PathBuf>,
    /// With --supports: write `sweep_supports.csv` and `sweep_supports.png` (TE_max/STE_max on
    /// rigid bearings and on the supports) into DIR.
    #[arg(long, value_name = "DIR", requires = "supports")]
    out: Option<std::path::PathBuf>,
}

/// The mesh model the dynamics run with: the full Andersson–Vedmar [`Mesh`] of `pair`
/// (its `d_mesh_n_s_per_m` is the mesh damping) at `fidelity` with the mesh friction
/// `friction`, a table sized for the drive line `drive`.
fn build_mesh(
    pair: &GearPair,
    drive: &DriveLine,
    fidelity: CliFidelity,
    friction: Friction,
) -> Result<impl MeshTorques + Clone + Send + use<>, MeshError> {
    let options = MeshOptions { fidelity: fidelity.fidelity(), friction, ..MeshOptions::default() };
    Mesh::new(pair, options.sized_for(drive))
}

/// Parameters with `--d-mesh` applied, the drivetrain of `--drive`, the mesh model with the
/// friction of `--friction` (building it may take a while: a note goes to stderr) and that
/// friction option.
#[allow(clippy::type_complexity)]
fn setup(
    common: &Common,
    drive: &DriveArg,
    d_mesh: Option<f64>,
    fidelity: CliFidelity,
    friction: &FrictionArg,
) -> Result<(GearPair, Drivetrain, impl MeshTorques + Clone + Send + use<>, Friction), String> {
    let friction = load_friction(friction)?;
    let mut pair = load_params(common)?;
    if let Some(d) = d_mesh {
        if !(d.is_finite() && d >= 0.0) {
            return Err(format!("--d-mesh = {d} N·s/m: allowed finite and >= 0"));
        }
        pair.d_mesh_n_s_per_m = d;
    }
    let line = load_drive(drive)?;
    let drive = Drivetrain::from_pair(&pair, &line).map_err(|e| e.to_string())?;
    eprintln!("building the mesh model ({} fidelity)…", fidelity.name());
    let t0 = std::time::Instant::now();
    let mesh =
        build_mesh(&pair, &line, fidelity, friction).map_err(|e| format!("mesh model: {e}"))?;
    eprintln!("mesh model ready in {:.1} s", t0.elapsed().as_secs_f64());
    Ok((pair, drive, mesh, friction))
}

/// Writes the static TE of the start `te_start` and the range of the run's TE `te` (m), in µm.
fn write_te_range(w: &mut impl Write, te_start: f64, te: &[f64]) -> Result<(), String> {
    let lo = te.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = te.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    writeln!(
        w,
        "  static TE at the start {:.4} µm; TE over the run {:.4} … {:.4} µm",
        te_start * 1e6,
        lo * 1e6,
        hi * 1e6
    )
    .map_err(io_err)
}

fn io_err(e: std::io::Error) -> String {
    format!("cannot write to stdout: {e}")
}

/// `helical-gear simulate`.
pub fn simulate_cmd(a: &SimulateArgs) -> Result<(), String> {
    // Standstill is an operating point: the start is the static equilibrium at rest and the
    // step comes from the fastest mode (`limits`), not from the infinite mesh period.
    if !(a.omega_p.is_finite()
        && a.omega_p.abs() <= helical_gear_mesh::mesh::validity::MAX_SPEED_RAD_S)
    {
        return Err(format!(
            "--omega-p = {:.4e}: allowed finite, |ω_p| <= 1e5 rad/s (the largest nominal speed; \
             negative: running backwards)",
            a.omega_p
        ));
    }
    if !(a.t_end.is_finite() && a.t_end > 0.0) {
        return Err(format!("--t-end = {}: allowed finite and > 0 (s)", a.t_end));
    }
    if let Some(dt) = a.dt
        && !(dt.is_finite() && dt > 0.0 && dt <= a.t_end)
    {
        return Err(format!("--dt = {dt}: allowed finite, > 0 and <= --t-end (s)"));
    }
    if let (Some(dt), CliMethod::Rk4) = (a.dt, a.method) {
        let n = (a.t_end / dt).round();
        if (n * dt - a.t_end).abs() > 1e-9 * a.t_end {
            return Err(format!(
                "--t-end = {} is not a whole number of RK4 steps --dt = {dt} (within 1e-9)",
                a.t_end
            ));
        }
    }
    if let Some(path) = &a.supports {
        return simulate_supported_cmd(a, path);
    }
    // The record's size is known before the mesh is built (limits::MAX_TRAJECTORY_SAMPLES).
    if let Some(dt) = a.dt {
        check_samples((a.t_end / dt).floor() + 1.0, "lower --t-end or raise --dt")
            .map_err(|e| e.to_string())?;
    }
    let (_, drive, mesh, friction) = setup(&a.common, &a.drive, a.d_mesh, a.fidelity, &a.friction)?;
    let t_m = drive.mesh_period(a.omega_p);
    let mut model = GearDynamics::new(mesh, drive).map_err(|e| e.to_string())?;
    let stepping = match a.method {
        CliMethod::Rk4 => {
            let dt = match a.dt {
                Some(dt) => dt,
                // The step rule of `limits`: mesh period and fastest mode, divides --t-end.
                None => default_rk4_step(&mut model, a.omega_p, a.phi_p0, a.t_end)
                    .map_err(|e| e.to_string())?,
            };
            Stepping::Rk4 { dt }
        }
        CliMethod::Dopri5 => {
            let mut options = Dopri5Options::with_tolerances(a.rtol, a.atol);
            // At rest T_m = ∞: no bound from the mesh period.
            options.h_max = t_m.is_finite().then_some(t_m);
            options.max_steps = MAX_TRAJECTORY_SAMPLES;
            Stepping::Dopri5 { options, output_dt: a.dt }
        }
    };
    // With friction the start is the quasi-static state at the nominal speed (its friction
    // torques inside M_F); without, the state at rest (the speed changes nothing).
    let settings = EquilibriumSettings {
        w_p: if friction.is_on() { a.omega_p } else { 0.0 },
        ..EquilibriumSettings::default()
    };
    let start = model
        .static_start(a.phi_p0, a.omega_p, &settings)
        .map_err(|e| format!("static start: {e}"))?;
    let t0 = std::time::Instant::now();
    let tr = simulate(&mut model, &start.y, a.t_end, &stepping).map_err(|e| e.to_string())?;
    let seconds = t0.elapsed().as_secs_f64();

    let record = TrajectoryRecord::new(&tr);
    record.check_finite()?;
    if !start.te.is_finite() {
        return Err(format!("result field te_static_start_m = {} is not finite", start.te));
    }
    let columns = record.columns();

    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    let dt_used = match &stepping {
        Stepping::Rk4 { dt } => Some(*dt),
        Stepping::Dopri5 { output_dt, .. } => *output_dt,
    };
    let method = match a.method {
        CliMethod::Rk4 => "rk4",
        CliMethod::Dopri5 => "dopri5",
    };
    if a.common.json {
        let names = columns.iter().map(|c| c.0.to_string()).collect();
        let out = TrajectoryRunRecord {
            trajectory: record,
            omega_p_rad_s: a.omega_p,
            t_end_s: a.t_end,
            method: method.into(),
            dt_s: dt_used,
            fidelity: a.fidelity.name().into(),
            // At rest the mesh period is infinite: null.
            mesh_period_s: t_m.is_finite().then_some(t_m),
            te_static_start_m: start.te,
            columns: names,
            supports: None,
        };
        out.check_finite()?;
        let text = serde_json::to_string(&out).map_err(|e| format!("JSON: {e}"))?;
        writeln!(w, "{text}").map_err(io_err)?;
    } else if a.csv {
        let header: Vec<&str> = columns.iter().map(|c| c.0).collect();
        writeln!(w, "{}", header.join(",")).map_err(io_err)?;
        for i in 0..tr.time.len() {
            let row: Vec<String> = columns.iter().map(|c| format!("{:e}", c.1[i])).collect();
            writeln!(w, "{}", row.join(",")).map_err(io_err)?;
        }
    } else {
        let te: &[f64] = record.mesh_column("te_m");
        writeln!(
            w,
            "Eqs. 1–4 from the static equilibrium at ω_p = {} rad/s ({method}, {} fidelity): \
             {} output times to {} s, {} steps, {} mesh evaluations, {seconds:.2} s",
            a.omega_p,
            a.fidelity.name(),
            tr.time.len(),
            a.t_end,
            tr.steps,
            tr.mesh_evaluations
        )
        .map_err(io_err)?;
        write_te_range(&mut w, start.te, te)?;
        let loss: &[f64] = record.mesh_column("p_loss_w");
        if loss.iter().any(|&x| x > 0.0) {
            let mean = loss.iter().sum::<f64>() / loss.len() as f64;
            writeln!(w, "  mesh friction loss P_loss: mean over the output times {mean:.3} W")
                .map_err(io_err)?;
        }
        writeln!(
            w,
            "  {:>12} {:>12} {:>12} {:>12} {:>12}",
            "time_s", "te_um", "m_f_p_nm", "w_p_rad_s", "w_g_rad_s"
        )
        .map_err(io_err)?;
        let stride = tr.time.len().div_ceil(40).max(1);
        for i in (0..tr.time.len()).step_by(stride) {
            writeln!(
                w,
                "  {:12.6e} {:12.5} {:12.5} {:12.5} {:12.5}",
                tr.time[i],
                te[i] * 1e6,
                tr.outputs[i].m_f_p,
                tr.states[i][5],
                tr.states[i][6]
            )
            .map_err(io_err)?;
        }
        writeln!(w, "  (every {stride}th row; --csv or --json for all)").map_err(io_err)?;
    }
    w.flush().map_err(io_err)
}

/// Most mesh orders of `simulate --supports --orders`.
const MAX_ORDERS: usize = 64;

/// `helical-gear simulate --supports FILE`: the gear bodies on their supports
/// ([`helical_gear_mesh::dynamics::bodies`]).
fn simulate_supported_cmd(a: &SimulateArgs, path: &std::path::Path) -> Result<(), String> {
    if a.method != CliMethod::Rk4 {
        return Err("--supports integrates with RK4 only (--method rk4)".into());
    }
    if a.dt.is_some() {
        return Err("--dt with --supports: the step is chosen from the coupled modes as a whole \
                    number of steps per mesh period; leave --dt out"
            .into());
    }
    if a.orders > MAX_ORDERS {
        return Err(format!("--orders = {}: allowed 0 … {MAX_ORDERS}", a.orders));
    }
    // Read and checked before the mesh is built; the shaft form needs the pair's face width.
    let b = load_params(&a.common)?.face_width_m;
    let supports = super::read_json_as("--supports", path, |t| Supports::from_json_for(t, b))?;
    let (_, drive, mesh, friction) = setup(&a.common, &a.drive, a.d_mesh, a.fidelity, &a.friction)?;
    if friction.is_on() {
        return Err("--supports with --friction: not supported yet (the friction forces' pose \
                    sensitivities are not derived); leave one out"
            .into());
    }
    let mut model = SupportedDynamics::new(mesh, drive, supports).map_err(|e| e.to_string())?;
    let start = model
        .static_start(a.phi_p0, a.omega_p, &EquilibriumSettings::default())
        .map_err(|e| format!("static start: {e}"))?;
    let modes = model.linear_modes(&start).map_err(|e| format!("coupled modes: {e}"))?;
    let dt = supported_rk4_step(&drive, &modes, a.omega_p);
    let t_m = drive.mesh_period(a.omega_p);
    let spp = if t_m.is_finite() { (t_m / dt).round() as usize } else { 0 };
    let n_steps = (a.t_end / dt).ceil().max(1.0);
    check_samples(n_steps + 1.0, "lower --t-end").map_err(|e| e.to_string())?;
    let n_steps = n_steps as usize;
    let t0 = std::time::Instant::now();
    let tr =
        simulate_supported(&mut model, &start.y, dt, n_steps, &modes).map_err(|e| e.to_string())?;
    let seconds = t0.elapsed().as_secs_f64();
    let t_end = n_steps as f64 * dt;
    let stats = support_force_stats(&tr, spp, a.orders);
    let window = n_steps.checked_div(spp).unwrap_or(0);

    if let (Some(dir), Some(s)) = (&a.out, &stats) {
        write_support_spectrum(dir, 1.0 / t_m, s)?;
    }
    let record = TrajectoryRecord::supported(&tr);
    record.check_finite()?;
    let columns = record.columns();
    let summary = SupportedRunRecord::new(&tr, &modes, model.supports(), spp, a.orders);
    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    if a.common.json {
        let out = TrajectoryRunRecord {
            trajectory: record.clone(),
            omega_p_rad_s: a.omega_p,
            t_end_s: t_end,
            method: "rk4".into(),
            dt_s: Some(dt),
            fidelity: a.fidelity.name().into(),
            mesh_period_s: t_m.is_finite().then_some(t_m),
            te_static_start_m: start.te,
            columns: columns.iter().map(|c| c.0.to_string()).collect(),
            supports: Some(summary),
        };
        out.check_finite()?;
        let text = serde_json::to_string(&out).map_err(|e| format!("JSON: {e}"))?;
        writeln!(w, "{text}").map_err(io_err)?;
    } else if a.csv {
        let header: Vec<&str> = columns.iter().map(|c| c.0).collect();
        writeln!(w, "{}", header.join(",")).map_err(io_err)?;
        for i in 0..tr.drive.time.len() {
            let row: Vec<String> = columns.iter().map(|c| format!("{:e}", c.1[i])).collect();
            writeln!(w, "{}", row.join(",")).map_err(io_err)?;
        }
    } else {
        let te = record.mesh_column("te_m");
        writeln!(
            w,
            "Eqs. 1–4 with both gear bodies on their supports from the static equilibrium at \
             ω_p = {} rad/s (rk4, {} fidelity): {} steps of {dt:.4e} s to {t_end:.6e} s, {} \
             mesh evaluations, {seconds:.2} s",
            a.omega_p,
            a.fidelity.name(),
            n_steps,
            tr.drive.mesh_evaluations
        )
        .map_err(io_err)?;
        write_te_range(&mut w, start.te, te)?;
        let f: Vec<String> = summary
            .modes_hz
            .iter()
            .zip(&summary.modes_damping_ratio)
            .map(|(f, z)| format!("{f:.1} Hz (ζ {z:.3})"))
            .collect();
        writeln!(w, "  linearised coupled modes: {}", f.join(", ")).map_err(io_err)?;
        let over = if window == 0 {
            "the whole run".to_string()
        } else {
            format!("the last {window} mesh periods")
        };
        writeln!(w, "  support forces on the bodies (N, N·m) over {over}:").map_err(io_err)?;
        writeln!(w, "  {:>8} {:>12} {:>12}  mesh orders 1…", "", "mean", "peak-peak")
            .map_err(io_err)?;
        for name in REACTION_NAMES {
            if let Some(s) = summary.support_forces.get(name) {
                let o: Vec<String> = s.orders.iter().map(|x| format!("{x:.3}")).collect();
                writeln!(
                    w,
                    "  {name:>8} {:12.3} {:12.3}  {}",
                    s.reaction_mean_n,
                    s.reaction_peak_to_peak_n,
                    o.join(" ")
                )
                .map_err(io_err)?;
            }
        }
        for b in &summary.bearings {
            writeln!(
                w,
                "  bearing {} of the {} shaft at z = {:.4} m: force on the shaft mean ({:.2}, \
                 {:.2}, {:.2}) N, peak to peak ({:.2}, {:.2}, {:.2}) N",
                b.bearing,
                b.shaft,
                b.z_m,
                b.reaction_mean_n[0],
                b.reaction_mean_n[1],
                b.reaction_mean_n[2],
                b.reaction_peak_to_peak_n[0],
                b.reaction_peak_to_peak_n[1],
                b.reaction_peak_to_peak_n[2]
            )
            .map_err(io_err)?;
        }
        if stats.is_none() {
            writeln!(w, "  (the run is shorter than one mesh period: no statistics)")
                .map_err(io_err)?;
        }
    }
    w.flush().map_err(io_err)
}

/// `helical-gear sweep`.
pub fn sweep_cmd(a: &SweepArgs) -> Result<(), String> {
    if !(a.from.is_finite() && a.from > 0.0 && a.to.is_finite() && a.to >= a.from) {
        return Err(format!(
            "--from = {} and --to = {}: allowed finite, 0 < from <= to (rad/s)",
            a.from, a.to
        ));
    }
    if !(1..=100_000).contains(&a.points) || (a.points == 1) != (a.from == a.to) {
        return Err(format!(
            "--points = {}: allowed 1 (with --from = --to) or 2 … 100000 (with --from < --to)",
            a.points
        ));
    }
    // Known before the model is built (the library checks it again).
    if a.refine_runs > MAX_REFINE_RUNS {
        return Err(format!(
            "--refine-runs = {}: at most {MAX_REFINE_RUNS} runs per resonance (each a run to \
             the steady state; the bracket shrinks by 0.618 per run)",
            a.refine_runs
        ));
    }
    let speeds: Vec<f64> = if a.points == 1 {
        vec![a.from]
    } else {
        (0..a.points).map(|i| a.from + (a.to - a.from) * i as f64 / (a.points - 1) as f64).collect()
    };
    // Every argument is checked before the mesh (a table build takes up to a minute).
    let request = SweepOptions {
        threads: a.threads,
        refine_runs: a.refine_runs,
        min_prominence: a.min_prominence,
        ..SweepOptions::default()
    };
    helical_gear_mesh::dynamics::check_sweep_request(&speeds, &request)
        .map_err(|e| e.to_string())?;
    let b = load_params(&a.common)?.face_width_m;
    let supports = a
        .supports
        .as_ref()
        .map(|path| super::read_json_as("--supports", path, |t| Supports::from_json_for(t, b)))
        .transpose()?;
    let (pair, drive, mesh, friction) =
        setup(&a.common, &a.drive, a.d_mesh, a.fidelity, &a.friction)?;
    if supports.is_some() && friction.is_on() {
        return Err("--supports with --friction: not supported yet (the friction forces' pose \
                    sensitivities are not derived); leave one out"
            .into());
    }
    // Tooth deviations: steady over their period (at least three periods integrated).
    let period = pair.modifications.period_meshes(pair.z_p, pair.z_g) as usize;
    let opts = SweepOptions {
        run: SteadyRunOptions {
            method: SteadyMethod::Rk4 { steps_per_period: a.steps_per_period },
            max_periods: steady_max_periods(a.max_periods, period),
            period_meshes: period,
            keep_window: false,
            ..SteadyRunOptions::default()
        },
        threads: a.threads,
        refine_runs: a.refine_runs,
        min_prominence: a.min_prominence,
        progress: true,
        ..SweepOptions::default()
    };
    let r = sweep(&mesh, &drive, &speeds, &opts).map_err(|e| e.to_string())?;
    let ste_max = r.ste.max();
    let supported = match &supports {
        None => None,
        Some(s) => {
            eprintln!("the same speeds with the gear bodies on their supports…");
            let o = SupportedSweepOptions {
                max_periods: a.max_periods,
                threads: a.threads,
                ..SupportedSweepOptions::default()
            };
            let sw = sweep_supported(&mesh, &drive, s, &speeds, &o).map_err(|e| e.to_string())?;
            Some(SupportedSweepRecord::new(&sw, drive.z_p, a.min_prominence))
        }
    };
    let record = SweepRunRecord {
        sweep: SweepRecord::new(&r, &speeds),
        d_mesh_n_s_per_m: pair.d_mesh_n_s_per_m,
        fidelity: a.fidelity.name().into(),
        steps_per_period: a.steps_per_period,
        supports: supported,
    };
    if let (Some(dir), Some(s)) = (&a.out, &record.supports) {
        write_sweep_supports(dir, &speeds, &record.sweep.te_max_over_ste_max, s)?;
    }
    record.check_finite()?;
    let warnings = &record.sweep.warnings;
    let out = serde_json::to_string(&record).map_err(|e| format!("JSON: {e}"))?;
    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    if a.common.json {
        writeln!(w, "{out}").map_err(io_err)?;
    } else {
        writeln!(
            w,
            "Speed sweep, d_mesh = {} N·s/m, {} fidelity, STE_max = {:.3} µm, {:.1} s",
            pair.d_mesh_n_s_per_m,
            a.fidelity.name(),
            ste_max * 1e6,
            r.wall_seconds
        )
        .map_err(io_err)?;
        writeln!(w, "  {:>12} {:>10} {:>10}  flags", "omega_p", "TEmax/STE", "TEmin/STE")
            .map_err(io_err)?;
        for p in &r.points {
            let mut flags = Vec::new();
            if p.separated {
                flags.push("separated");
            }
            if p.back_contact {
                flags.push("back contact");
            }
            if p.tip_contact {
                flags.push("tip contact");
            }
            if !p.steady {
                flags.push("NOT steady");
            }
            writeln!(
                w,
                "  {:12.3} {:10.4} {:10.4}  {}",
                p.omega_p,
                p.te_max_over_ste_max,
                p.te_min_over_ste_max,
                flags.join(", ")
            )
            .map_err(io_err)?;
        }
        for x in &r.resonances {
            writeln!(
                w,
                "  resonance at {:.2} rad/s (bracket {:.2} … {:.2}), TE_max/STE_max = {:.4}",
                x.omega_p, x.bracket.0, x.bracket.1, x.te_max_over_ste_max
            )
            .map_err(io_err)?;
        }
        if r.points.iter().any(|p| p.mesh_efficiency_mean < 1.0) {
            writeln!(w, "  mean mesh efficiency over the steady window (friction):")
                .map_err(io_err)?;
            for p in &r.points {
                writeln!(w, "  {:12.3} {:10.6}", p.omega_p, p.mesh_efficiency_mean)
                    .map_err(io_err)?;
            }
        }
        for s in warnings {
            writeln!(w, "  warning: {s}").map_err(io_err)?;
        }
        if let Some(s) = &record.supports {
            writeln!(
                w,
                "  with the gear bodies on their supports (STE_max = {:.3} µm):",
                s.ste_max_um
            )
            .map_err(io_err)?;
            writeln!(w, "  {:>12} {:>10} {:>10}  flags", "omega_p", "TEmax/STE", "TEmin/STE")
                .map_err(io_err)?;
            for (i, wp) in speeds.iter().enumerate() {
                let flag = if s.steady[i] { "" } else { "NOT steady" };
                writeln!(
                    w,
                    "  {wp:12.3} {:10.4} {:10.4}  {flag}",
                    s.te_max_over_ste_max[i], s.te_min_over_ste_max[i]
                )
                .map_err(io_err)?;
            }
            let f: Vec<String> = s.mode_speeds_rad_s.iter().map(|x| format!("{x:.1}")).collect();
            writeln!(w, "  mesh order 1 meets the coupled modes at {} rad/s", f.join(", "))
                .map_err(io_err)?;
            let p: Vec<String> = s.resonances_rad_s.iter().map(|x| format!("{x:.1}")).collect();
            writeln!(w, "  peaks of TE_max/STE_max on the supports at {} rad/s", p.join(", "))
                .map_err(io_err)?;
        }
    }
    w.flush().map_err(io_err)
}

/// Writes `support_spectrum.csv` and `support_spectrum.png` into `dir`: the mesh-order
/// amplitudes of the six support forces `stats` (order of [`REACTION_NAMES`]) at the mesh
/// frequency `f_mesh` (Hz).
fn write_support_spectrum(
    dir: &std::path::Path,
    f_mesh: f64,
    stats: &[ForceStats; 10],
) -> Result<(), String> {
    use helical_gear_app::plot::{LineChart, Series, SeriesStyle, line_chart, write_csv};
    let plot_err = |e: helical_gear_app::plot::PlotError| e.to_string();
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let forces = [0, 1, 2, 5, 6, 7];
    let orders = stats[0].orders.len();
    let mut header = vec!["order", "frequency_hz"];
    header.extend(forces.iter().map(|&c| REACTION_NAMES[c]));
    let rows = (0..orders).map(|k| {
        let mut r = vec![(k + 1) as f64, (k + 1) as f64 * f_mesh];
        r.extend(forces.iter().map(|&c| stats[c].orders[k]));
        r
    });
    write_csv(&dir.join("support_spectrum.csv"), &header, rows).map_err(plot_err)?;
    let series = forces
        .iter()
        .map(|&c| Series {
            name: format!("{} (N)", REACTION_NAMES[c]),
            points: (0..orders).map(|k| ((k + 1) as f64 * f_mesh, stats[c].orders[k])).collect(),
            style: SeriesStyle::LinePoints,
        })
        .collect();
    let chart = LineChart {
        title: "Support forces on the gear bodies: mesh-order amplitudes".into(),
        x_label: "frequency (Hz)".into(),
        y_label: "amplitude (N)".into(),
        series,
        y_log: true,
        ..LineChart::default()
    };
    line_chart(&dir.join("support_spectrum.png"), &chart, (900, 600)).map_err(plot_err)
}

/// Writes `sweep_supports.csv` and `sweep_supports.png` into `dir`: TE_max/STE_max over the
/// speeds on rigid bearings (`rigid`) and on the supports.
fn write_sweep_supports(
    dir: &std::path::Path,
    speeds: &[f64],
    rigid: &[f64],
    s: &SupportedSweepRecord,
) -> Result<(), String> {
    use helical_gear_app::plot::{LineChart, Series, SeriesStyle, line_chart, write_csv};
    let plot_err = |e: helical_gear_app::plot::PlotError| e.to_string();
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let header = ["omega_p_rad_s", "te_max_over_ste_max_rigid", "te_max_over_ste_max_supports"];
    let rows = (0..speeds.len()).map(|i| vec![speeds[i], rigid[i], s.te_max_over_ste_max[i]]);
    write_csv(&dir.join("sweep_supports.csv"), &header, rows).map_err(plot_err)?;
    let curve = |name: &str, y: &[f64]| Series {
        name: name.into(),
        points: speeds.iter().copied().zip(y.iter().copied()).collect(),
        style: SeriesStyle::LinePoints,
    };
    let (lo, hi) = (speeds[0], speeds[speeds.len() - 1]);
    let y_hi = rigid.iter().chain(&s.te_max_over_ste_max).copied().fold(1.0, f64::max);
    let mut series = vec![
        curve("rigid bearings", rigid),
        curve("bodies on their supports", &s.te_max_over_ste_max),
    ];
    // Where the first mesh order meets a coupled mode.
    for (k, w) in s.mode_speeds_rad_s.iter().filter(|w| (lo..=hi).contains(*w)).enumerate() {
        series.push(Series {
            name: if k == 0 { "coupled modes (mesh order 1)".into() } else { String::new() },
            points: vec![(*w, 0.9), (*w, y_hi)],
            style: SeriesStyle::Line,
        });
    }
    let chart = LineChart {
        title: "Steady TE_max/STE_max: rigid bearings and elastic supports".into(),
        x_label: "pinion speed (rad/s)".into(),
        y_label: "TE_max / STE_max".into(),
        series,
        ..LineChart::default()
    };
    line_chart(&dir.join("sweep_supports.png"), &chart, (900, 600)).map_err(plot_err)
}
