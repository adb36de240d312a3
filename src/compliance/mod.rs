//! Tooth compliance (paper §4): Vedmar's division of the deformation into a global part,
//! linear in the load, from a 3D finite-element model of each gear ([`fe`]), and a local,
//! non-linear contact part between the flank and the depth h ([`hertz`], Weber–Banaschek).

pub mod fe;
pub mod hertz;
