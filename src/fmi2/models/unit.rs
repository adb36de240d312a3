//! The stateful models `HelicalGearPair`, `HelicalGearStage` and `HelicalGearDrive`: a
//! [`DriveUnit`] of the matching [`UnitKind`] behind the FMI layer (docs/fmus.md).
//!
//! * `HelicalGearPair` — J_p, J_g and the mesh. Inputs `tau_p`, `tau_g`, the torques the shafts
//!   exert on the hubs (J_p·φp'' = tau_p − M_F_p − M_D_p); outputs the kinematics of both
//!   bodies, TE, the mesh torques and flags ("torque in, kinematics out").
//! * `HelicalGearStage` — the pair plus the shafts c1/d1, c2/d2. Inputs the motion of the
//!   shafts' far ends (`phi_1`, `w_1`, `phi_2`, `w_2`); outputs the torques the shafts exert on
//!   J1 and J2 (`tau_1`, `tau_2`: J1·φ1'' = M + tau_1) and everything the pair outputs
//!   ("kinematics in, torque out").
//! * `HelicalGearDrive` — Eqs. 1–4 whole, input the driving torque `M` (load M·z_g/z_p on J2),
//!   outputs the eight states, TE, the mesh torques and flags.
//!
//! The unit integrates inside each communication step (RK4 on the mesh-period grid or
//! DOPRI5, parameter `integrator`); inputs are passed to the unit when a value or a
//! derivative (`fmi2SetRealInputDerivatives`, first-order hold) was set since the last step
//! or when they differ from the unit's: a master that sets nothing between steps lets the
//! Stage's far ends keep turning at their rates from the last setting. A step the unit
//! cannot complete returns `fmi2Discard` with the unit's message (time and cause); the state
//! stays that of the step's start, so no output is ever NaN. The FMU state carries the unit's
//! snapshot (time, state, inputs and their rates, input time, step hint) as JSON with exact
//! floats.
//!
//! Model Exchange sees the unit's state in relative coordinates
//! ([`crate::dynamics::relative`]): the variables `v_TE` (and for the Drive `theta_1`,
//! `theta_2`, `w_theta_1`, `w_theta_2`) are states besides `phi_p`, `TE` and `w_p`, with
//! derivatives `der(…)`; `fmi2SetTime` re-anchors the held inputs at the new time (ME inputs are
//! the values at that time, never extrapolated).
//!
//! Slots (this file's map between the generic FMI values and the unit): an input is the slot
//! of its [`UnitInputs`] field (`slot`); the time derivatives of `tau_p`, `tau_g`, `w_1`,
//! `w_2` and `M` are used (their variables say `derivative: true`; the [`UnitInputRates`]),
//! those of `phi_1`, `phi_2` are accepted and not used (their rates are the inputs `w_1`,
//! `w_2`). The Real outputs are the mesh outputs' slots, then one slot per field of the
//! unit's outputs (`out`), then the Model Exchange state in relative coordinates and its time
//! derivative (`out::X` + i, `out::DX` + i).

use std::sync::OnceLock;

use crate::dynamics::Drivetrain;
use crate::dynamics::relative::RelativeCoordinates;
use crate::dynamics::unit::{
    DriveUnit, UnitInputRates, UnitInputs, UnitKind, UnitLinearization, UnitQuantity, UnitSnapshot,
    UnitStepping,
};
use crate::fmi2::model::{Engine, Experiment, Jacobian, MAX_STATES, ModelInfo, StepFailure};
use crate::fmi2::models::mesh::build_mesh;
use crate::fmi2::models::write_mesh_outputs;
use crate::fmi2::variables::{
    ANGLE, Access, CALCULATED, Causality, DEG, DRIVE_INERTIAS, DRIVE_SHAFTS, DRIVE_TORQUE, Depends,
    Derived, GEAR_PARAMS, InputValues, Integrator, MESH_OPTIONS, MESH_OUTPUTS, NM, NONE,
    OutputValues, RAD, START_OUTER, START_PAIR, Settings, TORQUE, UNIT_OPTIONS, Variability,
    Variable, concat, group, real_output_slots, total_len, with_depends,
};
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::{Fidelity, Mesh};

/// Mesh outputs of a stateful model: functions of the state only.
const STATE_ONLY: Depends =
    Depends { inputs: &HUB_STATES, linear_fixed: false, groups: group::ALL };

/// The Model Exchange states every stateful model has (relative coordinates of the hubs,
/// [`crate::dynamics::relative`]); the dependency lists below name states and inputs (the
/// knowns of Model Exchange).
pub(super) const HUB_STATES: [&str; 4] = ["phi_p", "TE", "w_p", "v_TE"];
const PAIR_KNOWN: [&str; 6] = ["phi_p", "TE", "w_p", "v_TE", "tau_p", "tau_g"];
const STAGE_KNOWN: [&str; 8] = ["phi_p", "TE", "w_p", "v_TE", "phi_1", "w_1", "phi_2", "w_2"];
pub(super) const DRIVE_STATES: [&str; 8] =
    ["phi_p", "theta_1", "TE", "theta_2", "w_p", "w_theta_1", "v_TE", "w_theta_2"];
pub(super) const DRIVE_KNOWN: [&str; 9] =
    ["phi_p", "theta_1", "TE", "theta_2", "w_p", "w_theta_1", "v_TE", "w_theta_2", "M"];
const UNIT_MESH_OUTPUTS: [Variable; 30] = with_depends(MESH_OUTPUTS, STATE_ONLY);

