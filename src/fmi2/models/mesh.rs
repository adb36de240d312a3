//! `HelicalGearMesh`: the mesh element without state. Inputs are the hub angles and speeds
//! (φp, φg, φ̇p, φ̇g), outputs the mesh torques of Eqs. 13–14 with diagnostics, every output
//! a direct function of the inputs (direct feedthrough); `fmi2DoStep` only advances the time.

use std::sync::OnceLock;

use crate::fmi2::instance::ensure_finite;
use crate::fmi2::model::{Engine, Experiment, Jacobian, ModelInfo, OutputsCodec, StepFailure};
use crate::fmi2::variables::{ANGLE, DEG, NM, RAD, TORQUE, group};
use crate::fmi2::variables::{
    Access, CALCULATED, Causality, Derived, GEAR_PARAMS, Inputs, MESH_OPTIONS, MESH_OUTPUTS, NONE,
    Outputs, Settings, Variability, Variable, concat, total_len,
};
use crate::mesh::table::TABLE_DESIGN_TORQUE_NM;
use crate::mesh::{Mesh, MeshError, MeshOutputs, MeshState, MeshTorques, WarmStart};

use Variable as V;

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
        access: Access::Input(|s| s.phi_p, |s, v| s.phi_p = v),
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
        access: Access::Input(|s| s.phi_g, |s, v| s.phi_g = v),
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
        access: Access::Input(|s| s.w_p, |s, v| s.w_p = v),
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
        access: Access::Input(|s| s.w_g, |s, v| s.w_g = v),
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

const PARTS: &[&[Variable]] =
    &[&INPUTS, &MESH_OUTPUTS, &CALCULATED, &GEAR_PARAMS, &MESH_OPTIONS, &TABLE_DESIGN_TORQUE];

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
    default_inputs: Inputs::default,
    experiment: Experiment { start: 0.0, stop: 0.1, step: 1e-5 },
    stateful: false,
    event_indicators: 0,
    build,
    check_tunable,
    cached_outputs: Some(CACHED_OUTPUTS),
    guid_cell: &GUID,
};

const DOC: &str = "<p>Inputs are the hub angles and speeds of pinion and gear; outputs are the \
mesh torques of Eqs. 13&ndash;14 and diagnostics. The element has no state: every output is a \
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

/// The element's cached outputs in a serialised FMU state (it evaluates lazily, so a state
/// taken after a read carries the evaluation): the eight Real mesh outputs (M_F_p, M_F_g,
/// M_D_p, M_D_g, TE, F_n, contact_length, p_max) as f64, `n_pairs` as u32 and the flags
/// `tip_contact`, `separated`, `back_contact` as one byte each, then the root stresses
/// (`root_stress_p`, `root_stress_g`) as f64, little endian (87 bytes).
const CACHED_OUTPUTS: OutputsCodec = OutputsCodec { save: save_outputs, load: load_outputs };

/// Length of [`CACHED_OUTPUTS`]' bytes.
const CACHED_LEN: usize = 8 * 8 + 4 + 3 + 2 * 8;

fn save_outputs(o: &Outputs, b: &mut Vec<u8>) {
    let MeshOutputs {
        m_f_p,
        m_f_g,
        m_d_p,
        m_d_g,
        te,
        f_n,
        contact_length,
        p_max,
        n_pairs,
        tip_contact,
        separated,
        back_contact,
        root_stress_p,
        root_stress_g,
    } = o.mesh;
    for x in [m_f_p, m_f_g, m_d_p, m_d_g, te, f_n, contact_length, p_max] {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b.extend_from_slice(&n_pairs.to_le_bytes());
    b.extend_from_slice(&[u8::from(tip_contact), u8::from(separated), u8::from(back_contact)]);
    for x in [root_stress_p, root_stress_g] {
        b.extend_from_slice(&x.to_le_bytes());
    }
}

fn load_outputs(bytes: &[u8]) -> Result<(Outputs, usize), String> {
    let b = bytes.get(..CACHED_LEN).ok_or_else(|| {
        format!(
            "serialised state truncated in the cached outputs ({} of {CACHED_LEN} bytes)",
            bytes.len()
        )
    })?;
    let x: [f64; 8] =
        std::array::from_fn(|i| f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().expect("8")));
    const NAMES: [&str; 8] =
        ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "F_n", "contact_length", "p_max"];
    ensure_finite("serialised state: cached output", &x, |i| NAMES[i].to_string())?;
    let stress: [f64; 2] = std::array::from_fn(|i| {
        f64::from_le_bytes(b[71 + 8 * i..79 + 8 * i].try_into().expect("8"))
    });
    ensure_finite("serialised state: cached output", &stress, |i| {
        ["root_stress_p", "root_stress_g"][i].to_string()
    })?;
    let flag = |i: usize| match b[68 + i] {
        0 => Ok(false),
        1 => Ok(true),
        v => Err(format!("serialised state: cached output flag byte {v} (allowed 0 or 1)")),
    };
    let mesh = MeshOutputs {
        m_f_p: x[0],
        m_f_g: x[1],
        m_d_p: x[2],
        m_d_g: x[3],
        te: x[4],
        f_n: x[5],
        contact_length: x[6],
        p_max: x[7],
        n_pairs: u32::from_le_bytes(b[64..68].try_into().expect("4")),
        tip_contact: flag(0)?,
        separated: flag(1)?,
        back_contact: flag(2)?,
        root_stress_p: stress[0],
        root_stress_g: stress[1],
    };
    Ok((Outputs { mesh, ..Outputs::default() }, CACHED_LEN))
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

