//! Time integration of Eqs. 1–4: trajectories and runs to the periodic steady state.
//!
//! * [`simulate`]: one trajectory from a given state, fixed-step RK4 (exactly the step given,
//!   the mesh evaluated at every RK stage with the stage state) or adaptive DOPRI5; the state
//!   and the mesh outputs are recorded at every output time. DOPRI5 (here and in
//!   [`run_to_steady`]) integrates the state in relative coordinates
//!   ([`super::relative::InRelative`]: φp, the shaft twists, TE and their rates), so that its
//!   `rtol`/`atol` act on TE and the twists; on the absolute angles rtol·|φp| (φp grows by
//!   ω_p per second) would allow TE errors larger than TE's own ripple. The recorded states
//!   are absolute.
//! * [`run_to_steady`]: from the static-equilibrium start at a nominal pinion speed
//!   ([`GearDynamics::static_start`]) until the transmission error is periodic with the mesh
//!   period T_m = 2π/(z_p·ω_p), or with k·T_m for a subharmonic response ([`SteadyState`]),
//!   or until a cap on the number of mesh periods; the result says which
//!   ([`SteadyResponse::warning`]) and gives max/min/mean TE and the contact flags over the
//!   steady window (the last k mesh periods). When tooth deviations break the periodicity
//!   in one pitch ([`crate::modifications`]), [`SteadyRunOptions::period_meshes`] sets the
//!   period P (in mesh periods) the TE must repeat with: z_p for deviations of the pinion
//!   only, z_g for the gear only, the hunting period otherwise
//!   ([`crate::modifications::Modifications::period_meshes`]); the detector then compares
//!   TE with its value one period P earlier, checks once per mesh period and the window is the
//!   last P mesh periods (no subharmonics of P are sought). With P > 1 the detector is fed
//!   TE at uniform **pinion angles** (N per pitch, cubic Hermite in φp between the RK4 steps
//!   with the slopes from the rates), not at uniform times: the drivetrain has a rigid-body
//!   mode (constant driving and braking torques), so the mean speed settles a little off the
//!   nominal one and, over hundreds of meshes, TE sampled in time drifts in phase against the
//!   mesh; sampled in angle it repeats (order tracking). RK4 only.
//!
//! # Step size of RK4
//!
//! The step is T_m/N with N steps per mesh period ([`DEFAULT_STEPS_PER_MESH_PERIOD`]), so that
//! the TE samples fall on a grid with an integer number of samples per period, as the
//! steady-state detector needs. N is raised where T_m/N would exceed
//! [`SteadyRunOptions::max_step`], by default the step rule of [`super::limits`]
//! ([`stable_rk4_step`]: 32 steps per period of the fastest linearised mode): below the main
//! resonance the mesh mode oscillates several times per mesh period, and it is the period of
//! the fastest mode, not T_m, that sets the accuracy (and, far below, RK4's stability).
//! [`default_rk4_step`] is the default step of [`simulate`] by the same rule; an explicit RK4
//! step outside the stability region is refused. Work is bounded before it starts: a
//! trajectory records at most [`MAX_TRAJECTORY_SAMPLES`] samples, a run to the steady state
//! takes at most [`MAX_STEADY_STEPS`] steps (`max_periods`·N) and keeps at most
//! [`MAX_WINDOW_SAMPLES`] window samples. The default N = 128 comes from a convergence study with the mesh-periodic
//! analytic mesh at its main resonance (z_p·ω_p equal to the mesh-mode frequency, 5 %
//! damping, TE after 40 mesh periods against a 1024-step reference; observed order 4):
//! relative TE error 1.3·10⁻³ at N = 16, 8.2·10⁻⁵ at 32, 5.1·10⁻⁶ at 64, 1.0·10⁻⁶ at 96,
//! 3.2·10⁻⁷ at 128. So about 100 steps per period give 10⁻⁶, and 128 give it with margin.
//! The study is the test `rk4_steps_per_mesh_period_convergence` in
//! `tests/dynamics_model.rs`.

use std::collections::VecDeque;
use std::fmt;
use std::ops::ControlFlow;

use super::integrators::{Dopri5, Dopri5Options, Rk4};
use super::limits::{
    MAX_STEADY_STEPS, MAX_TRAJECTORY_SAMPLES, MAX_WINDOW_SAMPLES, STEPS_PER_FAST_PERIOD,
    check_rk4_step, fastest_mode, stable_rk4_step, trajectory_sample_bytes,
};
use super::model::{DynamicsError, GearDynamics, N_STATES, invalid};
use super::relative::{InRelative, RelativeCoordinates};
use super::steady::{PeriodCheck, SteadyOptions, SteadyState, SteadyStatus};
use super::unit::UnitKind;
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::{MeshOutputs, MeshTorques};