/// Input slots of the stateful models: one per field of [`UnitInputs`] (each model's table
/// names only its own; the others stay 0, as the unit's unused inputs are).
pub(super) mod slot {
    /// [`super::UnitInputs::tau_p`].
    pub const TAU_P: usize = 0;
    /// [`super::UnitInputs::tau_g`].
    pub const TAU_G: usize = 1;
    /// [`super::UnitInputs::phi_1`].
    pub const PHI_1: usize = 2;
    /// [`super::UnitInputs::w_1`].
    pub const W_1: usize = 3;
    /// [`super::UnitInputs::phi_2`].
    pub const PHI_2: usize = 4;
    /// [`super::UnitInputs::w_2`].
    pub const W_2: usize = 5;
    /// [`super::UnitInputs::torque`].
    pub const TORQUE: usize = 6;
}

/// Real output slots of the stateful models: the mesh outputs' first
/// ([`write_mesh_outputs`]), then one per field of [`crate::dynamics::unit::UnitOutputs`]
/// that a table names, then the Model Exchange state in relative coordinates ([`X`]) and its
/// time derivative ([`DX`]).
pub(super) mod out {
    use super::{MAX_STATES, MESH_OUTPUTS, real_output_slots};
    /// The Real slots the mesh outputs take.
    const K: usize = real_output_slots(&MESH_OUTPUTS);
    // The fields of `UnitOutputs` of the same names (rad, rad/s, rad/s², N·m).
    pub const PHI_1: usize = K;
    pub const PHI_P: usize = K + 1;
    pub const PHI_G: usize = K + 2;
    pub const PHI_2: usize = K + 3;
    pub const W_1: usize = K + 4;
    pub const W_P: usize = K + 5;
    pub const W_G: usize = K + 6;
    pub const W_2: usize = K + 7;
    pub const A_P: usize = K + 8;
    pub const A_G: usize = K + 9;
    pub const TAU_1: usize = K + 10;
    pub const TAU_2: usize = K + 11;
    /// Model Exchange: state `i` in relative coordinates is slot `X + i`.
    pub const X: usize = K + 12;
    /// Model Exchange: the time derivative of state `i` is slot `DX + i`.
    pub const DX: usize = X + MAX_STATES;
}
use out::{DX, X};

macro_rules! input {
    ($name:literal, $vr:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal, $slot:expr,
     $derivative:expr) => {
        Variable {
            name: $name,
            vr: $vr,
            causality: Causality::Input,
            variability: Variability::Continuous,
            description: $desc,
            unit: $unit,
            display_unit: $disp,
            quantity: $q,
            access: crate::fmi2::variables::Access::Input { slot: $slot, derivative: $derivative },
            ..NONE
        }
    };
}

macro_rules! kin {
    ($name:literal, $vr:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal, $deps:expr,
     $slot:expr) => {
        Variable {
            name: $name,
            vr: $vr,
            causality: Causality::Output,
            variability: Variability::Continuous,
            description: $desc,
            unit: $unit,
            display_unit: $disp,
            quantity: $q,
            depends: Some(Depends { inputs: $deps, linear_fixed: false, groups: group::ALL }),
            access: crate::fmi2::variables::Access::RealOutput($slot),
            ..NONE
        }
    };
}

const RAD_S: Option<&str> = Some("rad/s");
const RPM: Option<&str> = Some("rpm");
const W: Option<&str> = Some("AngularVelocity");
const RAD_S2: Option<&str> = Some("rad/s2");
const ACC: Option<&str> = Some("AngularAcceleration");

/// φp, φ̇p, φ̇g, φg (functions of the state).
pub(super) const HUBS: [Variable; 4] = [
    kin!("phi_p", 40, RAD, DEG, ANGLE, "Pinion hub angle, rad (state)", &["phi_p"], out::PHI_P),
    kin!("w_p", 41, RAD_S, RPM, W, "Pinion speed, rad/s (state)", &["w_p"], out::W_P),
    kin!(
        "phi_g",
        43,
        RAD,
        DEG,
        ANGLE,
        "Gear hub angle, rad (state; negative in normal running)",
        &["phi_p", "TE"],
        out::PHI_G
    ),
    kin!(
        "w_g",
        44,
        RAD_S,
        RPM,
        W,
        "Gear speed, rad/s (state; negative in normal running)",
        &["w_p", "v_TE"],
        out::W_G
    ),
];

const PAIR_IO: [Variable; 4] = [
    input!(
        "tau_p",
        4,
        NM,
        None,
        TORQUE,
        "Torque the pinion shaft exerts on the pinion hub, N.m: J_p*phi_p'' = tau_p - M_F_p - \
         M_D_p (steady running: tau_p = M)",
        slot::TAU_P,
        true
    ),
    input!(
        "tau_g",
        5,
        NM,
        None,
        TORQUE,
        "Torque the gear shaft exerts on the gear hub, N.m: J_g*phi_g'' = tau_g - M_F_g - M_D_g \
         (steady running: tau_g = M*z_g/z_p)",
        slot::TAU_G,
        true
    ),
    kin!(
        "a_p",
        42,
        RAD_S2,
        None,
        ACC,
        "Pinion angular acceleration phi_p'', rad/s2",
        &["phi_p", "TE", "w_p", "v_TE", "tau_p"],
        out::A_P
    ),
    kin!(
        "a_g",
        45,
        RAD_S2,
        None,
        ACC,
        "Gear angular acceleration phi_g'', rad/s2",
        &["phi_p", "TE", "w_p", "v_TE", "tau_g"],
        out::A_G
    ),
];

