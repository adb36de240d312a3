//! Flank modifications, misalignment and tooth deviations: a small separation of the flanks
//! added to the overlap of every contact slice.
//!
//! # Model
//! Every modification or deviation is a small normal separation of the flank at a point
//! (ζ, roll length). The mesh model ([`crate::mesh::MeshModel`]) subtracts the sum of both
//! gears' separations and the pair's misalignment from the overlap Δ0t·m_n of each
//! driving-flank slice ([`crate::contact`]) before the load problem (Eq. 12) is set up:
//!
//! ```text
//! Δ'(ζ, pair) = Δ(ζ, pair) − s_p(ζ, L_p, tooth_p) − s_g(ζ, L_g, tooth_g) − f_ma·ζ/b₀
//! ```
//!
//! so load distribution, torques, statics and dynamics follow without further change. The
//! separations are small (micrometres against millimetre radii), so the contact point, the
//! radii of curvature and the moment arms of the unmodified flanks are kept (first order in
//! s/ρ).
//!
//! # Units and sign conventions
//! * Every amount is a length in m **along the transverse line of action** (the direction in
//!   which ISO 1328-1 measures profile, helix and pitch deviations, and the direction of TE,
//!   Eq. 16): a flank separation s raises the TE at which the slice starts to carry load by s.
//! * **A positive value removes material** (moves the flank away from the mating flank).
//! * ζ = z/m_n ∈ [0, b₀] is the pair's axial coordinate ([`crate::contact`]), the same for
//!   both gears; "start" is the ζ = 0 face end, "end" the ζ = b₀ end.
//! * L is the roll length of the contact point on the gear's base circle, L = √(r² − r_b²);
//!   the active profile of a gear runs from L_lo (start of active profile, where the mating
//!   tip meets it) to L_hi (its own tip circle), ℓ = L_hi − L_lo.
//!
//! | key | separation s (m) |
//! | --- | --- |
//! | `lead_crowning_m` C_β | C_β·(2ζ/b₀ − 1)²: C_β at each face end relative to mid-face |
//! | `helix_slope_m` f_Hβ | f_Hβ·ζ/b₀: 0 at ζ = 0, f_Hβ at ζ = b₀ |
//! | `end_relief` | C·(x/l)^p within the relief length l of a face end (x: distance into the relief zone from its inner edge; p = 1 linear, 2 parabolic) |
//! | `profile_crowning_m` C_α | C_α·(2(L − L_lo)/ℓ − 1)²: C_α at both ends of the active profile |
//! | `profile_slope_m` f_Hα | f_Hα·(L − L_lo)/ℓ: 0 at the start of the active profile, f_Hα at the tip |
//! | `tip_relief` | C·((L − L_s)/(L_a − L_s))^p above the roll length L_s of the start diameter (L_a: tip circle) |
//! | `deviation_map` | bilinear interpolation in a (roll length × axial position) grid, clamped at its edges |
//! | `pitch_deviations_m[i]` e_i | e_i on every point of tooth i (its flank position deviation) |
//! | `runout_m` e, `runout_phase_rad` ψ | e·cos(2π·i/z − ψ) on tooth i |
//! | `mesh_misalignment_m` f_ma | f_ma·ζ/b₀ (the pair's, ISO 6336-1 f_ma in the plane of action) |
//!
//! Worked example (Table 1, b₀ = 5): `mesh_misalignment_m = 10e-6` and `helix_slope_m = 0` on
//! both gears: at ζ = 0 nothing changes, at ζ = 2.5 the flanks are 5 µm apart and at ζ = 5
//! 10 µm, so under load the ζ = 0 end carries the most and at a TE below 10 µm the ζ = b₀ end
//! is unloaded. `helix_slope_m = -10e-6` on the pinion (material added at ζ = b₀) cancels it
//! exactly: a helix correction for a known misalignment.
//!
//! Tooth numbers: pinion tooth k and gear tooth −k form tooth pair k ([`crate::geometry`]);
//! the index into `pitch_deviations_m` is the tooth number modulo z (pinion: k mod z_p, gear:
//! (−k) mod z_g). `pitch_deviations_m[i]` is the position deviation of the flank of tooth i;
//! the single pitch deviations of ISO 1328-1 are f_pt,i = e_i − e_{i−1}. Runout: an
//! eccentricity e of the gear moves the flank of the tooth in mesh along the line of action by
//! e·cos(θ − ψ), θ the tooth's angular position in the gear (2π·i/z); it is applied as a
//! constant per tooth, its angular position when it passes the pitch point (the change within
//! one engagement, about e·2π/z, is neglected).
//!
//! The modifications act on the driving flanks; the back flanks (loaded only through the
//! backlash) keep the unmodified geometry.
//!
//! # Periodicity
//! Flank modifications that are the same on every tooth keep the mesh periodic in one pinion
//! pitch; pitch deviations and runout repeat only after the hunting period of
//! z_p·z_g/gcd(z_p, z_g) meshes ([`Modifications::hunting_meshes`], 1410 for Table 1). The
//! contact search keeps the absolute tooth-pair number, which picks the deviations of the
//! engaged teeth. The per-pitch table of the `table` fidelity holds the modifications that
//! repeat on every tooth (they must remove material; otherwise the mesh model evaluates at
//! full fidelity, [`crate::mesh::Mesh::from_model`]); pitch deviations and runout
//! are added on it per tooth pair ([`Separation::tooth_offset`], `crate::mesh::table`, "Tooth
//! deviations").

