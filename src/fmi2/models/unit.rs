//! The stateful models `HelicalGearPair`, `HelicalGearStage` and `HelicalGearDrive`: a
//! [`DriveUnit`] of the matching [`UnitKind`] behind the FMI layer (DESIGN §10).
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
//! DOPRI5, parameter `integrator`); inputs are passed to the unit only when they change, so
//! that the Stage's far ends keep turning at their rates between updates. A step the unit
//! cannot complete returns `fmi2Discard` with the unit's message (time and cause); the state
//! stays that of the step's start, so no output is ever NaN. The FMU state carries the unit's
//! snapshot (time, state, inputs, input time, step hint) as JSON with exact floats.

use std::sync::OnceLock;

use crate::dynamics::Drivetrain;
use crate::dynamics::unit::{DriveUnit, UnitInputs, UnitKind, UnitSnapshot, UnitStepping};
use crate::fmi2::model::{Engine, Experiment, ModelInfo, StepFailure};
use crate::fmi2::models::mesh::build_mesh;
use crate::fmi2::variables::{
    ANGLE, CALCULATED, Causality, DEG, Depends, Derived, GEAR_PARAMS, Inputs, Integrator,
    MESH_OPTIONS, MESH_OUTPUTS, NM, NONE, Outputs, RAD, START_OUTER, START_PAIR, Settings, TORQUE,
    UNIT_OPTIONS, Variability, Variable, concat, group, total_len, with_depends,
};
use crate::mesh::statics::EquilibriumSettings;
use crate::mesh::{Fidelity, MeshModel};

/// Mesh outputs of a stateful model: functions of the state only.
const STATE_ONLY: Depends = Depends { inputs: &[], linear_fixed: false, groups: group::ALL };
const UNIT_MESH_OUTPUTS: [Variable; 12] = with_depends(MESH_OUTPUTS, STATE_ONLY);

macro_rules! input {
    ($name:literal, $vr:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal, $field:ident) => {
        Variable {
            name: $name,
            vr: $vr,
            causality: Causality::Input,
            variability: Variability::Continuous,
            description: $desc,
            unit: $unit,
            display_unit: $disp,
            quantity: $q,
            access: crate::fmi2::variables::Access::Input(|s| s.$field, |s, v| s.$field = v),
            ..NONE
        }
    };
}

