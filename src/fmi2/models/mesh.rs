//! `HelicalGearMesh`: the mesh element without state. Inputs are the hub angles and speeds
//! (φp, φg, φ̇p, φ̇g) and the poses and pose rates of both gear bodies
//! ([`crate::mesh::pose`]), outputs the mesh torques of Eqs. 13–14 with diagnostics, every
//! output a direct function of the inputs (direct feedthrough); `fmi2DoStep` only advances the
//! time.
//!
//! Slots: the inputs φp, φg, φ̇p, φ̇g are input slots 0–3 and the twenty pose inputs
//! ([`crate::mesh::pose::INPUT_NAMES`], value references 500–519) slots 4–23 (a
//! [`MeshState`]; their time derivatives are accepted and not used), the outputs the shared
//! mesh outputs
//! (`super::write_mesh_outputs`). A serialised FMU state carries the cached outputs (the
//! element evaluates lazily) and the load solver's warm start.

use std::sync::OnceLock;

use super::write_mesh_outputs;
use crate::fmi2::model::{Engine, Experiment, Jacobian, ModelInfo, StepFailure};
use crate::fmi2::variables::{ANGLE, DEG, NM, RAD, TORQUE, group};
use crate::fmi2::variables::{
    Access, CALCULATED, Causality, Derived, GEAR_PARAMS, InputValues, MESH_OPTIONS, MESH_OUTPUTS,
    NONE, OutputValues, Settings, Variability, Variable, concat, total_len,
};
use crate::mesh::table::TABLE_DESIGN_TORQUE_NM;
use crate::mesh::{Mesh, MeshError, MeshState, MeshTorques, WarmStart, pose};

use Variable as V;

/// Input slots of φp, φg, φ̇p, φ̇g.
const PHI_P: usize = 0;
const PHI_G: usize = 1;
const W_P: usize = 2;
const W_G: usize = 3;

/// Input slot of the first pose input.
const POSE: usize = 4;

/// The mesh state the inputs hold.
fn mesh_state(i: &InputValues) -> MeshState {
    let v = &i.values;
    let mut s = MeshState {
        phi_p: v[PHI_P],
        phi_g: v[PHI_G],
        w_p: v[W_P],
        w_g: v[W_G],
        ..Default::default()
    };
    let pose: &[f64; 20] = v[POSE..POSE + 20].try_into().expect("MAX_INPUTS holds the pose");
    pose::set_inputs(&mut s, pose);
    s
}

/// Meaning of each pose input, in the order of [`pose::INPUT_NAMES`].
const POSE_MEANING: [&str; 20] = [
    "Pinion body: translation along x (towards the gear axis) from its nominal bearing axis at its centre at mid-face, m",
    "Pinion body: translation along y = z x x, m",
    "Pinion body: translation along z (the pinion axis, towards zeta = b), m",
    "Pinion body: tilt about x through its centre, rad (right-handed)",
    "Pinion body: tilt about y through its centre, rad (right-handed)",
    "Gear body: translation along x from its nominal bearing axis at its centre at mid-face, m (positive opens the centre distance)",
    "Gear body: translation along y, m",
    "Gear body: translation along z, m",
    "Gear body: tilt about x through its centre, rad",
    "Gear body: tilt about y through its centre, rad",
    "Rate of u_p_x, m/s",
    "Rate of u_p_y, m/s",
    "Rate of u_p_z, m/s",
    "Rate of th_p_x, rad/s",
    "Rate of th_p_y, rad/s",
    "Rate of u_g_x, m/s",
    "Rate of u_g_y, m/s",
    "Rate of u_g_z, m/s",
    "Rate of th_g_x, rad/s",
    "Rate of th_g_y, rad/s",
];

/// The pose input `k` (value reference 500 + k, slot 4 + k), start 0 (the rigid-bearing
/// model).
const fn pose_input(k: usize) -> Variable {
    let (unit, quantity) = match (k / 10, k % 5 < 3) {
        (0, true) => (Some("m"), Some("Length")),
        (0, false) => (RAD, ANGLE),
        (_, true) => (Some("m/s"), Some("Velocity")),
        (_, false) => (Some("rad/s"), Some("AngularVelocity")),
    };
    Variable {
        name: pose::INPUT_NAMES[k],
        vr: 500 + k as u32,
        causality: Causality::Input,
        variability: Variability::Continuous,
        description: POSE_MEANING[k],
        unit,
        quantity,
        access: Access::Input { slot: POSE + k, derivative: false },
        ..NONE
    }
}

