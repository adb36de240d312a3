//! # helical_gear_mesh
//!
//! The Andersson–Vedmar model of a helical gear mesh (A. Andersson, L. Vedmar, "A dynamic model
//! to determine vibrations in involute helical gears", J. Sound Vib. 260 (2003) 195–212):
//! the instant line of contact between two rotating elastic helical gears from their true
//! geometry (contacts outside the plane of action included), finite-element tooth compliance,
//! the non-linear load distribution along the contact lines and the resulting mesh torques.
//!
//! Data flow of one evaluation (see `ARCHITECTURE.md`):
//!
//! ```text
//! GearPair (params) ─> geometry::PairGeometry (validated; flank curves of both gears)
//! state (φp, φg)    ─> contact: per axial slice and tooth pair: common normal, overlap Δ0t·m_n,
//!                      radii of curvature, moment arms, flank coordinates
//! ```
//!
//! Units are SI throughout (m, rad, N, N·m, Pa, s). Angles φp, φg are hub rotations measured in
//! one absolute sense (counter-clockwise seen from the side where ζ = 0); the pinion drives in
//! the positive sense and the transmission error is `TE = φp·g_p + φg·g_g` (Eq. 16, g = base
//! radius): TE = 0 when ideal unloaded involute driving flanks just touch, TE > 0 when the teeth
//! must deform.

pub mod capi;
pub mod compliance;
pub mod contact;
pub mod dynamics;
pub mod error;
pub mod fmi2;
pub mod geometry;
pub mod iso6336;
pub mod load;
pub mod mesh;
pub mod modifications;
pub mod numeric;
pub mod options;
pub mod params;
pub mod results;

pub use error::ParamError;
pub use geometry::PairGeometry;
pub use modifications::Modifications;
pub use params::{DriveLine, GearPair, Material};
