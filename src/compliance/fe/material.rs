//! Isotropic linear-elastic material.
//!
//! Hooke's law in Lamé form, σ = λ·tr(ε)·I + 2μ·ε, with
//! λ = Eν / ((1 + ν)(1 − 2ν)) and μ = G = E / (2(1 + ν)).
//! Small strains; no thermal or initial strains.

use super::error::FeError;

/// Isotropic linear-elastic material constants for the finite-element model.
///
/// `e` is Young's modulus in Pa (finite, > 0); `nu` is Poisson's ratio, dimensionless, in
/// (−1, 0.5) — the open upper bound excludes the incompressible limit, for which the
/// displacement formulation locks and λ is infinite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E, Pa.
    pub e: f64,
    /// Poisson's ratio ν, dimensionless.
    pub nu: f64,
}

impl Material {
    /// Builds a material after checking E > 0 (finite) and −1 < ν < 0.5.
    pub fn new(e: f64, nu: f64) -> Result<Self, FeError> {
        let m = Self { e, nu };
        m.validate()?;
        Ok(m)
    }

    /// Checks E > 0 (finite) and −1 < ν < 0.5.
    pub fn validate(&self) -> Result<(), FeError> {
        if self.e.is_finite() && self.e > 0.0 && self.nu > -1.0 && self.nu < 0.5 {
            Ok(())
        } else {
            Err(FeError::InvalidMaterial { e: self.e, nu: self.nu })
        }
    }

    /// Lamé constants (λ, μ) in Pa; μ is the shear modulus G.
    pub fn lame(&self) -> (f64, f64) {
        let lambda = self.e * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu));
        let mu = self.e / (2.0 * (1.0 + self.nu));
        (lambda, mu)
    }

    /// Shear modulus G = E / (2(1 + ν)), Pa.
    pub fn shear_modulus(&self) -> f64 {
        self.e / (2.0 * (1.0 + self.nu))
    }
}

impl From<&crate::params::Material> for Material {
    /// Takes E and ν of a gear material (the density is not used by the static FE model).
    fn from(m: &crate::params::Material) -> Self {
        Self { e: m.youngs_modulus_pa, nu: m.poisson_ratio }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lame_constants_of_steel() {
        let m = Material::new(206e9, 0.3).expect("valid");
        let (l, mu) = m.lame();
        assert!((mu - 206e9 / 2.6).abs() < 1e-3);
        assert!((l - 206e9 * 0.3 / (1.3 * 0.4)).abs() < 1e-3);
        assert!(Material::new(206e9, 0.5).is_err());
        assert!(Material::new(-1.0, 0.3).is_err());
        assert!(Material::new(f64::NAN, 0.3).is_err());
    }
}
