//! Load distribution across the face width and the face load factor K_Hβ.
//!
//! # Line load
//! From the per-slice loads of the last evaluation ([`Mesh::slices`], so
//! [`super::MeshOptions::detail`] must be on): slice i carries the force q_i·w_i over the
//! axial width m_n·Δζ, w_i = m_n·Δζ/cos θ, i.e. the normal load per unit face width
//! q_i/cos θ (N/m). The line load at axial slice k is that sum over all tooth pairs in contact
//! there (driving flanks), and its mean over the face is F_n/b (F_n the total normal force).
//!
//! # Face load factor
//! K_Hβ = max_k line load / mean line load (ISO 6336-1 definition, there with the tangential
//! force; the ratio is the same since all loads of the plane of action share one direction).
//!
//! ISO 6336-1:2019 §7.6 (method C, Eqs. 41–42) gives, for an elastic foundation of stiffness
//! c_γβ per unit face width under a linear effective misalignment F_βy across the face:
//!
//! ```text
//! K_Hβ = 1 + F_βy·c_γβ / (2·F_m/b)          when this is ≤ 2 (contact over the whole face)
//! K_Hβ = √(2·F_βy·c_γβ / (F_m/b))            otherwise (contact over part of the face)
//! ```
//!
//! Derivation (which the tests check against the model with a Winkler compliance): line load
//! w(y) = c_γβ·(δ − F_βy·y/b) ≥ 0 for y ∈ [0, b]. Over the whole face, the mean is
//! c_γβ·(δ − F_βy/2) and the maximum c_γβ·δ, hence the first form (valid while δ ≥ F_βy,
//! i.e. K_Hβ ≤ 2). Over a part l < b, w is a triangle: F_m = w_max·l/2 and w_max = c_γβ·F_βy·l/b,
//! so l = √(2F_m·b/(c_γβ·F_βy)) and K_Hβ = w_max·b/F_m = √(2F_βy·c_γβ·b/F_m).
//!
//! For a lead crowning C (sum of both gears, parabolic, C at each face end relative to the
//! middle) the same reasoning gives K_Hβ = 1 + c_γβ·C·b/(3F_m) while the whole face carries load
//! (K_Hβ ≤ 1.5) and K_Hβ = (3/2)·√(C/δ) with δ = (3F_m·√C/(2c_γβ·b))^(2/3) otherwise
//! ([`k_h_beta_crowned`]).

use super::Mesh;
use crate::geometry::PairGeometry;

/// Line load across the face width at one evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLoad {
    /// Slice centres ζ = z/m_n.
    pub zeta: Vec<f64>,
    /// Normal load per unit face width at each slice, all tooth pairs summed, N/m.
    pub line_load: Vec<f64>,
}

impl FaceLoad {
    /// Largest line load, N/m.
    pub fn max(&self) -> f64 {
        self.line_load.iter().copied().fold(0.0, f64::max)
    }

    /// Mean line load over the face (F_n/b), N/m.
    pub fn mean(&self) -> f64 {
        self.line_load.iter().sum::<f64>() / self.line_load.len().max(1) as f64
    }

    /// K_Hβ = max/mean (1 for a uniform load; NaN without load).
    pub fn k_h_beta(&self) -> f64 {
        let m = self.mean();
        if m > 0.0 { self.max() / m } else { f64::NAN }
    }
}

/// The line load of the last evaluation of `model` (its per-slice detail must be on; driving
/// flanks only).
pub fn face_load(model: &Mesh) -> FaceLoad {
    let geo: &PairGeometry = model.geometry();
    let n = model.slices_per_line();
    let b0 = geo.b0();
    let ct = geo.base_helix_angle.cos();
    let zeta: Vec<f64> = (0..n).map(|k| (k as f64 + 0.5) * b0 / n as f64).collect();
    let mut line_load = vec![0.0; n];
    for s in model.slices() {
        if !s.back && s.q_n_per_m > 0.0 {
            let k = ((s.zeta / b0 * n as f64) as usize).min(n - 1);
            line_load[k] += s.q_n_per_m / ct;
        }
    }
    FaceLoad { zeta, line_load }
}

/// ISO 6336-1 method C face load factor for the effective misalignment `f_beta_y` (m, its
/// magnitude is used), the mesh stiffness per unit face width `c_gamma` (N/m per m of face,
/// i.e. N/m²) and the mean line load `w_m` = F_m/b (N/m); see the module docs.
pub fn k_h_beta_iso(f_beta_y: f64, c_gamma: f64, w_m: f64) -> f64 {
    let x = f_beta_y.abs() * c_gamma / w_m;
    if 1.0 + 0.5 * x <= 2.0 { 1.0 + 0.5 * x } else { (2.0 * x).sqrt() }
}

/// Elastic-foundation face load factor of a lead crowning `c` (m, sum of both gears) under the
/// mean line load `w_m` (N/m) with stiffness `c_gamma` (N/m²); see the module docs.
pub fn k_h_beta_crowned(c: f64, c_gamma: f64, w_m: f64) -> f64 {
    if c <= 0.0 {
        return 1.0;
    }
    let full = 1.0 + c_gamma * c / (3.0 * w_m);
    if full <= 1.5 {
        return full;
    }
    let delta = (1.5 * w_m * c.sqrt() / c_gamma).powf(2.0 / 3.0);
    1.5 * (c / delta).sqrt()
}
