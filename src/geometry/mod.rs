//! Gear geometry.
use crate::{GearPair, ParamError};
/// Validated geometry of a gear pair.
#[derive(Debug, Clone)]
pub struct PairGeometry {}
impl PairGeometry {
    /// Validates `p` and derives the geometry.
    pub fn new(p: &GearPair) -> Result<Self, ParamError> {
        p.check_ranges()?;
        Ok(Self {})
    }
}
