//! The models of the FMU family. Each contributes its variable table and its physics
//! ([`crate::fmi2::model::ModelInfo`], [`crate::fmi2::model::Engine`]); one shared library
//! serves them all, and `fmi2Instantiate` picks the model by the GUID it is given.
//!
//! A model's file holds its table and the meaning of its slots: which slot of the instance's
//! [`InputValues`] each input is (and whether its time derivative is used), which slot of
//! [`OutputValues`] each output is, and the map from those slots to its physics. The mesh
//! outputs every model has (the shared table [`MESH_OUTPUTS`]) take the first slots and are
//! written by one function, `write_mesh_outputs`.

pub mod mesh;
pub mod unit;

use super::model::ModelInfo;
use super::variables::{OutputValues, u32_to_i32};
use crate::mesh::MeshOutputs;

#[cfg(doc)]
use super::variables::{InputValues, MESH_OUTPUTS};

/// Writes the mesh outputs `m` into their slots of `o`, those of the shared table
/// [`MESH_OUTPUTS`] (Real slots 0…, Integer 0…, Boolean 0…, in table order): one line per
/// output, the one place where a mesh output meets its slot.
pub(crate) fn write_mesh_outputs(m: &MeshOutputs, o: &mut OutputValues) {
    o.reals[0] = m.m_f_p; // M_F_p, N·m
    o.reals[1] = m.m_f_g; // M_F_g, N·m
    o.reals[2] = m.m_d_p; // M_D_p, N·m
    o.reals[3] = m.m_d_g; // M_D_g, N·m
    o.reals[4] = m.te; // TE, m
    o.reals[5] = m.f_n; // F_n, N
    o.reals[6] = m.contact_length; // contact_length, m
    o.reals[7] = m.p_max; // p_max, Pa
    o.ints[0] = u32_to_i32(m.n_pairs); // n_pairs
    o.bools[0] = m.tip_contact; // tip_contact
    o.bools[1] = m.separated; // separated
    o.bools[2] = m.back_contact; // back_contact
    o.reals[8] = m.force_p[0]; // F_p_x, N
    o.reals[9] = m.force_p[1]; // F_p_y, N
    o.reals[10] = m.force_p[2]; // F_p_z, N
    o.reals[11] = m.moment_p[0]; // M_p_x, N·m
    o.reals[12] = m.moment_p[1]; // M_p_y, N·m
    o.reals[13] = m.force_g[0]; // F_g_x, N
    o.reals[14] = m.force_g[1]; // F_g_y, N
    o.reals[15] = m.force_g[2]; // F_g_z, N
    o.reals[16] = m.moment_g[0]; // M_g_x, N·m
    o.reals[17] = m.moment_g[1]; // M_g_y, N·m
    o.reals[18] = m.root_stress_p; // sigma_F_p, Pa
    o.reals[19] = m.root_stress_g; // sigma_F_g, Pa
}

/// Every model of the family, in the order of the documentation.
pub static MODELS: &[&ModelInfo] = &[&mesh::INFO, &unit::PAIR, &unit::STAGE, &unit::DRIVE];

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

    /// The shared mesh outputs take the first slots in table order, and
    /// [`write_mesh_outputs`] writes exactly those: a table entry without its line (or a line
    /// without its entry) fails here.
    #[test]
    fn mesh_outputs_fill_exactly_the_first_slots_of_their_table() {
        let (mut reals, mut ints, mut bools) = (0, 0, 0);
        for v in &MESH_OUTPUTS {
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
    }
}
