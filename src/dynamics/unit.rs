//! Stateful drive-line units: a part of the drive line of Eqs. 1–4 with its own state and
//! integrator, advanced over communication steps with its inputs held (co-simulation), or
//! evaluated as a right-hand side with its linearisation (Model Exchange).
//!
//! # Kinds and their equations
//!
//! All angles in one absolute rotational sense (the crate's: the pinion drives turning in the
//! positive sense); mesh torques M_F, M_D from the [`MeshTorques`] implementation, positive in
//! normal drive and entering with a minus sign (see [`super::model`]).
//!
//! * [`UnitKind::Pair`]: the gear bodies and the mesh. States (φp, φg, φ̇p, φ̇g), inputs the
//!   torques the shafts exert on the hubs, `tau_p`, `tau_g`:
//!   ```text
//!   J_p φ̈p = tau_p − M_F,p − M_D,p          J_g φ̈g = tau_g − M_F,g − M_D,g
//!   ```
//!   (steady running under M: tau_p = M, tau_g = M_F,g = M·z_g/z_p).
//! * [`UnitKind::Stage`]: the pair plus the massless shafts c₁/d₁, c₂/d₂ of Eqs. 2–3. States as
//!   for the pair, inputs the motion of the shafts' far ends (φ₁, φ̇₁, φ₂, φ̇₂):
//!   ```text
//!   tau_p = c₁(φ₁ − φp) + d₁(φ̇₁ − φ̇p)        tau_g = −c₂(φg − φ₂) − d₂(φ̇g − φ̇₂)
//!   J_p φ̈p = tau_p − M_F,p − M_D,p          J_g φ̈g = tau_g − M_F,g − M_D,g
//!   ```
//!   Outputs the torques the shafts exert on J₁ and J₂, tau_1 = −tau_p and tau_2 = −tau_g, so
//!   that the master integrates J₁ φ̈₁ = M + tau_1 and J₂ φ̈₂ = M·z_g/z_p + tau_2 (steady
//!   running: tau_1 = −M).
//! * [`UnitKind::Drive`]: the whole 4-DOF model of Eqs. 1–4 ([`GearDynamics`]), eight states in
//!   the order of [`super::model`], input the driving torque M (the load on J₂ is M·z_g/z_p).
//!
//! # Inputs over a communication step
//!
//! Inputs ([`UnitInputs`]) are held from the time they were set ([`DriveUnit::set_inputs`]
//! and [`DriveUnit::set_input_rates`] record the unit's time t_u): torques are constant
//! (zero-order hold) unless their rates ([`UnitInputRates`]) are given
//! (`tau_p_rate`, `tau_g_rate`, `torque_rate`: first-order hold, tau_p(t) = tau_p +
//! tau_p_rate·(t − t_u), FMI's `fmi2SetRealInputDerivatives`); the Stage's far-end angles move
//! with the given rates and accelerations, φ₁(t) = φ₁ + φ̇₁·s + ½·a₁·s², φ̇₁(t) = φ̇₁ + a₁·s
//! with s = t − t_u and a₁ = `w_1_rate` (0 by default: the angle's first-order hold consistent
//! with the held rate).
//!
//! The Pair's hub torques come from shafts the master integrates, and they depend on the
//! hub motion the unit computes within the step. Held, they miss the hub's vibration at the
//! mesh frequency, which a communication step of T_m/4 samples too coarsely (the error of the
//! hub cut, docs/fmus.md). With a [`HubCoupling`] — the stiffness
//! and damping of the master's connection, the interface Jacobian −∂tau/∂(φ, φ̇) of the
//! interface-Jacobian co-simulation methods — the unit corrects the held torques by its own
//! motion relative to the motion it had when the inputs were set (the reference r: hub angle,
//! rate and acceleration at t_r = t_u):
//! ```text
//! tau_p(t) = tau_p + tau_p_rate·s − c_p·(φp(t) − φp,r − φ̇p,r·s) − d_p·(φ̇p(t) − φ̇p,r − φ̈p,r·s)
//! ```
//! and the same for the gear with c_g, d_g. For a linear shaft to a far end that moves with
//! constant acceleration this is exact: the given rate (the total derivative of the torque at
//! t_u) already holds the hub's −c·φ̇p,r − d·φ̈p,r, so only the deviation from that trend is
//! added. The zero coupling (default) is the plain hold; Model Exchange never applies it.
//! [`DriveUnit::derivatives`] and
//! [`DriveUnit::linearize`] (Model Exchange, where the inputs are set at every time) use the
//! inputs as set, without this extrapolation.
//!
//! # Sub-step grid
//!
//! [`UnitStepping::Rk4`]: each [`DriveUnit::advance`]`(h)` is cut into n = ⌈h/h_max⌉ equal
//! sub-steps of the classical RK4 ([`Rk4`]), with
//! ```text
//! h_max = min( T_m/N , T_fast/32 ),   T_m = 2π/(z_p·|φ̇p|) at the start of the step
//! ```
//! N = `steps_per_mesh_period` and T_fast = 2π/ω_fast the period of the unit's fastest
//! linearised mode (the mesh mode), with the mesh stiffness k and damping coefficient c
//! measured at construction at the static equilibrium under the nominal torque `drive.torque`
//! ([`mesh_linearisation`]; ω_fast is the larger of the undamped frequency and the largest
//! |λ| of the damped eigenvalues, which a heavily damped mesh moves beyond it; a changed
//! damping is measured again by [`DriveUnit::refresh_fastest_mode`]). At rest
//! (φ̇p = 0, T_m = ∞) and at low speed the second bound holds: ω_fast·h ≤ 2π/32 ≈ 0.2, far
//! inside RK4's stability interval (|ω·h| < 2.8 on the imaginary axis), so a unit at rest is
//! stable and its mesh mode resolved even if the actual stiffness is several times k (the
//! mesh stiffens with load). For Table 1 (ω_fast ≈ 1.6·10⁴ rad/s) the mesh-period bound
//! governs above ≈ 34 rad/s at N = 128. This is the crate's one step rule,
//! [`super::limits::stable_rk4_step`] (see [`super::limits`] for the stability argument).
//!
//! Bounded work: the sub-step count n is checked against [`super::limits::MAX_UNIT_SUBSTEPS`]
//! before anything changes; a larger request (a communication step of 0.1 ms at
//! φ̇p = 10⁹ rad/s is 6·10⁷ sub-steps, a stiff light shaft 10¹⁰) is an error that leaves time
//! and state as they were (an FMU returns `fmi2Discard`), never a hang. A step whose time
//! cannot advance in double precision ((t + h) − t off h by more than [`TIME_RESOLUTION`]·h;
//! t + 10⁻⁴ s == t from t ≈ 10¹⁷ s on) is an error as well: the state never advances while
//! the time stands still.
//!
//! [`UnitStepping::Dopri5`]: each advance is one [`Dopri5::integrate`] call from t to t + h
//! with the given tolerances, on the state in relative coordinates
//! ([`super::relative`]: φp, TE, the shaft twists and their rates), so that the error control
//! acts on TE itself rather than on the absolute angles, whose `rtol·|φ|` (φp grows by 532 rad
//! per second at 532 rad/s) would allow errors far larger than TE (measured, Drive at
//! 532 rad/s over 1 s: TE error 8.8e-5 at rtol 1e-8 on the absolute angles, 5.2e-7 on the
//! relative state). Its first step is the step the controller proposed at the end of the
//! previous advance (the "step hint", part of the snapshot), so a run cut into
//! communication steps does not restart the step-size control at each of them.
//!
//! Neither path allocates in its step loop: the integrator workspaces live in the unit. On any
//! failure (mesh model, non-finite value, step-size collapse) `advance` returns the error,
//! which names the time and the cause, and leaves time, state and step hint as they were
//! before the call; no NaN reaches the state or the outputs.
//!
//! # History, snapshots and bit-for-bit restarts
//!
//! The full-fidelity mesh ([`crate::mesh::Mesh`]) warm-starts its load solver from the loads
//! of the previous evaluation ([`crate::mesh::WarmStart`]), so its results depend on that warm
//! start at the level of the solver tolerance. The warm start is therefore part of the unit's
//! state: the unit holds it, every [`DriveUnit::advance`] starts the mesh from it
//! ([`MeshTorques::set_warm_start`], which also drops the remembered evaluation) and, on
//! success, keeps the warm start the advance ended with ([`MeshTorques::warm_start`]); a failed
//! advance leaves it as it was. [`DriveUnit::outputs`] and [`DriveUnit::linearize`] evaluate
//! from it without changing it, so reading the outputs between steps leaves the trajectory
//! bit for bit as it is (`tests/dynamics_unit.rs`); [`DriveUnit::derivatives`] (Model
//! Exchange) starts from it and keeps the new one, so that a Model Exchange master's nearby
//! states stay warm-started. [`DriveUnit::start_static`] keeps the static solve's warm
//! start; a new unit starts cold. The trajectory is then a function of (time, state, inputs,
//! input time, step hint, hub reference, warm start) alone — the [`UnitSnapshot`] — and
//! continuing after [`DriveUnit::restore`] reproduces it bit for bit, in the same unit, a
//! clone, or a fresh unit built from the same parameters after a serde round trip
//! (serde_json with `float_roundtrip` keeps every f64 exactly). A restored warm start is
//! checked ([`crate::mesh::WarmStart::check`]). Meshes without history (the table inside its
//! range, the analytic meshes) have an empty warm start: for them a Drive unit stepped with
//! RK4 at the step of [`super::simulate()`] reproduces its trajectory bit for bit.
//!
//! Carrying the warm start instead of restarting cold at every communication step (as
//! earlier versions did) saves the cold solve's extra Newton iterations at the first
//! evaluation of each step; the measured cost per step is the generated page
//! `docs/bench/units.md` (`cargo run --release -p helical-gear-app --example measure -- units`).