/// The twenty pose inputs ([`crate::mesh::pose`]).
const POSE_INPUTS: [Variable; 20] = {
    let mut v = [NONE; 20];
    let mut k = 0;
    while k < 20 {
        v[k] = pose_input(k);
        k += 1;
    }
    v
};

/// The inputs of the mesh element (value references 0–3).
const INPUTS: [Variable; 4] = [
    Variable {
        name: "phi_p",
        vr: 0,
        causality: Causality::Input,
        variability: Variability::Continuous,
        description: "Pinion hub angle, rad; positive counter-clockwise seen from the zeta = 0 \
                      face (the pinion drives in the positive sense)",
        unit: RAD,
        display_unit: DEG,
        quantity: ANGLE,
        access: Access::Input { slot: PHI_P, derivative: false },
        ..NONE
    },
    Variable {
        name: "phi_g",
        vr: 1,
        causality: Causality::Input,
        variability: Variability::Continuous,
        description: "Gear hub angle, rad, same sense as phi_p (negative and decreasing in \
                      normal running); TE = phi_p*g_p + phi_g*g_g",
        unit: RAD,
        display_unit: DEG,
        quantity: ANGLE,
        access: Access::Input { slot: PHI_G, derivative: false },
        ..NONE
    },
    Variable {
        name: "w_p",
        vr: 2,
        causality: Causality::Input,
        variability: Variability::Continuous,
        description: "Pinion speed d(phi_p)/dt, rad/s",
        unit: Some("rad/s"),
        display_unit: Some("rpm"),
        quantity: Some("AngularVelocity"),
        access: Access::Input { slot: W_P, derivative: false },
        ..NONE
    },
    Variable {
        name: "w_g",
        vr: 3,
        causality: Causality::Input,
        variability: Variability::Continuous,
        description: "Gear speed d(phi_g)/dt, rad/s (negative in normal running)",
        unit: Some("rad/s"),
        display_unit: Some("rpm"),
        quantity: Some("AngularVelocity"),
        access: Access::Input { slot: W_G, derivative: false },
        ..NONE
    },
];

/// The table's design torque (value reference 207), `MeshOptions::table_design_torque_nm`:
/// a parameter of the mesh element only (the stateful models size their table for their
/// drive line's torque `drive.torque_nm`).
const TABLE_DESIGN_TORQUE: [Variable; 1] = [Variable {
    name: "table_design_torque_nm",
    vr: 207,
    description: "Table fidelity: design torque on the pinion, N.m, whose static TE sizes the \
                  table's TE range (driving flanks up to 4 times the largest static TE at this \
                  torque; outside the table: full); unused at full fidelity",
    unit: NM,
    quantity: TORQUE,
    min: Some(TABLE_DESIGN_TORQUE_NM.min),
    max: Some(TABLE_DESIGN_TORQUE_NM.max),
    group: group::OPTIONS,
    access: Access::RealParam(
        |s| s.options.table_design_torque_nm,
        |s, v| s.options.table_design_torque_nm = v,
    ),
    ..NONE
}];

const PARTS: &[&[Variable]] = &[
    &INPUTS,
    &POSE_INPUTS,
    &MESH_OUTPUTS,
    &CALCULATED,
    &GEAR_PARAMS,
    &MESH_OPTIONS,
    &TABLE_DESIGN_TORQUE,
];

/// Every variable of `HelicalGearMesh`, in `modelDescription.xml` order (the ScalarVariable
/// index is the position in this table plus one).
pub static VARIABLES: &[Variable] = &TABLE;

static TABLE: [V; total_len(PARTS)] = concat(PARTS);

/// Model identifier of the mesh element.
pub const MODEL_IDENTIFIER: &str = "HelicalGearMesh";

