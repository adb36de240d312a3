//! The stable RK4 step of every integration, and the bounds on the work a request may ask for.
//!
//! # The step rule
//!
//! Every fixed-step RK4 integration of Eqs. 1–4 ([`fn@super::simulate`]'s default step,
//! [`super::run_to_steady`], [`fn@super::sweep`], `spectrum --dynamic`, the units of
//! [`super::unit`] and the Python package) takes its largest step from one function,
//! [`stable_rk4_step`]:
//!
//! ```text
//! h_max = min( T_m/N , 2π/(ω_fast·S) ),   T_m = 2π/(z_p·|ω_p|)  (∞ at rest)
//! ```
//!
//! with N the steps per mesh period (default 128, see [`mod@super::simulate`]), ω_fast the fastest
//! natural frequency of the system linearised about its static equilibrium
//! ([`super::model::Drivetrain::linear_frequencies`] with the mesh stiffness measured by
//! [`super::model::mesh_stiffness`] under the nominal torque; the units use the same measured
//! stiffness), and S the steps per period of that mode, [`STEPS_PER_FAST_PERIOD`] = 32 unless
//! the caller asks for more (the sweep keeps its 128).
//!
//! Why both terms. The mesh period bounds the step at speed: the excitation (the mesh
//! stiffness variation) has period T_m, and the steady-state detector needs an integer number
//! of samples per period. At low speed and at rest T_m grows without bound, but the mesh mode
//! does not slow down: Table 1's mesh mode is at ω_fast ≈ 1.6·10⁴ rad/s, so at 8 rad/s the old
//! step T_m/128 = 2.6·10⁻⁴ s gave ω_fast·h ≈ 4.2, outside RK4's stability region, and TE grew
//! without bound. The second term keeps ω_fast·h ≤ 2π/32 ≈ 0.196.
//!
//! Why 32 steps per fastest period. RK4's region of absolute stability reaches 2√2 ≈ 2.83 on
//! the imaginary axis and 2.785 on the negative real axis; the largest half-disc about the
//! origin in the left half-plane inside it has radius ≈ 2.61 (measured on the boundary
//! |1 + z + z²/2 + z³/6 + z⁴/24| = 1), so every mode with |λ|·h ≤ 2.6 is stable whatever its
//! damping. At 32 steps ω·h = 0.196 lies a factor 13 inside that: the mesh may stiffen with
//! load (a dynamic TE of several times the static one) without leaving the stability region,
//! and the per-period amplitude error of a free oscillation, (ωh)⁶/144 per step, is about
//! 4·10⁻⁷ per period, so the mode is also resolved, not only stable.
//!
//! **Damping.** ω_fast is not only the undamped frequency: the shafts' damping d1, d2 and the
//! mesh damping of Eq. 14 (a force d_mesh·E·v_TE along the line of action, E the loaded axial
//! extent in units of m_n) make the linearisation J·q̈ + C·q̇ + K·q = 0, whose eigenvalues λ
//! are those of the state matrix [[0, I], [−J⁻¹K, −J⁻¹C]]. For the mesh mode alone
//! (equivalent mass m, stiffness k, damping c = d_mesh·E, ω = √(k/m), ζ = c/(2√(km))):
//!
//! ```text
//! ζ < 1:  λ = −ζω ± iω√(1 − ζ²),   |λ| = ω
//! ζ ≥ 1:  λ = −ω(ζ ∓ √(ζ² − 1)),   |λ|max = ω(ζ + √(ζ² − 1)) → c/m   (ζ → ∞)
//! ```
//!
//! Below critical damping every eigenvalue lies on the circle |λ| = ω, so the undamped rule
//! holds whatever ζ; above it the fast real eigenvalue grows with the damping, and with h set
//! by ω alone, h·λ leaves RK4's interval [−2.785, 0] on the real axis (Table 1 at 300 rad/s
//! and h = T_m/128: from d_mesh ≈ 2.4·10⁴ N·s/m on, with forces several times too large and
//! no error). The rule therefore takes ω_fast = max(ω, max|λ|) over the eigenvalues of the
//! damped linearisation ([`linear_eigenvalues`], [`fastest_linear_rate`],
//! [`super::model::Drivetrain::fastest_rate`], with c measured at the equilibrium by
//! [`super::model::mesh_linearisation`]): then |h·λ| ≤ 2π/32 for every λ, inside the
//! half-disc of radius 2.6 below. Lightly damped systems keep their step (|λ| = ω); an
//! overdamped mesh mode shortens it in proportion to c/m, and the work bounds below refuse a
//! request that would then take too many steps, naming the steps and the bound.
//!
//! An explicit step is refused ([`check_rk4_step`]) when ω_fast·h exceeds
//! [`RK4_MAX_OMEGA_H`] = 2.0: the stability radius 2.6 with a margin of 30 % in ω for the
//! stiffening of the mesh under dynamic load. Such a step does not give a coarse answer but a
//! diverging one.
//!
//! # Bounds on the work of a request
//!
//! Every request whose cost grows with an input is checked against one of the constants below
//! before memory is reserved or a loop starts; above it the error
//! ([`super::model::DynamicsError::TooLarge`]) names the request, its cost and the bound. The
//! bounds keep one request within a few hundred MB and a few minutes on one core at table
//! fidelity (an RK4 step of the Drive at table fidelity costs about 1 µs; at full fidelity
//! each mesh evaluation costs 10⁻⁴–10⁻³ s, so the same bound is proportionally slower).

