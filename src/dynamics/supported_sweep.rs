//! Speed sweeps with both gear bodies on their supports — a specification.
//!
//! Per speed ω_p (rad/s, > 0) the supported model ([`super::bodies`]) starts at its static
//! equilibrium and is integrated by RK4 on the step of [`supported_rk4_step`] (a whole number
//! N of steps per mesh period), one mesh period at a time. After at least
//! [`SupportedSweepOptions::min_periods`] periods it is steady when TE over the last period
//! repeats the period before sample by sample within [`SupportedSweepOptions::tol`] times
//! TE's peak-to-peak there (and 10⁻¹⁵ m); at most [`SupportedSweepOptions::max_periods`]
//! periods are run (the point then says it is not steady). Then
//! [`SupportedSweepOptions::window`] more periods are recorded: TE's largest and smallest
//! values and the support forces' statistics ([`support_force_stats`]: mean, peak to peak,
//! mesh-order amplitudes).
//!
//! The response is reported as TE_max/STE_max with STE_max the largest static TE of the mesh
//! on its supports over a pitch (16 points, [`crate::mesh::supported_static_curve`]), as the
//! rigid sweep ([`super::sweep()`]) reports its own over the rigid STE_max. The linearised
//! coupled modes ([`SupportedDynamics::linear_modes`]) predict where the mesh excites them:
//! a mode of frequency f resonates with mesh order k at ω_p = 2π·f/(k·z_p).
//!
//! The work of a run is bounded before it starts: at most
//! [`super::limits::MAX_STEADY_STEPS`] RK4 steps ((`max_periods` + `window`) × N), else
//! [`DynamicsError::TooLarge`] names the count and what to change.
//!
//! The speeds run in parallel on a rayon pool, each worker with its own clone of the mesh; a
//! table is prepared for poses once before the clones share it.

use rayon::prelude::*;

use super::bodies::{
    CoupledModes, ForceStats, SupportedDynamics, simulate_supported, support_force_stats,
    supported_rk4_step,
};
use super::model::{Drivetrain, DynamicsError, invalid};
use crate::mesh::MeshTorques;
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::supports::{Supports, supported_static_curve};

/// Options of [`sweep_supported`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupportedSweepOptions {
    /// Mesh periods run before the steady check starts. Default 20.
    pub min_periods: usize,
    /// Most mesh periods before the window. Default 2000.
    pub max_periods: usize,
    /// Relative tolerance of the period-to-period TE check. Default 10⁻⁴.
    pub tol: f64,
    /// Mesh periods of the recorded window. Default 4.
    pub window: usize,
    /// Mesh orders of the support-force amplitudes. Default 3.
    pub orders: usize,
    /// Worker threads; `None`: rayon's default.
    pub threads: Option<usize>,
}

impl Default for SupportedSweepOptions {
    fn default() -> Self {
        Self { min_periods: 20, max_periods: 2000, tol: 1e-4, window: 4, orders: 3, threads: None }
    }
}

/// The steady response at one speed.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportedSweepPoint {
    /// Pinion speed, rad/s.
    pub speed: f64,
    /// Largest and smallest TE over the window, m.
    pub te_max: f64,
    /// Smallest TE over the window, m.
    pub te_min: f64,
    /// Whether the period check passed before `max_periods`.
    pub steady: bool,
    /// Mesh periods run before the window.
    pub periods: usize,
    /// The support forces over the window, in the order of
    /// [`super::bodies::REACTION_NAMES`].
    pub forces: Vec<ForceStats>,
}

/// A sweep with the bodies on their supports.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportedSweep {
    /// Largest static TE of the mesh on its supports over a pitch, m.
    pub ste_max: f64,
    /// The coupled modes linearised at the static start at rest.
    pub modes: CoupledModes,
    /// One point per speed, in the order given.
    pub points: Vec<SupportedSweepPoint>,
}