static GUID: OnceLock<String> = OnceLock::new();

/// The description of `HelicalGearMesh`.
pub static INFO: ModelInfo = ModelInfo {
    identifier: MODEL_IDENTIFIER,
    description: "Helical gear mesh after Andersson and Vedmar (J. Sound Vib. 260, 2003): mesh \
                  torques from hub angles and speeds, with contact outside the plane of action, \
                  FE tooth compliance and non-linear load distribution",
    doc_html: DOC,
    variables: VARIABLES,
    default_settings: Settings::default,
    default_inputs: InputValues::default,
    experiment: Experiment { start: 0.0, stop: 0.1, step: 1e-5 },
    stateful: false,
    event_indicators: 0,
    provides_directional_derivative: true,
    build,
    check_tunable,
    cached_outputs: true,
    partial_output: super::torques_path_output,
    guid_cell: &GUID,
};

const DOC: &str = "<p>Inputs are the hub angles and speeds of pinion and gear, and the small \
displacements of both gear bodies from their bearing axes with their rates (<code>u_p_x</code> \
&hellip; <code>om_g_y</code>, start 0: rigid bearings), so that a multibody master can wire the \
mesh to its own bodies; outputs are the mesh torques of Eqs. 13&ndash;14 and diagnostics. The element has no state: every output is a \
direct function of the inputs, so a master may set inputs and read outputs at every stage of \
its own integrator (the outputs are recomputed on the first read after an input changed). \
<code>fmi2DoStep</code> only advances the time. Causality: kinematics in, torque out; the \
inertias J_p, J_g belong to the master.</p>";

/// The variable with value reference `vr`, if any.
pub fn by_vr(vr: u32) -> Option<&'static Variable> {
    INFO.by_vr(vr)
}

/// The variable named `name`, if any.
pub fn by_name(name: &str) -> Option<&'static Variable> {
    INFO.by_name(name)
}

/// The GUID of `HelicalGearMesh` (see [`ModelInfo::guid`]).
pub fn guid() -> &'static str {
    INFO.guid()
}

/// Text of a model-building error; names the FMI parameter.
pub(crate) fn mesh_error_text(e: &MeshError) -> String {
    match e {
        MeshError::Param(p) if p.name == "d_mesh_n_s_per_m" => {
            format!("{p} (FMI parameter `d_mesh`)")
        }
        other => other.to_string(),
    }
}

/// Builds the mesh model for `s` and the calculated parameters.
pub(crate) fn build_mesh(s: &Settings) -> Result<(Mesh, Derived), String> {
    let model = Mesh::new(&s.pair, s.options).map_err(|e| mesh_error_text(&e))?;
    let geometry = model.geometry();
    let derived = Derived {
        base_radius_p: geometry.pinion.rb,
        base_radius_g: geometry.gear.rb,
        j_p: geometry.j_p,
        j_g: geometry.j_g,
    };
    Ok((model, derived))
}

/// The tunable parameters' check of every model over the mesh: the mesh damping `d_mesh`
/// against the pair's own range ([`crate::params::check_d_mesh`]).
pub(crate) fn check_tunable(s: &Settings) -> Result<(), String> {
    crate::params::check_d_mesh(s.pair.d_mesh_n_s_per_m).map_err(|e| e.to_string())
}

fn build(s: &Settings) -> Result<(Box<dyn Engine>, Derived), String> {
    let (model, derived) = build_mesh(s)?;
    Ok((Box::new(MeshEngine(model)), derived))
}

/// The mesh model as an [`Engine`] without dynamic state. Its load solver's warm start (the
/// loads of the previous evaluation, [`WarmStart`]) is carried in FMU states (copied with
/// `fmi2GetFMUstate`, serialised by `fmi2SerializeFMUstate`), so that a restored element
/// evaluates bit for bit as the original would have.
struct MeshEngine(Mesh);

impl Clone for MeshEngine {
    /// A copy sharing the model, with a fresh workspace and the same warm start.
    fn clone(&self) -> Self {
        let mut m = self.0.clone();
        m.full_mut().set_warm(self.0.full().warm());
        Self(m)
    }
}

