//! The stateful model `HelicalGearbox`: the drive line of Eqs. 1–4 with both gear bodies on
//! elastic supports ([`crate::dynamics::bodies`]) behind the FMI layer (docs/fmus.md).
//!
//! # The model
//! 28 states: the four rotations of Eqs. 1–4 and their speeds, then each gear body's pose
//! p = (u_x, u_y, u_z, θ_x, θ_y) at its centre at mid-face and its rate
//! ([`crate::mesh::pose`]; a positive gear `u_x` opens the centre distance). The mesh is
//! evaluated at the whole state (angles, speeds, poses, pose rates); its torques drive
//! Eqs. 1–4, its 3D force and moments drive the bodies against their supports' reactions
//! R = −K·p − C·ṗ ([`crate::mesh::supports`]), with the gyroscopic moments of the spinning
//! bodies. Input: the driving torque `M` on J1 (the load on J2 is M·z_g/z_p, Eq. 4).
//! Outputs: the eight rotational states, TE, the mesh outputs (torques, 3D force and moments
//! on each body at its displaced state, §13 of the loads guide), the ten pose components and
//! the support force and moment on each body, `R_p_x` … `R_g_my` (what the support exerts on
//! the body, N and N·m).
//!
//! # Supports
//! The Real parameters `supports.pinion.*` and `supports.gear.*` give each body's mass,
//! transverse moment of inertia and an isotropic diagonal stiffness and damping
//! (K = diag(k_r, k_r, k_a, k_t, k_t), C likewise); their defaults are the example soft
//! support of the gear-bodies guide. The String parameter `supports`, when not empty, is the
//! supports JSON of the command line and Python (a 5 × 5 stiffness, the two-bearing shaft
//! form, a missing body held rigidly) and overrides the Real ones.
//!
//! # Start and stepping
//! The instance starts in the static equilibrium with the bodies displaced
//! ([`SupportedDynamics::static_start`]) at the nominal pinion speed `w_p_start` under the
//! drive line's torque `drive.torque_nm`, the value the input `M` is set to; with
//! `start_from_equilibrium` = false it starts from the explicit rotational state `phi_1_0` …
//! `w_2_0` with both bodies on their bearing axes at rest, under the input `M`. The coupled
//! modes linearised at the static equilibrium ([`SupportedDynamics::linear_modes`]) give the fastest rate |λ|max of the
//! step rule: a communication step h is integrated by RK4 in n equal sub-steps,
//! n = ⌈h/h_max⌉ with h_max = min(T_m/N, 2π/(32·|λ|max)) ([`stable_rk4_step`]; T_m the mesh
//! period at the current pinion speed, N = `rk4_steps_per_mesh_period`). DOPRI5 is not
//! offered, as in the command line and Python with supports: the body modes make the problem
//! stiff, and the step rule of the coupled modes is what keeps RK4 stable and resolved. `M` is
//! held over a step, or follows the first-order hold of `fmi2SetRealInputDerivatives`. A step beyond the
//! work bounds of the units ([`MAX_UNIT_SUBSTEPS`], [`MAX_UNIT_SLICE_EVALUATIONS`]) or that
//! meets an error of the mesh (a pose or TE outside the model's range) returns
//! `fmi2Discard` with the state of the step's start.
//!
//! The full-fidelity mesh warm-starts its load solver; each communication step and each
//! output evaluation starts it cold ([`MeshTorques::forget_history`]), so a result depends on
//! the state and the inputs alone and a restored FMU state continues bit for bit. The FMU
//! state is the time, the state, the held torque and its rate (raw little-endian `f64`s).
//!
//! # Model Exchange
//! The states are the Drive's relative coordinates ([`crate::dynamics::relative`]: φp, θ1,
//! TE, θ2 and their rates, so that TE is a state and an importer's tolerance acts on it),
//! then the twenty pose components and rates as they are. This model does not provide
//! directional derivatives (the mesh's exact Jacobian covers its torques, not its 3D force
//! and moments): `providesDirectionalDerivative="false"`, and an importer differentiates
//! numerically.

use std::sync::OnceLock;

use super::unit::{DRIVE_IO, DRIVE_KNOWN, DRIVE_STATES, HUB_STATES, HUBS, ME_DRIVE, slot};
use crate::dynamics::Drivetrain;
use crate::dynamics::bodies::{N_BODY_STATES, POSE_P, SupportedDynamics, SupportedStart};
use crate::dynamics::integrators::{OdeError, OdeSystem, Rk4};
use crate::dynamics::limits::{
    MAX_UNIT_SLICE_EVALUATIONS, MAX_UNIT_SUBSTEPS, STEPS_PER_FAST_PERIOD, stable_rk4_step,
};
use crate::dynamics::relative::RelativeCoordinates;
use crate::dynamics::unit::UnitKind;
use crate::fmi2::model::{Engine, Experiment, Jacobian, MAX_STATES, ModelInfo, StepFailure};
use crate::fmi2::models::mesh::build_mesh;
use crate::fmi2::models::write_mesh_outputs;
use crate::fmi2::variables::{
    ANGLE, Access, BodySupportOptions, CALCULATED, Causality, DRIVE_INERTIAS, DRIVE_SHAFTS,
    DRIVE_TORQUE, Depends, Derived, GEAR_PARAMS, InputValues, M, MESH_OPTIONS, MESH_OUTPUTS, NM,
    NONE, OutputValues, RAD, START_OUTER, START_PAIR, Settings, TORQUE, UNIT_OPTIONS, Variability,
    Variable, concat, group, total_len, with_depends,
};
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::supports::{Support, Supports};
use crate::mesh::{Mesh, MeshTorques, pose};
use crate::params::Bounds;

