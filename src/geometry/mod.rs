//! Geometry of the gear pair: validated parameters, both gears' transverse profiles, the
//! operating centre distance, contact ratios and the gear bodies' inertias.
//!
//! Fixed transverse frame (used by [`crate::contact`]): origin on the pinion axis, +x towards
//! the gear axis at `(a_w, 0)`, angles counter-clockwise seen from the side where ζ = 0. The
//! pinion turns in the positive sense when driving; its active (positive) flank faces +y near
//! the pitch point. The line of action of the driving flanks is tangent to the pinion base
//! circle at `T_p = r_bp·(cos α_wt, −sin α_wt)` and runs in the direction
//! `u = (sin α_wt, cos α_wt)` towards the gear base circle.
//!
//! Tooth placement: at φp = φg = 0 and ζ = 0 the driving involutes of pinion tooth 0 and gear
//! tooth 0 touch at the pitch point (unloaded, zero transmission error). Pinion tooth k and gear
//! tooth −k form tooth pair k.

pub mod flank;
pub mod gear;
pub mod inertia;
pub mod rack;

use std::f64::consts::PI;

pub use flank::{Flank, FlankPoint, Primitive, SegmentKind, Shape, inv};
pub use gear::{GearGeometry, Member};

use crate::error::ParamError;
use crate::params::GearPair;

/// Validated geometry of a gear pair (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct PairGeometry {
    /// The parameters this geometry was derived from.
    pub params: GearPair,
    /// The pinion.
    pub pinion: GearGeometry,
    /// The gear.
    pub gear: GearGeometry,
    /// Transverse pressure angle of the basic rack α_t, rad.
    pub alpha_t: f64,
    /// Operating transverse pressure angle α_wt, rad.
    pub alpha_wt: f64,
    /// Operating (zero-backlash) centre distance a_w, m.
    pub center_distance: f64,
    /// Base helix angle θ = β_b (tan β_b = tan β·cos α_t), rad.
    pub base_helix_angle: f64,
    /// Transverse base pitch p_bt = 2π·r_b/z, m.
    pub base_pitch: f64,
    /// Transverse contact ratio ε_α (ISO 21771, from the tip circles).
    pub eps_alpha: f64,
    /// Overlap ratio ε_β = b·sin β/(π·m_n).
    pub eps_beta: f64,
    /// Backlash along the transverse line of action (base tangent), m: the back flanks touch
    /// at TE = −`backlash_te`.
    pub backlash_te: f64,
    /// Roll length of the pinion at the start of the rigid path of contact (point A), m,
    /// measured from the tangency point T_p along the line of action.
    pub path_start: f64,
    /// Roll length of the pinion at the end of the rigid path of contact (point E), m.
    pub path_end: f64,
    /// Mass moment of inertia of the pinion body (teeth and web to the bore), kg·m².
    pub j_p: f64,
    /// Mass moment of inertia of the gear body, kg·m².
    pub j_g: f64,
}

impl GearPair {
    /// Validates every parameter ([`GearPair::check_params`]) and the derived geometry (the
    /// rules of [`PairGeometry::new`]). Declared here, beside the geometry it builds, so that
    /// the parameters' own module depends on nothing but the error type.
    pub fn validate(&self) -> Result<(), ParamError> {
        PairGeometry::new(self).map(|_| ())
    }
}