/// Default number of RK4 steps per mesh period (see the module doc for the study behind it).
pub const DEFAULT_STEPS_PER_MESH_PERIOD: usize = 128;

/// How [`simulate`] integrates and when it records.
#[derive(Debug, Clone, PartialEq)]
pub enum Stepping {
    /// Classical RK4 with the fixed step `dt` (s, > 0); output after every step, at
    /// t_i = i·dt.
    Rk4 {
        /// Step, s.
        dt: f64,
    },
    /// Adaptive Dormand–Prince 5(4); output at every accepted step, or, with `output_dt`, at
    /// t_i = i·output_dt from the dense output (the mesh is then evaluated at those states).
    Dopri5 {
        /// Integrator options.
        options: Dopri5Options,
        /// Output interval, s (> 0), or `None` for the accepted steps.
        output_dt: Option<f64>,
    },
}

/// A recorded trajectory: per output time, the state and the mesh outputs at that state.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    /// Output times, s (the first is the start, 0).
    pub time: Vec<f64>,
    /// States (φ₁, φp, φg, φ₂, φ̇₁, φ̇p, φ̇g, φ̇₂), rad and rad/s.
    pub states: Vec<[f64; N_STATES]>,
    /// Mesh outputs at each state (TE in m, torques in N·m, …).
    pub outputs: Vec<MeshOutputs>,
    /// Integration steps taken (accepted steps for DOPRI5).
    pub steps: usize,
    /// Mesh evaluations made (remembered evaluations not counted).
    pub mesh_evaluations: usize,
}

/// The map of the 8-state model to relative coordinates (φp, θ₁, TE, θ₂ and their rates) in
/// which DOPRI5 controls its error.
fn relative_map<M: MeshTorques>(model: &GearDynamics<M>) -> RelativeCoordinates {
    let (gp, gg) = model.base_radii();
    RelativeCoordinates::new(UnitKind::Drive, gp, gg)
}

/// The absolute state of relative state `x` under `rel`.
fn absolute_of(rel: &RelativeCoordinates, x: &[f64]) -> [f64; N_STATES] {
    let mut a = [0.0; N_STATES];
    rel.to_absolute(x, &mut a);
    a
}

/// Refuses a trajectory of `samples` recorded samples above [`MAX_TRAJECTORY_SAMPLES`]
/// before anything is reserved; the error names the count, its memory and the bound, and
/// `remedy` says what to change.
pub fn check_samples(samples: f64, remedy: &str) -> Result<(), DynamicsError> {
    if samples <= MAX_TRAJECTORY_SAMPLES as f64 {
        return Ok(());
    }
    let bytes = samples * trajectory_sample_bytes() as f64;
    Err(DynamicsError::TooLarge(format!(
        "simulate would store {samples:.3e} samples ({:.3e} GB); at most \
         {:.0e}: {remedy}",
        bytes * 1e-9,
        MAX_TRAJECTORY_SAMPLES as f64
    )))
}

/// The default RK4 step of [`simulate`] at nominal pinion speed `omega_p` (rad/s, ≥ 0; 0 is
/// standstill) over `t_end` (s, > 0): the step of [`stable_rk4_step`] with
/// [`DEFAULT_STEPS_PER_MESH_PERIOD`] steps per mesh period and [`STEPS_PER_FAST_PERIOD`] per
/// period of the fastest linearised mode ([`fastest_mode`] at pinion angle `phi_p0`, rad),
/// shortened to divide `t_end` into a whole number of steps. Errors: invalid arguments, a mesh
/// without a static equilibrium under the torque, or more steps than
/// [`MAX_TRAJECTORY_SAMPLES`] (the error names the count and the memory).
pub fn default_rk4_step<M: MeshTorques>(
    model: &mut GearDynamics<M>,
    omega_p: f64,
    phi_p0: f64,
    t_end: f64,
) -> Result<f64, DynamicsError> {
    if !(omega_p.is_finite() && omega_p.abs() <= crate::mesh::validity::MAX_SPEED_RAD_S) {
        return Err(invalid(
            "omega_p",
            omega_p,
            "finite, |ω_p| <= 1e5 rad/s (the largest nominal speed; negative: running backwards)",
        ));
    }
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(invalid("t_end", t_end, "finite and > 0 (s)"));
    }
    let w = fastest_mode(model, phi_p0)?;
    let t_m = model.drive().mesh_period(omega_p);
    let h = stable_rk4_step(t_m, DEFAULT_STEPS_PER_MESH_PERIOD as f64, w, STEPS_PER_FAST_PERIOD);
    let n = (t_end / h).ceil().max(1.0);
    check_samples(n + 1.0, "lower t_end")?;
    Ok(t_end / n)
}