/// Number of states.
const N: usize = N_BODY_STATES;

/// `a` followed by `b` (`C` = their lengths' sum).
const fn join<const C: usize>(a: &[&'static str], b: &[&'static str]) -> [&'static str; C] {
    assert!(a.len() + b.len() == C);
    let mut out = [""; C];
    let mut i = 0;
    while i < C {
        out[i] = if i < a.len() { a[i] } else { b[i - a.len()] };
        i += 1;
    }
    out
}

/// The Model Exchange states in order: the Drive's relative coordinates, then the poses and
/// the pose rates of both bodies (the order of [`pose::INPUT_NAMES`]).
const STATES: [&str; N] = join(&DRIVE_STATES, &pose::INPUT_NAMES);
/// The knowns of Model Exchange: the states and the input `M`.
const KNOWN: [&str; N + 1] = join(&STATES, &["M"]);
/// What the mesh outputs depend on: the hub states and both bodies' poses and rates.
const MESH_KNOWN: [&str; 24] = join(&HUB_STATES, &pose::INPUT_NAMES);
const GEARBOX_MESH_OUTPUTS: [Variable; 30] = with_depends(
    MESH_OUTPUTS,
    Depends { inputs: &MESH_KNOWN, linear_fixed: false, groups: group::ALL },
);

/// Real output slots: the Drive's ([`super::unit::out`]: the mesh outputs, the kinematics,
/// the Model Exchange state `X + i` and its derivative `DX + i`, both [`MAX_STATES`] long, so
/// the poses follow the Drive's eight states there), then the ten support reactions
/// `R_p_x` … `R_g_my` ([`crate::dynamics::bodies::REACTION_NAMES`]) at `R`.
use super::unit::out::{self, DX, X};
const R: usize = DX + MAX_STATES;

/// True when the lists `a` and `b` hold the same names in the same order.
const fn same(a: &[&str], b: &[&str]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        let (x, y) = (a[i].as_bytes(), b[i].as_bytes());
        if x.len() != y.len() {
            return false;
        }
        let mut k = 0;
        while k < x.len() {
            if x[k] != y[k] {
                return false;
            }
            k += 1;
        }
        i += 1;
    }
    true
}

/// The Drive's variables as the Gearbox has them: what depends on the Drive's whole state
/// (and `M`) depends on all 28 states (and `M`); every other dependency list stays.
const fn widened<const L: usize>(vars: [Variable; L]) -> [Variable; L] {
    let mut v = vars;
    let mut i = 0;
    while i < L {
        if let Some(d) = v[i].depends {
            let inputs: &'static [&'static str] = if same(d.inputs, &DRIVE_STATES) {
                &STATES
            } else if same(d.inputs, &DRIVE_KNOWN) {
                &KNOWN
            } else {
                d.inputs
            };
            v[i].depends = Some(Depends { inputs, ..d });
        }
        i += 1;
    }
    v
}

const DRIVE_IO_WIDE: [Variable; 7] = widened(DRIVE_IO);
const HUBS_WIDE: [Variable; 4] = widened(HUBS);
const ME_DRIVE_WIDE: [Variable; 13] = widened(ME_DRIVE);

const RAD_S: Option<&str> = Some("rad/s");
const W: Option<&str> = Some("AngularVelocity");
const RAD_S2: Option<&str> = Some("rad/s2");
const ACC: Option<&str> = Some("AngularAcceleration");
const M_S: Option<&str> = Some("m/s");
const M_S2: Option<&str> = Some("m/s2");
const VEL: Option<&str> = Some("Velocity");
const ACCEL: Option<&str> = Some("Acceleration");
const N_UNIT: Option<&str> = Some("N");
const FORCE: Option<&str> = Some("Force");
const LENGTH: Option<&str> = Some("Length");

/// A Real output or a Model Exchange local (`derivative_of` set for a state derivative) in
/// slot `slot`.
#[allow(clippy::too_many_arguments)]
const fn var(
    name: &'static str,
    vr: u32,
    causality: Causality,
    unit: Option<&'static str>,
    display_unit: Option<&'static str>,
    quantity: Option<&'static str>,
    description: &'static str,
    deps: &'static [&'static str],
    derivative_of: Option<&'static str>,
    slot: usize,
) -> Variable {
    Variable {
        name,
        vr,
        causality,
        variability: Variability::Continuous,
        description,
        unit,
        display_unit,
        quantity,
        depends: Some(Depends { inputs: deps, linear_fixed: false, groups: group::ALL }),
        access: Access::RealOutput(slot),
        derivative_of,
        ..NONE
    }
}

use Causality::{Local, Output};

/// The pose states in the order of the state vector (pinion pose, gear pose, pinion rate, gear
/// rate): poses are outputs, rates Model Exchange locals, value references 600 + s for state
/// 8 + s; then their derivatives, 640 + s.
const fn pose_variables() -> [Variable; 40] {
    let mut v = [NONE; 40];
    let mut s = 0;
    while s < 20 {
        let (is_rate, tilt) = (s >= 10, s % 5 >= 3);
        let name = STATES[8 + s];
        let (unit, q) = match (is_rate, tilt) {
            (false, false) => (M, LENGTH),
            (false, true) => (RAD, ANGLE),
            (true, false) => (M_S, VEL),
            (true, true) => (RAD_S, W),
        };
        let vr = 600 + s as u32;
        v[s] = var(
            name,
            vr,
            if is_rate { Local } else { Output },
            unit,
            None,
            q,
            POSE_DESCRIPTIONS[s],
            &[],
            None,
            X + 8 + s,
        );
        let deps: &'static [&'static str] = if is_rate { &KNOWN } else { RATE_OF[s] };
        let (dunit, dq) = match (is_rate, tilt) {
            (false, false) => (M_S, VEL),
            (false, true) => (RAD_S, W),
            (true, false) => (M_S2, ACCEL),
            (true, true) => (RAD_S2, ACC),
        };
        v[20 + s] = var(
            DER_NAMES[s],
            vr + 40,
            Local,
            dunit,
            None,
            dq,
            DER_DESCRIPTIONS[s],
            deps,
            Some(name),
            DX + 8 + s,
        );
        s += 1;
    }
    v
}