use std::ops::ControlFlow;

use super::integrators::{Dopri5, Dopri5Options, OdeError, OdeSystem, Rk4};
/// The unit kinds and the shape of a unit's linearisation ([`super::kind`]), where they were.
pub use super::kind::{UnitKind, UnitLinearization, UnitQuantity};
use super::limits::{MAX_UNIT_SLICE_EVALUATIONS, MAX_UNIT_SUBSTEPS, stable_rk4_step};
use super::model::{
    Drivetrain, DynamicsError, GearDynamics, MeshLoads, N_STATES, PHI_1, PHI_2, PHI_G, PHI_P,
    StaticStart, W_1, W_2, W_G, W_P, invalid, mesh_linearisation,
};
use super::relative::{InRelative, RelativeCoordinates};
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::{MeshJacobian, MeshOutputs, MeshState, MeshTorques, WarmStart};

pub use super::limits::STEPS_PER_FAST_PERIOD;

use crate::params::Bounds;

/// RK4 sub-steps per mesh period ([`UnitStepping::Rk4`]): 4 (the coarsest grid that still
/// resolves the mesh frequency) … 65 536.
pub const RK4_STEPS_PER_MESH_PERIOD: Bounds<i64> = Bounds::new(4, 65_536, "");
/// DOPRI5 relative tolerance ([`UnitStepping::Dopri5`]): 1e-14 (a few units of the double
/// rounding of the state) … 0.1 (beyond, no digit of TE is controlled).
pub const RTOL: Bounds<f64> = Bounds::new(1e-14, 0.1, "");
/// DOPRI5 absolute tolerance, one number for every component of the relative state (rad, m,
/// rad/s, m/s): 1e-30 … 1.
pub const ATOL: Bounds<f64> = Bounds::new(1e-30, 1.0, "");

/// Largest relative difference between the step a unit's time actually advances by in double
/// precision, (t + h) − t, and the step h asked for; beyond it [`DriveUnit::advance`] refuses
/// the step (at h = 10⁻⁴ s from about t = 10⁹ s on; `t + h == t` from about 10¹⁷ s on).
pub const TIME_RESOLUTION: f64 = 1e-3;

/// How a unit integrates inside a communication step.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum UnitStepping {
    /// Classic RK4 (dynamics::Rk4) on a grid tied to the mesh period: every communication step
    /// is cut into equal sub-steps no longer than T_m/steps_per_mesh_period (T_m at the current
    /// pinion speed, bounded so that a unit at rest stays stable: see the module doc).
    Rk4 {
        /// Sub-steps per mesh period N (≥ 4).
        steps_per_mesh_period: u32,
    },
    /// Dormand–Prince 5(4) (dynamics::Dopri5) with these tolerances; the step-size hint is part
    /// of the unit's state (snapshot).
    Dopri5 {
        /// Relative tolerance (> 0).
        rtol: f64,
        /// Absolute tolerance (> 0), for every component of the state in relative
        /// coordinates (rad, m, rad/s, m/s).
        atol: f64,
    },
}

/// Inputs of a unit as set (SI; the C API's `HgmUnitInputs`). Each kind reads only its own
/// fields (see UnitKind); their rates over a step are [`UnitInputRates`].
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct UnitInputs {
    /// Pair: torque the pinion shaft exerts on the pinion hub, N·m
    /// (J_p·φp'' = tau_p − M_F_p − M_D_p).
    pub tau_p: f64,
    /// Pair: torque the gear shaft exerts on the gear hub, N·m (J_g·φg'' = tau_g − M_F_g − M_D_g).
    pub tau_g: f64,
    /// Stage: angle of the pinion shaft's far end (J1 side), rad.
    pub phi_1: f64,
    /// Stage: rate of the pinion shaft's far end, rad/s.
    pub w_1: f64,
    /// Stage: angle of the gear shaft's far end (J2 side), rad.
    pub phi_2: f64,
    /// Stage: rate of the gear shaft's far end, rad/s.
    pub w_2: f64,
    /// Drive: driving torque M on J1, N·m (the load on J2 is M·z_g/z_p as in Eq. 4).
    pub torque: f64,
}

/// Time derivatives of a unit's inputs over a step (first-order hold, module doc; SI; the C
/// API's `HgmUnitInputRates`). Each kind reads only its own fields; all 0 is the plain hold.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct UnitInputRates {
    /// Pair: time derivative of `tau_p` over the step, N·m/s.
    pub tau_p_rate: f64,
    /// Pair: time derivative of `tau_g`, N·m/s.
    pub tau_g_rate: f64,
    /// Stage: angular acceleration of the pinion shaft's far end over the step, rad/s²
    /// (φ₁ moves as φ₁ + φ̇₁·s + ½·rate·s², its rate as φ̇₁ + rate·s).
    pub w_1_rate: f64,
    /// Stage: angular acceleration of the gear shaft's far end, rad/s².
    pub w_2_rate: f64,
    /// Drive: time derivative of the driving torque M, N·m/s.
    pub torque_rate: f64,
}

/// The inputs a unit holds: the values as set and their rates. Serialised as one JSON object
/// with the keys of both (`tau_p`, …, `torque`, `tau_p_rate`, …, `torque_rate`; a missing rate
/// reads as 0), the `inputs` of a [`UnitSnapshot`].
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct HeldInputs {
    /// The values as set.
    #[serde(flatten)]
    pub values: UnitInputs,
    /// Their rates over the step.
    #[serde(flatten)]
    pub rates: UnitInputRates,
}

/// Largest |angle| of a unit's inputs and state, rad. The mesh reduces angles by whole pitches
/// exactly (docs/robustness.md), so 10¹⁵ rad still give finite outputs; beyond, an
/// angle is no longer an operating point but a corrupted number.
pub const MAX_ANGLE_RAD: f64 = 1e15;

/// Largest |speed| of a unit's inputs and state, rad/s (about 10⁶ rpm, far above any gear's
/// running speed; beyond, the damping torques and the integrator's work per period explode).
pub const MAX_SPEED_RAD_S: f64 = crate::mesh::validity::MAX_SPEED_RAD_S;

/// Largest |speed| of a unit's state (explicit, restored or reached), rad/s: twice
/// [`MAX_SPEED_RAD_S`], room for the vibration of a unit running at the largest nominal speed
/// ([`crate::mesh::validity::MAX_STATE_SPEED_RAD_S`]).
pub const MAX_STATE_SPEED_RAD_S: f64 = crate::mesh::validity::MAX_STATE_SPEED_RAD_S;

/// Largest |torque| input of a unit, N·m (the range of the drive line's `torque_nm`).
pub const MAX_TORQUE_NM: f64 = 1e9;

/// Checks `v` of the value named `name` against |v| ≤ `max` (finite).
fn check_abs(
    name: &'static str,
    v: f64,
    max: f64,
    allowed: &'static str,
) -> Result<(), DynamicsError> {
    if v.is_finite() && v.abs() <= max { Ok(()) } else { Err(invalid(name, v, allowed)) }
}

impl UnitInputs {
    fn check(&self) -> Result<(), DynamicsError> {
        use UnitQuantity::*;
        for (q, v) in [(TauP, self.tau_p), (TauG, self.tau_g), (DrivingTorque, self.torque)] {
            check_abs(q.field_name(), v, MAX_TORQUE_NM, "finite, |torque| <= 1e9 N·m")?;
        }
        for (q, v) in [(Phi1, self.phi_1), (Phi2, self.phi_2)] {
            check_abs(q.field_name(), v, MAX_ANGLE_RAD, "finite, |angle| <= 1e15 rad")?;
        }
        for (q, v) in [(W1, self.w_1), (W2, self.w_2)] {
            check_abs(q.field_name(), v, MAX_SPEED_RAD_S, "finite, |speed| <= 1e5 rad/s")?;
        }
        Ok(())
    }
}

