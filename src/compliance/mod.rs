//! Tooth compliance (paper §4): Vedmar's division of the deformation into a global part,
//! linear in the load, from a 3D finite-element model of each gear ([`fe`]), and a local,
//! non-linear contact part between the flank and the depth h ([`hertz`], Weber–Banaschek).
//!
//! ## Flank coordinates
//! A point of a tooth flank is given by [`FlankCoord`]: η* (distance along the tooth centre line
//! from the reference point where a tip rounding of the same radius would be tangent to the
//! unrelieved involute, positive towards the root, in units of m_n), τ (angle turned by the
//! flank normal past the start of the actual tip rounding, rad, 0 below it) and ζ = z/m_n. These
//! are the coordinates [`crate::contact::ContactPoint`] reports. For grids and interpolation the
//! single monotone **profile coordinate** [`FlankCoord::profile`] combines η* and τ.
//!
//! ## Global compliance α*
//! α*(obs, load) of one gear, m/N: the displacement along the flank's unit normal (positive
//! into the tooth, i.e. in the direction a compressive contact force pushes the surface) of the
//! point at depth h beneath the observation point, caused by a unit normal force pressing on the
//! flank at the load point; both points on the positive (active) flank of their tooth. The hub
//! bore is fixed, so α* includes the twist of the gear body. `tooth_offset` = (tooth of the
//! observation point) − (tooth of the load point) in the gear's own tooth numbering
//! (counter-clockwise, see [`crate::geometry`]); for the pinion the tooth of contact pair j is j,
//! for the gear it is −j.
//!
//! ## Data and stiffness
//! [`data::ComplianceData`] holds both gears' FE grids, the fitted constants and their
//! provenance (embedded for Table 1, disk cache, or computed); [`stiffness::pair_stiffness`]
//! reduces them to the tooth-pair stiffness c′ at the pitch point (ISO 6336-1 convention).

pub mod data;
pub mod error;
pub mod fe;
pub mod fitted;
pub mod hertz;
pub mod influence_fe;
pub mod interpolated;
pub mod lm;
pub mod root_stress;
pub mod stiffness;

use serde::{Deserialize, Serialize};

/// A point on the active flank of a tooth, in the flank coordinates of the compliance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FlankCoord {
    /// η*, in units of m_n (positive towards the root).
    pub eta_star: f64,
    /// τ, rad (0 on involute and relief).
    pub tau: f64,
    /// ζ = z/m_n.
    pub zeta: f64,
}

impl FlankCoord {
    /// Monotone profile coordinate, in units of m_n, increasing from the tip towards the root:
    /// η* below the rounding and `η*_q − τ·ρ_r/m_n` on the rounding and tip (η*_q: η* at the
    /// start of the rounding, ρ_r: rounding radius), i.e. arc length continued over the rounding.
    pub fn profile(&self, eta_star_rounding_start: f64, rounding_radius_mn: f64) -> f64 {
        if self.tau > 0.0 {
            eta_star_rounding_start - self.tau * rounding_radius_mn
        } else {
            self.eta_star
        }
    }
}

/// A representation of one gear's global flank compliance α* (see the module docs).
pub trait Compliance: Send + Sync {
    /// α*(obs, load), m/N, for an observation point on the tooth `tooth_offset` teeth from the
    /// loaded tooth (0: same tooth).
    fn alpha(&self, obs: FlankCoord, load: FlankCoord, tooth_offset: i32) -> f64;

    /// Depth h of Vedmar's division used for the global part, m (the local Weber–Banaschek
    /// term must use the same h).
    fn depth(&self) -> f64;

    /// Largest |tooth_offset| with non-zero coupling in this representation.
    fn max_tooth_offset(&self) -> i32;
}

/// FE influence data of one gear on a structured flank grid: unit normal loads at every grid
/// point of the loaded tooth (tooth 0), observations at depth h beneath every grid point of the
/// loaded tooth and of its neighbours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InfluenceGrid {
    /// Profile coordinate of each grid row (units of m_n, see [`FlankCoord::profile`]),
    /// strictly increasing (tip to root).
    pub profile: Vec<f64>,
    /// η* of each grid row (units of m_n), at ζ of the mid face (η* does not depend on ζ).
    pub eta_star: Vec<f64>,
    /// τ of each grid row, rad.
    pub tau: Vec<f64>,
    /// ζ of each grid column, strictly increasing, in [0, b₀].
    pub zeta: Vec<f64>,
    /// Tooth offsets of the observation blocks, e.g. `[-1, 0, 1]`.
    pub teeth: Vec<i32>,
    /// α* in m/N: `alpha[t][obs * n + load]` with n = profile.len()·zeta.len() and the grid
    /// index `i = row * zeta.len() + column`; observation on tooth `teeth[t]`, load on tooth 0.
    pub alpha: Vec<Vec<f64>>,
    /// Depth h of Vedmar's division, m.
    pub depth_h: f64,
    /// η* at the start of the rounding (units of m_n), for [`FlankCoord::profile`].
    pub eta_star_rounding_start: f64,
    /// Tip-rounding radius in units of m_n, for [`FlankCoord::profile`].
    pub rounding_radius_mn: f64,
}

impl InfluenceGrid {
    /// Number of grid points on one flank (rows × columns).
    pub fn points(&self) -> usize {
        self.profile.len() * self.zeta.len()
    }

    /// Grid index of (row, column).
    pub fn index(&self, row: usize, column: usize) -> usize {
        row * self.zeta.len() + column
    }

    /// Flank coordinates of grid point `i`.
    pub fn coord(&self, i: usize) -> FlankCoord {
        let (row, col) = (i / self.zeta.len(), i % self.zeta.len());
        FlankCoord { eta_star: self.eta_star[row], tau: self.tau[row], zeta: self.zeta[col] }
    }

    /// α* for observation grid point `obs` on tooth offset `teeth[t]` and load point `load`.
    pub fn value(&self, t: usize, obs: usize, load: usize) -> f64 {
        self.alpha[t][obs * self.points() + load]
    }

    /// Checks shapes and finiteness; returns a message naming the first problem.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.points();
        if self.profile.len() < 2 || self.zeta.len() < 2 {
            return Err(format!(
                "influence grid needs at least 2 rows and 2 columns, has {}×{}",
                self.profile.len(),
                self.zeta.len()
            ));
        }
        if self.eta_star.len() != self.profile.len() || self.tau.len() != self.profile.len() {
            return Err("influence grid: eta_star/tau length differs from profile".into());
        }
        if !self.profile.windows(2).all(|w| w[1] > w[0]) {
            return Err("influence grid: profile coordinates not strictly increasing".into());
        }
        if !self.zeta.windows(2).all(|w| w[1] > w[0]) {
            return Err("influence grid: zeta not strictly increasing".into());
        }
        if self.teeth.len() != self.alpha.len() || !self.teeth.contains(&0) {
            return Err("influence grid: teeth/alpha blocks inconsistent or tooth 0 missing".into());
        }
        for (t, block) in self.alpha.iter().enumerate() {
            if block.len() != n * n {
                return Err(format!(
                    "influence grid: block {t} has {} values, expected {}",
                    block.len(),
                    n * n
                ));
            }
            if let Some(k) = block.iter().position(|v| !v.is_finite()) {
                return Err(format!("influence grid: non-finite α* in block {t} at {k}"));
            }
        }
        if !(self.depth_h.is_finite() && self.depth_h > 0.0) {
            return Err(format!("influence grid: depth_h = {} must be > 0", self.depth_h));
        }
        Ok(())
    }
}