/// A pose derivative depends on the pose's rate.
const RATE_OF: [&[&str]; 20] = [
    &["v_p_x"],
    &["v_p_y"],
    &["v_p_z"],
    &["om_p_x"],
    &["om_p_y"],
    &["v_g_x"],
    &["v_g_y"],
    &["v_g_z"],
    &["om_g_x"],
    &["om_g_y"],
    &[],
    &[],
    &[],
    &[],
    &[],
    &[],
    &[],
    &[],
    &[],
    &[],
];

const DER_NAMES: [&str; 20] = [
    "der(u_p_x)",
    "der(u_p_y)",
    "der(u_p_z)",
    "der(th_p_x)",
    "der(th_p_y)",
    "der(u_g_x)",
    "der(u_g_y)",
    "der(u_g_z)",
    "der(th_g_x)",
    "der(th_g_y)",
    "der(v_p_x)",
    "der(v_p_y)",
    "der(v_p_z)",
    "der(om_p_x)",
    "der(om_p_y)",
    "der(v_g_x)",
    "der(v_g_y)",
    "der(v_g_z)",
    "der(om_g_x)",
    "der(om_g_y)",
];

const POSE_DESCRIPTIONS: [&str; 20] = [
    "Pinion body's translation u_x at its centre at mid-face from its bearing axis, m (x from \
     the pinion axis to the gear axis; state)",
    "Pinion body's translation u_y, m (state)",
    "Pinion body's axial translation u_z, m (state)",
    "Pinion body's tilt th_x about x, rad (state)",
    "Pinion body's tilt th_y about y, rad (state)",
    "Gear body's translation u_x at its centre at mid-face from its bearing axis, m (positive \
     opens the centre distance; state)",
    "Gear body's translation u_y, m (state)",
    "Gear body's axial translation u_z, m (state)",
    "Gear body's tilt th_x about x, rad (state)",
    "Gear body's tilt th_y about y, rad (state)",
    "Rate of u_p_x, m/s (Model Exchange state)",
    "Rate of u_p_y, m/s (Model Exchange state)",
    "Rate of u_p_z, m/s (Model Exchange state)",
    "Rate of th_p_x, rad/s (Model Exchange state)",
    "Rate of th_p_y, rad/s (Model Exchange state)",
    "Rate of u_g_x, m/s (Model Exchange state)",
    "Rate of u_g_y, m/s (Model Exchange state)",
    "Rate of u_g_z, m/s (Model Exchange state)",
    "Rate of th_g_x, rad/s (Model Exchange state)",
    "Rate of th_g_y, rad/s (Model Exchange state)",
];

const DER_DESCRIPTIONS: [&str; 20] = [
    "Time derivative of u_p_x, m/s",
    "Time derivative of u_p_y, m/s",
    "Time derivative of u_p_z, m/s",
    "Time derivative of th_p_x, rad/s",
    "Time derivative of th_p_y, rad/s",
    "Time derivative of u_g_x, m/s",
    "Time derivative of u_g_y, m/s",
    "Time derivative of u_g_z, m/s",
    "Time derivative of th_g_x, rad/s",
    "Time derivative of th_g_y, rad/s",
    "Time derivative of v_p_x, m/s2",
    "Time derivative of v_p_y, m/s2",
    "Time derivative of v_p_z, m/s2",
    "Time derivative of om_p_x, rad/s2",
    "Time derivative of om_p_y, rad/s2",
    "Time derivative of v_g_x, m/s2",
    "Time derivative of v_g_y, m/s2",
    "Time derivative of v_g_z, m/s2",
    "Time derivative of om_g_x, rad/s2",
    "Time derivative of om_g_y, rad/s2",
];

const POSES: [Variable; 40] = pose_variables();

/// The support force and moment on each body (outputs, value references 680–689).
const REACTIONS: [Variable; 10] = [
    var(
        "R_p_x",
        680,
        Output,
        N_UNIT,
        None,
        FORCE,
        "Force x the pinion's support exerts on the pinion body, N (R = -K*p - C*p')",
        &STATES,
        None,
        R,
    ),
    var(
        "R_p_y",
        681,
        Output,
        N_UNIT,
        None,
        FORCE,
        "Force y the pinion's support exerts on the pinion body, N",
        &STATES,
        None,
        R + 1,
    ),
    var(
        "R_p_z",
        682,
        Output,
        N_UNIT,
        None,
        FORCE,
        "Axial force z the pinion's support exerts on the pinion body, N",
        &STATES,
        None,
        R + 2,
    ),
    var(
        "R_p_mx",
        683,
        Output,
        NM,
        None,
        TORQUE,
        "Moment about x the pinion's support exerts on the pinion body, N.m",
        &STATES,
        None,
        R + 3,
    ),
    var(
        "R_p_my",
        684,
        Output,
        NM,
        None,
        TORQUE,
        "Moment about y the pinion's support exerts on the pinion body, N.m",
        &STATES,
        None,
        R + 4,
    ),
    var(
        "R_g_x",
        685,
        Output,
        N_UNIT,
        None,
        FORCE,
        "Force x the gear's support exerts on the gear body, N",
        &STATES,
        None,
        R + 5,
    ),
    var(
        "R_g_y",
        686,
        Output,
        N_UNIT,
        None,
        FORCE,
        "Force y the gear's support exerts on the gear body, N",
        &STATES,
        None,
        R + 6,
    ),
    var(
        "R_g_z",
        687,
        Output,
        N_UNIT,
        None,
        FORCE,
        "Axial force z the gear's support exerts on the gear body, N",
        &STATES,
        None,
        R + 7,
    ),
    var(
        "R_g_mx",
        688,
        Output,
        NM,
        None,
        TORQUE,
        "Moment about x the gear's support exerts on the gear body, N.m",
        &STATES,
        None,
        R + 8,
    ),
    var(
        "R_g_my",
        689,
        Output,
        NM,
        None,
        TORQUE,
        "Moment about y the gear's support exerts on the gear body, N.m",
        &STATES,
        None,
        R + 9,
    ),
];