impl UnitInputRates {
    fn check(&self) -> Result<(), DynamicsError> {
        for (name, v) in [
            ("tau_p_rate", self.tau_p_rate),
            ("tau_g_rate", self.tau_g_rate),
            ("w_1_rate", self.w_1_rate),
            ("w_2_rate", self.w_2_rate),
            ("torque_rate", self.torque_rate),
        ] {
            if !v.is_finite() {
                return Err(invalid(name, v, "finite"));
            }
        }
        Ok(())
    }
}

impl HeldInputs {
    fn check(&self) -> Result<(), DynamicsError> {
        self.values.check()?;
        self.rates.check()
    }
}

/// Pair: stiffness and damping of the master's connections at the hubs (SI, each finite and
/// ≥ 0; all zero by default, the plain hold). For shafts c₁/d₁, c₂/d₂ in the master these are
/// c_p = c₁, d_p = d₁, c_g = c₂, d_g = d₂ (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct HubCoupling {
    /// −∂tau_p/∂φp of the pinion-side connection, N·m/rad.
    pub c_p: f64,
    /// −∂tau_p/∂φ̇p of the pinion-side connection, N·m·s/rad.
    pub d_p: f64,
    /// −∂tau_g/∂φg of the gear-side connection, N·m/rad.
    pub c_g: f64,
    /// −∂tau_g/∂φ̇g of the gear-side connection, N·m·s/rad.
    pub d_g: f64,
}

/// Hub-coupling stiffness ([`HubCoupling::c_p`], `c_g`): 0 … 1e15 N·m/rad (the drive line's
/// shaft-stiffness limit).
pub const HUB_STIFFNESS_NM_PER_RAD: Bounds<f64> = Bounds::new(0.0, 1e15, "N.m/rad");
/// Hub-coupling damping ([`HubCoupling::d_p`], `d_g`): 0 … 1e12 N·m·s/rad (the drive line's
/// shaft-damping limit).
pub const HUB_DAMPING_NMS_PER_RAD: Bounds<f64> = Bounds::new(0.0, 1e12, "N.m.s/rad");

impl HubCoupling {
    /// Errors: a component outside [`HUB_STIFFNESS_NM_PER_RAD`] or
    /// [`HUB_DAMPING_NMS_PER_RAD`], named by its FMI parameter
    /// (`hub_coupling.c_p_nm_per_rad` …).
    pub fn validate(&self) -> Result<(), DynamicsError> {
        let (c, d) = (HUB_STIFFNESS_NM_PER_RAD, HUB_DAMPING_NMS_PER_RAD);
        for (b, name, v) in [
            (c, "hub_coupling.c_p_nm_per_rad", self.c_p),
            (d, "hub_coupling.d_p_nms_per_rad", self.d_p),
            (c, "hub_coupling.c_g_nm_per_rad", self.c_g),
            (d, "hub_coupling.d_g_nms_per_rad", self.d_g),
        ] {
            b.check(name, v).map_err(DynamicsError::Param)?;
        }
        Ok(())
    }

    fn is_zero(&self) -> bool {
        *self == Self::default()
    }
}

/// Pair with a [`HubCoupling`]: the hub motion when the inputs were set, the reference of the
/// torque correction (module doc).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HubReference {
    /// Time of the reference, s.
    pub t: f64,
    /// (φp, φg, φ̇p, φ̇g), rad and rad/s.
    pub hub: [f64; 4],
    /// (φ̈p, φ̈g) under the inputs as set, rad/s².
    pub acc: [f64; 2],
}

impl HubReference {
    fn check(&self) -> Result<(), DynamicsError> {
        let all = [self.t].into_iter().chain(self.hub).chain(self.acc);
        match all.into_iter().find(|v| !v.is_finite()) {
            Some(v) => Err(invalid("snapshot hub reference", v, "finite")),
            None => Ok(()),
        }
    }
}

/// Outputs of a unit at its current time and state (SI). Fields a kind does not hold are the
/// values it sees (Stage: phi_1…w_2 are the far-end inputs at the current time) or 0. The C
/// API's `HgmUnitOutputs`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UnitOutputs {
    /// Time, s.
    pub t: f64,
    /// Pinion hub angle φp, rad.
    pub phi_p: f64,
    /// Pinion hub rate φ̇p, rad/s.
    pub w_p: f64,
    /// Pinion hub acceleration φ̈p, rad/s².
    pub a_p: f64,
    /// Gear hub angle φg, rad.
    pub phi_g: f64,
    /// Gear hub rate φ̇g, rad/s.
    pub w_g: f64,
    /// Gear hub acceleration φ̈g, rad/s².
    pub a_g: f64,
    /// State derivative at the current time, state and inputs, in the kind's state order
    /// ([`UnitKind::states`]; entries beyond [`UnitKind::n_states`] are 0), rad/s and
    /// rad/s².
    pub dydt: [f64; N_STATES],
    /// Angle of J1 (Drive) or of the pinion shaft's far end (Stage), rad; 0 for Pair.
    pub phi_1: f64,
    /// Rate of J1 (Drive) or of the pinion shaft's far end (Stage), rad/s; 0 for Pair.
    pub w_1: f64,
    /// Angle of J2 (Drive) or of the gear shaft's far end (Stage), rad; 0 for Pair.
    pub phi_2: f64,
    /// Rate of J2 (Drive) or of the gear shaft's far end (Stage), rad/s; 0 for Pair.
    pub w_2: f64,
    /// Torque the pinion shaft exerts on J1 (Stage, Drive), N·m: J1·φ1'' = M + tau_1
    /// (steady running: tau_1 = −M); 0 for Pair.
    pub tau_1: f64,
    /// Torque the gear shaft exerts on J2 (Stage, Drive), N·m: J2·φ2'' = M·z_g/z_p + tau_2;
    /// 0 for Pair.
    pub tau_2: f64,
    /// Torque the pinion shaft exerts on the pinion hub (Stage, Drive; the input for Pair), N·m.
    pub tau_p: f64,
    /// Torque the gear shaft exerts on the gear hub (Stage, Drive; the input for Pair), N·m.
    pub tau_g: f64,
    /// The mesh outputs (torques, TE, F_n, flags) at the current state.
    pub mesh: MeshOutputs,
}

/// One scalar field of [`UnitOutputs`]: its name, its SI unit and its reader.
pub type UnitOutputField = (&'static str, &'static str, fn(&UnitOutputs) -> f64);

/// The scalar fields of [`UnitOutputs`] besides the mesh outputs and `dydt`: the field name
/// of `UnitOutputs` and of the C struct `HgmUnitOutputs`, its SI unit, and its reader. The mesh
/// outputs are described by `mesh::outputs::MESH_OUTPUT_FIELDS`.
pub const UNIT_OUTPUT_FIELDS: [UnitOutputField; 15] = [
    ("t", "s", |o| o.t),
    ("phi_p", "rad", |o| o.phi_p),
    ("w_p", "rad/s", |o| o.w_p),
    ("a_p", "rad/s2", |o| o.a_p),
    ("phi_g", "rad", |o| o.phi_g),
    ("w_g", "rad/s", |o| o.w_g),
    ("a_g", "rad/s2", |o| o.a_g),
    ("phi_1", "rad", |o| o.phi_1),
    ("w_1", "rad/s", |o| o.w_1),
    ("phi_2", "rad", |o| o.phi_2),
    ("w_2", "rad/s", |o| o.w_2),
    ("tau_1", "N.m", |o| o.tau_1),
    ("tau_2", "N.m", |o| o.tau_2),
    ("tau_p", "N.m", |o| o.tau_p),
    ("tau_g", "N.m", |o| o.tau_g),
];