const STAGE_IO: [Variable; 8] = [
    input!(
        "phi_1",
        6,
        RAD,
        DEG,
        ANGLE,
        "Angle of the pinion shaft's far end (J1 side), rad; held at the rate w_1 over a step",
        slot::PHI_1,
        false
    ),
    input!("w_1", 7, RAD_S, RPM, W, "Rate of the pinion shaft's far end, rad/s", slot::W_1, true),
    input!(
        "phi_2",
        8,
        RAD,
        DEG,
        ANGLE,
        "Angle of the gear shaft's far end (J2 side), rad; held at the rate w_2 over a step",
        slot::PHI_2,
        false
    ),
    input!("w_2", 9, RAD_S, RPM, W, "Rate of the gear shaft's far end, rad/s", slot::W_2, true),
    kin!(
        "tau_1",
        46,
        NM,
        None,
        TORQUE,
        "Torque the pinion shaft exerts on J1, N.m: J1*phi_1'' = M + tau_1 (steady running: \
         tau_1 = -M)",
        &["phi_p", "w_p", "phi_1", "w_1"],
        out::TAU_1
    ),
    kin!(
        "tau_2",
        47,
        NM,
        None,
        TORQUE,
        "Torque the gear shaft exerts on J2, N.m: J2*phi_2'' = M*z_g/z_p + tau_2",
        &["phi_p", "TE", "w_p", "v_TE", "phi_2", "w_2"],
        out::TAU_2
    ),
    kin!(
        "a_p",
        42,
        RAD_S2,
        None,
        ACC,
        "Pinion angular acceleration phi_p'', rad/s2",
        &["phi_p", "TE", "w_p", "v_TE", "phi_1", "w_1"],
        out::A_P
    ),
    kin!(
        "a_g",
        45,
        RAD_S2,
        None,
        ACC,
        "Gear angular acceleration phi_g'', rad/s2",
        &["phi_p", "TE", "w_p", "v_TE", "phi_2", "w_2"],
        out::A_G
    ),
];

pub(super) const DRIVE_IO: [Variable; 7] = [
    input!(
        "M",
        60,
        NM,
        None,
        TORQUE,
        "Driving torque M on J1, N.m (the load on J2 is M*z_g/z_p, Eq. 4)",
        slot::TORQUE,
        true
    ),
    kin!(
        "phi_1",
        48,
        RAD,
        DEG,
        ANGLE,
        "Angle of J1, rad (state)",
        &["phi_p", "theta_1"],
        out::PHI_1
    ),
    kin!(
        "phi_2",
        50,
        RAD,
        DEG,
        ANGLE,
        "Angle of J2, rad (state)",
        &["phi_p", "TE", "theta_2"],
        out::PHI_2
    ),
    kin!("w_1", 49, RAD_S, RPM, W, "Speed of J1, rad/s (state)", &["w_p", "w_theta_1"], out::W_1),
    kin!(
        "w_2",
        51,
        RAD_S,
        RPM,
        W,
        "Speed of J2, rad/s (state)",
        &["w_p", "v_TE", "w_theta_2"],
        out::W_2
    ),
    kin!(
        "a_p",
        42,
        RAD_S2,
        None,
        ACC,
        "Pinion angular acceleration phi_p'', rad/s2",
        &DRIVE_STATES,
        out::A_P
    ),
    kin!(
        "a_g",
        45,
        RAD_S2,
        None,
        ACC,
        "Gear angular acceleration phi_g'', rad/s2",
        &DRIVE_STATES,
        out::A_G
    ),
];

/// A Model Exchange local: a relative-coordinate state or a state derivative, read from its
/// slot ([`X`] + i or [`DX`] + i).
macro_rules! me_local {
    ($name:literal, $vr:expr, $unit:expr, $q:expr, $desc:literal, $deps:expr, $linear:expr,
     $der_of:expr, $slot:expr) => {
        Variable {
            name: $name,
            vr: $vr,
            causality: Causality::Local,
            variability: Variability::Continuous,
            description: $desc,
            unit: $unit,
            quantity: $q,
            depends: Some(Depends { inputs: $deps, linear_fixed: $linear, groups: group::ALL }),
            access: crate::fmi2::variables::Access::RealOutput($slot),
            derivative_of: $der_of,
            ..NONE
        }
    };
}

const M_S: Option<&str> = Some("m/s");
const M_S2: Option<&str> = Some("m/s2");
const VEL: Option<&str> = Some("Velocity");
const ACCEL: Option<&str> = Some("Acceleration");

/// der(phi_p) = w_p, the first state derivative of every stateful model.
const DER_PHI_P: Variable = me_local!(
    "der(phi_p)",
    80,
    RAD_S,
    W,
    "Time derivative of phi_p, rad/s",
    &["w_p"],
    true,
    Some("phi_p"),
    DX
);

/// Model Exchange states and derivatives of the Pair and the Stage: x = (φp, TE, φ̇p, v_TE).
const fn me_pair(known: &'static [&'static str]) -> [Variable; 5] {
    [
        me_local!(
            "v_TE",
            70,
            M_S,
            VEL,
            "Rate of the transmission error g_p*w_p + g_g*w_g, m/s (Model Exchange state)",
            &[],
            false,
            None,
            X + 3
        ),
        DER_PHI_P,
        me_local!(
            "der(TE)",
            81,
            M_S,
            VEL,
            "Time derivative of TE, m/s",
            &["v_TE"],
            true,
            Some("TE"),
            DX + 1
        ),
        me_local!(
            "der(w_p)",
            82,
            RAD_S2,
            ACC,
            "Time derivative of w_p, rad/s2",
            known,
            false,
            Some("w_p"),
            DX + 2
        ),
        me_local!(
            "der(v_TE)",
            83,
            M_S2,
            ACCEL,
            "Time derivative of v_TE, m/s2",
            known,
            false,
            Some("v_TE"),
            DX + 3
        ),
    ]
}

const ME_PAIR: [Variable; 5] = me_pair(&PAIR_KNOWN);
const ME_STAGE: [Variable; 5] = me_pair(&STAGE_KNOWN);