/// Mass of a supported body, kg: 1 g … 100 t.
pub const SUPPORT_MASS_KG: Bounds<f64> = Bounds::new(1e-3, 1e5, "kg");
/// Transverse moment of inertia of a supported body, kg·m².
pub const SUPPORT_J_KGM2: Bounds<f64> = Bounds::new(1e-8, 1e4, "kg.m2");
/// Radial or axial support stiffness, N/m. The least keeps a body within the poses the table
/// takes (0.02·m_n) under the least drive torque, 1 N·m, for Table 1 (23 µm).
pub const SUPPORT_STIFFNESS_N_PER_M: Bounds<f64> = Bounds::new(1e6, 1e15, "N/m");
/// Tilting support stiffness, N·m/rad; the least as for [`SUPPORT_STIFFNESS_N_PER_M`]
/// (1.6·10⁻³ rad).
pub const SUPPORT_TILT_NM_PER_RAD: Bounds<f64> = Bounds::new(1e2, 1e13, "N.m/rad");
/// Radial or axial support damping, N·s/m. The largest over the least mass, 10¹¹ s⁻¹, still
/// leaves a 1 µs communication step within the sub-step bound of the units.
pub const SUPPORT_DAMPING_NS_PER_M: Bounds<f64> = Bounds::new(0.0, 1e8, "N.s/m");
/// Tilting support damping, N·m·s/rad (the largest, as for [`SUPPORT_DAMPING_NS_PER_M`]).
pub const SUPPORT_TILT_DAMPING_NMS_PER_RAD: Bounds<f64> = Bounds::new(0.0, 1e3, "N.m.s/rad");

/// A Real support parameter `supports.<body>.<field>` of [`BodySupportOptions`].
macro_rules! support_param {
    ($name:literal, $vr:expr, $body:ident, $field:ident, $bounds:expr, $unit:literal,
     $desc:literal) => {
        Variable {
            name: $name,
            vr: $vr,
            causality: Causality::Parameter,
            variability: Variability::Fixed,
            description: $desc,
            unit: Some($unit),
            min: Some($bounds.min),
            max: Some($bounds.max),
            group: group::DRIVE,
            access: Access::RealParam(
                |s| s.supports.$body.$field,
                |s, v| s.supports.$body.$field = v,
            ),
            ..NONE
        }
    };
}

