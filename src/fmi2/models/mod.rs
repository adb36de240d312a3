//! The models of the FMU family. Each contributes its variable table and its physics
//! ([`crate::fmi2::model::ModelInfo`], [`crate::fmi2::model::Engine`]); one shared library
//! serves them all, and `fmi2Instantiate` picks the model by the GUID it is given.
//!
//! A model's file holds its table and the meaning of its slots: which slot of the instance's
//! [`InputValues`] each input is (and whether its time derivative is used), which slot of
//! [`OutputValues`] each output is, and the map from those slots to its physics. The mesh
//! outputs every model has (the shared table [`MESH_OUTPUTS`], one entry per entry of the
//! core's `mesh::outputs::MESH_OUTPUT_FIELDS`) take the first slots and are written by one
//! loop over that table, `write_mesh_outputs`.

pub mod gearbox;
pub mod mesh;
pub mod unit;

use super::model::ModelInfo;
use super::variables::{Access, OutputValues, Variable, u32_to_i32};
use crate::mesh::MeshOutputs;
use crate::mesh::outputs::{FieldAccess, MESH_OUTPUT_FIELDS, OutputField, OutputKind};

#[cfg(doc)]
use super::variables::{InputValues, MESH_OUTPUTS};

/// Writes the mesh outputs `m` into their slots of `o`, those of the shared table
/// [`MESH_OUTPUTS`] (Real slots 0…, Integer 0…, Boolean 0…, in table order): one loop over
/// the core's table of the mesh outputs, whose order the FMI table follows.
pub(crate) fn write_mesh_outputs(m: &MeshOutputs, o: &mut OutputValues) {
    let (mut r, mut i, mut b) = (0, 0, 0);
    for f in &MESH_OUTPUT_FIELDS {
        match f.access {
            FieldAccess::Real { get, .. } => {
                o.reals[r] = get(m);
                r += 1;
            }
            FieldAccess::Integer { get } => {
                o.ints[i] = u32_to_i32(get(m));
                i += 1;
            }
            FieldAccess::Boolean { get } => {
                o.bools[b] = get(m);
                b += 1;
            }
        }
    }
}

/// [`ModelInfo::partial_output`] of a model whose engine's partial evaluation gives the mesh
/// outputs of the torques path (`OutputField::torques`: M_F, M_D, TE, the loaded contact length,
/// the friction torques and loss) and every output of its own beyond the mesh outputs' slots
/// (a unit's angles, speeds, accelerations, torques, states and state derivatives, which
/// follow from the torques path).
pub(crate) fn torques_path_output(v: &Variable) -> bool {
    let (kind, slot) = match v.access {
        Access::RealOutput(s) => (OutputKind::Real, s),
        Access::IntOutput(s) => (OutputKind::Integer, s),
        Access::BoolOutput(s) => (OutputKind::Boolean, s),
        _ => return false,
    };
    TORQUES_BY_SLOT[kind as usize].get(slot).is_none_or(|&t| t != 0)
}

/// [`TORQUES_BY_SLOT`]: no mesh output at this slot.
const NOT_MESH: u8 = 2;

/// Per output kind (Real, Integer, Boolean, as `OutputKind` numbers them) and slot: 1 when
/// the mesh output there is on the torques path, 0 when not, [`NOT_MESH`] beyond the mesh
/// outputs of that kind.
const TORQUES_BY_SLOT: [[u8; MESH_OUTPUT_FIELDS.len()]; 3] = {
    let mut t = [[NOT_MESH; MESH_OUTPUT_FIELDS.len()]; 3];
    let mut i = 0;
    while i < MESH_OUTPUT_FIELDS.len() {
        let f = &MESH_OUTPUT_FIELDS[i];
        t[f.kind() as usize][OutputField::slot(i)] = f.torques as u8;
        i += 1;
    }
    t
};

/// [`ModelInfo::partial_output`] of a model whose engine always evaluates every output.
pub(crate) fn no_partial_output(_: &Variable) -> bool {
    false
}

/// Every model of the family, in the order of the documentation.
pub static MODELS: &[&ModelInfo] =
    &[&mesh::INFO, &unit::PAIR, &unit::STAGE, &unit::DRIVE, &gearbox::GEARBOX];

/// The model whose GUID is `guid`, if any.
pub fn by_guid(guid: &str) -> Option<&'static ModelInfo> {
    MODELS.iter().copied().find(|m| m.guid() == guid)
}