impl UnitOutputs {
    /// The first value that is not finite, as (field name, value): a scalar field of
    /// [`UNIT_OUTPUT_FIELDS`], an entry of `dydt` (`dydt[i]`) or a Real mesh output
    /// (`mesh.` and its field, e.g. `mesh.force_p[0]`).
    pub fn first_non_finite(&self) -> Option<(String, f64)> {
        if let Some((name, _, get)) =
            UNIT_OUTPUT_FIELDS.iter().find(|(_, _, g)| !g(self).is_finite())
        {
            return Some(((*name).to_string(), get(self)));
        }
        if let Some((i, v)) = self.dydt.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Some((format!("dydt[{i}]"), *v));
        }
        crate::mesh::outputs::first_non_finite(&self.mesh).map(|(n, v)| (format!("mesh.{n}"), v))
    }

    /// The value of quantity `q` (in its unit, [`UnitQuantity`]), or `None` for one the
    /// outputs do not hold: the relative coordinates (θ₁, θ₂, θ̇₁, θ̇₂, v_TE) and the driving
    /// torque M (an input).
    pub fn value(&self, q: UnitQuantity) -> Option<f64> {
        use UnitQuantity::*;
        Some(match q {
            PhiP => self.phi_p,
            WP => self.w_p,
            AP => self.a_p,
            PhiG => self.phi_g,
            WG => self.w_g,
            AG => self.a_g,
            Phi1 => self.phi_1,
            W1 => self.w_1,
            Phi2 => self.phi_2,
            W2 => self.w_2,
            Tau1 => self.tau_1,
            Tau2 => self.tau_2,
            TauP => self.tau_p,
            TauG => self.tau_g,
            MFP => self.mesh.m_f_p,
            MFG => self.mesh.m_f_g,
            MDP => self.mesh.m_d_p,
            MDG => self.mesh.m_d_g,
            Te => self.mesh.te,
            FN => self.mesh.f_n,
            Theta1 | Theta2 | WTheta1 | WTheta2 | VTe | DrivingTorque => return None,
        })
    }
}

/// Everything needed to continue a unit's trajectory bit for bit (see the module doc).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UnitSnapshot {
    /// Kind of the unit it was taken from (restore checks it).
    pub kind: UnitKind,
    /// Time, s.
    pub time: f64,
    /// State, in the kind's order (rad, rad/s).
    pub state: Vec<f64>,
    /// Inputs as set, with their rates.
    pub inputs: HeldInputs,
    /// Time at which the inputs were set (the origin of the Stage's far-end extrapolation), s.
    pub input_time: f64,
    /// DOPRI5: first step of the next advance, s (`None`: automatic choice).
    pub step_hint: Option<f64>,
    /// Pair with a hub coupling: the reference of the torque correction (`None`: not yet
    /// taken since the inputs were set).
    #[serde(default)]
    pub hub_ref: Option<HubReference>,
    /// The warm start of the mesh's load solver the next advance starts from (empty for
    /// meshes without one; see the module doc).
    #[serde(default)]
    pub warm_start: WarmStart,
}

/// Format version of [`UnitSnapshot::to_text`]; a text of another version is refused.
pub const SNAPSHOT_FORMAT_VERSION: u32 = 2;

/// The envelope of a snapshot's text: format version, 64-bit FNV-1a checksum (16 hex digits)
/// of the snapshot's compact JSON, the snapshot.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SnapshotText {
    format_version: u32,
    checksum: String,
    snapshot: UnitSnapshot,
}

impl UnitSnapshot {
    /// The snapshot as JSON text with a format version and a checksum:
    /// `{"format_version":1,"checksum":"<16 hex digits>","snapshot":{…}}`, the checksum being
    /// [`crate::numeric::fnv1a_64`] of the snapshot's compact JSON (serde_json with
    /// `float_roundtrip`, so every f64 is kept exactly).
    pub fn to_text(&self) -> String {
        let body = serde_json::to_string(self).expect("a unit snapshot serialises");
        let envelope = SnapshotText {
            format_version: SNAPSHOT_FORMAT_VERSION,
            checksum: format!("{:016x}", crate::numeric::fnv1a_64(body.as_bytes())),
            snapshot: self.clone(),
        };
        serde_json::to_string(&envelope).expect("a unit snapshot serialises")
    }

    /// Reads a text of [`UnitSnapshot::to_text`]. Refused whole when it is not that JSON, has
    /// another format version, or its checksum does not match the snapshot it carries (the
    /// snapshot is serialised again and hashed: any change of a value is caught, a change of
    /// spelling that keeps every value, such as `1e-5` for `1E-5`, is harmless). The values are
    /// range-checked by [`DriveUnit::restore`].
    pub fn from_text(text: &str) -> Result<Self, String> {
        let e: SnapshotText =
            serde_json::from_str(text).map_err(|e| format!("unit snapshot text: {e}"))?;
        if e.format_version != SNAPSHOT_FORMAT_VERSION {
            return Err(format!(
                "unit snapshot has format version {}; this build reads version \
                 {SNAPSHOT_FORMAT_VERSION}",
                e.format_version
            ));
        }
        let body = serde_json::to_string(&e.snapshot).map_err(|e| e.to_string())?;
        let sum = format!("{:016x}", crate::numeric::fnv1a_64(body.as_bytes()));
        if sum != e.checksum {
            return Err(format!(
                "unit snapshot checksum mismatch (stored {}, computed {sum}): the snapshot was \
                 altered or corrupted",
                e.checksum.chars().take(16).collect::<String>()
            ));
        }
        Ok(e.snapshot)
    }
}

/// The right-hand side of a unit: the kind's equations over a [`GearDynamics`].
#[derive(Debug, Clone)]
struct UnitSystem<M> {
    kind: UnitKind,
    model: GearDynamics<M>,
    inputs: HeldInputs,
    input_time: f64,
    /// Move the Stage's far ends with their rates from `input_time` (co-simulation).
    extrapolate: bool,
    /// Pair: the master's connection stiffness and damping at the hubs.
    coupling: HubCoupling,
    /// Pair with a coupling: the reference of the correction (co-simulation only).
    hub_ref: Option<HubReference>,
}

/// Shaft torques (on the pinion hub, c₁(φ₁ − φp) + d₁(φ̇₁ − φ̇p); and the gear shaft's
/// c₂(φg − φ₂) + d₂(φ̇g − φ̇₂), which acts on the gear hub with a minus sign), N·m.
fn shaft_torques(d: &Drivetrain, far: [f64; 4], hub: [f64; 4]) -> (f64, f64) {
    let [a1, v1, a2, v2] = far;
    let [pp, pg, wp, wg] = hub;
    (d.c1 * (a1 - pp) + d.d1 * (v1 - wp), d.c2 * (pg - a2) + d.d2 * (wg - v2))
}

impl<M: MeshTorques> UnitSystem<M> {
    /// Far-end motion (φ₁, φ̇₁, φ₂, φ̇₂) the Stage sees at time `t`.
    fn far_ends(&self, t: f64) -> [f64; 4] {
        let (u, r) = (&self.inputs.values, &self.inputs.rates);
        let dt = self.held_for(t);
        let (a1, a2) = (r.w_1_rate, r.w_2_rate);
        [
            u.phi_1 + (u.w_1 + 0.5 * a1 * dt) * dt,
            u.w_1 + a1 * dt,
            u.phi_2 + (u.w_2 + 0.5 * a2 * dt) * dt,
            u.w_2 + a2 * dt,
        ]
    }

    /// Time since the inputs were set (co-simulation), 0 without extrapolation (Model
    /// Exchange), s.
    fn held_for(&self, t: f64) -> f64 {
        if self.extrapolate { t - self.input_time } else { 0.0 }
    }

    /// Hub torques (tau_p, tau_g) of a 4-state kind at time `t` and hub state `hub`.
    fn hub_torques(&self, t: f64, hub: [f64; 4]) -> (f64, f64) {
        match self.kind {
            UnitKind::Pair => {
                let (u, r, dt) = (&self.inputs.values, &self.inputs.rates, self.held_for(t));
                let tp = u.tau_p + r.tau_p_rate * dt;
                let tg = u.tau_g + r.tau_g_rate * dt;
                match (&self.hub_ref, self.extrapolate) {
                    (Some(r), true) => {
                        let (c, s) = (&self.coupling, t - r.t);
                        let [pp, pg, wp, wg] = r.hub;
                        let dp =
                            c.c_p * (hub[0] - pp - wp * s) + c.d_p * (hub[2] - wp - r.acc[0] * s);
                        let dg =
                            c.c_g * (hub[1] - pg - wg * s) + c.d_g * (hub[3] - wg - r.acc[1] * s);
                        (tp - dp, tg - dg)
                    }
                    _ => (tp, tg),
                }
            }
            _ => {
                let (s1, s2) = shaft_torques(self.model.drive(), self.far_ends(t), hub);
                (s1, -s2)
            }
        }
    }

    fn hub(&self, y: &[f64]) -> [f64; 4] {
        let [i, j, k, l] = self.kind.hub_indices();
        [y[i], y[j], y[k], y[l]]
    }

    /// Mesh outputs at `y`, as an [`OdeError`] at time `t` on failure.
    fn mesh(&mut self, t: f64, y: &[f64]) -> Result<MeshOutputs, OdeError> {
        let [pp, pg, wp, wg] = self.hub(y);
        self.model.mesh_at(pp, pg, wp, wg).map_err(|e| OdeError::rhs(t, e))
    }

    /// The mesh outputs of the torques path at `y` and whether they are complete
    /// ([`GearDynamics::torques_flagged_at`]).
    fn mesh_torques(&mut self, t: f64, y: &[f64]) -> Result<(MeshOutputs, bool), OdeError> {
        let [pp, pg, wp, wg] = self.hub(y);
        self.model.torques_flagged_at(pp, pg, wp, wg).map_err(|e| OdeError::rhs(t, e))
    }