/// The supports: eight Real parameters per body (value references 700–715) and the JSON
/// text (716).
const SUPPORT_PARAMS: [Variable; 17] = [
    support_param!(
        "supports.pinion.mass_kg",
        700,
        pinion,
        mass_kg,
        SUPPORT_MASS_KG,
        "kg",
        "Mass of the pinion body on its support, kg"
    ),
    support_param!(
        "supports.pinion.j_transverse_kgm2",
        701,
        pinion,
        j_transverse_kgm2,
        SUPPORT_J_KGM2,
        "kg.m2",
        "Moment of inertia of the pinion body about a transverse axis through its centre, kg.m2"
    ),
    support_param!(
        "supports.pinion.radial_n_per_m",
        702,
        pinion,
        radial_n_per_m,
        SUPPORT_STIFFNESS_N_PER_M,
        "N/m",
        "Radial stiffness of the pinion's support at the body's centre (u_x and u_y), N/m"
    ),
    support_param!(
        "supports.pinion.axial_n_per_m",
        703,
        pinion,
        axial_n_per_m,
        SUPPORT_STIFFNESS_N_PER_M,
        "N/m",
        "Axial stiffness of the pinion's support (u_z), N/m"
    ),
    support_param!(
        "supports.pinion.tilt_nm_per_rad",
        704,
        pinion,
        tilt_nm_per_rad,
        SUPPORT_TILT_NM_PER_RAD,
        "N.m/rad",
        "Tilting stiffness of the pinion's support (th_x and th_y), N.m/rad"
    ),
    support_param!(
        "supports.pinion.radial_ns_per_m",
        705,
        pinion,
        radial_ns_per_m,
        SUPPORT_DAMPING_NS_PER_M,
        "N.s/m",
        "Radial damping of the pinion's support, N.s/m"
    ),
    support_param!(
        "supports.pinion.axial_ns_per_m",
        706,
        pinion,
        axial_ns_per_m,
        SUPPORT_DAMPING_NS_PER_M,
        "N.s/m",
        "Axial damping of the pinion's support, N.s/m"
    ),
    support_param!(
        "supports.pinion.tilt_nms_per_rad",
        707,
        pinion,
        tilt_nms_per_rad,
        SUPPORT_TILT_DAMPING_NMS_PER_RAD,
        "N.m.s/rad",
        "Tilting damping of the pinion's support, N.m.s/rad"
    ),
    support_param!(
        "supports.gear.mass_kg",
        708,
        gear,
        mass_kg,
        SUPPORT_MASS_KG,
        "kg",
        "Mass of the gear body on its support, kg"
    ),
    support_param!(
        "supports.gear.j_transverse_kgm2",
        709,
        gear,
        j_transverse_kgm2,
        SUPPORT_J_KGM2,
        "kg.m2",
        "Moment of inertia of the gear body about a transverse axis through its centre, kg.m2"
    ),
    support_param!(
        "supports.gear.radial_n_per_m",
        710,
        gear,
        radial_n_per_m,
        SUPPORT_STIFFNESS_N_PER_M,
        "N/m",
        "Radial stiffness of the gear's support at the body's centre (u_x and u_y), N/m"
    ),
    support_param!(
        "supports.gear.axial_n_per_m",
        711,
        gear,
        axial_n_per_m,
        SUPPORT_STIFFNESS_N_PER_M,
        "N/m",
        "Axial stiffness of the gear's support (u_z), N/m"
    ),
    support_param!(
        "supports.gear.tilt_nm_per_rad",
        712,
        gear,
        tilt_nm_per_rad,
        SUPPORT_TILT_NM_PER_RAD,
        "N.m/rad",
        "Tilting stiffness of the gear's support (th_x and th_y), N.m/rad"
    ),
    support_param!(
        "supports.gear.radial_ns_per_m",
        713,
        gear,
        radial_ns_per_m,
        SUPPORT_DAMPING_NS_PER_M,
        "N.s/m",
        "Radial damping of the gear's support, N.s/m"
    ),
    support_param!(
        "supports.gear.axial_ns_per_m",
        714,
        gear,
        axial_ns_per_m,
        SUPPORT_DAMPING_NS_PER_M,
        "N.s/m",
        "Axial damping of the gear's support, N.s/m"
    ),
    support_param!(
        "supports.gear.tilt_nms_per_rad",
        715,
        gear,
        tilt_nms_per_rad,
        SUPPORT_TILT_DAMPING_NMS_PER_RAD,
        "N.m.s/rad",
        "Tilting damping of the gear's support, N.m.s/rad"
    ),
    Variable {
        name: "supports",
        vr: 716,
        description: "The supports as JSON (docs/gear-bodies.md: {\"pinion\": {\"mass_kg\", \
                      \"j_transverse_kgm2\", \"stiffness\" or \"stiffness_matrix\" or \"shaft\", \
                      \"damping\"}, \"gear\": {...}}; a missing body is held rigidly); empty: \
                      the Real parameters supports.pinion.* and supports.gear.*",
        group: group::DRIVE,
        access: Access::StringParam(|s| s.supports.json.clone(), set_supports_json),
        ..NONE
    },
];

/// Parses the `supports` parameter (empty: the Real parameters); an error names the key.
fn set_supports_json(s: &mut Settings, text: &str) -> Result<(), String> {
    if !text.trim().is_empty() {
        Supports::from_json_for(text, s.pair.face_width_m).map_err(|e| e.to_string())?;
    }
    s.supports.json = text.to_string();
    Ok(())
}

/// `w_p_start`, `rk4_steps_per_mesh_period` and `start_from_equilibrium` of the stateful
/// models' options (the Gearbox integrates with RK4 only, module docs).
const GEARBOX_OPTIONS: [Variable; 3] = [UNIT_OPTIONS[0], UNIT_OPTIONS[2], UNIT_OPTIONS[5]];

const PARTS: &[&[Variable]] = &[
    &DRIVE_IO_WIDE,
    &HUBS_WIDE,
    &GEARBOX_MESH_OUTPUTS,
    &REACTIONS,
    &CALCULATED,
    &GEAR_PARAMS,
    &DRIVE_TORQUE,
    &DRIVE_INERTIAS,
    &DRIVE_SHAFTS,
    &MESH_OPTIONS,
    &GEARBOX_OPTIONS,
    &START_PAIR,
    &START_OUTER,
    &SUPPORT_PARAMS,
    // The state derivatives in state order: the rotations', then the poses'.
    &ME_DRIVE_WIDE,
    &POSES,
];

static TABLE: [Variable; total_len(PARTS)] = concat(PARTS);

/// Default parameters: those of the other stateful models (table fidelity) with the example
/// supports.
fn gearbox_settings() -> Settings {
    let mut s = Settings::default();
    s.options.fidelity = crate::mesh::Fidelity::Table;
    s
}

/// The start input: the default driving torque.
fn gearbox_inputs() -> InputValues {
    let mut i = InputValues::default();
    i.values[slot::TORQUE] = Settings::default().drive.torque_nm;
    i
}

static GUID: OnceLock<String> = OnceLock::new();

/// `HelicalGearbox`.
pub static GEARBOX: ModelInfo = ModelInfo {
    identifier: "HelicalGearbox",
    description: "Helical gearbox (Andersson and Vedmar 2003 with gear bodies on elastic \
                  supports): Eqs. 1-4 and both gear bodies' translations and tilts integrated \
                  inside; driving torque M in, states, TE, mesh loads, poses and support forces \
                  out",
    doc_html: "<p>The 4-DOF torsional model of Eqs. 1&ndash;4 with both gear bodies on elastic \
               supports (28 states: the rotations, and each body's translation and tilt at \
               its centre with their rates), integrated inside each communication step. The \
               mesh is evaluated on the displaced true geometry; its 3D force and moments move \
               the bodies against their supports. Input: the driving torque <code>M</code> on \
               J1. Outputs: the states, TE, the mesh torques, forces and moments, the poses \
               <code>u_p_x</code> &hellip; <code>th_g_y</code> and the support forces \
               <code>R_p_x</code> &hellip; <code>R_g_my</code>. Starts in static equilibrium \
               with the bodies displaced at <code>w_p_start</code>. Supports: the Real \
               parameters <code>supports.pinion.*</code>, <code>supports.gear.*</code> or the \
               JSON parameter <code>supports</code>. No directional derivatives.</p>",
    variables: &TABLE,
    default_settings: gearbox_settings,
    default_inputs: gearbox_inputs,
    experiment: Experiment { start: 0.0, stop: 0.02, step: 1e-4 },
    stateful: true,
    event_indicators: 0,
    provides_directional_derivative: false,
    build: build_gearbox,
    check_tunable: super::mesh::check_tunable,
    cached_outputs: false,
    partial_output: super::no_partial_output,
    guid_cell: &GUID,
};

