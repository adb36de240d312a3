//! The models of the FMU family. Each contributes its variable table and its physics
//! ([`crate::fmi2::model::ModelInfo`], [`crate::fmi2::model::Engine`]); one shared library
//! serves them all, and `fmi2Instantiate` picks the model by the GUID it is given.

pub mod mesh;
pub mod unit;

use super::model::ModelInfo;

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
    use crate::fmi2::variables::Outputs;

    #[test]
    fn every_model_fits_the_instance_state_buffers() {
        let o = Outputs::default();
        assert_eq!((o.x.len(), o.dx.len()), (MAX_STATES, MAX_STATES));
        for m in MODELS {
            assert!(m.derivatives().count() <= MAX_STATES, "{}", m.identifier);
        }
    }
}
