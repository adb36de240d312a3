//! The range of mesh states in which the model holds — a specification.
//!
//! # Transmission error: flank overlaps up to 0.2·m_n
//! The model is a small-deformation model: the contact is found on the undeformed flanks
//! ([`crate::contact`]), the tooth and body compliance is linear FE elasticity and the local
//! term is Hertzian. The required approach of a slice is its overlap, and the real flanks lie
//! inside the full involutes, whose overlap is TE on the driving flanks and −TE − j_t on the
//! back flanks (j_t the backlash along the line of action): every slice overlap is at most
//! that distance from the flanks' onset (plus the few micrometres that flank modifications may
//! add). The model therefore holds for
//!
//! ```text
//! −j_t − Δ_max ≤ TE ≤ Δ_max,   Δ_max = 0.2·m_n
//! ```
//!
//! and a state outside it is [`MeshError::OutOfRange`](super::MeshError::OutOfRange) (TE, the
//! mesh phase, this range), at full and at table fidelity and whatever the contact search would
//! find there. Why 0.2·m_n:
//!
//! * **Elasticity.** Tooth dimensions scale with m_n (height 2.25·m_n, thickness at the
//!   reference circle ≈ 1.57·m_n), so a tooth deflection δ means strains of order δ/m_n at the
//!   root: about 1 % at 0.02·m_n, 10 % at 0.2·m_n. Gear steels yield at strains of 0.2–0.7 %
//!   (σ_y/E); at 0.2·m_n the linear model would describe strains 15–50 times the yield strain
//!   and rotations of the tooth of order 0.1 rad, where even small-strain kinematics no longer
//!   hold. Contact approaches at the nominal load are micrometres to tens of micrometres
//!   (Table 1: the nominal static TE is 29–31 µm = 0.01·m_n; the bound is 20 times it and
//!   carries about 2.3–2.5 kN·m, 23–25 times the nominal torque).
//! * **Geometry.** The teeth pass through each other at overlaps of the order of the tooth
//!   thickness (the tip is 0.6–0.8·m_n thick for a standard tooth); before that the contact
//!   search on the undeformed flanks loses the loaded pairs one by one (their common normals
//!   run off the flanks) and the outputs fall towards "separated" although the teeth are
//!   crushed. Measured for Table 1 without this bound: overlaps of 2–10 mm (0.7–3·m_n) gave
//!   20–30 kN·m (200–300× the nominal torque) and beyond about 2 cm no contact at all, zero
//!   torque, both with a success status.
//! * **Margin for real use.** The table's designed range, 4× the nominal static TE on the
//!   driving flanks and half of that on the back flanks, is 0.04·m_n for Table 1 (0.17·m_n for
//!   the heavily loaded β = 18.5°, b = 10.7 mm test design at 200 N·m); the kicked Table 1 runs
//!   of `tests/stress_dynamics.rs` reach TE = 378 µm = 0.13·m_n and back-flank overlaps of
//!   318 µm = 0.11·m_n; the random designs of `tests/stress_designs.rs` (Winkler c′ =
//!   14 N/(mm·µm) under up to five times a line load of 300 N/mm, an approach of the order of
//!   0.1 mm, with m_n ≥ 1 mm) pass unchanged. All lie inside.
//!
//! Inside the range the load problem may still be ill posed (heavily overloaded tip contacts:
//! Table 1 measured well posed to 0.19·m_n with the fitted and 0.59·m_n with the interpolated
//! compliance); the load solver proves it and the state is reported out of range as well, with
//! the solver's cause. Searches that probe TE ([`super::statics::equilibrium`], the table
//! build) treat the range as the end of their search interval.
//!
//! # Pinion angle: the exact range |φp| ≤ 2⁵³ pitches
//! The mesh phase and the tooth-pair numbers come from the reduction φp = k·2π/z_p + r
//! ([`crate::numeric::Pitch::reduce`]); the pair number of a contact is an `i64` found from k.
//! k is exact (every integer up to 2⁵³ is a double) and the remainder is exact as long as
//! |k| ≤ 2⁵³, i.e.
//!
//! ```text
//! |φp| ≤ 2⁵³·2π/z_p   (1.9·10¹⁵ rad for z_p = 30, 3.8·10¹⁴ rad for z_p = 150).
//! ```
//!
//! Beyond it the whole number of pitches is no longer determined by the double φp and, from
//! about 1.9·10¹⁸ rad (z_p = 30), not even representable in an i64; such an angle is
//! [`MeshError::AngleOutOfRange`](super::MeshError::AngleOutOfRange), naming the angle and the
//! bound. The gear angle needs no bound of its own: it enters only through TE (computed
//! exactly from any finite angles, [`crate::numeric::dot2`]), whose range is the one above.
//!
//! **Angles formed from TE.** Where a caller gives φp and TE and the gear angle must be formed,
//! φg = (TE − g_p·φp)/g_g ([`crate::numeric::phi_g_for_te`]: the static-equilibrium start of
//! every run, the Model Exchange states (φp, TE) of the units), the double φg carries a
//! rounding of ½·ulp(φg) and the difference TE − g_p·φp one of ½·ulp(g_p·φp), so TE is kept
//! only to about 2⁻⁵²·|φp|·g_p (both terms: |φg|·g_g ≈ |φp|·g_p). At 10¹² rad (Table 1) that
//! is 7–11 µm, a third of the static TE: the static start failed and the outputs were wrong
//! with success. Those paths therefore accept |φp|·g_p ≤ [`MAX_FORMED_ARC_M`] = 4.5·10⁶ m of
//! rolled base-circle arc, where TE is kept to 1 nm (10⁻⁸ rad … for a 0.045 m base radius:
//! |φp| ≤ 10⁸ rad, 52 hours at 532 rad/s); beyond it the error names the angle, the bound and
//! what to do ([`check_formed_angle`]). An angle pair given as two doubles keeps the bound
//! above.