/// One body's support from its Real parameters, each checked against its bounds (the error
/// names the parameter `supports.<body>.<field>`).
fn body_support(body: &str, b: &BodySupportOptions) -> Result<Support, String> {
    let check = |field: &str, bounds: &Bounds<f64>, x: f64| {
        bounds.check(&format!("supports.{body}.{field}"), x).map_err(|e| e.to_string())
    };
    check("mass_kg", &SUPPORT_MASS_KG, b.mass_kg)?;
    check("j_transverse_kgm2", &SUPPORT_J_KGM2, b.j_transverse_kgm2)?;
    check("radial_n_per_m", &SUPPORT_STIFFNESS_N_PER_M, b.radial_n_per_m)?;
    check("axial_n_per_m", &SUPPORT_STIFFNESS_N_PER_M, b.axial_n_per_m)?;
    check("tilt_nm_per_rad", &SUPPORT_TILT_NM_PER_RAD, b.tilt_nm_per_rad)?;
    check("radial_ns_per_m", &SUPPORT_DAMPING_NS_PER_M, b.radial_ns_per_m)?;
    check("axial_ns_per_m", &SUPPORT_DAMPING_NS_PER_M, b.axial_ns_per_m)?;
    check("tilt_nms_per_rad", &SUPPORT_TILT_DAMPING_NMS_PER_RAD, b.tilt_nms_per_rad)?;
    Ok(Support {
        mass_kg: b.mass_kg,
        j_transverse_kgm2: b.j_transverse_kgm2,
        stiffness: Support::isotropic(b.radial_n_per_m, b.axial_n_per_m, b.tilt_nm_per_rad),
        damping: Support::isotropic(b.radial_ns_per_m, b.axial_ns_per_m, b.tilt_nms_per_rad),
        shaft: None,
    })
}

/// The supports of the settings: the JSON when given, else the Real parameters.
fn supports_of(s: &Settings) -> Result<Supports, String> {
    if !s.supports.json.trim().is_empty() {
        return Supports::from_json_for(&s.supports.json, s.pair.face_width_m)
            .map_err(|e| e.to_string());
    }
    Ok(Supports {
        pinion: Some(body_support("pinion", &s.supports.pinion)?),
        gear: Some(body_support("gear", &s.supports.gear)?),
    })
}

fn build_gearbox(s: &Settings) -> Result<(Box<dyn Engine>, Derived), String> {
    let u = &s.unit;
    u.check().map_err(|e| e.to_string())?;
    s.drive.check().map_err(|e| e.to_string())?;
    // The supports are checked before the mesh is built (a bad value costs no table).
    let supports = supports_of(s)?;
    let mut s = s.clone();
    s.options = s.options.sized_for(&s.drive);
    let (mesh, derived) = build_mesh(&s)?;
    let slices = mesh.evaluation_slices();
    let drive = Drivetrain::new(mesh.geometry(), &s.drive).map_err(|e| e.to_string())?;
    let dynamics =
        SupportedDynamics::new(mesh, drive, supports).map_err(|e| format!("gearbox: {e}"))?;
    let rel =
        RelativeCoordinates::new(UnitKind::Drive, derived.base_radius_p, derived.base_radius_g);
    Ok((
        Box::new(GearboxEngine {
            dynamics,
            rel,
            y: [0.0; N],
            t: 0.0,
            torque: drive.torque,
            torque_rate: 0.0,
            torque_time: 0.0,
            fastest: 1.0,
            start_point: None,
            steps_per_mesh_period: u.rk4_steps_per_mesh_period,
            slices,
            nominals: [1.0; N],
            rk4: Rk4::new(N),
        }),
        derived,
    ))
}

/// The supported model with the driving torque held from `time` at `torque` and changing at
/// `rate` (N·m/s): M(t) = torque + rate·(t − time).
struct Held<'a> {
    sys: &'a mut SupportedDynamics<Mesh>,
    torque: f64,
    rate: f64,
    time: f64,
}

impl OdeSystem for Held<'_> {
    fn dim(&self) -> usize {
        N
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError> {
        self.sys.set_torque(self.torque + self.rate * (t - self.time));
        self.sys.rhs(t, y, dydt)
    }
}

/// The supported drive line as an [`Engine`] (module docs).
#[derive(Clone)]
struct GearboxEngine {
    dynamics: SupportedDynamics<Mesh>,
    rel: RelativeCoordinates,
    /// The state (module docs of [`crate::dynamics::bodies`]).
    y: [f64; N],
    /// Time, s.
    t: f64,
    /// The held driving torque, N·m, its rate, N·m/s, and the time it was set, s.
    torque: f64,
    torque_rate: f64,
    torque_time: f64,
    /// |λ|max of the coupled modes at the start, rad/s.
    fastest: f64,
    /// The static start (the point of the coupled modes), once started.
    start_point: Option<Box<SupportedStart>>,
    steps_per_mesh_period: u32,
    /// Slices of one mesh evaluation (0 for the table).
    slices: usize,
    /// Nominal magnitudes of the Model Exchange states.
    nominals: [f64; N],
    rk4: Rk4,
}