/// The state for an error message, SI units; the pose inputs that are not zero.
fn state_text(s: &MeshState) -> String {
    let mut t = format!(
        "phi_p = {} rad, phi_g = {} rad, w_p = {} rad/s, w_g = {} rad/s",
        s.phi_p, s.phi_g, s.w_p, s.w_g
    );
    for (name, v) in pose::INPUT_NAMES.iter().zip(pose::inputs_of(s)) {
        if v != 0.0 {
            t.push_str(&format!(", {name} = {v}"));
        }
    }
    t
}

impl Engine for MeshEngine {
    fn clone_box(&self) -> Box<dyn Engine> {
        Box::new(self.clone())
    }

    /// Applies the mesh damping `d_mesh` (the one tunable parameter).
    fn tune(&mut self, s: &Settings) -> Result<(), String> {
        self.0.set_d_mesh(s.pair.d_mesh_n_s_per_m).map_err(|e| mesh_error_text(&e))
    }

    fn start(&mut self, _: &Settings, _: &mut InputValues, _: f64) -> Result<(), String> {
        Ok(())
    }

    fn outputs(&mut self, i: &InputValues, o: &mut OutputValues) -> Result<(), String> {
        let s = mesh_state(i);
        let mesh = self.0.evaluate(&s).map_err(|e| {
            format!("mesh evaluation at {}: {}", state_text(&s), mesh_error_text(&e))
        })?;
        write_mesh_outputs(&mesh, o);
        Ok(())
    }

    /// The torques path ([`MeshTorques::torques`]): at table fidelity the table's torques,
    /// TE, contact length and friction alone; at full fidelity every output.
    fn outputs_partial(&mut self, i: &InputValues, o: &mut OutputValues) -> Result<bool, String> {
        let s = mesh_state(i);
        let (mesh, complete) = self.0.torques(&s).map_err(|e| {
            format!("mesh evaluation at {}: {}", state_text(&s), mesh_error_text(&e))
        })?;
        write_mesh_outputs(&mesh, o);
        Ok(complete)
    }

    fn step(&mut self, _: &InputValues, _: f64, _: f64) -> Result<(), StepFailure> {
        Ok(())
    }

    /// The warm start ([`WarmStart::to_bytes`]); nothing for a cold start.
    fn save(&self) -> Vec<u8> {
        let w = self.0.full().warm();
        let mut b = Vec::new();
        if !w.is_empty() {
            w.to_bytes(&mut b);
        }
        b
    }

    /// The warm start of [`Self::save`], checked ([`WarmStart::from_bytes`]).
    fn load(&mut self, bytes: &[u8]) -> Result<(), String> {
        let w = WarmStart::from_bytes(bytes).map_err(|e| format!("serialised state: {e}"))?;
        self.0.full_mut().set_warm(&w);
        Ok(())
    }