impl PairGeometry {
    /// Validates `p` and derives the geometry.
    ///
    /// Rules (each violation returns a [`ParamError`] naming the key, the value and the
    /// allowed range): scalar ranges (module, angles, β < 45°, widths > 0, 0 < ν < 0.5, …);
    /// tooth numbers at or above the undercut limit of the rack and shift; root fillets that fit
    /// in the tooth space; a relief that starts above the form circle; a tip rounding that fits
    /// between relief and tip circle; a remaining tip land; a bore inside the root circle with
    /// a rim of at least one module; no tip interference with the mating fillet; total contact
    /// ratio ε_α + ε_β ≥ 1; flank modifications and deviations within their limits
    /// ([`crate::modifications::Modifications::validate`]).
    pub fn new(p: &GearPair) -> Result<Self, ParamError> {
        p.check_params()?;
        let pinion = GearGeometry::new(p, Member::Pinion)?;
        let gear = GearGeometry::new(p, Member::Gear)?;
        let mn = p.normal_module_m;
        let alpha_t = (p.pressure_angle_rad.tan() / p.helix_angle_rad.cos()).atan();
        let inv_wt = inv(alpha_t)
            + 2.0 * p.pressure_angle_rad.tan() * (p.profile_shift_p + p.profile_shift_g)
                / (p.z_p + p.z_g) as f64;
        let alpha_wt = flank::inv_inverse(inv_wt);
        let center_distance = (pinion.r + gear.r) * alpha_t.cos() / alpha_wt.cos();
        let base_helix_angle = (p.helix_angle_rad.tan() * alpha_t.cos()).atan();
        let base_pitch = 2.0 * PI * pinion.rb / p.z_p as f64;
        let line = center_distance * alpha_wt.sin();
        let roll_tip_p = (pinion.ra.powi(2) - pinion.rb.powi(2)).sqrt();
        let roll_tip_g = (gear.ra.powi(2) - gear.rb.powi(2)).sqrt();
        let path_start = line - roll_tip_g;
        let path_end = roll_tip_p;
        let eps_alpha = (path_end - path_start) / base_pitch;
        let eps_beta = p.face_width_m * p.helix_angle_rad.sin() / (PI * mn);

        for g in [&pinion, &gear] {
            if p.bore_diameter_m / 2.0 > g.rf - mn {
                return Err(ParamError::new(
                    "bore_diameter_m",
                    p.bore_diameter_m,
                    format!(
                        "<= root diameter − 2·m_n = {:.6} m (gear {}: rim of at least one module)",
                        2.0 * (g.rf - mn),
                        g.member.suffix()
                    ),
                ));
            }
        }
        // Tip interference: the mating tip must meet each flank above its form circle.
        let roll_form = |g: &GearGeometry| (g.r_form.powi(2) - g.rb.powi(2)).max(0.0).sqrt();
        if path_start < roll_form(&pinion) {
            return Err(ParamError::new(
                "addendum_mn",
                p.addendum_mn,
                format!(
                    "small enough that the gear tip meets the pinion above its form circle \
                     (contact starts at roll {:.6} m < form roll {:.6} m: tip interference)",
                    path_start,
                    roll_form(&pinion)
                ),
            ));
        }
        if line - path_end < roll_form(&gear) {
            return Err(ParamError::new(
                "addendum_mn",
                p.addendum_mn,
                format!(
                    "small enough that the pinion tip meets the gear above its form circle \
                     (contact ends at gear roll {:.6} m < form roll {:.6} m: tip interference)",
                    line - path_end,
                    roll_form(&gear)
                ),
            ));
        }
        if eps_alpha + eps_beta < 1.0 {
            return Err(ParamError::new(
                "face_width_m",
                p.face_width_m,
                format!(
                    "large enough for a total contact ratio ε_α + ε_β >= 1 \
                     (ε_α = {eps_alpha:.4}, ε_β = {eps_beta:.4})"
                ),
            ));
        }
        let backlash_te = p.normal_backlash_mn * mn / base_helix_angle.cos();
        let j_p = inertia::gear_body_inertia(
            &pinion,
            p.face_width_m,
            p.bore_diameter_m / 2.0,
            p.material_p.density_kg_m3,
        );
        let j_g = inertia::gear_body_inertia(
            &gear,
            p.face_width_m,
            p.bore_diameter_m / 2.0,
            p.material_g.density_kg_m3,
        );
        let geo = Self {
            params: p.clone(),
            pinion,
            gear,
            alpha_t,
            alpha_wt,
            center_distance,
            base_helix_angle,
            base_pitch,
            eps_alpha,
            eps_beta,
            backlash_te,
            path_start,
            path_end,
            j_p,
            j_g,
        };
        p.modifications.validate(&geo)?;
        Ok(geo)
    }

    /// The gear of `member`.
    pub fn member(&self, member: Member) -> &GearGeometry {
        match member {
            Member::Pinion => &self.pinion,
            Member::Gear => &self.gear,
        }
    }

    /// Non-dimensional face width b₀ = b/m_n.
    pub fn b0(&self) -> f64 {
        self.params.face_width_m / self.params.normal_module_m
    }

    /// Transmission error along the line of action, TE = φp·r_bp + φg·r_bg (Eq. 16), m,
    /// computed in twice the working precision and rounded once ([`crate::numeric::dot2`]), so
    /// that huge hub angles lose no digits (error ≤ ½ ulp(TE) + 10⁻²⁰ m at 10¹² rad).
    pub fn transmission_error(&self, phi_p: f64, phi_g: f64) -> f64 {
        crate::numeric::dot2(phi_p, self.pinion.rb, phi_g, self.gear.rb)
    }

    /// Gear angle φg that gives transmission error `te` (m) at pinion angle `phi_p`, rad.
    pub fn phi_g_for_te(&self, phi_p: f64, te: f64) -> f64 {
        crate::numeric::phi_g_for_te(phi_p, te, self.pinion.rb, self.gear.rb)
    }
}