macro_rules! kin {
    ($name:literal, $vr:expr, $unit:expr, $disp:expr, $q:expr, $desc:literal, $deps:expr,
     $field:ident) => {
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
            access: crate::fmi2::variables::Access::RealOutput(|o| o.$field),
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
const HUBS: [Variable; 4] = [
    kin!("phi_p", 40, RAD, DEG, ANGLE, "Pinion hub angle, rad (state)", &[], phi_p),
    kin!("w_p", 41, RAD_S, RPM, W, "Pinion speed, rad/s (state)", &[], w_p),
    kin!(
        "phi_g",
        43,
        RAD,
        DEG,
        ANGLE,
        "Gear hub angle, rad (state; negative in normal running)",
        &[],
        phi_g
    ),
    kin!(
        "w_g",
        44,
        RAD_S,
        RPM,
        W,
        "Gear speed, rad/s (state; negative in normal running)",
        &[],
        w_g
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
        tau_p
    ),
    input!(
        "tau_g",
        5,
        NM,
        None,
        TORQUE,
        "Torque the gear shaft exerts on the gear hub, N.m: J_g*phi_g'' = tau_g - M_F_g - M_D_g \
         (steady running: tau_g = M*z_g/z_p)",
        tau_g
    ),
    kin!(
        "a_p",
        42,
        RAD_S2,
        None,
        ACC,
        "Pinion angular acceleration phi_p'', rad/s2",
        &["tau_p"],
        a_p
    ),
    kin!(
        "a_g",
        45,
        RAD_S2,
        None,
        ACC,
        "Gear angular acceleration phi_g'', rad/s2",
        &["tau_g"],
        a_g
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
        phi_1
    ),
    input!("w_1", 7, RAD_S, RPM, W, "Rate of the pinion shaft's far end, rad/s", w_1),
    input!(
        "phi_2",
        8,
        RAD,
        DEG,
        ANGLE,
        "Angle of the gear shaft's far end (J2 side), rad; held at the rate w_2 over a step",
        phi_2
    ),
    input!("w_2", 9, RAD_S, RPM, W, "Rate of the gear shaft's far end, rad/s", w_2),
    kin!(
        "tau_1",
        46,
        NM,
        None,
        TORQUE,
        "Torque the pinion shaft exerts on J1, N.m: J1*phi_1'' = M + tau_1 (steady running: \
         tau_1 = -M)",
        &["phi_1", "w_1"],
        tau_1
    ),
    kin!(
        "tau_2",
        47,
        NM,
        None,
        TORQUE,
        "Torque the gear shaft exerts on J2, N.m: J2*phi_2'' = M*z_g/z_p + tau_2",
        &["phi_2", "w_2"],
        tau_2
    ),
    kin!(
        "a_p",
        42,
        RAD_S2,
        None,
        ACC,
        "Pinion angular acceleration phi_p'', rad/s2",
        &["phi_1", "w_1"],
        a_p
    ),
    kin!(
        "a_g",
        45,
        RAD_S2,
        None,
        ACC,
        "Gear angular acceleration phi_g'', rad/s2",
        &["phi_2", "w_2"],
        a_g
    ),
];

const DRIVE_IO: [Variable; 7] = [
    input!(
        "M",
        60,
        NM,
        None,
        TORQUE,
        "Driving torque M on J1, N.m (the load on J2 is M*z_g/z_p, Eq. 4)",
        m
    ),
    kin!("phi_1", 48, RAD, DEG, ANGLE, "Angle of J1, rad (state)", &[], phi_1),
    kin!("phi_2", 50, RAD, DEG, ANGLE, "Angle of J2, rad (state)", &[], phi_2),
    kin!("w_1", 49, RAD_S, RPM, W, "Speed of J1, rad/s (state)", &[], w_1),
    kin!("w_2", 51, RAD_S, RPM, W, "Speed of J2, rad/s (state)", &[], w_2),
    kin!("a_p", 42, RAD_S2, None, ACC, "Pinion angular acceleration phi_p'', rad/s2", &[], a_p),
    kin!("a_g", 45, RAD_S2, None, ACC, "Gear angular acceleration phi_g'', rad/s2", &[], a_g),
];

const PAIR_PARTS: &[&[Variable]] = &[
    &PAIR_IO,
    &HUBS,
    &UNIT_MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &MESH_OPTIONS,
    &UNIT_OPTIONS,
    &START_PAIR,
];
const STAGE_PARTS: &[&[Variable]] = &[
    &STAGE_IO,
    &HUBS,
    &UNIT_MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &MESH_OPTIONS,
    &UNIT_OPTIONS,
    &START_PAIR,
];
const DRIVE_PARTS: &[&[Variable]] = &[
    &DRIVE_IO,
    &HUBS,
    &UNIT_MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &MESH_OPTIONS,
    &UNIT_OPTIONS,
    &START_PAIR,
    &START_OUTER,
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

fn pair_inputs() -> Inputs {
    let p = Settings::default().pair;
    let m = p.drive.torque_nm;
    Inputs { tau_p: m, tau_g: m * f64::from(p.z_g) / f64::from(p.z_p), ..Inputs::default() }
}

fn stage_inputs() -> Inputs {
    let s = Settings::default();
    let w = s.unit.w_p_start;
    Inputs { w_1: w, w_2: -w * f64::from(s.pair.z_p) / f64::from(s.pair.z_g), ..Inputs::default() }
}

fn drive_inputs() -> Inputs {
    Inputs { m: Settings::default().pair.drive.torque_nm, ..Inputs::default() }
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
    build: |s| build_unit(UnitKind::Pair, s),
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
    build: |s| build_unit(UnitKind::Stage, s),
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
    build: |s| build_unit(UnitKind::Drive, s),
    guid_cell: &DRIVE_GUID,
};

fn build_unit(kind: UnitKind, s: &Settings) -> Result<(Box<dyn Engine>, Derived), String> {
    let u = &s.unit;
    let stepping = match u.integrator {
        Integrator::Rk4 => {
            if u.rk4_steps_per_mesh_period < 4 {
                return Err(format!(
                    "invalid parameter `rk4_steps_per_mesh_period` = {}: allowed >= 4",
                    u.rk4_steps_per_mesh_period
                ));
            }
            UnitStepping::Rk4 { steps_per_mesh_period: u.rk4_steps_per_mesh_period }
        }
        Integrator::Dopri5 => {
            for (name, x) in [("rtol", u.rtol), ("atol", u.atol)] {
                if !(x.is_finite() && x > 0.0) {
                    return Err(format!(
                        "invalid parameter `{name}` = {x}: allowed finite and > 0"
                    ));
                }
            }
            UnitStepping::Dopri5 { rtol: u.rtol, atol: u.atol }
        }
    };
    if !u.w_p_start.is_finite() {
        return Err(format!("invalid parameter `w_p_start` = {}: allowed finite", u.w_p_start));
    }
    let (mesh, derived) = build_mesh(s)?;
    let drive = Drivetrain::from_pair(&s.pair).map_err(|e| e.to_string())?;
    let unit = DriveUnit::new(kind, mesh, drive, stepping)
        .map_err(|e| format!("{} unit: {e}", kind_name(kind)))?;
    Ok((Box::new(UnitEngine { unit }), derived))
}

fn kind_name(kind: UnitKind) -> &'static str {
    match kind {
        UnitKind::Pair => "pair",
        UnitKind::Stage => "stage",
        UnitKind::Drive => "drive",
    }
}

fn unit_inputs(i: &Inputs) -> UnitInputs {
    UnitInputs {
        tau_p: i.tau_p,
        tau_g: i.tau_g,
        phi_1: i.phi_1,
        w_1: i.w_1,
        phi_2: i.phi_2,
        w_2: i.w_2,
        torque: i.m,
    }
}

/// A [`DriveUnit`] over the mesh model as an [`Engine`].
#[derive(Clone)]
struct UnitEngine {
    unit: DriveUnit<MeshModel>,
}

impl UnitEngine {
    /// Passes the inputs to the unit when they differ from the ones it holds (so the unit's
    /// input time, from which the Stage's far ends advance, is that of the last change).
    fn sync(&mut self, i: &Inputs) -> Result<(), String> {
        let u = unit_inputs(i);
        if *self.unit.inputs() != u {
            self.unit.set_inputs(u).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

impl Engine for UnitEngine {
    fn clone_box(&self) -> Box<dyn Engine> {
        Box::new(self.clone())
    }

    fn set_d_mesh(&mut self, d_mesh: f64) -> Result<(), String> {
        self.unit.mesh_mut().set_d_mesh(d_mesh).map_err(|e| super::mesh::mesh_error_text(&e))
    }

    fn start(&mut self, s: &Settings, inputs: &mut Inputs, t0: f64) -> Result<(), String> {
        let u = &s.unit;
        if u.start_from_equilibrium {
            self.unit.start_static(t0, u.w_p_start, &EquilibriumSettings::default()).map_err(
                |e| format!("static-equilibrium start at w_p_start = {}: {e}", u.w_p_start),
            )?;
            let ui = *self.unit.inputs();
            match self.unit.kind() {
                UnitKind::Pair => (inputs.tau_p, inputs.tau_g) = (ui.tau_p, ui.tau_g),
                UnitKind::Stage => {
                    (inputs.phi_1, inputs.w_1, inputs.phi_2, inputs.w_2) =
                        (ui.phi_1, ui.w_1, ui.phi_2, ui.w_2)
                }
                UnitKind::Drive => inputs.m = ui.torque,
            }
        } else {
            let y = &u.start;
            let state: Vec<f64> = match self.unit.kind() {
                UnitKind::Drive => y.to_vec(),
                _ => vec![y[1], y[2], y[5], y[6]],
            };
            self.unit.set_time(t0).map_err(|e| e.to_string())?;
            self.unit.set_state(&state).map_err(|e| format!("explicit start state: {e}"))?;
            self.unit.set_inputs(unit_inputs(inputs)).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn outputs(&mut self, inputs: &Inputs) -> Result<Outputs, String> {
        self.sync(inputs)?;
        let o = self.unit.outputs().map_err(|e| format!("outputs: {e}"))?;
        Ok(Outputs {
            mesh: o.mesh,
            phi_1: o.phi_1,
            phi_p: o.phi_p,
            phi_g: o.phi_g,
            phi_2: o.phi_2,
            w_1: o.w_1,
            w_p: o.w_p,
            w_g: o.w_g,
            w_2: o.w_2,
            a_p: o.a_p,
            a_g: o.a_g,
            tau_1: o.tau_1,
            tau_2: o.tau_2,
        })
    }

    fn step(&mut self, inputs: &Inputs, t: f64, h: f64) -> Result<(), StepFailure> {
        self.sync(inputs).map_err(StepFailure::Error)?;
        self.unit.advance(h).map_err(|e| {
            StepFailure::Discard(format!(
                "the step from t = {t} s by h = {h} s cannot be completed (state kept at t = \
                 {t} s): {e}"
            ))
        })
    }

    fn save(&self) -> Vec<u8> {
        serde_json::to_vec(&self.unit.snapshot()).expect("a unit snapshot serialises")
    }

    fn load(&mut self, bytes: &[u8]) -> Result<(), String> {
        let s: UnitSnapshot = serde_json::from_slice(bytes)
            .map_err(|e| format!("serialised state: unit snapshot: {e}"))?;
        self.unit.restore(&s).map_err(|e| format!("serialised state: unit snapshot: {e}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_and_names_are_unique_per_model() {
        for m in [&PAIR, &STAGE, &DRIVE] {
            for (i, a) in m.variables.iter().enumerate() {
                for b in &m.variables[i + 1..] {
                    assert_ne!(a.vr, b.vr, "{}: {} and {}", m.identifier, a.name, b.name);
                    assert_ne!(a.name, b.name, "{}", m.identifier);
                }
            }
        }
    }
}