/// Integrates Eqs. 1–4 from `y0` at t = 0 to `t_end` (s, > 0) and records the trajectory.
///
/// With [`Stepping::Rk4`], `t_end` must be a whole number n of steps (|n·dt − t_end| ≤
/// 10⁻⁹·t_end); n steps of exactly `dt` are taken and the times are i·dt. A step outside
/// RK4's stability region for the fastest linearised mode (ω_fast·dt >
/// [`super::limits::RK4_MAX_OMEGA_H`], [`check_rk4_step`]) is an error, and so is a record of
/// more than [`MAX_TRAJECTORY_SAMPLES`] samples (checked before anything is reserved; DOPRI5:
/// t_end/output_dt + 1, or `max_steps` without an output interval). The mesh is evaluated
/// at every stage state (four times per step, the first stage's evaluation being the recorded
/// output of the previous step).
pub fn simulate<M: MeshTorques>(
    model: &mut GearDynamics<M>,
    y0: &[f64; N_STATES],
    t_end: f64,
    stepping: &Stepping,
) -> Result<Trajectory, DynamicsError> {
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(invalid("t_end", t_end, "finite and > 0 (s)"));
    }
    let evals0 = model.mesh_evaluations();
    let mut tr = Trajectory::default();
    let mut y = *y0;
    let o = model.outputs(&y)?;
    tr.time.push(0.0);
    tr.states.push(y);
    tr.outputs.push(o);
    match stepping {
        Stepping::Rk4 { dt } => {
            let dt = *dt;
            if !(dt.is_finite() && dt > 0.0) {
                return Err(invalid("dt", dt, "finite and > 0 (s)"));
            }
            let n = (t_end / dt).round();
            if n < 1.0 || (n * dt - t_end).abs() > 1e-9 * t_end {
                return Err(invalid("t_end", t_end, "a whole number of steps dt (within 1e-9)"));
            }
            check_samples(n + 1.0, "lower t_end or raise dt")?;
            // A step outside RK4's stability region gives a diverging trajectory, not a coarse
            // one (see `limits`); checked where the fastest mode can be measured (a mesh
            // without a static equilibrium under the torque is left to the caller).
            if let Ok(w) = fastest_mode(model, y0[1]) {
                check_rk4_step(dt, w)?;
            }
            let n = n as usize;
            tr.time.reserve(n);
            tr.states.reserve(n);
            tr.outputs.reserve(n);
            let mut rk4 = Rk4::new(N_STATES);
            for i in 1..=n {
                let t = (i - 1) as f64 * dt;
                rk4.step(model, t, dt, &mut y).map_err(DynamicsError::from)?;
                let o = model.outputs(&y)?;
                tr.time.push(i as f64 * dt);
                tr.states.push(y);
                tr.outputs.push(o);
            }
            tr.steps = n;
        }
        Stepping::Dopri5 { options, output_dt } => {
            if let Some(h) = output_dt
                && !(h.is_finite() && *h > 0.0)
            {
                return Err(invalid("output_dt", *h, "finite and > 0 (s)"));
            }
            match output_dt {
                Some(h) => check_samples((t_end / h).floor() + 1.0, "lower t_end or raise dt")?,
                None => check_samples(
                    options.max_steps as f64,
                    "lower max_steps (one sample per accepted step) or give an output interval",
                )?,
            }
            let mut dp = Dopri5::new(N_STATES, options.clone())?;
            let mut samples: Vec<(f64, [f64; N_STATES])> = Vec::new();
            let mut next_out = 1usize;
            let mut buf = [0.0; N_STATES];
            let mut dense_failure = None;
            // Integrated in relative coordinates (the tolerances act on TE and the shaft
            // twists, see the module doc); samples are mapped back to the absolute state.
            let rel = relative_map(model);
            let mut x = [0.0; N_STATES];
            rel.to_relative(&y, &mut x);
            let absolute = |x: &[f64]| absolute_of(&rel, x);
            let mut sys = InRelative::new(model, rel);
            let stats = dp.integrate(&mut sys, 0.0, t_end, &mut x, |step| {
                match output_dt {
                    None => samples.push((step.t_end(), absolute(step.y_end()))),
                    Some(h) => loop {
                        let t = next_out as f64 * h;
                        // The last output may exceed t_end by round-off of next_out·h.
                        let last_step = step.t_end() >= t_end;
                        if t > t_end * (1.0 + 1e-12) || (t > step.t_end() && !last_step) {
                            break;
                        }
                        if let Err(e) = step.dense_output(t.min(step.t_end()), &mut buf) {
                            dense_failure = Some(e);
                            return ControlFlow::Break(());
                        }
                        samples.push((t, absolute(&buf)));
                        next_out += 1;
                    },
                }
                ControlFlow::Continue(())
            })?;
            if let Some(e) = dense_failure {
                return Err(e.into());
            }
            tr.steps = stats.accepted;
            // The mesh outputs at the recorded states, in time order (a second pass: the
            // integrator holds the model while it runs).
            for (t, ys) in samples {
                let o = model.outputs(&ys)?;
                tr.time.push(t);
                tr.states.push(ys);
                tr.outputs.push(o);
            }
        }
    }
    tr.mesh_evaluations = model.mesh_evaluations() - evals0;
    Ok(tr)
}