/// Model Exchange states and derivatives of the Drive: x = (φp, θ1, TE, θ2, φ̇p, θ̇1, v_TE,
/// θ̇2).
pub(super) const ME_DRIVE: [Variable; 13] = [
    me_local!(
        "theta_1",
        71,
        RAD,
        ANGLE,
        "Twist of the pinion shaft phi_1 - phi_p, rad (Model Exchange state)",
        &[],
        false,
        None,
        X + 1
    ),
    me_local!(
        "theta_2",
        72,
        RAD,
        ANGLE,
        "Twist of the gear shaft phi_g - phi_2, rad (Model Exchange state)",
        &[],
        false,
        None,
        X + 3
    ),
    me_local!(
        "w_theta_1",
        73,
        RAD_S,
        W,
        "Rate of the pinion shaft's twist w_1 - w_p, rad/s (Model Exchange state)",
        &[],
        false,
        None,
        X + 5
    ),
    me_local!(
        "v_TE",
        70,
        M_S,
        VEL,
        "Rate of the transmission error g_p*w_p + g_g*w_g, m/s (Model Exchange state)",
        &[],
        false,
        None,
        X + 6
    ),
    me_local!(
        "w_theta_2",
        74,
        RAD_S,
        W,
        "Rate of the gear shaft's twist w_g - w_2, rad/s (Model Exchange state)",
        &[],
        false,
        None,
        X + 7
    ),
    DER_PHI_P,
    me_local!(
        "der(theta_1)",
        84,
        RAD_S,
        W,
        "Time derivative of theta_1, rad/s",
        &["w_theta_1"],
        true,
        Some("theta_1"),
        DX + 1
    ),
    me_local!(
        "der(TE)",
        81,
        M_S,
        VEL,
        "Time derivative of TE, m/s",
        &["v_TE"],
        true,
        Some("TE"),
        DX + 2
    ),
    me_local!(
        "der(theta_2)",
        85,
        RAD_S,
        W,
        "Time derivative of theta_2, rad/s",
        &["w_theta_2"],
        true,
        Some("theta_2"),
        DX + 3
    ),
    me_local!(
        "der(w_p)",
        82,
        RAD_S2,
        ACC,
        "Time derivative of w_p, rad/s2",
        &DRIVE_STATES,
        false,
        Some("w_p"),
        DX + 4
    ),
    me_local!(
        "der(w_theta_1)",
        86,
        RAD_S2,
        ACC,
        "Time derivative of w_theta_1, rad/s2",
        &DRIVE_KNOWN,
        false,
        Some("w_theta_1"),
        DX + 5
    ),
    me_local!(
        "der(v_TE)",
        83,
        M_S2,
        ACCEL,
        "Time derivative of v_TE, m/s2",
        &DRIVE_STATES,
        false,
        Some("v_TE"),
        DX + 6
    ),
    me_local!(
        "der(w_theta_2)",
        87,
        RAD_S2,
        ACC,
        "Time derivative of w_theta_2, rad/s2",
        &DRIVE_KNOWN,
        false,
        Some("w_theta_2"),
        DX + 7
    ),
];

/// `HelicalGearPair`: the master's connection stiffness and damping at the hubs
/// ([`HubCoupling`]).
const PAIR_COUPLING: [Variable; 4] = [
    Variable {
        name: "hub_coupling.c_p_nm_per_rad",
        vr: 320,
        description: "Torsional stiffness of the master's connection at the pinion hub, \
                      -d(tau_p)/d(phi_p), N.m/rad (the pinion shaft's c1): with it and the inputs' \
                      derivatives (fmi2SetRealInputDerivatives) the held tau_p is corrected by the \
                      hub's own motion within a step; 0 = plain hold",
        unit: Some("N.m/rad"),
        min: Some(crate::dynamics::unit::HUB_STIFFNESS_NM_PER_RAD.min),
        max: Some(crate::dynamics::unit::HUB_STIFFNESS_NM_PER_RAD.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.hub_coupling.c_p, |s, v| s.unit.hub_coupling.c_p = v),
        ..NONE
    },
    Variable {
        name: "hub_coupling.d_p_nms_per_rad",
        vr: 321,
        description: "Torsional damping of the master's connection at the pinion hub, \
                      -d(tau_p)/d(w_p), N.m.s/rad (the pinion shaft's d1); 0 = plain hold",
        unit: Some("N.m.s/rad"),
        min: Some(crate::dynamics::unit::HUB_DAMPING_NMS_PER_RAD.min),
        max: Some(crate::dynamics::unit::HUB_DAMPING_NMS_PER_RAD.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.hub_coupling.d_p, |s, v| s.unit.hub_coupling.d_p = v),
        ..NONE
    },
    Variable {
        name: "hub_coupling.c_g_nm_per_rad",
        vr: 322,
        description: "Torsional stiffness of the master's connection at the gear hub, \
                      -d(tau_g)/d(phi_g), N.m/rad (the gear shaft's c2); 0 = plain hold",
        unit: Some("N.m/rad"),
        min: Some(crate::dynamics::unit::HUB_STIFFNESS_NM_PER_RAD.min),
        max: Some(crate::dynamics::unit::HUB_STIFFNESS_NM_PER_RAD.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.hub_coupling.c_g, |s, v| s.unit.hub_coupling.c_g = v),
        ..NONE
    },
    Variable {
        name: "hub_coupling.d_g_nms_per_rad",
        vr: 323,
        description: "Torsional damping of the master's connection at the gear hub, \
                      -d(tau_g)/d(w_g), N.m.s/rad (the gear shaft's d2); 0 = plain hold",
        unit: Some("N.m.s/rad"),
        min: Some(crate::dynamics::unit::HUB_DAMPING_NMS_PER_RAD.min),
        max: Some(crate::dynamics::unit::HUB_DAMPING_NMS_PER_RAD.max),
        group: group::UNIT,
        access: Access::RealParam(|s| s.unit.hub_coupling.d_g, |s, v| s.unit.hub_coupling.d_g = v),
        ..NONE
    },
];