impl GearboxEngine {
    /// Takes the input `M` (and its rate) when it differs from the held one or was set since
    /// the last step: held from the current time.
    fn sync(&mut self, i: &InputValues) {
        let (m, r) = (i.values[slot::TORQUE], i.rates[slot::TORQUE]);
        if i.fresh || m != self.torque || r != self.torque_rate {
            (self.torque, self.torque_rate, self.torque_time) = (m, r, self.t);
        }
    }

    /// The driving torque at time `t`, N·m.
    fn torque_at(&self, t: f64) -> f64 {
        self.torque + self.torque_rate * (t - self.torque_time)
    }
}

impl Engine for GearboxEngine {
    fn clone_box(&self) -> Box<dyn Engine> {
        Box::new(self.clone())
    }

    /// Applies the mesh damping `d_mesh` (the one tunable parameter); the step rule follows
    /// it (an overdamped mesh mode needs a shorter step): the coupled modes at the start are
    /// linearised again.
    fn tune(&mut self, s: &Settings) -> Result<(), String> {
        self.dynamics
            .mesh_mut()
            .set_d_mesh(s.pair.d_mesh_n_s_per_m)
            .map_err(|e| super::mesh::mesh_error_text(&e))?;
        if let Some(start) = &self.start_point {
            let modes = self
                .dynamics
                .linear_modes(start)
                .map_err(|e| format!("coupled modes at the start: {e}"))?;
            self.fastest = modes.fastest;
        }
        Ok(())
    }

    fn start(&mut self, s: &Settings, inputs: &mut InputValues, t0: f64) -> Result<(), String> {
        let w = s.unit.w_p_start;
        let start = self
            .dynamics
            .static_start(0.0, w, &EquilibriumSettings::default())
            .map_err(|e| format!("static-equilibrium start at w_p_start = {w}: {e}"))?;
        let modes = self
            .dynamics
            .linear_modes(&start)
            .map_err(|e| format!("coupled modes at the start: {e}"))?;
        let d = *self.dynamics.drive();
        self.t = t0;
        if s.unit.start_from_equilibrium {
            self.y = start.y;
            (self.torque, self.torque_rate, self.torque_time) = (d.torque, 0.0, t0);
            inputs.values[slot::TORQUE] = d.torque;
            inputs.rates[slot::TORQUE] = 0.0;
        } else {
            // The explicit rotational state, the bodies on their bearing axes at rest.
            let mut y = [0.0; N];
            y[..8].copy_from_slice(&s.unit.start);
            let gp = self.dynamics.mesh_mut().geometry().pinion.rb;
            crate::mesh::validity::check_formed_angle("phi_p_0", y[1], gp)
                .map_err(|e| format!("explicit start state: {e}"))?;
            self.dynamics.mesh_mut().forget_history();
            self.dynamics.outputs(&y).map_err(|e| format!("explicit start state: {e}"))?;
            self.y = y;
            let (m, r) = (inputs.values[slot::TORQUE], inputs.rates[slot::TORQUE]);
            (self.torque, self.torque_rate, self.torque_time) = (m, r, t0);
        }
        self.fastest = modes.fastest;
        self.start_point = Some(Box::new(start));
        let mut nominals = [1.0; N];
        self.rel.nominals(
            d.torque,
            d.z_g as f64 / d.z_p as f64,
            modes.mesh_stiffness,
            d.c1,
            d.c2,
            modes.fastest,
            w,
            &mut nominals[..8],
        );
        // Poses: the largest static translation (tilt) of the start, at least 10 nm (1 µrad);
        // rates: that times |λ|max.
        let size = |comps: &[usize], least: f64| {
            comps.iter().map(|&i| start.y[POSE_P + i].abs()).fold(least, f64::max)
        };
        let tr = size(&[0, 1, 2, 5, 6, 7], 1e-8);
        let tl = size(&[3, 4, 8, 9], 1e-6);
        for i in 0..20 {
            let base = if i % 5 >= 3 { tl } else { tr };
            nominals[8 + i] = if i < 10 { base } else { base * modes.fastest.max(1.0) };
        }
        self.nominals = nominals;
        Ok(())
    }

    fn outputs(&mut self, inputs: &InputValues, v: &mut OutputValues) -> Result<(), String> {
        self.sync(inputs);
        let torque = self.torque_at(self.t);
        let sys = &mut self.dynamics;
        sys.mesh_mut().forget_history();
        let o = sys.outputs(&self.y).map_err(|e| format!("outputs: {e}"))?;
        sys.set_torque(torque);
        let mut dydt = [0.0; N];
        sys.rhs(self.t, &self.y, &mut dydt).map_err(|e| format!("outputs: {e}"))?;
        write_mesh_outputs(&o, v);
        let (y, r) = (&self.y, &mut v.reals);
        (r[out::PHI_1], r[out::PHI_P], r[out::PHI_G], r[out::PHI_2]) = (y[0], y[1], y[2], y[3]);
        (r[out::W_1], r[out::W_P], r[out::W_G], r[out::W_2]) = (y[4], y[5], y[6], y[7]);
        (r[out::A_P], r[out::A_G]) = (dydt[5], dydt[6]);
        r[R..R + 10].copy_from_slice(&sys.reactions(y).values());
        self.rel.to_relative(&y[..8], &mut r[X..X + 8]);
        r[X + 8..X + N].copy_from_slice(&y[8..]);
        self.rel.to_relative(&dydt[..8], &mut r[DX..DX + 8]);
        r[DX + 8..DX + N].copy_from_slice(&dydt[8..]);
        Ok(())
    }