/// The model named `identifier`, if any.
pub fn by_identifier(identifier: &str) -> Option<&'static ModelInfo> {
    MODELS.iter().copied().find(|m| m.identifier == identifier)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::model::MAX_STATES;
    use crate::fmi2::variables::{
        Access, Causality, MAX_BOOL_OUTPUTS, MAX_INPUTS, MAX_INT_OUTPUTS, MAX_REAL_OUTPUTS,
        MESH_OUTPUTS,
    };

    /// Every model's states fit the instance's state buffers, and its input and output slots
    /// fit the instance's value arrays, one variable per slot; inputs and outputs (locals
    /// included) and nothing else have slots; every state derivative is a Real slot.
    #[test]
    fn every_model_fits_the_instance_state_buffers_and_value_slots() {
        for m in MODELS {
            let id = m.identifier;
            assert!(m.derivatives().count() <= MAX_STATES, "{id}");
            let mut used = [[false; MAX_REAL_OUTPUTS]; 4];
            for v in m.variables {
                let (kind, slot, max) = match v.access {
                    Access::Input { slot, .. } => (0, slot, MAX_INPUTS),
                    Access::RealOutput(slot) => (1, slot, MAX_REAL_OUTPUTS),
                    Access::IntOutput(slot) => (2, slot, MAX_INT_OUTPUTS),
                    Access::BoolOutput(slot) => (3, slot, MAX_BOOL_OUTPUTS),
                    _ => {
                        assert!(
                            !matches!(
                                v.causality,
                                Causality::Input | Causality::Output | Causality::Local
                            ),
                            "{id}: {}",
                            v.name
                        );
                        continue;
                    }
                };
                assert_eq!(kind == 0, v.causality == Causality::Input, "{id}: {}", v.name);
                assert!(slot < max, "{id}: `{}` slot {slot} >= {max}", v.name);
                assert!(!used[kind][slot], "{id}: `{}` shares slot {slot}", v.name);
                used[kind][slot] = true;
            }
            for v in m.derivatives() {
                assert!(matches!(v.access, Access::RealOutput(_)), "{id}: {}", v.name);
            }
        }
    }

    /// The shared mesh outputs take the first slots in table order, follow the core's table
    /// entry by entry (name, unit, description), and [`write_mesh_outputs`] writes exactly
    /// their slots, each with its field's value.
    #[test]
    fn mesh_outputs_fill_exactly_the_first_slots_of_their_table() {
        let (mut reals, mut ints, mut bools) = (0, 0, 0);
        assert_eq!(MESH_OUTPUTS.len(), MESH_OUTPUT_FIELDS.len());
        for (v, f) in MESH_OUTPUTS.iter().zip(&MESH_OUTPUT_FIELDS) {
            assert_eq!((v.name, v.description), (f.name, f.description));
            assert_eq!(v.unit.unwrap_or(""), f.unit, "{}", v.name);
            let (slot, next) = match v.access {
                Access::RealOutput(s) => (s, &mut reals),
                Access::IntOutput(s) => (s, &mut ints),
                Access::BoolOutput(s) => (s, &mut bools),
                _ => panic!("{} is not an output", v.name),
            };
            assert_eq!(slot, *next, "{}", v.name);
            *next += 1;
        }
        // Reals and integers are told by their sentinels (NaN, -1), flags by being set.
        let mesh = MeshOutputs {
            tip_contact: true,
            separated: true,
            back_contact: true,
            ..MeshOutputs::default()
        };
        let mut o = OutputValues {
            reals: [f64::NAN; MAX_REAL_OUTPUTS],
            ints: [-1; MAX_INT_OUTPUTS],
            bools: [false; MAX_BOOL_OUTPUTS],
        };
        write_mesh_outputs(&mesh, &mut o);
        assert!(o.reals.iter().enumerate().all(|(i, x)| x.is_nan() != (i < reals)), "{o:?}");
        assert!(o.ints.iter().enumerate().all(|(i, &x)| (x == -1) != (i < ints)), "{o:?}");
        assert!(o.bools.iter().enumerate().all(|(i, &x)| x == (i < bools)), "{o:?}");
        // Each Real slot holds its own field: plant a distinct value in each field in turn.
        for (k, (v, f)) in MESH_OUTPUTS.iter().zip(&MESH_OUTPUT_FIELDS).enumerate() {
            let (Access::RealOutput(slot), FieldAccess::Real { get_mut, .. }) =
                (v.access, f.access)
            else {
                continue;
            };
            // All zero (the efficiency's default is 1), then one field planted.
            let mut mesh = MeshOutputs { eta_mesh: 0.0, ..MeshOutputs::default() };
            *get_mut(&mut mesh) = 1.0 + k as f64;
            write_mesh_outputs(&mesh, &mut o);
            assert_eq!(o.reals[slot], 1.0 + k as f64, "{}", v.name);
            assert_eq!(o.reals[..reals].iter().filter(|x| **x != 0.0).count(), 1, "{}", v.name);
        }
    }
}