/// Runs `model` from its static start at pinion speed `omega_p` (rad/s, > 0) to the steady
/// state and records the window (module docs).
pub fn run_supported_to_steady<M: MeshTorques>(
    model: &mut SupportedDynamics<M>,
    omega_p: f64,
    opts: &SupportedSweepOptions,
) -> Result<SupportedSweepPoint, DynamicsError> {
    if !(omega_p.is_finite() && omega_p > 0.0) {
        return Err(invalid("omega_p", omega_p, "finite and > 0 (rad/s)"));
    }
    if opts.window == 0 || opts.max_periods == 0 {
        return Err(invalid("window", opts.window as f64, ">= 1, with max_periods >= 1"));
    }
    let start = model.static_start(0.0, omega_p, &EquilibriumSettings::default())?;
    let modes = model.linear_modes(&start)?;
    let drive = *model.drive();
    let dt = supported_rk4_step(&drive, &modes, omega_p);
    let spp_f = (drive.mesh_period(omega_p) / dt).round();
    // Work is bounded before the run (stiff supports or a low speed make the steps many).
    let steps = spp_f * (opts.max_periods + opts.window) as f64;
    if steps.is_nan() || steps > super::limits::MAX_STEADY_STEPS {
        return Err(DynamicsError::TooLarge(format!(
            "a supported run at {omega_p} rad/s would take up to {steps:.3e} RK4 steps \
             ({spp_f:.0} per mesh period for the fastest coupled mode, |λ| = {:.3e} rad/s, \
             times {} periods); at most {:.0e}: lower max_periods, raise the speed, or soften \
             the stiffest support or make its body heavier",
            modes.fastest,
            opts.max_periods + opts.window,
            super::limits::MAX_STEADY_STEPS
        )));
    }
    let spp = spp_f as usize;
    let mut y = start.y;
    let mut last: Vec<f64> = Vec::new();
    let mut steady = false;
    let mut periods = 0;
    while periods < opts.max_periods {
        let tr = simulate_supported(model, &y, dt, spp, &modes)?;
        periods += 1;
        let te: Vec<f64> = tr.drive.outputs.iter().map(|o| o.te).collect();
        y = tr.end_state();
        if periods > opts.min_periods && !last.is_empty() {
            let (lo, hi) = last
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
            let d = te.iter().zip(&last).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            if d <= opts.tol * (hi - lo) + 1e-15 {
                steady = true;
                break;
            }
        }
        last = te;
    }
    let tr = simulate_supported(model, &y, dt, spp * opts.window, &modes)?;
    let (te_min, te_max) = tr
        .drive
        .outputs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), o| (a.min(o.te), b.max(o.te)));
    let forces = support_force_stats(&tr, spp, opts.orders).map(|s| s.to_vec()).unwrap_or_default();
    Ok(SupportedSweepPoint { speed: omega_p, te_max, te_min, steady, periods, forces })
}

/// The steady response at every speed of `speeds` (rad/s, each > 0) of the mesh `mesh` with
/// drivetrain `drive` and both bodies on `supports` (module docs).
pub fn sweep_supported<M: MeshTorques + Clone + Send + Sync>(
    mesh: &M,
    drive: &Drivetrain,
    supports: &Supports,
    speeds: &[f64],
    opts: &SupportedSweepOptions,
) -> Result<SupportedSweep, DynamicsError> {
    if speeds.is_empty() || speeds.len() > super::limits::MAX_SWEEP_SPEEDS {
        return Err(invalid("speeds", speeds.len() as f64, "1 … 100000 speeds"));
    }
    for &w in speeds {
        if !(w.is_finite() && w > 0.0 && w <= crate::mesh::validity::MAX_SPEED_RAD_S) {
            return Err(invalid("speed", w, "finite, > 0 and <= 1e5 rad/s"));
        }
    }
    // Prepared once, shared by the clones.
    let mut model = SupportedDynamics::new(mesh.clone(), *drive, *supports)?;
    let pitch = 2.0 * std::f64::consts::PI / drive.z_p as f64;
    let curve = supported_static_curve(
        model.mesh_mut(),
        drive.torque,
        0.0,
        pitch,
        16,
        1,
        supports,
        &EquilibriumSettings::default(),
    )
    .map_err(|source| DynamicsError::Mesh { t: None, source })?;
    let ste_max = curve.points.iter().map(|e| e.te).fold(f64::NEG_INFINITY, f64::max);
    let start = model.static_start(0.0, 0.0, &EquilibriumSettings::default())?;
    let modes = model.linear_modes(&start)?;
    let prepared = model.mesh_mut().clone();
    let run = || -> Result<Vec<SupportedSweepPoint>, DynamicsError> {
        speeds
            .par_iter()
            .map_init(
                || SupportedDynamics::new(prepared.clone(), *drive, *supports),
                |m, &w| match m {
                    Ok(m) => run_supported_to_steady(m, w, opts),
                    // The first build above succeeded; a worker's own error is its own.
                    Err(_) => SupportedDynamics::new(prepared.clone(), *drive, *supports)
                        .and_then(|mut m| run_supported_to_steady(&mut m, w, opts)),
                },
            )
            .collect()
    };
    let points = match opts.threads {
        None => run()?,
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build()
            .map_err(|_| invalid("threads", n as f64, "a thread pool that can be built"))?
            .install(run)?,
    };
    Ok(SupportedSweep { ste_max, modes, points })
}