const PAIR_PARTS: &[&[Variable]] = &[
    &PAIR_IO,
    &HUBS,
    &UNIT_MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &DRIVE_TORQUE,
    &MESH_OPTIONS,
    &UNIT_OPTIONS,
    &PAIR_COUPLING,
    &START_PAIR,
    &ME_PAIR,
];
const STAGE_PARTS: &[&[Variable]] = &[
    &STAGE_IO,
    &HUBS,
    &UNIT_MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &DRIVE_TORQUE,
    &DRIVE_SHAFTS,
    &MESH_OPTIONS,
    &UNIT_OPTIONS,
    &START_PAIR,
    &ME_STAGE,
];
const DRIVE_PARTS: &[&[Variable]] = &[
    &DRIVE_IO,
    &HUBS,
    &UNIT_MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &DRIVE_TORQUE,
    &DRIVE_INERTIAS,
    &DRIVE_SHAFTS,
    &MESH_OPTIONS,
    &UNIT_OPTIONS,
    &START_PAIR,
    &START_OUTER,
    &ME_DRIVE,
];

static PAIR_TABLE: [Variable; total_len(PAIR_PARTS)] = concat(PAIR_PARTS);
static STAGE_TABLE: [Variable; total_len(STAGE_PARTS)] = concat(STAGE_PARTS);
static DRIVE_TABLE: [Variable; total_len(DRIVE_PARTS)] = concat(DRIVE_PARTS);

/// Default parameters of the stateful models: those of `HelicalGearMesh` with table fidelity.
fn unit_settings() -> Settings {
    let mut s = Settings::default();
    s.options.fidelity = Fidelity::Table;
    s
}

/// The Pair's start inputs: the shaft torques of steady running at the default torque.
fn pair_inputs() -> InputValues {
    let s = Settings::default();
    let (p, m) = (s.pair, s.drive.torque_nm);
    let mut i = InputValues::default();
    i.values[slot::TAU_P] = m;
    i.values[slot::TAU_G] = m * f64::from(p.z_g) / f64::from(p.z_p);
    i
}

/// The Stage's start inputs: far-end rates of steady running at `w_p_start`.
fn stage_inputs() -> InputValues {
    let s = Settings::default();
    let w = s.unit.w_p_start;
    let mut i = InputValues::default();
    i.values[slot::W_1] = w;
    i.values[slot::W_2] = -w * f64::from(s.pair.z_p) / f64::from(s.pair.z_g);
    i
}

/// The Drive's start input: the default driving torque.
fn drive_inputs() -> InputValues {
    let mut i = InputValues::default();
    i.values[slot::TORQUE] = Settings::default().drive.torque_nm;
    i
}

static PAIR_GUID: OnceLock<String> = OnceLock::new();
static STAGE_GUID: OnceLock<String> = OnceLock::new();
static DRIVE_GUID: OnceLock<String> = OnceLock::new();

/// `HelicalGearPair`.
pub static PAIR: ModelInfo = ModelInfo {
    identifier: "HelicalGearPair",
    description: "Helical gear pair (Andersson and Vedmar 2003): gear bodies J_p, J_g and the \
                  mesh integrated inside; shaft torques on the hubs in, kinematics out",
    doc_html: "<p>The gear bodies J_p, J_g and the mesh, integrated inside each communication \
               step. Inputs: the torques the shafts exert on the hubs, <code>tau_p</code>, \
               <code>tau_g</code> (J_p&middot;phi_p'' = tau_p &minus; M_F_p &minus; M_D_p). \
               Outputs: angles, speeds and accelerations of both bodies, TE, the mesh torques \
               and flags. Causality: torque in, kinematics out (as Modelica's \
               DirectInertia).</p>",
    variables: &PAIR_TABLE,
    default_settings: unit_settings,
    default_inputs: pair_inputs,
    experiment: Experiment { start: 0.0, stop: 0.05, step: 1e-4 },
    stateful: true,
    event_indicators: 0,
    provides_directional_derivative: true,
    build: |s| build_unit(UnitKind::Pair, s),
    check_tunable: super::mesh::check_tunable,
    cached_outputs: false,
    partial_output: super::torques_path_output,
    guid_cell: &PAIR_GUID,
};

/// `HelicalGearStage`.
pub static STAGE: ModelInfo = ModelInfo {
    identifier: "HelicalGearStage",
    description: "Helical gear stage (Andersson and Vedmar 2003): shafts c1/d1, c2/d2, gear \
                  bodies and mesh integrated inside; shaft far-end motion in, shaft torques out",
    doc_html: "<p>The gear pair plus the shafts c1/d1 and c2/d2 of Eqs. 2&ndash;3, integrated \
               inside each communication step. Inputs: angle and rate of the shafts' far ends \
               (<code>phi_1</code>, <code>w_1</code>, <code>phi_2</code>, <code>w_2</code>; \
               the angles advance at the given rates over a step). Outputs: the torques the \
               shafts exert on J1 and J2, <code>tau_1</code>, <code>tau_2</code> \
               (J1&middot;phi_1'' = M + tau_1), and everything the pair outputs. Causality: \
               kinematics in, torque out &mdash; connect the motor and load inertias.</p>",
    variables: &STAGE_TABLE,
    default_settings: unit_settings,
    default_inputs: stage_inputs,
    experiment: Experiment { start: 0.0, stop: 0.05, step: 1e-4 },
    stateful: true,
    event_indicators: 0,
    provides_directional_derivative: true,
    build: |s| build_unit(UnitKind::Stage, s),
    check_tunable: super::mesh::check_tunable,
    cached_outputs: false,
    partial_output: super::torques_path_output,
    guid_cell: &STAGE_GUID,
};