/// Integrator of [`run_to_steady`].
#[derive(Debug, Clone, PartialEq)]
pub enum SteadyMethod {
    /// Fixed-step RK4 with `steps_per_period` steps per mesh period (≥ 4; see the module doc
    /// and [`SteadyRunOptions::max_step`]). TE is sampled at every step.
    Rk4 {
        /// Steps per mesh period N.
        steps_per_period: usize,
    },
    /// Adaptive DOPRI5; TE is sampled from the dense output at `samples_per_period` (≥ 4)
    /// points per mesh period, the contact flags at the accepted steps. When
    /// `options.h_max` is `None` the step is limited to one mesh period.
    Dopri5 {
        /// Integrator options.
        options: Dopri5Options,
        /// TE samples per mesh period for the steady-state detector.
        samples_per_period: usize,
    },
}

/// Options of [`run_to_steady`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyRunOptions {
    /// Integrator. Default: RK4 with [`DEFAULT_STEPS_PER_MESH_PERIOD`].
    pub method: SteadyMethod,
    /// Largest RK4 step, s: N is raised to ⌈T_m/max_step⌉ where T_m/N would exceed it. A
    /// natural choice is the period of the fastest linearised mode divided by the steps per
    /// period wanted (see [`super::model::Drivetrain::linear_frequencies`]). Default `None`:
    /// the step rule of [`super::limits`] ([`stable_rk4_step`] with
    /// [`STEPS_PER_FAST_PERIOD`] and the fastest mode measured at the static equilibrium).
    pub max_step: Option<f64>,
    /// Pinion angle φp at t = 0, rad. Default 0.
    pub phi_p0: f64,
    /// Mesh periods integrated at least before steady state may be declared (≥ 0). Default 4.
    pub min_periods: usize,
    /// Cap on the mesh periods integrated (≥ 2·`max_multiple`); reaching it gives the warning
    /// [`SteadyWarning::NotSteady`]. Default 3000.
    pub max_periods: usize,
    /// Periodicity tolerance relative to the window's peak-to-peak TE (see
    /// [`super::steady`]). Default 1e-3.
    pub rel_tol: f64,
    /// Absolute floor of the periodicity tolerance, m. Default 1e-12 m.
    pub abs_tol: f64,
    /// Largest period multiple k tried (subharmonics). Default 4.
    pub max_multiple: usize,
    /// Consecutive passing checks (one per mesh period) required. Default 3.
    pub consecutive: usize,
    /// Keep the states and outputs of the steady window in [`SteadyResponse::window`].
    /// Default true.
    pub keep_window: bool,
    /// Settings of the static equilibrium of the start.
    pub equilibrium: EquilibriumSettings,
    /// Period P of the excitation in mesh periods (≥ 1; see the module docs): 1 for a mesh
    /// periodic in one pitch, else [`crate::modifications::Modifications::period_meshes`].
    /// With P > 1 the multiple is 1 (`max_multiple` is not used) and `max_periods` must be at
    /// least 2·P. Default 1.
    pub period_meshes: usize,
}

impl Default for SteadyRunOptions {
    fn default() -> Self {
        Self {
            method: SteadyMethod::Rk4 { steps_per_period: DEFAULT_STEPS_PER_MESH_PERIOD },
            max_step: None,
            phi_p0: 0.0,
            min_periods: 4,
            max_periods: 3000,
            rel_tol: 1e-3,
            abs_tol: 1e-12,
            max_multiple: 4,
            consecutive: 3,
            keep_window: true,
            equilibrium: EquilibriumSettings::default(),
            period_meshes: 1,
        }
    }
}

impl SteadyResponse {
    /// TE of the steady window of an RK4 run at `per_mesh` uniform samples per mesh period
    /// (`per_mesh` must divide the steps per mesh period), oldest first: period_multiple ·
    /// per_mesh values covering exactly the last `period_multiple` mesh periods (one period of
    /// the response, ready for [`crate::numeric::amplitude_spectrum`]), m. Errors: the window
    /// was not kept, is not an RK4 window, or `per_mesh` does not divide the steps.
    pub fn window_te(&self, per_mesh: usize) -> Result<Vec<f64>, DynamicsError> {
        let n = self.samples_per_period;
        if per_mesh == 0 || !n.is_multiple_of(per_mesh) {
            return Err(invalid("per_mesh", per_mesh as f64, "a divisor of the steps per period"));
        }
        let len = self.period_multiple * n;
        if !self.te_by_angle.is_empty() {
            if self.te_by_angle.len() != len {
                return Err(invalid(
                    "te_by_angle",
                    self.te_by_angle.len() as f64,
                    "period_multiple·steps samples (a run that reached one whole period)",
                ));
            }
            return Ok(self.te_by_angle.iter().step_by(n / per_mesh).copied().collect());
        }
        if self.window.len() != len + 1 {
            return Err(invalid(
                "window",
                self.window.len() as f64,
                "an RK4 window kept with keep_window (period_multiple·steps + 1 points)",
            ));
        }
        Ok(self.window[..len].iter().step_by(n / per_mesh).map(|w| w.outputs.te).collect())
    }
}

