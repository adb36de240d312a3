//! Local contact deformation (Weber–Banaschek, Eqs. 10–11) and Hertz pressure (Eq. 15).
//!
//! Two cylinders (the flanks, with radii of curvature ρ_p, ρ_g in the normal section) pressed
//! together with a load intensity q (N/m, force per unit length of the contact line) touch in
//! a strip of half width L (Eq. 11):
//!
//! L = sqrt( (4/π)·C·q·ρ ),  C = (1 − ν_p²)/E_p + (1 − ν_g²)/E_g,  ρ = ρ_p·ρ_g/(ρ_p + ρ_g),
//!
//! with the maximum (Hertz) pressure (Eq. 15) p = sqrt( q/(π·C·ρ) ), so that q = (π/2)·p·L.
//!
//! The local, non-linear part of the tooth deformation is the approach of the surface of one
//! body towards a plane at the depth h below it (Vedmar's division: the global part, linear in
//! q, comes from the finite-element model up to that depth). Weber and Banaschek give (Eq. 10),
//! for a body with Young's modulus E and Poisson's ratio ν,
//!
//! u_c = 2(1 − ν²)/(π·E) · q · B(h/L),
//! B(x) = ln( x + sqrt(1 + x²) ) − ν/(1 − ν) · x² · ( sqrt(1 + 1/x²) − 1 ).
//!
//! Paper Eq. 12 uses 2·u_c for two equal bodies; [`LocalContact::deformation`] returns the sum
//! of the pinion's and the gear's u_c with their own E, ν and h.
//!
//! Numerics: B is evaluated without cancellation for all x > 0: ln(x + sqrt(1 + x²)) = asinh x
//! via `ln_1p` for small x and ln 2x + 1/(4x²) for huge x, and
//! x²·(sqrt(1 + 1/x²) − 1) = x/(x + sqrt(1 + x²)) = 1/(1 + sqrt(1 + 1/x²)), which tends to 1/2 for
//! x → ∞ (no difference of nearly equal numbers). Since L ∝ sqrt(q), h/L → ∞ as q → 0 and
//! u_c ≈ 2(1 − ν²)/(πE)·q·(ln(2h/L) − ν/(2(1 − ν))) ~ q·ln(1/sqrt(q)) → 0; u_c(0) = 0 exactly.
//!
//! Units: q in N/m, ρ, h, L and u_c in m, E and p in Pa. Positive u_c is an approach
//! (compression). Loads q < 0 (tension) are rejected: the contact cannot transmit them.

use std::f64::consts::{LN_2, PI};
use std::fmt;

use crate::params::Material;

/// Errors of the contact formulas.
#[derive(Debug, Clone, PartialEq)]
pub enum HertzError {
    /// A radius of curvature is not > 0 (NaN included). Concave flanks are not supported.
    NonPositiveRadius {
        /// `"rho_p"`, `"rho_g"` or `"rho"` (reduced radius).
        name: &'static str,
        /// The value, m.
        value: f64,
    },
    /// Both radii are infinite (two flat surfaces): there is no Hertz contact.
    BothFlat,
    /// A load intensity q < 0 or not finite, N/m.
    InvalidLoad {
        /// The value, N/m.
        q: f64,
    },
    /// A depth h that is not finite and > 0, m.
    InvalidDepth {
        /// `"h_p"`, `"h_g"` or `"h"`.
        name: &'static str,
        /// The value, m.
        value: f64,
    },
    /// A contact half width L that is not finite and > 0 (with q > 0), m.
    InvalidHalfWidth {
        /// The value, m.
        value: f64,
    },
    /// Young's modulus not finite and > 0, or Poisson's ratio outside [0, 0.5].
    InvalidMaterial {
        /// `"youngs_modulus_pa"` or `"poisson_ratio"`.
        name: &'static str,
        /// The value.
        value: f64,
    },
}