    /// ∂(M_F_p, M_F_g, M_D_p, M_D_g, TE)/∂(phi_p, phi_g, w_p, w_g): the mesh stiffness and
    /// damping from [`MeshTorques::mesh_jacobian`] (table interpolant or load-solution
    /// sensitivity), TE = g_p·phi_p + g_g·phi_g exactly; and with respect to the twenty pose
    /// inputs where the mesh provides them (full fidelity without friction; TE does not depend
    /// on them).
    fn jacobian(&mut self, i: &InputValues) -> Result<Jacobian, String> {
        let s = mesh_state(i);
        let (_, j) = self
            .0
            .mesh_jacobian(&s)
            .map_err(|e| format!("mesh Jacobian at {}: {}", state_text(&s), mesh_error_text(&e)))?;
        let (gp, gg) = self.0.base_radii();
        let mut cols = vec!["phi_p", "phi_g", "w_p", "w_g"];
        if j.pose.is_some() {
            cols.extend(pose::INPUT_NAMES);
        }
        let mut values = Vec::with_capacity(5 * cols.len());
        for (i, row) in j.d.iter().enumerate() {
            values.extend_from_slice(row);
            if let Some(p) = &j.pose {
                for block in [p.d_pose_p, p.d_pose_g, p.d_rate_p, p.d_rate_g] {
                    values.extend_from_slice(&block[i]);
                }
            }
        }
        values.extend_from_slice(&[gp, gg, 0.0, 0.0]);
        values.resize(5 * cols.len(), 0.0);
        Ok(Jacobian { rows: vec!["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE"], cols, values })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_inputs_outputs_calculated_parameters_options() {
        // 24 gear-pair parameters: none of the drive line's seven (the element does not use
        // them); 9 mesh options (friction and the table's sample slices included) and the
        // table's design torque.
        assert_eq!(VARIABLES.len(), 4 + 20 + 30 + 4 + 24 + 9 + 1);
        assert_eq!(VARIABLES[0].name, "phi_p");
        assert!(VARIABLES[..24].iter().all(|v| v.causality == Causality::Input));
        assert_eq!(VARIABLES[4].name, "u_p_x");
        assert_eq!(VARIABLES[23].name, "om_g_y");
        assert!(matches!(VARIABLES[24].access, Access::RealOutput(_)));
        let _ = NONE;
    }

    /// The dependency lists of the outputs name the pose inputs as the library's table does:
    /// the elastic outputs the ten poses, the damping ones all twenty inputs.
    #[test]
    fn the_dependency_lists_follow_the_pose_input_names() {
        let deps = |name: &str| VARIABLES.iter().find(|v| v.name == name).unwrap().depends.unwrap();
        assert_eq!(&deps("M_F_p").inputs[2..], &pose::INPUT_NAMES[..10]);
        assert_eq!(&deps("M_D_p").inputs[4..], &pose::INPUT_NAMES[..]);
        assert_eq!(deps("TE").inputs, &["phi_p", "phi_g"]);
    }

    /// The cached outputs in a serialised state: the mesh outputs in table order (Real f64,
    /// Integer i32, flag bytes), read back bit for bit; a short, non-finite or bad flag is
    /// refused.
    #[test]
    fn cached_outputs_round_trip_bit_for_bit_and_refuse_short_or_bad_bytes() {
        use crate::fmi2::instance::{load_outputs, save_outputs};
        let count = |f: fn(&Access) -> bool| MESH_OUTPUTS.iter().filter(|v| f(&v.access)).count();
        let reals = count(|a| matches!(a, Access::RealOutput(_)));
        let ints = count(|a| matches!(a, Access::IntOutput(_)));
        let bools = count(|a| matches!(a, Access::BoolOutput(_)));
        let cached_len = 8 * reals + 4 * ints + bools;
        assert!(cached_len >= 8 * 8 + 4 + 3);
        let mut o = OutputValues::default();
        for (k, x) in o.reals[..reals].iter_mut().enumerate() {
            *x = [101.25, 160.5, -0.125, 1e-300, 1.5e-5, 3.2e3, 0.041, 1.1e9][k % 8]
                * (k + 1) as f64;
        }
        o.ints[..ints].fill(2);
        for (k, f) in o.bools[..bools].iter_mut().enumerate() {
            *f = k % 2 == 0;
        }
        let mut b = vec![7];
        save_outputs(&INFO, &o, &mut b);
        assert_eq!(b.len(), 1 + cached_len);
        b.push(9); // what follows is not read
        let (back, n) = load_outputs(&INFO, &b[1..]).unwrap();
        assert_eq!((back, n), (o, cached_len));
        let e = load_outputs(&INFO, &b[1..cached_len]).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let mut bad = b.clone();
        bad[1 + 8 * 4..1 + 8 * 5].copy_from_slice(&f64::NAN.to_le_bytes());
        let e = load_outputs(&INFO, &bad[1..]).unwrap_err();
        assert!(e.contains("`TE`"), "{e}");
        // The first flag byte: the outputs before it in table order, at their sizes.
        let flag_at: usize = MESH_OUTPUTS
            .iter()
            .map(|v| match v.access {
                Access::RealOutput(_) => 8,
                Access::IntOutput(_) => 4,
                _ => 1,
            })
            .take_while(|&size| size != 1)
            .sum();
        let mut bad = b;
        bad[1 + flag_at] = 2;
        assert!(load_outputs(&INFO, &bad[1..]).is_err());
    }
}