impl SteadyRunOptions {
    /// The defaults for `pair`: with tooth deviations ([`crate::modifications`]) the period
    /// P = [`crate::modifications::Modifications::period_meshes`] and the cap of
    /// [`super::steady::steady_max_periods`] (at least 3·P mesh periods); otherwise
    /// [`SteadyRunOptions::default`].
    pub fn for_pair(pair: &crate::params::GearPair) -> Self {
        let period = pair.modifications.period_meshes(pair.z_p, pair.z_g) as usize;
        let d = Self::default();
        let max_periods = super::steady::steady_max_periods(d.max_periods, period);
        Self { period_meshes: period, max_periods, ..d }
    }
}

/// Why a run's result is not a detected steady state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SteadyWarning {
    /// The cap of mesh periods was reached before TE became periodic; the statistics are those
    /// of the last `period_multiple` periods (the multiple whose residual was closest to its
    /// tolerance).
    NotSteady {
        /// Mesh periods integrated.
        periods: usize,
        /// Last residual max |TE(t) − TE(t − k·T_m)|, m.
        residual: f64,
        /// Its tolerance, m.
        tolerance: f64,
    },
}

impl fmt::Display for SteadyWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SteadyWarning::NotSteady { periods, residual, tolerance } => write!(
                f,
                "no steady state after {periods} mesh periods (TE residual {residual:.3e} m > \
                 tolerance {tolerance:.3e} m)"
            ),
        }
    }
}

/// One recorded point of the steady window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowSample {
    /// Time, s.
    pub t: f64,
    /// State (φ₁, φp, φg, φ₂, φ̇₁, φ̇p, φ̇g, φ̇₂), rad and rad/s.
    pub y: [f64; N_STATES],
    /// Mesh outputs at the state.
    pub outputs: MeshOutputs,
}

/// Result of [`run_to_steady`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyResponse {
    /// Nominal pinion speed ω_p, rad/s.
    pub omega_p: f64,
    /// Mesh period T_m = 2π/(z_p·ω_p), s.
    pub mesh_period: f64,
    /// True when the steady state was detected; otherwise see `warning`.
    pub steady: bool,
    /// Set when the result is not a detected steady state.
    pub warning: Option<SteadyWarning>,
    /// Period of the steady TE in mesh periods (1, or k for a subharmonic response; P =
    /// [`SteadyRunOptions::period_meshes`] when that is > 1).
    pub period_multiple: usize,
    /// Mesh periods integrated (fractional for DOPRI5).
    pub periods: f64,
    /// Largest TE over the steady window (the last `period_multiple` mesh periods), m.
    pub te_max: f64,
    /// Smallest TE over the steady window, m.
    pub te_min: f64,
    /// Mean TE over the steady window, m.
    pub te_mean: f64,
    /// Static TE at the start (φp = `phi_p0`), m.
    pub te_static_start: f64,
    /// True when the teeth lose contact anywhere in the steady window (`separated` output).
    pub separated: bool,
    /// True when the tip rounding or edge is in contact anywhere in the steady window.
    pub tip_contact: bool,
    /// True when the back flanks are in contact anywhere in the steady window.
    pub back_contact: bool,
    /// Largest magnitude |F_p| of the mesh force on the pinion over the recorded points of the
    /// steady window (the samples that give `te_max` and `te_min`), N (0 for a mesh without
    /// contact geometry, e.g. the analytic test meshes).
    pub force_p_max: f64,
    /// Largest tooth-root stress of the pinion and of the gear ([`crate::mesh::MeshOutputs`]'s
    /// `root_stress_p`, `root_stress_g`) over the same recorded points, Pa (0 for a mesh
    /// without FE data).
    pub root_stress_max: [f64; 2],
    /// Mean mesh friction loss P_loss ([`crate::mesh::MeshOutputs::p_loss`]) over the steady
    /// window, W: the time average (trapezoidal) over the same recorded points (0 without
    /// friction).
    pub p_loss_mean: f64,
    /// Mean power the pinion puts into the mesh, (M_F,p + M_D,p)·φ̇p, over the steady window
    /// (time average over the same recorded points), W.
    pub p_in_mean: f64,
    /// Recorded points of the steady window (RK4: every step; DOPRI5: every accepted step);
    /// empty unless [`SteadyRunOptions::keep_window`].
    pub window: Vec<WindowSample>,
    /// Integration steps (accepted steps for DOPRI5).
    pub steps: usize,
    /// Steps per mesh period used (RK4) or TE samples per mesh period (DOPRI5).
    pub samples_per_period: usize,
    /// Mesh evaluations of the run, the static start included.
    pub mesh_evaluations: usize,
    /// State at the end of the run.
    pub y_end: [f64; N_STATES],
    /// With [`SteadyRunOptions::period_meshes`] P > 1: TE at uniform pinion angles, N per
    /// pinion pitch (N the steps per mesh period), over the last P pitches, oldest first, m
    /// (empty for P = 1).
    pub te_by_angle: Vec<f64>,
}