impl fmt::Display for HertzError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HertzError::NonPositiveRadius { name, value } => {
                write!(f, "radius of curvature `{name}` = {value} m: must be > 0")
            }
            HertzError::BothFlat => {
                f.write_str("both radii of curvature are infinite: no Hertz contact")
            }
            HertzError::InvalidLoad { q } => {
                write!(f, "load intensity q = {q} N/m: must be finite and >= 0")
            }
            HertzError::InvalidDepth { name, value } => {
                write!(f, "depth `{name}` = {value} m: must be finite and > 0")
            }
            HertzError::InvalidHalfWidth { value } => {
                write!(f, "contact half width L = {value} m: must be finite and > 0")
            }
            HertzError::InvalidMaterial { name, value } => {
                write!(f, "material `{name}` = {value}: E must be > 0, 0 <= nu <= 0.5")
            }
        }
    }
}

impl std::error::Error for HertzError {}

fn check_material(m: &Material) -> Result<(), HertzError> {
    let e = m.youngs_modulus_pa;
    if !(e.is_finite() && e > 0.0) {
        return Err(HertzError::InvalidMaterial { name: "youngs_modulus_pa", value: e });
    }
    let nu = m.poisson_ratio;
    if !(0.0..=0.5).contains(&nu) {
        return Err(HertzError::InvalidMaterial { name: "poisson_ratio", value: nu });
    }
    Ok(())
}

fn check_load(q: f64) -> Result<(), HertzError> {
    if q.is_finite() && q >= 0.0 { Ok(()) } else { Err(HertzError::InvalidLoad { q }) }
}

fn check_depth(name: &'static str, h: f64) -> Result<(), HertzError> {
    if h.is_finite() && h > 0.0 { Ok(()) } else { Err(HertzError::InvalidDepth { name, value: h }) }
}

fn check_rho(rho: f64) -> Result<(), HertzError> {
    if rho > 0.0 && rho.is_finite() {
        Ok(())
    } else {
        Err(HertzError::NonPositiveRadius { name: "rho", value: rho })
    }
}

/// Combined elastic compliance C = (1 − ν_p²)/E_p + (1 − ν_g²)/E_g, 1/Pa.
pub fn compliance_sum(pinion: &Material, gear: &Material) -> Result<f64, HertzError> {
    check_material(pinion)?;
    check_material(gear)?;
    Ok((1.0 - pinion.poisson_ratio.powi(2)) / pinion.youngs_modulus_pa
        + (1.0 - gear.poisson_ratio.powi(2)) / gear.youngs_modulus_pa)
}

/// Reduced radius of curvature ρ = ρ_p·ρ_g/(ρ_p + ρ_g), m.
///
/// Radii are those of the two convex flanks in the normal section, m, each > 0; one of them
/// may be `f64::INFINITY` (a flat surface, e.g. a rack), then ρ is the other radius. Errors:
/// a radius ≤ 0 or NaN ([`HertzError::NonPositiveRadius`]), both infinite
/// ([`HertzError::BothFlat`]).
pub fn reduced_radius(rho_p: f64, rho_g: f64) -> Result<f64, HertzError> {
    for (name, r) in [("rho_p", rho_p), ("rho_g", rho_g)] {
        if r.is_nan() || r <= 0.0 {
            return Err(HertzError::NonPositiveRadius { name, value: r });
        }
    }
    match (rho_p.is_infinite(), rho_g.is_infinite()) {
        (true, true) => Err(HertzError::BothFlat),
        (true, false) => Ok(rho_g),
        (false, true) => Ok(rho_p),
        // 1/(1/ρp + 1/ρg): no overflow of the product for large radii.
        (false, false) => Ok(1.0 / (1.0 / rho_p + 1.0 / rho_g)),
    }
}

/// Half width L of the contact strip (Eq. 11), m: L = sqrt((4/π)·C·q·ρ).
///
/// `q` load intensity, N/m (≥ 0); `rho` reduced radius, m (> 0, see [`reduced_radius`]);
/// `compliance` C from [`compliance_sum`], 1/Pa.
pub fn half_width(q: f64, rho: f64, compliance: f64) -> Result<f64, HertzError> {
    check_load(q)?;
    check_rho(rho)?;
    Ok((4.0 / PI * compliance * q * rho).sqrt())
}

