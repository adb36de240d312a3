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
//!
//! ## Example
//!
//! The mesh torques of the paper's Table 1 pair at one state (its FE compliance is embedded,
//! so no FE run is needed). The README shows this same code.
//!
//! ```
//! use helical_gear_mesh::GearPair;
//! use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions, MeshState};
//!
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     let pair = GearPair::paper_table1();
//!     let options = MeshOptions { fidelity: Fidelity::Full, ..MeshOptions::default() };
//!     let mut mesh = Mesh::new(&pair, options)?;
//!     // Pinion at 0.01 rad, the gear placed for TE = 30 µm, pinion at 300 rad/s.
//!     let phi_p = 0.01;
//!     let phi_g = mesh.geometry().phi_g_for_te(phi_p, 30e-6);
//!     let w_p = 300.0;
//!     let w_g = -w_p * f64::from(pair.z_p) / f64::from(pair.z_g);
//!     let out = mesh.evaluate(&MeshState { phi_p, phi_g, w_p, w_g, ..Default::default() })?;
//!     let (m, n, te) = (out.m_f_p, out.n_pairs, out.te * 1e6);
//!     println!("M_F,p = {m:.1} N·m on {n} tooth pairs, TE = {te:.1} µm");
//!     assert!(out.m_f_p > 0.0 && out.n_pairs >= 1);
//!     Ok(())
//! }
//! ```

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