    fn step(&mut self, inputs: &InputValues, t: f64, h: f64) -> Result<(), StepFailure> {
        self.sync(inputs);
        let d = *self.dynamics.drive();
        let h_max = stable_rk4_step(
            d.mesh_period(self.y[5]),
            f64::from(self.steps_per_mesh_period),
            self.fastest,
            STEPS_PER_FAST_PERIOD,
        );
        let n = (h / h_max).ceil().max(1.0);
        let discard = |why: String| {
            StepFailure::Discard(format!(
                "the step from t = {} s by h = {} s cannot be completed (state kept at t = {} \
                 s): {why}",
                crate::error::short_num(t),
                crate::error::short_num(h),
                crate::error::short_num(t)
            ))
        };
        if n.is_nan() || n > MAX_UNIT_SUBSTEPS {
            return Err(discard(format!(
                "it needs {} RK4 sub-steps of at most {} s, more than {MAX_UNIT_SUBSTEPS:e}: \
                 take shorter communication steps",
                crate::error::short_num(n),
                crate::error::short_num(h_max)
            )));
        }
        let work = 4.0 * n * self.slices as f64;
        if work > MAX_UNIT_SLICE_EVALUATIONS {
            return Err(discard(format!(
                "its {} RK4 sub-steps take {} slice-evaluations of the full mesh, more than \
                 {MAX_UNIT_SLICE_EVALUATIONS:e}: take shorter communication steps or table \
                 fidelity",
                crate::error::short_num(n),
                crate::error::short_num(work)
            )));
        }
        let n = n as usize;
        let dt = h / n as f64;
        let mut y = self.y;
        self.dynamics.mesh_mut().forget_history();
        let mut held = Held {
            sys: &mut self.dynamics,
            torque: self.torque,
            rate: self.torque_rate,
            time: self.torque_time,
        };
        for i in 0..n {
            let ti = t + i as f64 * dt;
            self.rk4.step(&mut held, ti, dt, &mut y).map_err(|e| discard(e.to_string()))?;
        }
        if y.iter().any(|x| !x.is_finite()) {
            return Err(discard("the state is not finite".into()));
        }
        self.y = y;
        self.t = t + h;
        Ok(())
    }

    /// The time, the held torque, its rate and time, and the 28 states.
    fn save(&self) -> Vec<u8> {
        [self.t, self.torque, self.torque_rate, self.torque_time]
            .iter()
            .chain(&self.y)
            .flat_map(|x| x.to_le_bytes())
            .collect()
    }

    fn load(&mut self, bytes: &[u8]) -> Result<(), String> {
        if bytes.len() != 8 * (N + 4) {
            return Err(format!(
                "serialised state: {} bytes of gearbox state, expected {}",
                bytes.len(),
                8 * (N + 4)
            ));
        }
        let v: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("chunks of 8")))
            .collect();
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(format!("serialised state: value {i} of the gearbox state is not finite"));
        }
        (self.t, self.torque, self.torque_rate, self.torque_time) = (v[0], v[1], v[2], v[3]);
        self.y.copy_from_slice(&v[4..]);
        Ok(())
    }

    fn n_states(&self) -> usize {
        N
    }

    /// Sets the time; the input is taken as valid from it (Model Exchange inputs are the
    /// values at that time).
    fn set_time(&mut self, t: f64) -> Result<(), String> {
        self.torque = self.torque_at(t);
        (self.t, self.torque_rate, self.torque_time) = (t, 0.0, t);
        Ok(())
    }

    fn get_states(&self, x: &mut [f64]) {
        self.rel.to_relative(&self.y[..8], &mut x[..8]);
        x[8..].copy_from_slice(&self.y[8..]);
    }

    fn set_states(&mut self, x: &[f64]) -> Result<(), String> {
        if x.len() != N {
            return Err(format!("{} continuous states given: the model has {N}", x.len()));
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(format!("continuous state {} = {} is not finite", STATES[i], x[i]));
        }
        // φg is formed from (φp, TE): TE keeps its digits only up to a bound on φp.
        let gp = self.dynamics.mesh_mut().geometry().pinion.rb;
        crate::mesh::validity::check_formed_angle("phi_p", x[0], gp)
            .map_err(|e| format!("continuous state {e}"))?;
        let mut y = [0.0; N];
        self.rel.to_absolute(&x[..8], &mut y[..8]);
        y[8..].copy_from_slice(&x[8..]);
        self.y = y;
        Ok(())
    }

    fn nominals(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.nominals[..x.len()]);
    }

    /// Not provided (module docs).
    fn jacobian(&mut self, _inputs: &InputValues) -> Result<Jacobian, String> {
        Err("HelicalGearbox does not provide directional derivatives \
             (providesDirectionalDerivative=\"false\"): difference the states numerically"
            .into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Model Exchange states of the table (the order of its derivative variables) are the
    /// engine's: [`STATES`], the 28 of [`crate::dynamics::bodies`] with the rotations in the
    /// Drive's relative coordinates; each pose state's derivative is its rate.
    #[test]
    fn the_table_states_are_the_engine_states_in_order() {
        assert_eq!(GEARBOX.state_names(), STATES);
        let rel = RelativeCoordinates::new(UnitKind::Drive, 0.03, 0.05);
        let drive: Vec<&str> =
            rel.states().iter().map(|&q| super::super::unit::variable_name(q)).collect();
        assert_eq!(&STATES[..8], &drive[..]);
        assert_eq!(&STATES[8..], &crate::mesh::pose::INPUT_NAMES[..]);
        for s in 0..10 {
            let der = GEARBOX.by_name(DER_NAMES[s]).unwrap();
            assert_eq!(der.derivative_of, Some(STATES[8 + s]));
            assert_eq!(der.depends.unwrap().inputs, &[STATES[18 + s]]);
        }
    }
}