/// Maximum Hertz pressure (Eq. 15), Pa: p = sqrt(q/(π·C·ρ)); equivalently q = (π/2)·p·L.
///
/// Arguments as for [`half_width`].
pub fn max_pressure(q: f64, rho: f64, compliance: f64) -> Result<f64, HertzError> {
    check_load(q)?;
    check_rho(rho)?;
    Ok((q / (PI * compliance * rho)).sqrt())
}

/// asinh(x) = ln(x + sqrt(1 + x²)) for x ≥ 0 without cancellation or overflow.
fn asinh_pos(x: f64) -> f64 {
    if x > 1e8 {
        // ln(2x) + 1/(4x²) − …; the next term is O(x⁻⁴).
        LN_2 + x.ln() + 0.25 / (x * x)
    } else {
        // x + sqrt(1+x²) − 1 = x + x²/(1 + sqrt(1+x²)).
        (x + x * x / (1.0 + (1.0 + x * x).sqrt())).ln_1p()
    }
}

/// G(x) = x²·(sqrt(1 + 1/x²) − 1) for x ≥ 0 without cancellation (G(0) = 0, G(∞) = 1/2).
fn g_pos(x: f64) -> f64 {
    if x <= 1.0 {
        x / (x + (1.0 + x * x).sqrt())
    } else {
        let y = 1.0 / x;
        1.0 / (1.0 + (1.0 + y * y).sqrt())
    }
}

/// The bracket of Eq. 10 as a function of x = h/L (> 0) and ν:
/// B(x) = ln(x + sqrt(1 + x²)) − ν/(1 − ν)·x²·(sqrt(1 + (1/x)²) − 1), dimensionless.
///
/// Evaluated without cancellation for all x ≥ 0 (see the module doc); B(0) = 0,
/// B(+∞) = +∞. Returns NaN for NaN or negative x, or ν outside [0, 0.5].
pub fn weber_banaschek_bracket(x: f64, nu: f64) -> f64 {
    if x.is_nan() || x < 0.0 || !(0.0..=0.5).contains(&nu) {
        return f64::NAN;
    }
    if x == f64::INFINITY {
        return f64::INFINITY;
    }
    asinh_pos(x) - nu / (1.0 - nu) * g_pos(x)
}

/// x·B'(x)/2 for x ≥ 0, where B' = 1/sqrt(1+x²) − κ/(s·(x+s)²), s = sqrt(1+x²), κ = ν/(1−ν).
fn half_x_dbracket(x: f64, kappa: f64) -> f64 {
    if x <= 1.0 {
        let s = (1.0 + x * x).sqrt();
        0.5 * x / s * (1.0 - kappa / ((x + s) * (x + s)))
    } else {
        // x/s = 1/sqrt(1 + y²), (x + s)² = x²·(1 + sqrt(1 + y²))², y = 1/x.
        let y = 1.0 / x;
        let r = (1.0 + y * y).sqrt();
        let w = y / (1.0 + r);
        0.5 / r * (1.0 - kappa * w * w)
    }
}

/// u_c of one body (Eq. 10) and du_c/dq for load intensity `q`, given L(q) = `l_coef`·sqrt(q).
fn body_uc(q: f64, l_coef: f64, h: f64, body: &Material) -> (f64, f64) {
    let nu = body.poisson_ratio;
    let a = 2.0 * (1.0 - nu * nu) / (PI * body.youngs_modulus_pa);
    if q == 0.0 {
        // Limit q → 0+: u_c ~ q·ln(1/sqrt(q)) → 0, du_c/dq ~ ln(1/sqrt(q)) → +∞.
        return (0.0, f64::INFINITY);
    }
    let l = l_coef * q.sqrt();
    let x = h / l;
    let kappa = nu / (1.0 - nu);
    let b = weber_banaschek_bracket(x, nu);
    // d/dq [a·q·B(x(q))] with x ∝ q^(−1/2): a·(B − x·B'/2).
    (a * q * b, a * (b - half_x_dbracket(x, kappa)))
}