use crate::geometry::PairGeometry;
use crate::numeric::Pitch;

/// Largest flank overlap Δ_max in which the model holds, in units of m_n (see the module docs).
pub const MAX_OVERLAP_MN: f64 = 0.2;

/// Largest nominal speed, rad/s (about 10⁶ rpm, far above any gear's running speed): the
/// bound of every speed a caller sets — start speeds (`--omega-p`, `w_p_start`, Python's
/// `w_p`), the units' speed inputs and the C API's and Python's mesh evaluations. A running
/// state vibrates about its nominal speed, so the states may exceed it up to
/// [`MAX_STATE_SPEED_RAD_S`]. The damping torque M_D = d_mesh·(g_p·φ̇p + g_g·φ̇g)·g is linear in the speeds; with
/// the largest d_mesh (10⁹ N·s/m) and base radii of metres it stays below 10¹⁵ N·m here, while
/// speeds of 10³⁰⁸ rad/s would make it infinite with a success status. The units, the FMUs, the
/// C API and Python hold their inputs and states to the same bound.
pub const MAX_SPEED_RAD_S: f64 = 1e5;

/// Largest rolled base-circle arc |φp|·g_p, m, at which a gear angle formed from TE keeps TE
/// to 1 nm: 2⁻⁵²·4.5·10⁶ m ≈ 10⁻⁹ m (see the module docs).
pub const MAX_FORMED_ARC_M: f64 = 4.5e6;

/// Refuses a pinion angle `phi_p` (rad), named `name`, whose gear angle is to be formed from TE
/// on base radius `g_p` (m) when |φp|·g_p exceeds [`MAX_FORMED_ARC_M`]: the error names the
/// angle, the bound in rad for this pair and why.
pub fn check_formed_angle(name: &str, phi_p: f64, g_p: f64) -> Result<(), crate::ParamError> {
    let max = MAX_FORMED_ARC_M / g_p;
    if phi_p.is_finite() && phi_p.abs() <= max {
        return Ok(());
    }
    Err(crate::ParamError::new(
        name,
        phi_p,
        format!(
            "|{name}| <= {:.3e} rad for this pair (a rolled arc |φp|·g_p of at most {:.1e} m: \
             beyond it the gear angle formed from TE rounds TE by more than 1 nm); shift the \
             angles by whole turns of both gears",
            max, MAX_FORMED_ARC_M
        ),
    ))
}

/// Largest |φ̇p|, |φ̇g| of a mesh state and of a unit's state, rad/s: twice
/// [`MAX_SPEED_RAD_S`]. A run started at the largest nominal speed overshoots it by its
/// vibration at once (a start at exactly 10⁵ rad/s failed at its first RK4 sub-step when
/// states were held to 10⁵); the torsional vibration of a running drive is a small fraction
/// of its speed, so a factor 2 leaves every run started within [`MAX_SPEED_RAD_S`] room,
/// while the damping torque stays below 2·10¹⁵ N·m.
pub const MAX_STATE_SPEED_RAD_S: f64 = 2.0 * MAX_SPEED_RAD_S;

/// The validity range of the mesh state of one gear pair (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValidityRange {
    /// Lowest transmission error, −j_t − Δ_max, m (back flanks overlapping by Δ_max).
    pub te_min: f64,
    /// Highest transmission error, Δ_max, m (driving flanks overlapping by Δ_max).
    pub te_max: f64,
    /// Largest flank overlap Δ_max = 0.2·m_n, m.
    pub max_overlap: f64,
    /// Largest |φp|, rad: 2⁵³ pinion pitches.
    pub phi_p_max: f64,
}

impl ValidityRange {
    /// The range of the pair `geo`.
    pub fn of(geo: &PairGeometry) -> Self {
        let max_overlap = MAX_OVERLAP_MN * geo.params.normal_module_m;
        Self {
            te_min: -geo.backlash_te - max_overlap,
            te_max: max_overlap,
            max_overlap,
            phi_p_max: Pitch::of_teeth(geo.pinion.z).max_angle(),
        }
    }

    /// True when TE (m) lies in [`Self::te_min`, `Self::te_max`].
    #[inline]
    pub fn contains_te(&self, te: f64) -> bool {
        (self.te_min..=self.te_max).contains(&te)
    }

    /// True when |φp| (rad) is at most [`Self::phi_p_max`].
    #[inline]
    pub fn contains_phi_p(&self, phi_p: f64) -> bool {
        phi_p.abs() <= self.phi_p_max
    }

    /// The largest flank overlap a state at `te` requires (m): TE on the driving flanks,
    /// −TE − j_t on the back flanks, 0 inside the backlash.
    pub fn required_overlap(&self, te: f64) -> f64 {
        let jt = -self.te_min - self.max_overlap;
        te.max(-te - jt).max(0.0)
    }
}