    /// The mesh torques and TE at `y` (the right-hand side's; [`GearDynamics::torques_at`]).
    fn torques(&mut self, t: f64, y: &[f64]) -> Result<MeshLoads, OdeError> {
        let [pp, pg, wp, wg] = self.hub(y);
        self.model.torques_at(pp, pg, wp, wg).map(MeshLoads::of).map_err(|e| OdeError::rhs(t, e))
    }
}

impl<M: MeshTorques> OdeSystem for UnitSystem<M> {
    fn dim(&self) -> usize {
        self.kind.n_states()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError> {
        if self.kind == UnitKind::Drive {
            if self.inputs.rates.torque_rate != 0.0 {
                let m =
                    self.inputs.values.torque + self.inputs.rates.torque_rate * self.held_for(t);
                self.model.set_torque(m);
            }
            return self.model.rhs(t, y, dydt);
        }
        let n = self.dim();
        if y.len() != n || dydt.len() != n {
            return Err(OdeError::DimensionMismatch {
                what: "y/dydt",
                expected: n,
                found: if y.len() != n { y.len() } else { dydt.len() },
            });
        }
        let o = self.torques(t, y)?;
        let hub = self.hub(y);
        let (tau_p, tau_g) = self.hub_torques(t, hub);
        let d = self.model.drive();
        dydt[0] = y[2];
        dydt[1] = y[3];
        dydt[2] = (tau_p - o.m_f_p - o.m_d_p) / d.j_p;
        dydt[3] = (tau_g - o.m_f_g - o.m_d_g) / d.j_g;
        Ok(())
    }
}

/// A unit: a drive-line part with its own state and integrator (see the module doc).
#[derive(Debug, Clone)]
pub struct DriveUnit<M> {
    sys: UnitSystem<M>,
    stepping: UnitStepping,
    /// The drivetrain as built (its torque is the nominal load of the static start).
    drive0: Drivetrain,
    t: f64,
    y: [f64; N_STATES],
    rk4: Rk4,
    dopri: Option<Dopri5>,
    step_hint: Option<f64>,
    /// The fastest rate of the damped linearisation (the step rule's ω_fast), rad/s.
    omega_fast: f64,
    /// Mesh stiffness at the static equilibrium under the nominal torque, N/m.
    k_mesh: f64,
    /// Static TE of that equilibrium (φp = 0), m: where the damping is measured again.
    te_nominal: f64,
    dydt: [f64; N_STATES],
    /// The mesh's warm start at the current state: part of the state (snapshots carry it).
    warm: WarmStart,
}

/// Largest eigenvalue ω of K v = ω² J v for two inertias `j` and a symmetric stiffness `k`.
fn fastest_2x2(j: [f64; 2], k: [[f64; 2]; 2]) -> f64 {
    let a = k[0][0] / j[0];
    let d = k[1][1] / j[1];
    let b = k[0][1] / (j[0] * j[1]).sqrt();
    let mean = 0.5 * (a + d);
    let rad = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    (mean + rad).max(0.0).sqrt()
}

/// The fastest rate (rad/s) of a unit of `kind` linearised with mesh stiffness `k` (N/m) and
/// mesh damping coefficient `c` (N·s/m) along the line of action: the hubs' 2 × 2 system (with
/// the shafts to fixed far ends for Stage and Drive) and, for the Drive, the whole drive line;
/// for each the larger of the undamped frequency and the largest |λ| of the damped
/// eigenvalues ([`super::limits::fastest_linear_rate`]).
fn unit_fastest_rate(kind: UnitKind, d: &Drivetrain, k: f64, c: f64, gp: f64, gg: f64) -> f64 {
    let (c1, c2, d1, d2) =
        if kind == UnitKind::Pair { (0.0, 0.0, 0.0, 0.0) } else { (d.c1, d.c2, d.d1, d.d2) };
    let hub_k = [[c1 + k * gp * gp, k * gp * gg], [k * gp * gg, c2 + k * gg * gg]];
    let hub_c = [d1 + c * gp * gp, c * gp * gg, c * gp * gg, d2 + c * gg * gg];
    let hub = fastest_2x2([d.j_p, d.j_g], hub_k).max(super::limits::fastest_linear_rate(
        &[d.j_p, d.j_g],
        &[hub_k[0][0], hub_k[0][1], hub_k[1][0], hub_k[1][1]],
        &hub_c,
    ));
    match kind {
        UnitKind::Drive => {
            hub.max(d.linear_frequencies(k, gp, gg)[3]).max(d.fastest_rate(k, c, gp, gg))
        }
        _ => hub,
    }
}

impl<M: MeshTorques + Clone> DriveUnit<M> {
    /// A unit of `kind` with mesh `mesh`, drivetrain `drive` (validated; `drive.torque` > 0 is
    /// the nominal load of the static start and of the mesh-stiffness estimate behind the
    /// low-speed step bound) and integration `stepping`. Time 0, state 0, inputs 0 (Drive:
    /// torque = `drive.torque`).
    ///
    /// Errors: invalid drivetrain, stepping or torque (named), or a mesh that fails at the
    /// static equilibrium used to estimate its stiffness.
    pub fn new(
        kind: UnitKind,
        mut mesh: M,
        drive: Drivetrain,
        stepping: UnitStepping,
    ) -> Result<Self, DynamicsError> {
        drive.validate()?;
        if drive.torque.is_nan() || drive.torque <= 0.0 {
            return Err(invalid(
                "torque",
                drive.torque,
                "> 0 (N·m; the nominal load of the static start and the step bound)",
            ));
        }
        let dopri = match stepping {
            UnitStepping::Rk4 { steps_per_mesh_period } => {
                RK4_STEPS_PER_MESH_PERIOD
                    .check_int("steps_per_mesh_period", i64::from(steps_per_mesh_period))
                    .map_err(DynamicsError::Param)?;
                None
            }
            UnitStepping::Dopri5 { rtol, atol } => {
                RTOL.check("rtol", rtol).map_err(DynamicsError::Param)?;
                ATOL.check("atol", atol).map_err(DynamicsError::Param)?;
                let opts = Dopri5Options::with_tolerances(rtol, atol);
                Some(Dopri5::new(kind.n_states(), opts)?)
            }
        };
        let lin = mesh_linearisation(&mut mesh, 0.0, drive.torque)
            .map_err(|source| DynamicsError::Mesh { t: None, source })?;
        let k = lin.stiffness;
        if !(k.is_finite() && k > 0.0) {
            return Err(invalid("mesh stiffness", k, "finite and > 0 at the nominal load (N/m)"));
        }
        mesh.forget_history();
        let model = GearDynamics::new(mesh, drive)?;
        let (gp, gg) = model.base_radii();
        let omega_fast = unit_fastest_rate(kind, &drive, k, lin.damping, gp, gg);
        let inputs = HeldInputs {
            values: UnitInputs { torque: drive.torque, ..UnitInputs::default() },
            rates: UnitInputRates::default(),
        };
        Ok(Self {
            sys: UnitSystem {
                kind,
                model,
                inputs,
                input_time: 0.0,
                extrapolate: true,
                coupling: HubCoupling::default(),
                hub_ref: None,
            },
            stepping,
            drive0: drive,
            t: 0.0,
            y: [0.0; N_STATES],
            rk4: Rk4::new(kind.n_states()),
            dopri,
            step_hint: None,
            omega_fast,
            k_mesh: k,
            te_nominal: lin.te,
            warm: WarmStart::default(),
            dydt: [0.0; N_STATES],
        })
    }

    /// Which part of the drive line the unit holds.
    pub fn kind(&self) -> UnitKind {
        self.sys.kind
    }

    /// Number of states (4 or 8).
    pub fn n_states(&self) -> usize {
        self.sys.kind.n_states()
    }

    /// The states in state order ([`UnitKind::states`]).
    pub fn states(&self) -> &'static [UnitQuantity] {
        self.sys.kind.states()
    }

    /// The integration settings.
    pub fn stepping(&self) -> UnitStepping {
        self.stepping
    }

    /// The drivetrain (torque: the nominal load given at construction).
    pub fn drive(&self) -> &Drivetrain {
        &self.drive0
    }

    /// Angular frequency of the unit's fastest linearised mode (the mesh mode) at the nominal
    /// load, rad/s; it bounds the RK4 sub-step at low speed (see the module doc).
    pub fn fastest_mode(&self) -> f64 {
        self.omega_fast
    }

    /// Mesh stiffness at the static equilibrium under the nominal torque (measured at
    /// construction), N/m.
    pub fn nominal_mesh_stiffness(&self) -> f64 {
        self.k_mesh
    }