/// The state for an error message, SI units.
fn state_text(s: &MeshState) -> String {
    format!(
        "phi_p = {} rad, phi_g = {} rad, w_p = {} rad/s, w_g = {} rad/s",
        s.phi_p, s.phi_g, s.w_p, s.w_g
    )
}

impl Engine for MeshEngine {
    fn clone_box(&self) -> Box<dyn Engine> {
        Box::new(self.clone())
    }

    /// Applies the mesh damping `d_mesh` (the one tunable parameter).
    fn tune(&mut self, s: &Settings) -> Result<(), String> {
        self.0.set_d_mesh(s.pair.d_mesh_n_s_per_m).map_err(|e| mesh_error_text(&e))
    }

    fn start(&mut self, _: &Settings, _: &mut Inputs, _: f64) -> Result<(), String> {
        Ok(())
    }

    fn outputs(&mut self, i: &Inputs) -> Result<Outputs, String> {
        let s = MeshState { phi_p: i.phi_p, phi_g: i.phi_g, w_p: i.w_p, w_g: i.w_g };
        let mesh = self.0.evaluate(&s).map_err(|e| {
            format!("mesh evaluation at {}: {}", state_text(&s), mesh_error_text(&e))
        })?;
        Ok(Outputs { mesh, ..Outputs::default() })
    }

    fn step(&mut self, _: &Inputs, _: f64, _: f64) -> Result<(), StepFailure> {
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
    /// sensitivity), TE = g_p·phi_p + g_g·phi_g exactly.
    fn jacobian(&mut self, i: &Inputs) -> Result<Jacobian, String> {
        let s = MeshState { phi_p: i.phi_p, phi_g: i.phi_g, w_p: i.w_p, w_g: i.w_g };
        let (_, j) = self
            .0
            .mesh_jacobian(&s)
            .map_err(|e| format!("mesh Jacobian at {}: {}", state_text(&s), mesh_error_text(&e)))?;
        let (gp, gg) = self.0.base_radii();
        let mut values = Vec::with_capacity(20);
        for row in &j.d {
            values.extend_from_slice(row);
        }
        values.extend_from_slice(&[gp, gg, 0.0, 0.0]);
        Ok(Jacobian {
            rows: vec!["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE"],
            cols: vec!["phi_p", "phi_g", "w_p", "w_g"],
            values,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_inputs_outputs_calculated_parameters_options() {
        // 24 gear-pair parameters: none of the drive line's seven (the element does not use
        // them); 7 mesh options and the table's design torque.
        assert_eq!(VARIABLES.len(), 4 + 14 + 4 + 24 + 7 + 1);
        assert_eq!(VARIABLES[0].name, "phi_p");
        assert!(VARIABLES[..4].iter().all(|v| v.causality == Causality::Input));
        assert!(matches!(VARIABLES[4].access, Access::RealOutput(_)));
        let _ = NONE;
    }

    #[test]
    fn cached_outputs_round_trip_bit_for_bit_and_refuse_short_or_bad_bytes() {
        let mesh = MeshOutputs {
            m_f_p: 101.25,
            m_f_g: 160.5,
            m_d_p: -0.125,
            m_d_g: 1e-300,
            te: 1.5e-5,
            f_n: 3.2e3,
            contact_length: 0.041,
            p_max: 1.1e9,
            n_pairs: 2,
            tip_contact: true,
            separated: false,
            back_contact: true,
            root_stress_p: 2.5e8,
            root_stress_g: 1.75e8,
        };
        let o = Outputs { mesh, ..Outputs::default() };
        let mut b = vec![7];
        (CACHED_OUTPUTS.save)(&o, &mut b);
        assert_eq!(b.len(), 1 + CACHED_LEN);
        b.push(9); // what follows is not read
        let (back, n) = (CACHED_OUTPUTS.load)(&b[1..]).unwrap();
        assert_eq!((back, n), (o, CACHED_LEN));
        let e = (CACHED_OUTPUTS.load)(&b[1..CACHED_LEN]).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let mut bad = b.clone();
        bad[1 + 8 * 4..1 + 8 * 5].copy_from_slice(&f64::NAN.to_le_bytes());
        let e = (CACHED_OUTPUTS.load)(&bad[1..]).unwrap_err();
        assert!(e.contains("`TE`"), "{e}");
        let mut bad = b;
        bad[1 + 68] = 2;
        assert!((CACHED_OUTPUTS.load)(&bad[1..]).is_err());
    }
}