/// `HelicalGearDrive`.
pub static DRIVE: ModelInfo = ModelInfo {
    identifier: "HelicalGearDrive",
    description: "Helical gear drive (Andersson and Vedmar 2003): the 4-DOF torsional model of \
                  Eqs. 1-4 integrated inside; driving torque M in, states, TE and mesh torques \
                  out",
    doc_html: "<p>The whole 4-DOF torsional model of Eqs. 1&ndash;4 (J1, c1/d1, J_p, mesh, J_g, \
               c2/d2, J2), integrated inside each communication step. Input: the driving \
               torque <code>M</code> on J1; the load on J2 is M&middot;z_g/z_p. Outputs: the \
               eight states, TE, the mesh torques and flags. Starts in static equilibrium at \
               <code>w_p_start</code>, so a plain simulation shows the dynamic TE.</p>",
    variables: &DRIVE_TABLE,
    default_settings: unit_settings,
    default_inputs: drive_inputs,
    experiment: Experiment { start: 0.0, stop: 0.05, step: 1e-4 },
    stateful: true,
    event_indicators: 0,
    provides_directional_derivative: true,
    build: |s| build_unit(UnitKind::Drive, s),
    check_tunable: super::mesh::check_tunable,
    cached_outputs: false,
    partial_output: super::torques_path_output,
    guid_cell: &DRIVE_GUID,
};

fn build_unit(kind: UnitKind, s: &Settings) -> Result<(Box<dyn Engine>, Derived), String> {
    let u = &s.unit;
    u.check().map_err(|e| e.to_string())?;
    let stepping = match u.integrator {
        Integrator::Rk4 => UnitStepping::Rk4 { steps_per_mesh_period: u.rk4_steps_per_mesh_period },
        Integrator::Dopri5 => UnitStepping::Dopri5 { rtol: u.rtol, atol: u.atol },
    };
    s.drive.check().map_err(|e| e.to_string())?;
    // The table's TE range is sized for the drive line's torque (at least 1 N·m).
    let mut s = s.clone();
    s.options = s.options.sized_for(&s.drive);
    let (mesh, derived) = build_mesh(&s)?;
    let drive = Drivetrain::new(mesh.geometry(), &s.drive).map_err(|e| e.to_string())?;
    let mut unit = DriveUnit::new(kind, mesh, drive, stepping)
        .map_err(|e| format!("{} unit: {e}", kind_name(kind)))?;
    let c = u.hub_coupling;
    if kind == UnitKind::Pair {
        unit.set_hub_coupling(c).map_err(|e| format!("pair unit: {e}"))?;
    }
    let rel = RelativeCoordinates::new(kind, derived.base_radius_p, derived.base_radius_g);
    let mut nominals = [1.0; 8];
    rel.nominals(
        drive.torque,
        drive.z_g as f64 / drive.z_p as f64,
        unit.nominal_mesh_stiffness(),
        drive.c1,
        drive.c2,
        unit.fastest_mode(),
        u.w_p_start,
        &mut nominals[..rel.n()],
    );
    Ok((Box::new(UnitEngine { unit, rel, nominals }), derived))
}

fn kind_name(kind: UnitKind) -> &'static str {
    match kind {
        UnitKind::Pair => "pair",
        UnitKind::Stage => "stage",
        UnitKind::Drive => "drive",
    }
}

/// The unit's inputs and their rates from the input slots ([`slot`]; the derivatives of the
/// Stage's angles `phi_1`, `phi_2` are their rate inputs `w_1`, `w_2`, so no slot holds them).
fn unit_inputs(i: &InputValues) -> (UnitInputs, UnitInputRates) {
    let (v, r) = (&i.values, &i.rates);
    let u = UnitInputs {
        tau_p: v[slot::TAU_P],
        tau_g: v[slot::TAU_G],
        phi_1: v[slot::PHI_1],
        w_1: v[slot::W_1],
        phi_2: v[slot::PHI_2],
        w_2: v[slot::W_2],
        torque: v[slot::TORQUE],
    };
    let r = UnitInputRates {
        tau_p_rate: r[slot::TAU_P],
        tau_g_rate: r[slot::TAU_G],
        w_1_rate: r[slot::W_1],
        w_2_rate: r[slot::W_2],
        torque_rate: r[slot::TORQUE],
    };
    (u, r)
}

/// Names of the state-derivative variables in state order (Pair and Stage).
const PAIR_DERS: [&str; 4] = ["der(phi_p)", "der(TE)", "der(w_p)", "der(v_TE)"];
/// Names of the state-derivative variables in state order (Drive).
const DRIVE_DERS: [&str; 8] = [
    "der(phi_p)",
    "der(theta_1)",
    "der(TE)",
    "der(theta_2)",
    "der(w_p)",
    "der(w_theta_1)",
    "der(v_TE)",
    "der(w_theta_2)",
];

/// The FMI variable name of a unit quantity: the one map from the physics' quantities to the
/// names of the stateful models' variables (states, inputs, outputs).
pub fn variable_name(q: UnitQuantity) -> &'static str {
    use UnitQuantity::*;
    match q {
        PhiP => "phi_p",
        WP => "w_p",
        AP => "a_p",
        PhiG => "phi_g",
        WG => "w_g",
        AG => "a_g",
        Phi1 => "phi_1",
        W1 => "w_1",
        Phi2 => "phi_2",
        W2 => "w_2",
        Tau1 => "tau_1",
        Tau2 => "tau_2",
        TauP => "tau_p",
        TauG => "tau_g",
        MFP => "M_F_p",
        MFG => "M_F_g",
        MDP => "M_D_p",
        MDG => "M_D_g",
        Te => "TE",
        FN => "F_n",
        Theta1 => "theta_1",
        Theta2 => "theta_2",
        WTheta1 => "w_theta_1",
        WTheta2 => "w_theta_2",
        VTe => "v_TE",
        DrivingTorque => "M",
    }
}