    /// Measures the mesh damping coefficient again at the nominal static equilibrium (one mesh
    /// evaluation) and sets the fastest rate of the step rule from it: to be called after the
    /// mesh's damping changed ([`Self::mesh_mut`], e.g. a tuned `d_mesh`), so that the RK4
    /// sub-step stays inside the stability region of the damped linearisation.
    pub fn refresh_fastest_mode(&mut self) -> Result<(), DynamicsError> {
        let (gp, gg) = self.sys.model.base_radii();
        let v = 1e-3;
        let state = MeshState {
            phi_p: 0.0,
            phi_g: crate::numeric::phi_g_for_te(0.0, self.te_nominal, gp, gg),
            w_p: v / gp,
            w_g: 0.0,
            ..Default::default()
        };
        let mesh = self.sys.model.mesh_mut();
        let m_d =
            mesh.mesh(&state).map_err(|source| DynamicsError::Mesh { t: None, source })?.m_d_p;
        mesh.forget_history();
        let c = (m_d / (v * gp)).max(0.0);
        self.omega_fast = unit_fastest_rate(self.sys.kind, &self.drive0, self.k_mesh, c, gp, gg);
        Ok(())
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Current state (length [`Self::n_states`]), rad and rad/s.
    pub fn state(&self) -> &[f64] {
        &self.y[..self.n_states()]
    }

    /// Sets the time (s, finite).
    pub fn set_time(&mut self, t: f64) -> Result<(), DynamicsError> {
        if !t.is_finite() {
            return Err(invalid("t", t, "finite (s)"));
        }
        self.t = t;
        Ok(())
    }

    /// Sets the state (length [`Self::n_states`], every component finite).
    pub fn set_state(&mut self, y: &[f64]) -> Result<(), DynamicsError> {
        let n = self.n_states();
        if y.len() != n {
            return Err(invalid("state length", y.len() as f64, "the unit's number of states"));
        }
        if let Some(v) = y.iter().find(|v| !v.is_finite()) {
            return Err(invalid("state component", *v, "finite"));
        }
        self.y[..n].copy_from_slice(y);
        Ok(())
    }

    /// The inputs as set.
    pub fn inputs(&self) -> &UnitInputs {
        &self.sys.inputs.values
    }

    /// The rates of the inputs as set (0 unless [`DriveUnit::set_input_rates`] gave others
    /// since the inputs were last set).
    pub fn input_rates(&self) -> &UnitInputRates {
        &self.sys.inputs.rates
    }

    /// Time at which the inputs were set, s (origin of the Stage's far-end extrapolation).
    pub fn input_time(&self) -> f64 {
        self.sys.input_time
    }

    /// Sets the inputs, valid from the current time on, with rates 0 (zero-order hold):
    /// torques within ±[`MAX_TORQUE_NM`], angles within ±[`MAX_ANGLE_RAD`], speeds within
    /// ±[`MAX_SPEED_RAD_S`].
    pub fn set_inputs(&mut self, u: UnitInputs) -> Result<(), DynamicsError> {
        self.hold(HeldInputs { values: u, rates: UnitInputRates::default() })
    }

    /// Sets the rates of the inputs (each finite), the inputs as set moving with them from the
    /// current time on (first-order hold, module doc).
    pub fn set_input_rates(&mut self, r: UnitInputRates) -> Result<(), DynamicsError> {
        self.hold(HeldInputs { values: self.sys.inputs.values, rates: r })
    }

    /// Holds `h` from the current time on (checked first; unchanged on error).
    fn hold(&mut self, h: HeldInputs) -> Result<(), DynamicsError> {
        h.check()?;
        self.sys.inputs = h;
        self.sys.input_time = self.t;
        self.sys.hub_ref = None;
        self.sys.model.set_torque(h.values.torque);
        Ok(())
    }

    /// Pair: sets the master's connection stiffness and damping at the hubs (module doc;
    /// validated, zero = plain hold). Other kinds: an error, they hold their shafts themselves.
    pub fn set_hub_coupling(&mut self, c: HubCoupling) -> Result<(), DynamicsError> {
        c.validate()?;
        if self.sys.kind != UnitKind::Pair && !c.is_zero() {
            return Err(invalid(
                "hub coupling",
                c.c_p.max(c.c_g),
                "0 for units other than the Pair",
            ));
        }
        self.sys.coupling = c;
        self.sys.hub_ref = None;
        Ok(())
    }

    /// The hub coupling (zero unless set).
    pub fn hub_coupling(&self) -> HubCoupling {
        self.sys.coupling
    }

    /// Pair with a coupling and no reference yet: takes it at the current time and state (the
    /// hub accelerations under the inputs as set; one right-hand side evaluation).
    fn take_hub_reference(&mut self) -> Result<(), OdeError> {
        if self.sys.kind != UnitKind::Pair
            || self.sys.coupling.is_zero()
            || self.sys.hub_ref.is_some()
        {
            return Ok(());
        }
        let mut dydt = [0.0; 4];
        self.sys.rhs(self.t, &self.y[..4], &mut dydt)?;
        let [pp, pg, wp, wg] = self.sys.hub(&self.y);
        self.sys.hub_ref =
            Some(HubReference { t: self.t, hub: [pp, pg, wp, wg], acc: [dydt[2], dydt[3]] });
        Ok(())
    }

    /// Static equilibrium at nominal pinion speed `w_p_start` (rad/s, finite), φp = 0, under
    /// the nominal torque `drive.torque` (as [`super::simulate()`]'s start,
    /// [`GearDynamics::static_start`]): sets the time to `t0`, the state to the equilibrium's
    /// and the inputs to the ones that keep it (Pair: tau_p = M, tau_g = the shaft's torque on
    /// the gear hub; Stage: the far ends of the 8-state start; Drive: M = `drive.torque`).
    /// The DOPRI5 step hint is cleared.
    pub fn start_static(
        &mut self,
        t0: f64,
        w_p_start: f64,
        settings: &EquilibriumSettings,
    ) -> Result<StaticStart, DynamicsError> {
        if !t0.is_finite() {
            return Err(invalid("t0", t0, "finite (s)"));
        }
        check_abs(
            "w_p_start",
            w_p_start,
            MAX_SPEED_RAD_S,
            "finite, |speed| <= 1e5 rad/s (the largest nominal speed; negative: running \
             backwards)",
        )?;
        let m = self.drive0.torque;
        self.sys.model.set_torque(m);
        let start = match self.sys.model.static_start(0.0, w_p_start, settings) {
            Ok(s) => s,
            Err(e) => {
                self.sys.model.set_torque(self.sys.inputs.values.torque);
                return Err(e);
            }
        };
        let y = start.y;
        let (s1, s2) = shaft_torques(
            &self.drive0,
            [y[PHI_1], y[W_1], y[PHI_2], y[W_2]],
            [y[PHI_P], y[PHI_G], y[W_P], y[W_G]],
        );
        let mut u = UnitInputs { torque: m, ..UnitInputs::default() };
        match self.sys.kind {
            UnitKind::Pair => {
                u.tau_p = s1;
                u.tau_g = -s2;
            }
            UnitKind::Stage => {
                u.phi_1 = y[PHI_1];
                u.w_1 = y[W_1];
                u.phi_2 = y[PHI_2];
                u.w_2 = y[W_2];
            }
            UnitKind::Drive => {}
        }
        match self.sys.kind {
            UnitKind::Drive => self.y = y,
            _ => self.y[..4].copy_from_slice(&[y[PHI_P], y[PHI_G], y[W_P], y[W_G]]),
        }
        self.t = t0;
        self.step_hint = None;
        self.sys.model.warm_start(&mut self.warm);
        self.set_inputs(u)?;
        Ok(start)
    }

    /// Largest RK4 sub-step at the current state, s: min(T_m/N, T_fast/32) (module doc).
    fn rk4_max_step(&self, steps_per_mesh_period: u32) -> f64 {
        let [_, _, iw, _] = self.sys.kind.hub_indices();
        let w = self.y[iw].abs();
        let z = self.drive0.z_p as f64;
        let t_m = 2.0 * std::f64::consts::PI / (z * w);
        stable_rk4_step(t_m, steps_per_mesh_period as f64, self.omega_fast, STEPS_PER_FAST_PERIOD)
    }

    /// Advances from time() to time()+h (h > 0, finite), inputs held over the step (Stage: the
    /// far-end angles move with their given rates, phi_1(t) = phi_1 + w_1·(t − t_u), t_u the
    /// time the inputs were set). On error: state, time and step hint unchanged, the error
    /// names the time and the cause.
    pub fn advance(&mut self, h: f64) -> Result<(), DynamicsError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(invalid("h", h, "finite and > 0 (s)"));
        }
        let n = self.n_states();
        let t0 = self.t;
        let t1 = t0 + h;
        if !t1.is_finite() {
            return Err(invalid("t + h", t1, "finite (s)"));
        }
        // Time that stops advancing: at |t| ≳ 10¹⁷ s, t + 10⁻⁴ s == t; the state must not
        // advance while the time stands still (or moves by a different amount than h).
        if (t1 - t0 - h).abs() > TIME_RESOLUTION * h {
            return Err(DynamicsError::TooLarge(format!(
                "time t = {t0:.6e} s cannot advance by h = {h:.3e} s in double precision \
                 (t + h − t = {:.3e} s, more than {TIME_RESOLUTION:e}·h off): restart the \
                 time nearer 0",
                t1 - t0
            )));
        }
        // The sub-step count is bounded before anything changes (limits::MAX_UNIT_SUBSTEPS).
        let rk4_steps = match self.stepping {
            UnitStepping::Rk4 { steps_per_mesh_period } => {
                let h_max = self.rk4_max_step(steps_per_mesh_period);
                let steps = (h / h_max).ceil().max(1.0);
                if steps.is_nan() || steps > MAX_UNIT_SUBSTEPS {
                    let [_, _, iw, _] = self.sys.kind.hub_indices();
                    return Err(DynamicsError::TooLarge(format!(
                        "a unit step of h = {h:.3e} s would take {steps:.3e} RK4 sub-steps of \
                         {h_max:.3e} s (ω_p = {:.3e} rad/s, {steps_per_mesh_period} steps per \
                         mesh period, fastest mode {:.3e} rad/s); at most \
                         {MAX_UNIT_SUBSTEPS:.0e}: take shorter communication steps",
                        self.y[iw], self.omega_fast
                    )));
                }
                // Full fidelity: the work also grows with the slices of each evaluation.
                let slices = self.sys.model.mesh().evaluation_slices() as f64;
                let work = 4.0 * steps * slices;
                if work > MAX_UNIT_SLICE_EVALUATIONS {
                    return Err(DynamicsError::TooLarge(format!(
                        "a unit step of h = {h:.3e} s would take {steps:.3e} RK4 sub-steps × 4 \
                         mesh evaluations × {slices} slices = {work:.3e} slice-evaluations \
                         (full fidelity); at most {MAX_UNIT_SLICE_EVALUATIONS:.0e} (about a \
                         minute): take shorter communication steps, fewer sub-steps per mesh \
                         period, fewer slices or the table fidelity"
                    )));
                }
                steps as u64
            }
            UnitStepping::Dopri5 { .. } => 0,
        };
        let y0 = self.y;
        self.sys.extrapolate = true;
        self.sys.model.set_warm_start(&self.warm);
        if let Err(e) = self.take_hub_reference() {
            return Err(e.into());
        }
        let result = match self.stepping {
            UnitStepping::Rk4 { .. } => {
                let steps = rk4_steps;
                let hs = h / steps as f64;
                let mut r = Ok(());
                for i in 0..steps {
                    let t = if i == 0 { t0 } else { t0 + i as f64 * hs };
                    if let Err(e) = self.rk4.step(&mut self.sys, t, hs, &mut self.y[..n]) {
                        r = Err(e);
                        break;
                    }
                }
                r
            }
            UnitStepping::Dopri5 { .. } => {
                let dp = self.dopri.as_mut().expect("Dopri5 stepping has its workspace");
                let (gp, gg) = self.sys.model.base_radii();
                let rel = RelativeCoordinates::new(self.sys.kind, gp, gg);
                let mut x = [0.0; N_STATES];
                rel.to_relative(&self.y[..n], &mut x[..n]);
                let mut rs = InRelative::new(&mut self.sys, rel);
                let r = match dp.set_h_init(self.step_hint) {
                    Err(e) => Err(e),
                    Ok(()) => dp
                        .integrate(&mut rs, t0, t1, &mut x[..n], |_| ControlFlow::Continue(()))
                        .map(|stats| {
                            let hn = stats.h_next;
                            self.step_hint = (hn.is_finite() && hn > 0.0).then_some(hn);
                        }),
                };
                if r.is_ok() {
                    rel.to_absolute(&x[..n], &mut self.y[..n]);
                }
                r
            }
        };
        match result {
            Ok(()) => {
                self.t = t1;
                self.sys.model.warm_start(&mut self.warm);
                Ok(())
            }
            Err(e) => {
                self.y = y0;
                Err(e.into())
            }
        }
    }

    /// The outputs at the current time and state (the mesh evaluated from the unit's warm
    /// start, which it leaves unchanged; see the module doc). Errors: a mesh failure, with the
    /// current time.
    pub fn outputs(&mut self) -> Result<UnitOutputs, DynamicsError> {
        self.outputs_with(true).map(|(o, _)| o)
    }

    /// [`Self::outputs`] for a reader of the torques path's mesh outputs
    /// ([`crate::mesh::outputs::OutputField::torques`]) and the unit's own outputs: those
    /// bit for bit as [`Self::outputs`] gives them, and whether the other mesh outputs are
    /// there too (`false`: they are unspecified). At table fidelity this skips the table's
    /// forces, pressure and root stress.
    pub fn outputs_partial(&mut self) -> Result<(UnitOutputs, bool), DynamicsError> {
        self.outputs_with(false)
    }

    fn outputs_with(&mut self, complete: bool) -> Result<(UnitOutputs, bool), DynamicsError> {
        let n = self.n_states();
        let t = self.t;
        self.sys.extrapolate = true;
        self.sys.model.set_warm_start(&self.warm);
        let mut dydt = self.dydt;
        self.sys.rhs(t, &self.y[..n], &mut dydt[..n]).map_err(DynamicsError::from)?;
        let (o, all) = if complete {
            (self.sys.mesh(t, &self.y[..n]).map_err(DynamicsError::from)?, true)
        } else {
            self.sys.mesh_torques(t, &self.y[..n]).map_err(DynamicsError::from)?
        };
        let hub = self.sys.hub(&self.y);
        let [.., iwp, iwg] = self.sys.kind.hub_indices();
        let mut out = UnitOutputs {
            t,
            phi_p: hub[0],
            w_p: hub[2],
            a_p: dydt[iwp],
            phi_g: hub[1],
            w_g: hub[3],
            a_g: dydt[iwg],
            dydt,
            mesh: o,
            ..UnitOutputs::default()
        };
        let far = match self.sys.kind {
            UnitKind::Pair => None,
            UnitKind::Stage => Some(self.sys.far_ends(t)),
            UnitKind::Drive => {
                let y = &self.y;
                Some([y[PHI_1], y[W_1], y[PHI_2], y[W_2]])
            }
        };
        match far {
            None => {
                out.tau_p = self.sys.inputs.values.tau_p;
                out.tau_g = self.sys.inputs.values.tau_g;
            }
            Some(f) => {
                let (s1, s2) = shaft_torques(self.sys.model.drive(), f, hub);
                [out.phi_1, out.w_1, out.phi_2, out.w_2] = f;
                out.tau_1 = -s1;
                out.tau_2 = s2;
                out.tau_p = s1;
                out.tau_g = -s2;
            }
        }
        Ok((out, all))
    }

    /// Model Exchange: state derivative at (`t`, `y`) with the inputs as set (no
    /// extrapolation), into `dydt` (both of length [`Self::n_states`]).
    pub fn derivatives(
        &mut self,
        t: f64,
        y: &[f64],
        dydt: &mut [f64],
    ) -> Result<(), DynamicsError> {
        let n = self.n_states();
        if y.len() != n || dydt.len() != n {
            return Err(invalid(
                "y/dydt length",
                y.len().max(dydt.len()) as f64,
                "the unit's number of states",
            ));
        }
        if !t.is_finite() {
            return Err(invalid("t", t, "finite (s)"));
        }
        if let Some(v) = y.iter().find(|v| !v.is_finite()) {
            return Err(invalid("state component", *v, "finite"));
        }
        self.sys.extrapolate = false;
        self.sys.model.set_warm_start(&self.warm);
        let r = self.sys.rhs(t, y, dydt);
        self.sys.extrapolate = true;
        r?;
        self.sys.model.warm_start(&mut self.warm);
        if let Some(v) = dydt.iter().find(|v| !v.is_finite()) {
            return Err(invalid("derivative component", *v, "finite"));
        }
        Ok(())
    }

    /// Model Exchange: linearisation at the current (t, y, u), inputs as set (no
    /// extrapolation), from [`MeshTorques::mesh_jacobian`] (exact, no finite differences):
    /// A = ∂f/∂x, B = ∂f/∂u, C = ∂out/∂x, D = ∂out/∂u, with u and out in the orders of
    /// [`UnitLinearization::inputs`] / [`UnitLinearization::outputs`].
    ///
    /// Errors: the mesh's error ([`crate::mesh::MeshError::Unsupported`] for meshes without derivatives),
    /// with the current time.
    pub fn linearize(&mut self) -> Result<UnitLinearization, DynamicsError> {
        let kind = self.sys.kind;
        let n = kind.n_states();
        let t = self.t;
        let hub = self.sys.hub(&self.y);
        let state = MeshState {
            phi_p: hub[0],
            phi_g: hub[1],
            w_p: hub[2],
            w_g: hub[3],
            ..Default::default()
        };
        self.sys.model.set_warm_start(&self.warm);
        let (_, jac) = self
            .sys
            .model
            .mesh_mut()
            .mesh_jacobian(&state)
            .map_err(|source| DynamicsError::Mesh { t: Some(t), source })?;
        let d = *self.sys.model.drive();
        let (gp, gg) = self.sys.model.base_radii();
        let idx = kind.hub_indices();
        let inputs = UnitLinearization::inputs(kind);
        let outputs = UnitLinearization::outputs(kind);
        let n_u = inputs.len();
        let n_y = outputs.len();
        let mut a = vec![0.0; n * n];
        let mut b = vec![0.0; n * n_u];
        // Mesh torque rows in state columns: dm[r][col].
        let mut dm = [[0.0; N_STATES]; 4];
        for (r, row) in dm.iter_mut().enumerate() {
            for (c, &i) in idx.iter().enumerate() {
                row[i] += jac.d[r][c];
            }
        }
        let (ipp, ipg, iwp, iwg) = (idx[0], idx[1], idx[2], idx[3]);
        // Kinematic rows: φ' = ω.
        for i in 0..n / 2 {
            a[i * n + n / 2 + i] = 1.0;
        }
        // Shaft torques s1 (on the pinion hub) and s2 (gear shaft) as linear forms in
        // (x, u): coefficients on the state and on the inputs.
        let mut s1x = [0.0; N_STATES];
        let mut s2x = [0.0; N_STATES];
        let mut s1u = [0.0; 4];
        let mut s2u = [0.0; 4];
        match kind {
            UnitKind::Pair => {
                // tau_p = u0, tau_g = u1 = −s2 → s2 = −u1.
                s1u[0] = 1.0;
                s2u[1] = -1.0;
            }
            UnitKind::Stage => {
                s1x[ipp] = -d.c1;
                s1x[iwp] = -d.d1;
                s1u[0] = d.c1;
                s1u[1] = d.d1;
                s2x[ipg] = d.c2;
                s2x[iwg] = d.d2;
                s2u[2] = -d.c2;
                s2u[3] = -d.d2;
            }
            UnitKind::Drive => {
                s1x[PHI_1] = d.c1;
                s1x[PHI_P] = -d.c1;
                s1x[W_1] = d.d1;
                s1x[W_P] = -d.d1;
                s2x[PHI_G] = d.c2;
                s2x[PHI_2] = -d.c2;
                s2x[W_G] = d.d2;
                s2x[W_2] = -d.d2;
            }
        }
        let m = MeshJacobian::M_F_P;
        let (mfp, mfg, mdp, mdg) =
            (m, MeshJacobian::M_F_G, MeshJacobian::M_D_P, MeshJacobian::M_D_G);
        for c in 0..n {
            a[iwp * n + c] = (s1x[c] - dm[mfp][c] - dm[mdp][c]) / d.j_p;
            a[iwg * n + c] = (-s2x[c] - dm[mfg][c] - dm[mdg][c]) / d.j_g;
        }
        for c in 0..n_u {
            b[iwp * n_u + c] = s1u[c] / d.j_p;
            b[iwg * n_u + c] = -s2u[c] / d.j_g;
        }
        if kind == UnitKind::Drive {
            for c in 0..n {
                a[W_1 * n + c] = -s1x[c] / d.j1;
                a[W_2 * n + c] = s2x[c] / d.j2;
            }
            b[W_1 * n_u] = 1.0 / d.j1;
            b[W_2 * n_u] = d.z_g as f64 / d.z_p as f64 / d.j2;
        }
        // Output rows.
        let mut c_mat = vec![0.0; n_y * n];
        let mut d_mat = vec![0.0; n_y * n_u];
        let states = kind.states();
        for (r, &q) in outputs.iter().enumerate() {
            let crow = &mut c_mat[r * n..(r + 1) * n];
            let drow = &mut d_mat[r * n_u..(r + 1) * n_u];
            if let Some(i) = states.iter().position(|&s| s == q) {
                crow[i] = 1.0;
                continue;
            }
            use UnitQuantity::*;
            match q {
                AP | AG => {
                    let i = if q == AP { iwp } else { iwg };
                    crow.copy_from_slice(&a[i * n..(i + 1) * n]);
                    drow.copy_from_slice(&b[i * n_u..(i + 1) * n_u]);
                }
                Tau1 => {
                    for (cv, s) in crow.iter_mut().zip(&s1x) {
                        *cv = -s;
                    }
                    for (dv, s) in drow.iter_mut().zip(&s1u) {
                        *dv = -s;
                    }
                }
                Tau2 => {
                    crow.copy_from_slice(&s2x[..n]);
                    drow.copy_from_slice(&s2u[..n_u]);
                }
                MFP => crow.copy_from_slice(&dm[mfp][..n]),
                MFG => crow.copy_from_slice(&dm[mfg][..n]),
                MDP => crow.copy_from_slice(&dm[mdp][..n]),
                MDG => crow.copy_from_slice(&dm[mdg][..n]),
                Te => {
                    crow[ipp] = gp;
                    crow[ipg] = gg;
                }
                other => unreachable!("output {other} has no linearisation row"),
            }
        }
        Ok(UnitLinearization { n_x: n, n_u, n_y, a, b, c: c_mat, d: d_mat })
    }

    /// Everything needed to continue bit for bit: time, state, inputs (and the time they were
    /// set), integrator step hint.
    pub fn snapshot(&self) -> UnitSnapshot {
        UnitSnapshot {
            kind: self.sys.kind,
            time: self.t,
            state: self.state().to_vec(),
            inputs: self.sys.inputs,
            input_time: self.sys.input_time,
            step_hint: self.step_hint,
            hub_ref: self.sys.hub_ref,
            warm_start: self.warm.clone(),
        }
    }

    /// Restores a snapshot of a unit of the same kind (checked, as are all values: right
    /// length, angles within ±[`MAX_ANGLE_RAD`], speeds within ±[`MAX_STATE_SPEED_RAD_S`], inputs as
    /// [`DriveUnit::set_inputs`] checks them, times finite, step hint > 0).
    pub fn restore(&mut self, s: &UnitSnapshot) -> Result<(), DynamicsError> {
        if s.kind != self.sys.kind {
            return Err(invalid("snapshot kind", s.kind.n_states() as f64, "the unit's kind"));
        }
        let n = self.n_states();
        if s.state.len() != n {
            return Err(invalid("snapshot state length", s.state.len() as f64, "the unit's"));
        }
        for (&v, q) in s.state.iter().zip(self.sys.kind.states()) {
            let name = q.field_name();
            if q.is_angle() {
                check_abs(name, v, MAX_ANGLE_RAD, "finite, |angle| <= 1e15 rad (snapshot state)")?;
            } else {
                check_abs(
                    name,
                    v,
                    MAX_STATE_SPEED_RAD_S,
                    "finite, |speed| <= 2e5 rad/s (snapshot state)",
                )?;
            }
        }
        s.inputs.check()?;
        if let Some(r) = &s.hub_ref {
            r.check()?;
        }
        for (name, v) in [("snapshot time", s.time), ("snapshot input_time", s.input_time)] {
            if !v.is_finite() {
                return Err(invalid(name, v, "finite (s)"));
            }
        }
        if let Some(h) = s.step_hint
            && !(h.is_finite() && h > 0.0)
        {
            return Err(invalid("snapshot step_hint", h, "finite and > 0 (s)"));
        }
        s.warm_start.check().map_err(DynamicsError::Param)?;
        self.t = s.time;
        self.y[..n].copy_from_slice(&s.state);
        self.warm.copy_from(&s.warm_start);
        self.sys.inputs = s.inputs;
        self.sys.input_time = s.input_time;
        self.sys.hub_ref = s.hub_ref;
        self.sys.model.set_torque(s.inputs.values.torque);
        self.step_hint = s.step_hint;
        Ok(())
    }

    /// The mesh model.
    pub fn mesh(&self) -> &M {
        self.sys.model.mesh()
    }

    /// The mesh model, mutable (the remembered evaluation is dropped).
    pub fn mesh_mut(&mut self) -> &mut M {
        self.sys.model.mesh_mut()
    }

    /// Actual mesh evaluations so far (remembered ones not counted).
    pub fn mesh_evaluations(&self) -> usize {
        self.sys.model.mesh_evaluations()
    }
}