/// Runs Eqs. 1–4 at nominal pinion speed `omega_p` (rad/s, > 0) from the static-equilibrium
/// start until the steady state (see the module doc).
pub fn run_to_steady<M: MeshTorques>(
    model: &mut GearDynamics<M>,
    omega_p: f64,
    opts: &SteadyRunOptions,
) -> Result<SteadyResponse, DynamicsError> {
    if !(omega_p.is_finite() && omega_p > 0.0) {
        return Err(invalid("omega_p", omega_p, "finite and > 0 (rad/s)"));
    }
    let period = opts.period_meshes;
    if !(1..=10_000_000).contains(&period) {
        return Err(invalid("period_meshes", period as f64, "1 ..= 1e7"));
    }
    // Period multiples sought: up to max_multiple of one mesh period, or 1 of P.
    let multiple = if period > 1 { 1 } else { opts.max_multiple };
    if opts.max_periods < 2 * multiple.max(1) * period || opts.max_periods > 100_000_000 {
        return Err(invalid(
            "max_periods",
            opts.max_periods as f64,
            ">= 2·max_multiple (2·period_meshes when > 1) and <= 1e8",
        ));
    }
    if let Some(h) = opts.max_step
        && !(h.is_finite() && h > 0.0)
    {
        return Err(invalid("max_step", h, "finite and > 0 (s)"));
    }
    let t_m = model.drive().mesh_period(omega_p);
    let n = match &opts.method {
        SteadyMethod::Rk4 { steps_per_period } => {
            let mut n = *steps_per_period;
            if n < 4 {
                return Err(invalid("steps_per_period", n as f64, ">= 4"));
            }
            // Without a caller's bound the step rule of `limits` gives it: the mesh mode, not
            // the mesh period, sets the step at low speed.
            let max_step = match opts.max_step {
                Some(h) => Some(h),
                None => {
                    let w = fastest_mode(model, opts.phi_p0)?;
                    Some(stable_rk4_step(t_m, n as f64, w, STEPS_PER_FAST_PERIOD))
                }
            };
            if let Some(h) = max_step {
                let need = (t_m / h).ceil();
                if need * opts.max_periods as f64 > MAX_STEADY_STEPS {
                    return Err(DynamicsError::TooLarge(format!(
                        "run_to_steady at ω_p = {omega_p:.3e} rad/s would take up to {:.3e} \
                         RK4 steps ({} mesh periods × {need:.3e} steps of {h:.3e} s); at most \
                         {MAX_STEADY_STEPS:.0e}: lower max_periods or raise ω_p",
                        need * opts.max_periods as f64,
                        opts.max_periods,
                    )));
                }
                if need > 1e7 {
                    return Err(invalid(
                        "max_step",
                        h,
                        ">= T_m/1e7 (at most 1e7 steps per period)",
                    ));
                }
                n = n.max(need as usize);
            }
            let total = opts.max_periods as f64 * n as f64;
            if total > MAX_STEADY_STEPS {
                return Err(DynamicsError::TooLarge(format!(
                    "run_to_steady at ω_p = {omega_p:.3e} rad/s would take up to {total:.3e} \
                     RK4 steps ({} mesh periods × {n} steps of {:.3e} s); at most \
                     {MAX_STEADY_STEPS:.0e}: lower max_periods or raise ω_p",
                    opts.max_periods,
                    t_m / n as f64
                )));
            }
            n
        }
        SteadyMethod::Dopri5 { samples_per_period, .. } => {
            if *samples_per_period < 4 {
                return Err(invalid("samples_per_period", *samples_per_period as f64, ">= 4"));
            }
            *samples_per_period
        }
    };
    let window = (multiple * period) as f64 * n as f64;
    if window > MAX_WINDOW_SAMPLES as f64 {
        return Err(DynamicsError::TooLarge(format!(
            "run_to_steady at ω_p = {omega_p:.3e} rad/s would keep {window:.3e} samples of the \
             steady window ({} × {period} mesh periods × {n} samples); at most {:.0e}: lower \
             the steps per period, max_multiple or the period, or raise ω_p",
            multiple, MAX_WINDOW_SAMPLES as f64
        )));
    }
    let mut det = SteadyState::new(SteadyOptions {
        samples_per_period: n * period,
        max_multiple: multiple,
        rel_tol: opts.rel_tol,
        abs_tol: opts.abs_tol,
        consecutive: opts.consecutive,
        check_interval: (period > 1).then_some(n),
    })?;
    let evals0 = model.mesh_evaluations();
    let start = model.static_start(opts.phi_p0, omega_p, &opts.equilibrium)?;
    let mut y = start.y;
    let (gp, gg) = model.base_radii();
    let te_of = |y: &[f64]| crate::numeric::dot2(y[1], gp, y[2], gg);
    det.push(te_of(&y))?;
    let min_samples = (opts.min_periods * n) as u64;
    let window_span = (multiple * period) as f64 * t_m;

    // Recorded points of the last K periods (outputs filled in for RK4, later for DOPRI5).
    let mut ring: VecDeque<(f64, [f64; N_STATES], Option<MeshOutputs>)> = VecDeque::new();
    let mut by_angle: VecDeque<f64> = VecDeque::new();
    if period > 1 && !matches!(opts.method, SteadyMethod::Rk4 { .. }) {
        return Err(invalid("period_meshes", period as f64, "1 unless the method is RK4"));
    }
    let steps;
    let t_end;
    match &opts.method {
        SteadyMethod::Rk4 { .. } => {
            let h = t_m / n as f64;
            let mut rk4 = Rk4::new(N_STATES);
            let o = model.outputs(&y)?;
            ring.push_back((0.0, y, Some(o)));
            let cap = multiple * period * n + 1;
            let total = opts.max_periods * n;
            // P > 1: TE sampled at uniform pinion angles (order tracking, see the module docs).
            let dphi = t_m * omega_p / n as f64;
            let phi0 = y[1];
            let mut n_angle = 1u64;
            let mut prev = y;
            let mut i = 0usize;
            'steps: while i < total {
                let t = i as f64 * h;
                rk4.step(model, t, h, &mut y).map_err(DynamicsError::from)?;
                i += 1;
                // Free: the next step's first stage is evaluated at this state.
                let o = model.outputs(&y)?;
                ring.push_back((i as f64 * h, y, Some(o)));
                if ring.len() > cap {
                    ring.pop_front();
                }
                if period == 1 {
                    let status = det.push(te_of(&y))?;
                    if status.is_steady() && det.samples_seen() > min_samples {
                        break;
                    }
                    continue;
                }
                let (pa, pb) = (prev[1], y[1]);
                while pb > pa && phi0 + n_angle as f64 * dphi <= pb {
                    let phi = phi0 + n_angle as f64 * dphi;
                    let te = te_at_angle(&prev, &y, phi, gp, gg);
                    n_angle += 1;
                    by_angle.push_back(te);
                    if by_angle.len() > period * n {
                        by_angle.pop_front();
                    }
                    let status = det.push(te)?;
                    if status.is_steady() && det.samples_seen() > min_samples {
                        break 'steps;
                    }
                }
                prev = y;
            }
            steps = i;
            t_end = i as f64 * h;
        }
        SteadyMethod::Dopri5 { options, .. } => {
            let mut options = options.clone();
            if options.h_max.is_none() {
                options.h_max = Some(t_m);
            }
            let mut dp = Dopri5::new(N_STATES, options)?;
            let dt_s = t_m / n as f64;
            let mut next = 1u64;
            let mut buf = [0.0; N_STATES];
            let mut failure: Option<DynamicsError> = None;
            ring.push_back((0.0, y, None));
            let t1 = opts.max_periods as f64 * t_m;
            // In relative coordinates, as in `simulate`; states mapped back for the record.
            let rel = relative_map(model);
            let mut x = [0.0; N_STATES];
            rel.to_relative(&y, &mut x);
            let absolute = |x: &[f64]| absolute_of(&rel, x);
            let mut sys = InRelative::new(model, rel);
            let stats = dp.integrate(&mut sys, 0.0, t1, &mut x, |step| {
                let mut stop = false;
                loop {
                    let t = next as f64 * dt_s;
                    if t > step.t_end() {
                        break;
                    }
                    if let Err(e) = step.dense_output(t, &mut buf) {
                        failure = Some(e.into());
                        return ControlFlow::Break(());
                    }
                    next += 1;
                    match det.push(te_of(&absolute(&buf))) {
                        Ok(s) => {
                            if s.is_steady() && det.samples_seen() > min_samples {
                                stop = true;
                                break;
                            }
                        }
                        Err(e) => {
                            failure = Some(e.into());
                            return ControlFlow::Break(());
                        }
                    }
                }
                ring.push_back((step.t_end(), absolute(step.y_end()), None));
                while ring.front().is_some_and(|f| f.0 < step.t_end() - window_span - t_m) {
                    ring.pop_front();
                }
                if stop { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
            })?;
            if let Some(e) = failure {
                return Err(e);
            }
            steps = stats.accepted;
            t_end = stats.t_end;
        }
    }

    let (steady, check) = match det.status() {
        SteadyStatus::Steady(c) => (true, c),
        SteadyStatus::Transient(c) => (false, c),
        SteadyStatus::Collecting => {
            return Err(invalid("max_periods", opts.max_periods as f64, ">= 2 (nothing checked)"));
        }
    };
    let PeriodCheck { period_multiple: k, residual, tolerance, max, min, mean, .. } = check;
    let k = k * period;
    let periods = t_end / t_m;
    let warning = (!steady).then_some(SteadyWarning::NotSteady {
        periods: periods.round() as usize,
        residual,
        tolerance,
    });
    // The steady window: the last k mesh periods (a small margin for the time round-off).
    let t_from = t_end - k as f64 * t_m * (1.0 + 1e-9);
    let mut window = Vec::new();
    let (mut separated, mut tip_contact, mut back_contact) = (false, false, false);
    let mut force_p_max: f64 = 0.0;
    let mut root_stress_max = [0.0f64; 2];
    // Time integrals of the loss and the mesh input power (trapezoidal) for their means.
    let (mut loss_int, mut p_in_int, mut span) = (0.0, 0.0, 0.0);
    let mut last: Option<(f64, f64, f64)> = None;
    for (t, ys, o) in ring.iter().filter(|r| r.0 >= t_from) {
        let o = match o {
            Some(o) => *o,
            None => model.outputs(ys)?,
        };
        let p_in = (o.m_f_p + o.m_d_p) * ys[5];
        if let Some((t0, l0, p0)) = last {
            let dt = *t - t0;
            loss_int += 0.5 * (l0 + o.p_loss) * dt;
            p_in_int += 0.5 * (p0 + p_in) * dt;
            span += dt;
        }
        last = Some((*t, o.p_loss, p_in));
        separated |= o.separated;
        tip_contact |= o.tip_contact;
        back_contact |= o.back_contact;
        force_p_max = force_p_max.max(norm3(o.force_p));
        root_stress_max[0] = root_stress_max[0].max(o.root_stress_p);
        root_stress_max[1] = root_stress_max[1].max(o.root_stress_g);
        if opts.keep_window {
            window.push(WindowSample { t: *t, y: *ys, outputs: o });
        }
    }
    Ok(SteadyResponse {
        omega_p,
        mesh_period: t_m,
        steady,
        warning,
        period_multiple: k,
        periods,
        te_max: max,
        te_min: min,
        te_mean: mean,
        te_static_start: start.te,
        separated,
        tip_contact,
        back_contact,
        force_p_max,
        root_stress_max,
        // One recorded point only (a window shorter than a step): its values.
        p_loss_mean: if span > 0.0 { loss_int / span } else { last.map_or(0.0, |l| l.1) },
        p_in_mean: if span > 0.0 { p_in_int / span } else { last.map_or(0.0, |l| l.2) },
        window,
        steps,
        samples_per_period: n,
        mesh_evaluations: model.mesh_evaluations() - evals0,
        y_end: y,
        te_by_angle: by_angle.into(),
    })
}