/// Local deformation u_c of one body (Eq. 10), m, given the half width L (m) directly.
///
/// `q` load intensity, N/m (≥ 0); `half_width` L, m (> 0 when q > 0); `depth` h, m (> 0);
/// `body` gives E and ν. u_c(0) = 0.
pub fn body_deformation(
    q: f64,
    half_width: f64,
    depth: f64,
    body: &Material,
) -> Result<f64, HertzError> {
    check_load(q)?;
    check_depth("h", depth)?;
    check_material(body)?;
    if q == 0.0 {
        return Ok(0.0);
    }
    if !(half_width > 0.0 && half_width.is_finite()) {
        return Err(HertzError::InvalidHalfWidth { value: half_width });
    }
    let nu = body.poisson_ratio;
    let a = 2.0 * (1.0 - nu * nu) / (PI * body.youngs_modulus_pa);
    Ok(a * q * weber_banaschek_bracket(depth / half_width, nu))
}

/// Total local deformation u_c,p + u_c,g (m) and its derivative with respect to q (m²/N).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalDeformation {
    /// u_c of the pinion, m.
    pub pinion: f64,
    /// u_c of the gear, m.
    pub gear: f64,
    /// u_c,p + u_c,g, m (the term 2·u_c of Eq. 12 for equal bodies).
    pub total: f64,
    /// d(u_c,p + u_c,g)/dq, m/(N/m) = m²/N; +∞ at q = 0 (logarithmic singularity).
    pub d_total_dq: f64,
}

/// The local contact of a pinion and a gear of given materials, with the depths h_p, h_g that
/// bound the local deformation region of each (Eqs. 10, 11, 15). Radii and load vary per
/// contact point and are arguments of the methods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalContact {
    pinion: Material,
    gear: Material,
    depth_p: f64,
    depth_g: f64,
    compliance: f64,
    /// Same material and depth: both bodies deform alike ([`LocalContact::deformation`]).
    equal_bodies: bool,
}

impl LocalContact {
    /// Validates the materials (E > 0, 0 ≤ ν ≤ 0.5) and depths (m, > 0).
    pub fn new(
        pinion: &Material,
        gear: &Material,
        depth_p: f64,
        depth_g: f64,
    ) -> Result<Self, HertzError> {
        let compliance = compliance_sum(pinion, gear)?;
        check_depth("h_p", depth_p)?;
        check_depth("h_g", depth_g)?;
        let equal_bodies = depth_p == depth_g && pinion == gear;
        Ok(Self { pinion: *pinion, gear: *gear, depth_p, depth_g, compliance, equal_bodies })
    }

    /// C = (1 − ν_p²)/E_p + (1 − ν_g²)/E_g, 1/Pa.
    pub fn compliance(&self) -> f64 {
        self.compliance
    }

    /// Half width L (Eq. 11), m, for load intensity `q` (N/m) and reduced radius `rho` (m).
    pub fn half_width(&self, q: f64, rho: f64) -> Result<f64, HertzError> {
        half_width(q, rho, self.compliance)
    }

    /// Maximum Hertz pressure (Eq. 15), Pa, for `q` (N/m) and reduced radius `rho` (m).
    pub fn max_pressure(&self, q: f64, rho: f64) -> Result<f64, HertzError> {
        max_pressure(q, rho, self.compliance)
    }

    /// Local deformations (Eq. 10) of both bodies, their sum and the derivative of the sum with
    /// respect to q (analytic), for load intensity `q` (N/m, ≥ 0) and reduced radius `rho`
    /// (m, > 0). L is computed from Eq. 11 with the same q and ρ.
    pub fn deformation(&self, q: f64, rho: f64) -> Result<LocalDeformation, HertzError> {
        check_load(q)?;
        check_rho(rho)?;
        let l_coef = (4.0 / PI * self.compliance * rho).sqrt();
        let (up, dp) = body_uc(q, l_coef, self.depth_p, &self.pinion);
        // Equal bodies (same material and depth, the common case) deform equally: the gear's
        // term is the pinion's, bit for bit, without a second logarithm.
        let (ug, dg) =
            if self.equal_bodies { (up, dp) } else { body_uc(q, l_coef, self.depth_g, &self.gear) };
        Ok(LocalDeformation { pinion: up, gear: ug, total: up + ug, d_total_dq: dp + dg })
    }
}