/// A [`DriveUnit`] over the mesh model as an [`Engine`]. Model Exchange sees the unit's state
/// in relative coordinates ([`RelativeCoordinates`]: TE and the shaft twists are states, so
/// that an importer's tolerances act on them).
#[derive(Clone)]
struct UnitEngine {
    unit: DriveUnit<Mesh>,
    rel: RelativeCoordinates,
    /// Nominal magnitudes of the relative coordinates.
    nominals: [f64; 8],
}

impl UnitEngine {
    /// Passes the inputs to the unit when they differ from the ones it holds or were set since
    /// the last step (so the unit's input time, the origin of the held inputs' extrapolation,
    /// is that of the last setting).
    fn sync(&mut self, i: &InputValues) -> Result<(), String> {
        let (u, r) = unit_inputs(i);
        if i.fresh || *self.unit.inputs() != u || *self.unit.input_rates() != r {
            self.unit.set_inputs(u).map_err(|e| e.to_string())?;
            self.unit.set_input_rates(r).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// The outputs into their slots ([`out`]): the mesh outputs, the unit's outputs and the
    /// Model Exchange state and derivative in relative coordinates; every mesh output when
    /// `complete`, else those of the torques path at least (with the flag of completeness).
    fn outputs_with(
        &mut self,
        inputs: &InputValues,
        complete: bool,
        v: &mut OutputValues,
    ) -> Result<bool, String> {
        self.sync(inputs)?;
        let (o, all) = if complete {
            (self.unit.outputs().map_err(|e| format!("outputs: {e}"))?, true)
        } else {
            self.unit.outputs_partial().map_err(|e| format!("outputs: {e}"))?
        };
        write_mesh_outputs(&o.mesh, v);
        let r = &mut v.reals;
        (r[out::PHI_1], r[out::PHI_P], r[out::PHI_G], r[out::PHI_2]) =
            (o.phi_1, o.phi_p, o.phi_g, o.phi_2);
        (r[out::W_1], r[out::W_P], r[out::W_G], r[out::W_2]) = (o.w_1, o.w_p, o.w_g, o.w_2);
        (r[out::A_P], r[out::A_G], r[out::TAU_1], r[out::TAU_2]) = (o.a_p, o.a_g, o.tau_1, o.tau_2);
        let n = self.rel.n();
        self.rel.to_relative(self.unit.state(), &mut r[X..X + n]);
        self.rel.to_relative(&o.dydt[..n], &mut r[DX..DX + n]);
        Ok(all)
    }
}

impl Engine for UnitEngine {
    fn clone_box(&self) -> Box<dyn Engine> {
        Box::new(self.clone())
    }

    /// Applies the mesh damping `d_mesh` (the one tunable parameter).
    fn tune(&mut self, s: &Settings) -> Result<(), String> {
        self.unit
            .mesh_mut()
            .set_d_mesh(s.pair.d_mesh_n_s_per_m)
            .map_err(|e| super::mesh::mesh_error_text(&e))?;
        // The step rule follows the damping (an overdamped mesh mode needs a shorter step).
        self.unit.refresh_fastest_mode().map_err(|e| e.to_string())
    }

    fn start(&mut self, s: &Settings, inputs: &mut InputValues, t0: f64) -> Result<(), String> {
        let u = &s.unit;
        if u.start_from_equilibrium {
            self.unit.start_static(t0, u.w_p_start, &EquilibriumSettings::default()).map_err(
                |e| format!("static-equilibrium start at w_p_start = {}: {e}", u.w_p_start),
            )?;
            let ui = *self.unit.inputs();
            let v = &mut inputs.values;
            match self.unit.kind() {
                UnitKind::Pair => (v[slot::TAU_P], v[slot::TAU_G]) = (ui.tau_p, ui.tau_g),
                UnitKind::Stage => {
                    (v[slot::PHI_1], v[slot::W_1], v[slot::PHI_2], v[slot::W_2]) =
                        (ui.phi_1, ui.w_1, ui.phi_2, ui.w_2)
                }
                UnitKind::Drive => v[slot::TORQUE] = ui.torque,
            }
        } else {
            let y = &u.start;
            let state: Vec<f64> = match self.unit.kind() {
                UnitKind::Drive => y.to_vec(),
                _ => vec![y[1], y[2], y[5], y[6]],
            };
            self.unit.set_time(t0).map_err(|e| e.to_string())?;
            self.unit.set_state(&state).map_err(|e| format!("explicit start state: {e}"))?;
            let (u, r) = unit_inputs(inputs);
            self.unit.set_inputs(u).map_err(|e| e.to_string())?;
            self.unit.set_input_rates(r).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// The mesh outputs, the unit's outputs and the Model Exchange state and derivative in
    /// relative coordinates into their slots ([`out`]).
    fn outputs(&mut self, inputs: &InputValues, v: &mut OutputValues) -> Result<(), String> {
        self.outputs_with(inputs, true, v).map(|_| ())
    }

    /// The unit's own outputs and the torques path's mesh outputs
    /// ([`Unit::outputs_partial`]).
    fn outputs_partial(
        &mut self,
        inputs: &InputValues,
        v: &mut OutputValues,
    ) -> Result<bool, String> {
        self.outputs_with(inputs, false, v)
    }

    fn step(&mut self, inputs: &InputValues, t: f64, h: f64) -> Result<(), StepFailure> {
        self.sync(inputs).map_err(StepFailure::Error)?;
        self.unit.advance(h).map_err(|e| {
            StepFailure::Discard(format!(
                "the step from t = {} s by h = {} s cannot be completed (state kept at t = \
                 {} s): {e}",
                crate::error::short_num(t),
                crate::error::short_num(h),
                crate::error::short_num(t)
            ))
        })
    }

    fn save(&self) -> Vec<u8> {
        self.unit.snapshot().to_text().into_bytes()
    }

    fn load(&mut self, bytes: &[u8]) -> Result<(), String> {
        let text = std::str::from_utf8(bytes)
            .map_err(|e| format!("serialised state: unit snapshot: {e}"))?;
        let s = UnitSnapshot::from_text(text)
            .map_err(|e| format!("serialised state: unit snapshot: {e}"))?;
        self.unit.restore(&s).map_err(|e| format!("serialised state: unit snapshot: {e}"))
    }

    fn n_states(&self) -> usize {
        self.rel.n()
    }

    /// Sets the unit's time and takes the inputs as valid from it (Model Exchange sets the
    /// inputs for the current time, so the Stage's far ends are not extrapolated).
    fn set_time(&mut self, t: f64) -> Result<(), String> {
        self.unit.set_time(t).map_err(|e| e.to_string())?;
        let (u, r) = (*self.unit.inputs(), *self.unit.input_rates());
        self.unit.set_inputs(u).map_err(|e| e.to_string())?;
        self.unit.set_input_rates(r).map_err(|e| e.to_string())
    }

    fn get_states(&self, x: &mut [f64]) {
        self.rel.to_relative(self.unit.state(), x);
    }

    fn set_states(&mut self, x: &[f64]) -> Result<(), String> {
        let n = self.rel.n();
        if x.len() != n {
            return Err(format!("{} continuous states given: the model has {n}", x.len()));
        }
        // φg is formed from (φp, TE): TE keeps its digits only up to a bound on φp.
        let gp = self.unit.mesh_mut().geometry().pinion.rb;
        crate::mesh::validity::check_formed_angle("phi_p", x[0], gp)
            .map_err(|e| format!("continuous state {e}"))?;
        let mut y = [0.0; 8];
        self.rel.to_absolute(x, &mut y[..n]);
        self.unit.set_state(&y[..n]).map_err(|e| e.to_string())
    }

    fn nominals(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.nominals[..x.len()]);
    }

    /// Rows: the outputs of [`UnitLinearization::outputs`] and the state derivatives; columns:
    /// the states (relative coordinates) and the inputs. From [`DriveUnit::linearize`] (the
    /// mesh Jacobian: table interpolant or load-solution sensitivity), transformed exactly.
    fn jacobian(&mut self, inputs: &InputValues) -> Result<Jacobian, String> {
        // Only when they changed: a Co-Simulation master asking between steps must not move
        // the origin of the Stage's held far-end motion.
        self.sync(inputs)?;
        let kind = self.unit.kind();
        let lin = self.unit.linearize().map_err(|e| format!("linearisation: {e}"))?;
        let l = self.rel.linearization(&lin);
        let (n, nu) = (l.n_x, l.n_u);
        let ders: &[&'static str] = if kind == UnitKind::Drive { &DRIVE_DERS } else { &PAIR_DERS };
        let outs = UnitLinearization::outputs(kind);
        let mut rows: Vec<&'static str> = outs.iter().map(|&q| variable_name(q)).collect();
        rows.extend_from_slice(ders);
        let cols: Vec<&'static str> = (self.rel.states().iter())
            .chain(UnitLinearization::inputs(kind))
            .map(|&q| variable_name(q))
            .collect();
        let w = n + nu;
        let mut values = vec![0.0; rows.len() * w];
        for r in 0..outs.len() {
            values[r * w..r * w + n].copy_from_slice(&l.c[r * n..(r + 1) * n]);
            values[r * w + n..(r + 1) * w].copy_from_slice(&l.d[r * nu..(r + 1) * nu]);
        }
        for i in 0..n {
            let r = outs.len() + i;
            values[r * w..r * w + n].copy_from_slice(&l.a[i * n..(i + 1) * n]);
            values[r * w + n..(r + 1) * w].copy_from_slice(&l.b[i * nu..(i + 1) * nu]);
        }
        Ok(Jacobian { rows, cols, values })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_and_names_are_unique_per_model() {
        for m in super::super::MODELS {
            for (i, a) in m.variables.iter().enumerate() {
                for b in &m.variables[i + 1..] {
                    assert_ne!(a.vr, b.vr, "{}: {} and {}", m.identifier, a.name, b.name);
                    assert_ne!(a.name, b.name, "{}", m.identifier);
                }
            }
        }
    }

    #[test]
    fn every_unit_quantity_of_a_model_names_one_of_its_variables() {
        for (m, kind) in
            [(&PAIR, UnitKind::Pair), (&STAGE, UnitKind::Stage), (&DRIVE, UnitKind::Drive)]
        {
            let rel = RelativeCoordinates::new(kind, 0.03, 0.05);
            // Every input and state; every output but the Drive's shaft torques τ₁, τ₂
            // (rows of its linearisation that the FMU does not output).
            let outputs = UnitLinearization::outputs(kind).iter().filter(|&&q| {
                !(kind == UnitKind::Drive && matches!(q, UnitQuantity::Tau1 | UnitQuantity::Tau2))
            });
            let quantities = outputs.chain(UnitLinearization::inputs(kind)).chain(rel.states());
            for &q in quantities {
                let name = variable_name(q);
                assert!(m.by_name(name).is_some(), "{}: {q:?} → `{name}`", m.identifier);
            }
            let states: Vec<&str> = rel.states().iter().map(|&q| variable_name(q)).collect();
            assert_eq!(m.state_names(), states, "{}: Model Exchange state order", m.identifier);
        }
    }
}