/// |v|, the Euclidean norm of a 3-vector.
pub(crate) fn norm3(v: [f64; 3]) -> f64 {
    v[0].hypot(v[1]).hypot(v[2])
}

/// TE at pinion angle `phi` between the states `a` and `b` of one step (φp(a) < phi ≤
/// φp(b)): cubic Hermite in φp with the slopes dTE/dφp = (φ̇p·g_p + φ̇g·g_g)/φ̇p of the two
/// states (the secant where φ̇p ≤ 0), m.
fn te_at_angle(a: &[f64; N_STATES], b: &[f64; N_STATES], phi: f64, gp: f64, gg: f64) -> f64 {
    let te = |y: &[f64; N_STATES]| crate::numeric::dot2(y[1], gp, y[2], gg);
    let (ta, tb) = (te(a), te(b));
    let h = b[1] - a[1];
    let secant = (tb - ta) / h;
    let slope = |y: &[f64; N_STATES]| {
        if y[5] > 0.0 { (y[5] * gp + y[6] * gg) / y[5] } else { secant }
    };
    let u = (phi - a[1]) / h;
    let (u2, u3) = (u * u, u * u * u);
    (2.0 * u3 - 3.0 * u2 + 1.0) * ta
        + (u3 - 2.0 * u2 + u) * h * slope(a)
        + (-2.0 * u3 + 3.0 * u2) * tb
        + (u3 - u2) * h * slope(b)
}