use super::model::{Drivetrain, DynamicsError, GearDynamics, mesh_linearisation};
/// The eigenvalues of the linearisation behind the step rule (defined beside the drivetrain).
pub use super::model::{fastest_linear_rate, linear_eigenvalues};
use crate::mesh::MeshTorques;

/// Steps per period of the fastest linearised mode of the step rule (see the module doc).
pub const STEPS_PER_FAST_PERIOD: f64 = 32.0;

/// Radius of the largest left half-disc inside RK4's region of absolute stability (≈ 2.61,
/// the boundary's smallest distance from the origin in the left half-plane), dimensionless.
pub const RK4_STABILITY_RADIUS: f64 = 2.6;

/// Largest ω_fast·h accepted for an explicit RK4 step: [`RK4_STABILITY_RADIUS`]/1.3 (a 30 %
/// margin in ω for the mesh stiffening under dynamic load), dimensionless.
pub const RK4_MAX_OMEGA_H: f64 = 2.0;

/// Most samples a trajectory of [`fn@super::simulate`] may record (one per RK4 step or output
/// time): a sample (time, 8 states, the mesh outputs) is 144 bytes, so 2·10⁶ samples are
/// 288 MB, and 2·10⁶ RK4 steps at table fidelity take about 3 s (Table 1 at 532 rad/s with
/// T_m/128 needs 3.3·10⁵ per simulated second). The request refused first: 1 ms at 10⁹ rad/s
/// (6.1·10⁸ samples, 88 GB).
pub const MAX_TRAJECTORY_SAMPLES: usize = 2_000_000;

/// Most RK4 steps of one run of [`super::run_to_steady`] (`max_periods` × steps per mesh
/// period), checked before the run starts: at table fidelity about 2.5 minutes. A sweep point
/// at 0.01 rad/s (Table 1: 6.7·10⁶ steps per mesh period, 3000 periods, 2·10¹⁰ steps, about
/// 8 hours) is refused at once.
pub const MAX_STEADY_STEPS: f64 = 1e8;

/// Most samples of the steady window (period multiple × period P × steps per mesh period)
/// kept by [`super::run_to_steady`] (states and outputs, 144 bytes each, plus the detector's
/// 2 samples of 8 bytes each): about 3·10² MB at most.
pub const MAX_WINDOW_SAMPLES: usize = 2_000_000;

/// Most RK4 sub-steps of one [`super::DriveUnit::advance`] (a communication step): at table
/// fidelity about 1.5 s, at full fidelity minutes (a 0.1 ms step at w_p = 10⁹ rad/s asked for
/// 6·10⁷). A longer step is refused before it starts
/// (an FMU returns `fmi2Discard` with its state unchanged); a master takes shorter steps.
pub const MAX_UNIT_SUBSTEPS: f64 = 1e6;

/// Most mesh evaluations × slices per evaluation of one [`super::DriveUnit::advance`] with a
/// mesh whose evaluation cost grows with its slices (full fidelity,
/// [`crate::mesh::MeshTorques::evaluation_slices`]; RK4: 4 evaluations per sub-step): about a
/// minute at the measured 5.4 µs per slice-evaluation (Table 1, 200 slices: 1.1 ms per
/// evaluation, `docs/bench/units.md`), i.e. 5·10⁴ evaluations at 200 slices. The sub-step
/// bound [`MAX_UNIT_SUBSTEPS`] alone let one full-fidelity `doStep(1e-2)` at 65 536 sub-steps
/// per mesh period run for 27 minutes. A table mesh (no growth with slices) is bounded by
/// [`MAX_UNIT_SUBSTEPS`] only.
pub const MAX_UNIT_SLICE_EVALUATIONS: f64 = 1e7;

/// Most golden-section refinement runs per resonance peak of [`fn@super::sweep`] (each a
/// [`super::run_to_steady`]); more would not narrow the bracket below round-off anyway
/// (0.618⁶⁴ ≈ 4·10⁻¹⁴).
pub const MAX_REFINE_RUNS: usize = 64;