use crate::contact::ContactPoint;
use crate::error::ParamError;
use crate::geometry::PairGeometry;
/// The modifications' data (what users write), where they were.
pub use crate::params::modifications::{
    DeviationMap, EndRelief, FlankModification, Modifications, ReliefShape, TipRelief,
};

impl Modifications {
    /// Validates every value against `geo` (the pair's derived geometry). Errors name the key
    /// (e.g. `modifications.pinion.lead_crowning_m`), the value and the limit.
    pub fn validate(&self, geo: &PairGeometry) -> Result<(), ParamError> {
        let mn = geo.params.normal_module_m;
        let b = geo.params.face_width_m;
        // A modification larger than a tenth of the module would remove a large part of the
        // tooth (the tip tooth thickness is 0.3–0.8·m_n); real ones are a few hundredths.
        let lim = 0.1 * mn;
        let signed = |key: &str, v: f64| -> Result<(), ParamError> {
            if v.is_finite() && v.abs() <= lim {
                Ok(())
            } else {
                Err(ParamError::new(key, v, format!("finite, |value| <= 0.1·m_n = {lim:.3e} m")))
            }
        };
        let removal = |key: &str, v: f64| -> Result<(), ParamError> {
            if v.is_finite() && (0.0..=lim).contains(&v) {
                Ok(())
            } else {
                Err(ParamError::new(
                    key,
                    v,
                    format!(
                        "in [0, 0.1·m_n = {lim:.3e}] m (removes material, less than the tooth)"
                    ),
                ))
            }
        };
        signed("modifications.mesh_misalignment_m", self.mesh_misalignment_m)?;
        for (name, g, gear) in
            [("pinion", &self.pinion, &geo.pinion), ("gear", &self.gear, &geo.gear)]
        {
            let k = |s: &str| format!("modifications.{name}.{s}");
            removal(&k("lead_crowning_m"), g.lead_crowning_m)?;
            signed(&k("helix_slope_m"), g.helix_slope_m)?;
            removal(&k("profile_crowning_m"), g.profile_crowning_m)?;
            signed(&k("profile_slope_m"), g.profile_slope_m)?;
            let er = &g.end_relief;
            removal(&k("end_relief.amount_start_m"), er.amount_start_m)?;
            removal(&k("end_relief.amount_end_m"), er.amount_end_m)?;
            for (key, v) in
                [("length_start_m", er.length_start_m), ("length_end_m", er.length_end_m)]
            {
                if !(v.is_finite() && (0.0..=b).contains(&v)) {
                    return Err(ParamError::new(
                        &k(&format!("end_relief.{key}")),
                        v,
                        format!("in [0, face width b = {b} m]"),
                    ));
                }
            }
            if er.length_start_m + er.length_end_m > b {
                return Err(ParamError::new(
                    &k("end_relief.length_end_m"),
                    er.length_end_m,
                    format!("<= b − length_start_m = {} m", b - er.length_start_m),
                ));
            }
            for (key, amount, length) in [
                ("amount_start_m", er.amount_start_m, er.length_start_m),
                ("amount_end_m", er.amount_end_m, er.length_end_m),
            ] {
                if amount > 0.0 && length <= 0.0 {
                    return Err(ParamError::new(
                        &k(&format!("end_relief.{key}")),
                        amount,
                        "0 unless its relief length is > 0",
                    ));
                }
            }
            let tr = &g.tip_relief;
            removal(&k("tip_relief.amount_m"), tr.amount_m)?;
            if tr.amount_m > 0.0 {
                let (db, da) = (2.0 * gear.rb, 2.0 * gear.ra);
                let d = tr.start_diameter_m;
                if !(d.is_finite() && d > db && d < da) {
                    return Err(ParamError::new(
                        &k("tip_relief.start_diameter_m"),
                        d,
                        format!("in (base diameter {db:.6} m, tip diameter {da:.6} m)"),
                    ));
                }
            }
            if !g.pitch_deviations_m.is_empty() {
                let z = gear.z as usize;
                if g.pitch_deviations_m.len() != z {
                    return Err(ParamError::new(
                        &k("pitch_deviations_m"),
                        g.pitch_deviations_m.len() as f64,
                        format!("a list of exactly z = {z} values (one per tooth), or empty"),
                    ));
                }
                for (i, &e) in g.pitch_deviations_m.iter().enumerate() {
                    signed(&k(&format!("pitch_deviations_m[{i}]")), e)?;
                }
            }
            removal(&k("runout_m"), g.runout_m)?;
            if !g.runout_phase_rad.is_finite() {
                return Err(ParamError::new(&k("runout_phase_rad"), g.runout_phase_rad, "finite"));
            }
            if let Some(m) = &g.deviation_map {
                for (key, xs) in [("roll_length_m", &m.roll_length_m), ("face_m", &m.face_m)] {
                    let ok = xs.len() >= 2
                        && xs.iter().all(|v| v.is_finite())
                        && xs.windows(2).all(|w| w[1] > w[0]);
                    if !ok {
                        return Err(ParamError::new(
                            &k(&format!("deviation_map.{key}")),
                            xs.len() as f64,
                            "at least 2 finite, strictly increasing values",
                        ));
                    }
                }
                let (nr, nc) = (m.roll_length_m.len(), m.face_m.len());
                if m.values_m.len() != nr || m.values_m.iter().any(|r| r.len() != nc) {
                    return Err(ParamError::new(
                        &k("deviation_map.values_m"),
                        m.values_m.len() as f64,
                        format!("{nr} rows (roll_length_m) of {nc} values (face_m)"),
                    ));
                }
                for (i, row) in m.values_m.iter().enumerate() {
                    for (j, &v) in row.iter().enumerate() {
                        signed(&k(&format!("deviation_map.values_m[{i}][{j}]")), v)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// One gear's separation, prepared for evaluation (lengths in m).
#[derive(Debug, Clone)]
struct GearSeparation {
    m: FlankModification,
    rb: f64,
    /// Active profile, roll lengths (L_lo, ℓ).
    roll_lo: f64,
    roll_len: f64,
    /// Tip relief: start roll length and the relief zone's roll length.
    tip_roll_start: f64,
    tip_roll_len: f64,
    /// Per tooth: pitch deviation plus runout, m (empty when both are zero).
    tooth: Vec<f64>,
}

impl GearSeparation {
    fn new(m: &FlankModification, rb: f64, ra: f64, roll_lo: f64, roll_hi: f64, z: u32) -> Self {
        let roll = |r: f64| (r * r - rb * rb).max(0.0).sqrt();
        let tip_roll_start = roll(0.5 * m.tip_relief.start_diameter_m);
        let mut tooth = Vec::new();
        if m.runout_m != 0.0 || !m.pitch_deviations_m.is_empty() {
            tooth = (0..z as usize)
                .map(|i| {
                    let th = 2.0 * std::f64::consts::PI * i as f64 / z as f64;
                    m.pitch_deviations_m.get(i).copied().unwrap_or(0.0)
                        + m.runout_m * (th - m.runout_phase_rad).cos()
                })
                .collect();
        }
        Self {
            m: m.clone(),
            rb,
            roll_lo,
            roll_len: (roll_hi - roll_lo).max(f64::MIN_POSITIVE),
            tip_roll_start,
            tip_roll_len: (roll(ra) - tip_roll_start).max(f64::MIN_POSITIVE),
            tooth,
        }
    }

    /// Separation at axial position t = ζ/b₀ ∈ [0, 1] (z = t·b in m), radius r and tooth
    /// index `tooth` (already reduced modulo z).
    fn at(&self, t: f64, z: f64, b: f64, r: f64, tooth: usize) -> f64 {
        let m = &self.m;
        let mut s = 0.0;
        if m.lead_crowning_m != 0.0 {
            let u = 2.0 * t - 1.0;
            s += m.lead_crowning_m * u * u;
        }
        if m.helix_slope_m != 0.0 {
            s += m.helix_slope_m * t;
        }
        let er = &m.end_relief;
        if er.amount_start_m != 0.0 && z < er.length_start_m {
            s += er.amount_start_m * er.shape.apply((er.length_start_m - z) / er.length_start_m);
        }
        if er.amount_end_m != 0.0 && z > b - er.length_end_m {
            s += er.amount_end_m * er.shape.apply((z - (b - er.length_end_m)) / er.length_end_m);
        }
        let needs_roll = m.profile_crowning_m != 0.0
            || m.profile_slope_m != 0.0
            || m.tip_relief.amount_m != 0.0
            || m.deviation_map.is_some();
        if needs_roll {
            let roll = (r * r - self.rb * self.rb).max(0.0).sqrt();
            let v = (roll - self.roll_lo) / self.roll_len;
            if m.profile_crowning_m != 0.0 {
                let u = 2.0 * v - 1.0;
                s += m.profile_crowning_m * u * u;
            }
            if m.profile_slope_m != 0.0 {
                s += m.profile_slope_m * v;
            }
            let tr = &m.tip_relief;
            if tr.amount_m != 0.0 && roll > self.tip_roll_start {
                let w = ((roll - self.tip_roll_start) / self.tip_roll_len).min(1.0);
                s += tr.amount_m * tr.shape.apply(w);
            }
            if let Some(map) = &m.deviation_map {
                s += map.value(roll, z);
            }
        }
        if let Some(&e) = self.tooth.get(tooth) {
            s += e;
        }
        s
    }

    /// ∂s/∂r of [`GearSeparation::at`] at axial position z (m) and radius r (m): the profile
    /// terms (crowning, slope, tip relief, map) through the roll length L = √(r² − r_b²).
    fn d_dr(&self, z: f64, r: f64) -> f64 {
        let m = &self.m;
        let needs_roll = m.profile_crowning_m != 0.0
            || m.profile_slope_m != 0.0
            || m.tip_relief.amount_m != 0.0
            || m.deviation_map.is_some();
        let roll = (r * r - self.rb * self.rb).max(0.0).sqrt();
        if !needs_roll || roll <= 0.0 {
            return 0.0;
        }
        let v = (roll - self.roll_lo) / self.roll_len;
        let mut ds = 0.0; // per unit roll length
        if m.profile_crowning_m != 0.0 {
            ds += 4.0 * m.profile_crowning_m * (2.0 * v - 1.0) / self.roll_len;
        }
        if m.profile_slope_m != 0.0 {
            ds += m.profile_slope_m / self.roll_len;
        }
        let tr = &m.tip_relief;
        if tr.amount_m != 0.0 && roll > self.tip_roll_start {
            let w = (roll - self.tip_roll_start) / self.tip_roll_len;
            if w < 1.0 {
                let dw = match tr.shape {
                    ReliefShape::Linear => 1.0,
                    ReliefShape::Parabolic => 2.0 * w,
                };
                ds += tr.amount_m * dw / self.tip_roll_len;
            }
        }
        if let Some(map) = &m.deviation_map {
            ds += map.d_roll(roll, z);
        }
        ds * r / roll
    }

    /// A lower bound of the separation over the flank (≤ 0 where material is added), m.
    fn min_bound(&self) -> f64 {
        let m = &self.m;
        let neg = |v: f64| v.min(0.0);
        let map = m
            .deviation_map
            .as_ref()
            .map(|d| d.values_m.iter().flatten().copied().fold(0.0, f64::min))
            .unwrap_or(0.0);
        let tooth = self.tooth.iter().copied().fold(0.0, f64::min);
        neg(m.helix_slope_m) + neg(m.profile_slope_m) + map + tooth
    }
}

/// The separation of the driving flanks of a pair at any contact point, built from the
/// [`Modifications`] of a validated [`PairGeometry`]. Allocation-free to evaluate.
#[derive(Debug, Clone)]
pub struct Separation {
    pinion: GearSeparation,
    gear: GearSeparation,
    misalignment: f64,
    b0: f64,
    b: f64,
    z_p: i64,
    z_g: i64,
    min_bound: f64,
    tooth_deviations: bool,
}

impl Separation {
    /// The separation model of `geo`'s modifications; `None` when they are the default (no
    /// key given), so a pair without modifications runs exactly the unmodified code.
    pub fn new(geo: &PairGeometry) -> Option<Self> {
        let mods = &geo.params.modifications;
        if mods.is_default() {
            return None;
        }
        let line = geo.center_distance * geo.alpha_wt.sin();
        let pinion = GearSeparation::new(
            &mods.pinion,
            geo.pinion.rb,
            geo.pinion.ra,
            geo.path_start,
            geo.path_end,
            geo.pinion.z,
        );
        let gear = GearSeparation::new(
            &mods.gear,
            geo.gear.rb,
            geo.gear.ra,
            line - geo.path_end,
            line - geo.path_start,
            geo.gear.z,
        );
        let min_bound = pinion.min_bound() + gear.min_bound() + mods.mesh_misalignment_m.min(0.0);
        Some(Self {
            pinion,
            gear,
            misalignment: mods.mesh_misalignment_m,
            b0: geo.b0(),
            b: geo.params.face_width_m,
            z_p: geo.pinion.z as i64,
            z_g: geo.gear.z as i64,
            min_bound,
            tooth_deviations: mods.has_tooth_deviations(),
        })
    }

    /// Separation of the driving flanks of tooth pair `pair` (absolute number) at axial
    /// coordinate `zeta` with the contact at radii `r_p`, `r_g` (m): s_p + s_g + f_ma·ζ/b₀, m.
    #[inline]
    pub fn at(&self, zeta: f64, pair: i64, r_p: f64, r_g: f64) -> f64 {
        let t = zeta / self.b0;
        let z = t * self.b;
        let tp = pair.rem_euclid(self.z_p) as usize;
        let tg = (-pair).rem_euclid(self.z_g) as usize;
        self.pinion.at(t, z, self.b, r_p, tp)
            + self.gear.at(t, z, self.b, r_g, tg)
            + self.misalignment * t
    }

    /// Partial derivatives (∂s/∂r_p, ∂s/∂r_g) of [`Separation::at`] with respect to the
    /// contact radii on pinion and gear (m/m): nonzero for the profile modifications only.
    #[inline]
    pub fn radial_rates(&self, zeta: f64, r_p: f64, r_g: f64) -> (f64, f64) {
        let z = zeta / self.b0 * self.b;
        (self.pinion.d_dr(z, r_p), self.gear.d_dr(z, r_g))
    }

    /// Separation at a driving-flank contact point, m (0 for back flanks).
    #[inline]
    pub fn of_contact(&self, c: &ContactPoint) -> f64 {
        if c.side == crate::contact::FlankSide::Back {
            return 0.0;
        }
        self.at(c.zeta, c.pair, c.radius_p_m, c.radius_g_m)
    }

    /// A lower bound of the separation (≤ 0; below 0 where material is added), m: driving
    /// flanks can touch from TE = this value on.
    pub fn min_bound(&self) -> f64 {
        self.min_bound
    }

    /// True when pitch deviations or runout are given (no periodicity in one pitch).
    pub fn has_tooth_deviations(&self) -> bool {
        self.tooth_deviations
    }

    /// The tooth-by-tooth part of the separation of tooth pair `pair` (absolute number): the
    /// pinion's and the gear's pitch deviation plus runout of the two teeth, m. It is the same
    /// at every point of the pair's flanks.
    #[inline]
    pub fn tooth_offset(&self, pair: i64) -> f64 {
        let tp = pair.rem_euclid(self.z_p) as usize;
        let tg = (-pair).rem_euclid(self.z_g) as usize;
        self.pinion.tooth.get(tp).copied().unwrap_or(0.0)
            + self.gear.tooth.get(tg).copied().unwrap_or(0.0)
    }

    /// The separation without its tooth-by-tooth part (pitch deviations and runout): the part
    /// that repeats on every tooth, periodic in one pitch. `at` of the result plus
    /// [`Separation::tooth_offset`] is `at` of `self`.
    pub fn periodic_part(&self) -> Self {
        let mut s = self.clone();
        s.pinion.tooth.clear();
        s.gear.tooth.clear();
        s.tooth_deviations = false;
        s.min_bound = s.pinion.min_bound() + s.gear.min_bound() + self.misalignment.min(0.0);
        s
    }
}