/// Most speeds of one [`fn@super::sweep`].
pub const MAX_SWEEP_SPEEDS: usize = 100_000;

/// Most TE samples of a static spectrum (meshes of the period × points per mesh period) or of
/// a sweep's static TE curve ([`super::SweepOptions::static_points`]): one static equilibrium
/// each, about 10⁻³ s at full fidelity, so 10⁶ samples take ~20 minutes and
/// 8 MB.
pub const MAX_SPECTRUM_SAMPLES: u64 = 1_000_000;

/// Largest RK4 step, s: min(T_m/N, 2π/(ω_fast·S)) with T_m = `mesh_period` (s; `f64::INFINITY`
/// at rest), N = `steps_per_mesh_period` (> 0), ω_fast = `omega_fast` (rad/s, > 0) the fastest
/// linearised mode and S = `steps_per_fast_period` (≥ [`STEPS_PER_FAST_PERIOD`] in every
/// caller). The one step rule of the crate (see the module doc).
pub fn stable_rk4_step(
    mesh_period: f64,
    steps_per_mesh_period: f64,
    omega_fast: f64,
    steps_per_fast_period: f64,
) -> f64 {
    let h_mesh = mesh_period / steps_per_mesh_period;
    let h_fast = 2.0 * std::f64::consts::PI / (omega_fast * steps_per_fast_period);
    h_mesh.min(h_fast)
}

/// The fastest rate ω_fast (rad/s) of Eqs. 1–4 linearised about the static equilibrium under
/// the drivetrain's torque at pinion angle `phi_p` (rad): the largest of the fastest undamped
/// natural frequency ([`Drivetrain::linear_frequencies`]) and the largest modulus |λ| of the
/// eigenvalues of the damped linearisation ([`Drivetrain::fastest_rate`], shaft damping and
/// the mesh damping of Eq. 14), with the mesh stiffness and damping coefficient measured by
/// [`mesh_linearisation`]. A few mesh evaluations (the equilibrium, a central difference and
/// one damping evaluation).
pub fn fastest_mode<M: MeshTorques>(
    model: &mut GearDynamics<M>,
    phi_p: f64,
) -> Result<f64, DynamicsError> {
    let drive: Drivetrain = *model.drive();
    let (gp, gg) = model.base_radii();
    let lin = mesh_linearisation(model.mesh_mut(), phi_p, drive.torque)
        .map_err(|source| DynamicsError::Mesh { t: None, source })?;
    model.mesh_mut().forget_history();
    let k = lin.stiffness;
    if !(k.is_finite() && k > 0.0) {
        return Err(DynamicsError::InvalidInput {
            name: "mesh stiffness",
            value: k,
            allowed: "finite and > 0 at the static equilibrium under the torque (N/m)",
        });
    }
    let undamped = drive.linear_frequencies(k, gp, gg)[3];
    Ok(undamped.max(drive.fastest_rate(k, lin.damping, gp, gg)))
}

/// RK4's amplification factor R(z) = 1 + z + z²/2 + z³/6 + z⁴/24 for z = h·λ: a linear mode
/// is integrated stably when |R(z)| ≤ 1.
pub fn rk4_amplification(z: num_complex::Complex<f64>) -> f64 {
    let z2 = z * z;
    (1.0 + z + z2 / 2.0 + z2 * z / 6.0 + z2 * z2 / 24.0).norm()
}

/// Refuses an explicit RK4 step `dt` (s) for which ω_fast·dt (`omega_fast` in rad/s) exceeds
/// [`RK4_MAX_OMEGA_H`]: the error names dt, ω_fast and the largest stable step.
pub fn check_rk4_step(dt: f64, omega_fast: f64) -> Result<(), DynamicsError> {
    if omega_fast * dt > RK4_MAX_OMEGA_H {
        return Err(DynamicsError::TooLarge(format!(
            "RK4 step dt = {dt:.3e} s is unstable for the fastest mode of the linearised \
             drive line (with the shaft and mesh damping) |λ| = {omega_fast:.3e} rad/s \
             (|λ|·dt = {:.3e}; RK4 diverges beyond {RK4_STABILITY_RADIUS}); at most \
             dt = {:.3e} s (|λ|·dt <= {RK4_MAX_OMEGA_H}), or leave the step to the default",
            omega_fast * dt,
            RK4_MAX_OMEGA_H / omega_fast
        )));
    }
    Ok(())
}

/// Bytes of one recorded trajectory sample (time, state, mesh outputs).
pub fn trajectory_sample_bytes() -> usize {
    std::mem::size_of::<f64>()
        + std::mem::size_of::<[f64; super::model::N_STATES]>()
        + std::mem::size_of::<crate::mesh::MeshOutputs>()
}
