//! The instant line of contact (paper §3, Fig. 3) from the true, undeformed geometry.
//!
//! For hub angles (φp, φg), every axial slice ζ and every tooth pair that can be in mesh, this
//! module finds the points P1 (pinion flank) and P2 (gear flank) with a common normal in the
//! transverse plane and the signed **overlap** Δ0t·m_n = (P1 − P2)·n along it (n: outward normal
//! of the pinion flank; positive = the teeth interpenetrate and must deform, negative = gap).
//! Contacts outside the plane of action (tip rounding on involute, relief on involute, corner
//! contacts) come out of the same construction; nothing is approximated by a profile deviation.
//!
//! ## Common normal, explicitly
//! Each flank is a chain of involutes and circular arcs (see [`crate::geometry::flank`]). With
//! m = n rotated by −90°, a pinion piece satisfies `P1·m = A1·m + K1` and a gear piece (outward
//! normal −n) `P2·m = A2·m − K2`, where A is the piece's anchor (gear axis or arc centre) and K
//! its offset (base radius or 0). A common normal needs P1·m = P2·m, i.e.
//! `|D|·sin(ν − δ) = K1 + K2` with D = A2 − A1 = |D|·(cos δ, sin δ): ν is explicit for every
//! combination of pieces, and the overlap is `Δ = L1 + L2 − D·n` with L the pieces' normal
//! reach (roll length of an involute, radius of an arc). For two involutes this is the line of
//! action and Δ = TE minus the profile deviations. A fast walk over the pieces finds the valid
//! combination; an exhaustive search over all combinations is the fallback.
//!
//! ## Outputs per contact
//! Moment arms `s_p = (P1 − O_p)·m` and `s_g = −(P2 − O_g)·m` are the distances from each axis
//! to the contact normal, signed so that a compressive normal force F gives the mesh torques
//! M_F,p = F·s_p and M_F,g = F·s_g of Eqs. 2–3 (positive for normal drive); in the plane of
//! action they equal the base radii. Radii of curvature: roll length on an involute, arc radius
//! on the rounding and tip, 0 at a corner. Flank coordinates for the compliance: η* (distance
//! along the tooth centre line from the reference point where a rounding of the same radius
//! would be tangent to the unrelieved involute, positive towards the root, in units of m_n) and
//! τ (angle turned by the normal past the start of the rounding, 0 below it, rad).
//!
//! ## Cost
//! The search runs for every slice and tooth pair of every evaluation, so its trigonometry
//! is kept to what the construction needs. A tooth's turn Θ = Θ₀(pair) + twist_rate·ζ·m_n
//! is composed by the angle-addition formulas from one `sin_cos` of Θ₀ per pair and gear and
//! the helix's turn at the slice, which is the same for every pair and call (`SliceTwist`,
//! kept by the mesh model for its slices). Of a trial normal ν = δ + asin s (or δ + π − asin s)
//! only the angle takes `atan2` and `asin`; its sine and cosine come from the direction of D
//! and √((1 − s)(1 + s)), and the contact record reuses them. The values agree with direct
//! `sin_cos` to a few units in the last place (a checksum of torques, force, root stress and
//! pressure over 192 Table 1 states moved by 1.2·10⁻¹³ relative). Against one `sin_cos` per
//! slice and pair for each tooth, one for each trial normal and one for the contact, and
//! `hypot` for distances and radii (which needs no overflow guard at a gear's size), a full
//! evaluation at 200 slices runs 5 % fewer instructions (7.69 → 7.31 million on Table 1) and
//! the default table with its pose sensitivities and back-flank axis 12 % fewer (19.5 → 17.2
//! billion): the table's nodes at 100 slices spend a larger share in the search.

use std::f64::consts::PI;

use crate::geometry::{GearGeometry, PairGeometry, Primitive, SegmentKind};

/// One contact (or gap) between a pinion and a gear flank in one transverse slice.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ContactPoint {
    /// Non-dimensional axial coordinate ζ = z/m_n of the slice, in [0, b₀].
    pub zeta: f64,
    /// Tooth-pair number: the absolute index j of the pinion tooth, whose centre line is at
    /// φp + 2π·j/z_p (+ the fixed offset and helix twist); pinion tooth j meets gear tooth −j.
    /// A pair keeps its number as the gears turn; the pair found at a given place in the mesh
    /// one pinion pitch later has the number one lower.
    pub pair: i64,
    /// Which flanks touch: the driving flanks, or the back flanks through the backlash.
    pub side: FlankSide,
    /// Surface of the pinion flank at P1.
    pub kind_p: SegmentKind,
    /// Surface of the gear flank at P2.
    pub kind_g: SegmentKind,
    /// Signed overlap Δ0t·m_n along the common normal, m (positive = teeth must deform).
    pub overlap_m: f64,
    /// Angle of the pinion's outward unit normal n in the fixed frame, rad.
    pub normal_angle: f64,
    /// P1 in the fixed frame, m.
    pub point_p: [f64; 2],
    /// P2 in the fixed frame, m.
    pub point_g: [f64; 2],
    /// Radius of curvature of the pinion flank at P1 (transverse), m.
    pub rho_p_m: f64,
    /// Radius of curvature of the gear flank at P2 (transverse), m.
    pub rho_g_m: f64,
    /// Moment arm s_p of the normal force about the pinion axis, m.
    pub arm_p_m: f64,
    /// Moment arm s_g of the normal force about the gear axis, m.
    pub arm_g_m: f64,
    /// Distance of P1 from the pinion axis, m.
    pub radius_p_m: f64,
    /// Distance of P2 from the gear axis, m.
    pub radius_g_m: f64,
    /// η* of P1 on the pinion tooth, in units of m_n.
    pub eta_star_p: f64,
    /// τ of P1 on the pinion tooth, rad.
    pub tau_p: f64,
    /// η* of P2 on the gear tooth, in units of m_n.
    pub eta_star_g: f64,
    /// τ of P2 on the gear tooth, rad.
    pub tau_g: f64,
}

impl ContactPoint {
    /// Contact kind as `"<pinion surface>/<gear surface>"`, e.g. `"involute/rounding"`.
    pub fn kind_name(&self) -> String {
        format!("{}/{}", self.kind_p.name(), self.kind_g.name())
    }

    /// Residual of the common-normal condition: distance of P2 from the normal line through P1,
    /// m (zero for an exact solution).
    pub fn normal_residual(&self) -> f64 {
        let (s, c) = self.normal_angle.sin_cos();
        let d = [self.point_g[0] - self.point_p[0], self.point_g[1] - self.point_p[1]];
        (d[0] * s - d[1] * c).abs()
    }
}

/// Which pair of flanks a contact is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FlankSide {
    /// The driving flanks (the positive flank of each tooth; loaded when TE > 0).
    Drive,
    /// The back flanks (mirror images of the driving flanks), which touch when TE falls below
    /// −[`PairGeometry::backlash_te`]. Pinion tooth j's back flank meets gear tooth 1 − j.
    Back,
}

/// Settings of the contact search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSettings {
    /// Candidate tooth pairs are those whose rigid involute contact lies within the path of
    /// contact extended by this many base pitches at both ends.
    pub pair_margin_pitches: f64,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self { pair_margin_pitches: 0.5 }
    }
}

/// Angles reduced to one mesh cycle: φp − k·2π/z_p and φg + k·2π/z_g, with `k` whole pitches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReducedAngles {
    /// Pinion angle reduced to [−π/z_p, π/z_p], rad.
    pub phi_p: f64,
    /// Gear angle shifted by the same number of (gear) pitches, rad.
    pub phi_g: f64,
    /// Number of whole pinion pitches removed (exact for |φp| ≤ [`ContactSolver::max_angle`];
    /// saturated at the `i64` range beyond).
    pub pitches: i64,
    /// Transmission error TE = φp·r_bp + φg·r_bg, m.
    pub te: f64,
}

/// The gear body's displacement relative to the pinion body, in the pinion's frame ([`crate::mesh::pose`],
/// "The gear seen from the pinion"): translation U of the gear centre (m) and tilt Θ
/// (rad), or their rates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct RelativePose {
    /// U, m.
    pub u: [f64; 3],
    /// Θ = (Θ_x, Θ_y), rad.
    pub th: [f64; 2],
}

impl RelativePose {
    /// Offset (x, y) of the gear axis in the slice at height `z` (m) for face width `b` (m).
    #[inline]
    pub fn axis_offset(&self, z: f64, b: f64) -> [f64; 2] {
        let h = z - 0.5 * b;
        [self.u[0] + self.th[1] * h, self.u[1] - self.th[0] * h]
    }

    /// Axial displacement (m) of the gear material at transverse offset `rho` (m) from its
    /// displaced axis: w = U_z + Θ_x·ρ_y − Θ_y·ρ_x.
    #[inline]
    pub fn axial(&self, rho: [f64; 2]) -> f64 {
        self.u[2] + self.th[0] * rho[1] - self.th[1] * rho[0]
    }
}

/// Instant-line-of-contact solver for one gear pair.
#[derive(Debug, Clone)]
pub struct ContactSolver<'a> {
    geo: &'a PairGeometry,
    settings: ContactSettings,
    psi0_p: f64,
    psi0_g: f64,
    center_g: [f64; 2],
    pitch_p: crate::numeric::Pitch,
}

/// The helix's turn of the teeth at one slice ζ: (sin, cos) of twist_rate·ζ·m_n for the
/// pinion and for the gear. The same for every tooth pair and every call at that slice, so a
/// model computes them once for its slices ([`ContactSolver::slice_twist`]) and the contact
/// search adds them to each pair's turn instead of taking a `sin_cos` per slice and pair.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SliceTwist {
    pinion: (f64, f64),
    gear: (f64, f64),
}

/// A tooth's rotation angle (rad) with its sine and cosine, taken once per slice and pair:
/// the contact search rotates every piece it tries, and the contact it finds, by the same two
/// angles, so one `sin_cos` each serves them all. [`Turn::apply`] rotates by the angle,
/// [`Turn::apply_inverse`] by minus it (sin odd, cos even: the values of `sin_cos(−angle)`).
#[derive(Debug, Clone, Copy)]
struct Turn {
    angle: f64,
    sin: f64,
    cos: f64,
}

impl Turn {
    fn new(angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self { angle, sin, cos }
    }

    /// The turn by `angle` = `base.angle` + β, from the base turn and (sin β, cos β) by the
    /// angle-addition formulas: no `sin_cos` (the values agree with `Turn::new(angle)` to a few
    /// units in the last place).
    #[inline]
    fn added(base: Turn, angle: f64, (sin_b, cos_b): (f64, f64)) -> Self {
        Self {
            angle,
            sin: base.sin * cos_b + base.cos * sin_b,
            cos: base.cos * cos_b - base.sin * sin_b,
        }
    }

    /// `p` rotated by the angle.
    #[inline]
    fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        [self.cos * p[0] - self.sin * p[1], self.sin * p[0] + self.cos * p[1]]
    }

    /// `p` rotated by minus the angle.
    #[inline]
    fn apply_inverse(&self, p: [f64; 2]) -> [f64; 2] {
        [self.cos * p[0] - (-self.sin) * p[1], (-self.sin) * p[0] + self.cos * p[1]]
    }
}

/// `angle` wrapped into (ref − π, ref + π].
#[inline]
fn wrap_near(angle: f64, reference: f64) -> f64 {
    let d = angle - reference;
    // `numeric::floor`: `floor` bit for bit, without the library call.
    reference + (d - 2.0 * PI * crate::numeric::floor((d + PI) / (2.0 * PI)))
}

/// One flank piece as seen on a given side: the back flank is the mirror image (y → −y in
/// the tooth-local frame) of the driving flank, so its anchor is mirrored, its offset changes
/// sign, its normal angles change sign and it runs root to tip with increasing ν.
#[derive(Debug, Clone, Copy)]
struct Piece<'p> {
    prim: &'p Primitive,
    mirror: bool,
}

impl Piece<'_> {
    #[inline]
    fn anchor(&self) -> [f64; 2] {
        let a = self.prim.anchor();
        if self.mirror { [a[0], -a[1]] } else { a }
    }
    #[inline]
    fn offset(&self) -> f64 {
        if self.mirror { -self.prim.offset() } else { self.prim.offset() }
    }
    #[inline]
    fn reach(&self, nu: f64) -> f64 {
        self.prim.reach(if self.mirror { -nu } else { nu })
    }
    #[inline]
    fn nu_min(&self) -> f64 {
        if self.mirror { -self.prim.nu_max } else { self.prim.nu_min }
    }
    #[inline]
    fn nu_max(&self) -> f64 {
        if self.mirror { -self.prim.nu_min } else { self.prim.nu_max }
    }
    /// Step in the chain index (root to tip) towards normal angle `nu` outside the piece.
    #[inline]
    fn step_towards(&self, nu: f64) -> i8 {
        // Driving flank: ν decreases root→tip, so ν above the piece means "towards the root".
        let s = if nu > self.nu_max() {
            -1
        } else if nu < self.nu_min() {
            1
        } else {
            0
        };
        if self.mirror { -s } else { s }
    }
}

/// A trial solution for one combination of pieces.
#[derive(Debug, Clone, Copy)]
struct Trial {
    nu: f64,
    /// sin ν and cos ν.
    sin_nu: f64,
    cos_nu: f64,
    nu_p_local: f64,
    nu_g_local: f64,
    /// Chain-index step towards the solution on the pinion (−1 rootward, +1 tipward, 0 inside).
    side_p: i8,
    side_g: i8,
}

impl<'a> ContactSolver<'a> {
    /// A solver for the pair `geo` with default settings.
    pub fn new(geo: &'a PairGeometry) -> Self {
        Self::with_settings(geo, ContactSettings::default())
    }

    /// A solver for the pair `geo` with `settings`.
    pub fn with_settings(geo: &'a PairGeometry, settings: ContactSettings) -> Self {
        let inv_w = crate::geometry::inv(geo.alpha_wt);
        Self {
            geo,
            settings,
            psi0_p: inv_w - geo.pinion.lambda0,
            psi0_g: PI + inv_w - geo.gear.lambda0,
            center_g: [geo.center_distance, 0.0],
            pitch_p: crate::numeric::Pitch::of_teeth(geo.pinion.z),
        }
    }

    /// The geometry this solver works on.
    pub fn geometry(&self) -> &PairGeometry {
        self.geo
    }

    /// The exact range of the pinion angle, rad: |φp| ≤ 2⁵³ pinion pitches
    /// ([`crate::numeric::Pitch::max_angle`], [`crate::mesh::validity`]). Within it the
    /// reduction is exact and the tooth-pair numbers are exact `i64`s; beyond it
    /// [`ContactSolver::contacts_on`] finds no contacts (the mesh model reports such an angle
    /// as an error before any search).
    pub fn max_angle(&self) -> f64 {
        self.pitch_p.max_angle()
    }

    /// Reduces (φp, φg) to one mesh cycle without changing the contact set.
    ///
    /// Exact in the given doubles ([`crate::numeric`]): TE = φp·g_p + φg·g_g is computed from
    /// the absolute angles in twice the working precision and rounded once, the pinion angle is
    /// reduced modulo a double-double pitch 2π/z_p, and the reduced gear angle is the one that
    /// gives that TE at the reduced pinion angle (so the contacts see exactly the TE that is
    /// reported; a gear angle reduced by whole gear pitches would differ by the few-ulp
    /// mismatch of g_p/g_g and z_p/z_g, which 10¹² rad turn into micrometres). Without a whole
    /// pitch to remove (k = 0) the angles pass unchanged. Exact for |φp| ≤
    /// [`ContactSolver::max_angle`].
    pub fn reduce(&self, phi_p: f64, phi_g: f64) -> ReducedAngles {
        let te = self.geo.transmission_error(phi_p, phi_g);
        let (rp, k) = self.pitch_p.reduce(phi_p);
        let rg = if k == 0.0 { phi_g } else { self.geo.phi_g_for_te(rp, te) };
        ReducedAngles { phi_p: rp, phi_g: rg, pitches: k as i64, te }
    }

    /// Mid-slice coordinates ζ_i = (i + ½)·b₀/n of `n` equal axial slices.
    pub fn slice_zetas(&self, n: usize) -> Vec<f64> {
        let b0 = self.geo.b0();
        (0..n).map(|i| (i as f64 + 0.5) * b0 / n as f64).collect()
    }

    /// Range of tooth-pair indices (relative to the reduced angles) that can be in mesh for
    /// reduced pinion angle `phi_p` over axial coordinates `zetas`.
    fn pair_range(&self, phi_p: f64, zeta_min: f64, zeta_max: f64, side: FlankSide) -> (i64, i64) {
        let g = self.geo;
        let rb = g.pinion.rb;
        let mn = g.params.normal_module_m;
        let margin = self.settings.pair_margin_pitches * g.base_pitch;
        let l_at =
            |zeta: f64| rb * (phi_p + g.pinion.twist_rate * zeta * mn) + rb * g.alpha_wt.tan();
        let (l_a, l_b) = (l_at(zeta_min), l_at(zeta_max));
        let (l_min, l_max) = (l_a.min(l_b), l_a.max(l_b));
        let lo = ((g.path_start - margin - l_max) / g.base_pitch).ceil() as i64;
        let hi = ((g.path_end + margin - l_min) / g.base_pitch).floor() as i64;
        match side {
            FlankSide::Drive => (lo, hi),
            // The back line of action is the mirror image: a wider, safe window.
            FlankSide::Back => (lo - 2, hi + 2),
        }
    }

    /// All driving-flank contacts (and gaps) for hub angles (`phi_p`, `phi_g`) at the axial
    /// coordinates `zetas`, written to `out` (cleared first). Returns the reduced angles.
    ///
    /// At most one contact per slice and tooth pair; pairs whose flanks have no common normal
    /// in a slice (out of mesh there) are absent.
    pub fn contacts(
        &self,
        phi_p: f64,
        phi_g: f64,
        zetas: &[f64],
        out: &mut Vec<ContactPoint>,
    ) -> ReducedAngles {
        self.contacts_on(FlankSide::Drive, phi_p, phi_g, zetas, out)
    }

    /// Like [`ContactSolver::contacts`] for the flanks `side` (driving or back flanks). A pinion
    /// angle beyond [`ContactSolver::max_angle`] gives no contacts (its tooth-pair numbers would
    /// not be exact); check it first.
    pub fn contacts_on(
        &self,
        side: FlankSide,
        phi_p: f64,
        phi_g: f64,
        zetas: &[f64],
        out: &mut Vec<ContactPoint>,
    ) -> ReducedAngles {
        self.contacts_posed(side, phi_p, phi_g, (zetas, &[]), None, out)
    }

    /// Like [`ContactSolver::contacts_on`], with the gear body displaced relative to the pinion
    /// by `pose` when given ([`crate::mesh::pose`], "The contact on the displaced geometry"):
    /// in each slice the gear's axis is offset, its tooth turned by the helix for the axial
    /// displacement at the operating pitch point, and each contact's overlap corrected for the
    /// axial displacement at its own point. `(zetas, twists)`: the slices, and
    /// [`ContactSolver::slice_twist`] of each (a model computes them once; with any other
    /// length of `twists` each slice's is computed where it is needed).
    pub(crate) fn contacts_posed(
        &self,
        side: FlankSide,
        phi_p: f64,
        phi_g: f64,
        (zetas, twists): (&[f64], &[SliceTwist]),
        pose: Option<&RelativePose>,
        out: &mut Vec<ContactPoint>,
    ) -> ReducedAngles {
        out.clear();
        let red = self.reduce(phi_p, phi_g);
        if zetas.is_empty() || phi_p.abs() > self.max_angle() {
            return red;
        }
        let g = self.geo;
        let (mn, b, tw) = (g.params.normal_module_m, g.params.face_width_m, g.gear.twist_rate);
        let r_wg = g.gear.rb / g.alpha_wt.cos();
        let w_ref = pose.map_or(0.0, |p| p.axial([-r_wg, 0.0]));
        let zmin = zetas.iter().copied().fold(f64::INFINITY, f64::min);
        let zmax = zetas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // The pair window holds for the nominal geometry; a pose moves the contact by at most
        // 0.05·m_n plus the helix turn, well inside its half-pitch margin.
        let (lo, hi) = self.pair_range(red.phi_p, zmin, zmax, side);
        // The gear tooth turned by the helix for the axial displacement at the pitch point.
        let phi_g = if pose.is_some() { red.phi_g - tw * w_ref } else { red.phi_g };
        // Each tooth's turn is its pair's base turn plus the helix's turn at the slice: one
        // `sin_cos` per pair and gear, the slices' from `twists` ([`SliceTwist`]; computed
        // here, slice by slice, when not given).
        let given = twists.len() == zetas.len();
        for k in lo..=hi {
            let (base_p, base_g) = self.theta_base(side, red.phi_p, phi_g, k);
            let (turn_p, turn_g) = (Turn::new(base_p), Turn::new(base_g));
            for (i, &zeta) in zetas.iter().enumerate() {
                let tw_z = if given { twists[i] } else { self.slice_twist(zeta) };
                let z_m = zeta * mn;
                let tp = Turn::added(turn_p, base_p + g.pinion.twist_rate * z_m, tw_z.pinion);
                let tg = Turn::added(turn_g, base_g + g.gear.twist_rate * z_m, tw_z.gear);
                let found = match pose {
                    None => self.contact_walk(side, tp, tg, zeta, self.center_g),
                    Some(pose) => {
                        let o = pose.axis_offset(zeta * mn, b);
                        let center = [self.center_g[0] + o[0], self.center_g[1] + o[1]];
                        self.contact_walk(side, tp, tg, zeta, center).map(|mut c| {
                            let rho = [c.point_g[0] - center[0], c.point_g[1] - center[1]];
                            c.overlap_m -= c.arm_g_m * tw * (pose.axial(rho) - w_ref);
                            c
                        })
                    }
                };
                if let Some(mut c) = found {
                    // |k| is a few pitches and |pitches| ≤ 2⁵³ here: no overflow.
                    c.pair = k - red.pitches;
                    out.push(c);
                }
            }
        }
        red
    }

    /// Tooth rotation angles (Θp, Θg), rad, of the teeth of contact `pair` (as numbered in
    /// [`ContactPoint::pair`]) on flanks `side` at slice `zeta`, for the reduced angles `red`
    /// of the call that found the contact. Θ = φ + constant, so ∂Θp/∂φp = ∂Θg/∂φg = 1.
    pub(crate) fn tooth_angles(
        &self,
        side: FlankSide,
        red: &ReducedAngles,
        pair: i64,
        zeta: f64,
    ) -> (f64, f64) {
        self.theta(side, red.phi_p, red.phi_g, pair + red.pitches, zeta)
    }

    /// Tooth rotation angles (Θp, Θg) of pair `k` at slice `zeta` for reduced angles.
    fn theta(&self, side: FlankSide, phi_p: f64, phi_g: f64, k: i64, zeta: f64) -> (f64, f64) {
        let g = self.geo;
        let z_m = zeta * g.params.normal_module_m;
        let (bp, bg) = self.theta_base(side, phi_p, phi_g, k);
        (bp + g.pinion.twist_rate * z_m, bg + g.gear.twist_rate * z_m)
    }

    /// The tooth rotation angles of pair `k` at ζ = 0 (rad); the helix adds twist_rate·ζ·m_n
    /// at slice ζ ([`ContactSolver::theta`]).
    fn theta_base(&self, side: FlankSide, phi_p: f64, phi_g: f64, k: i64) -> (f64, f64) {
        let g = self.geo;
        let gear_tooth = match side {
            FlankSide::Drive => -k,
            FlankSide::Back => 1 - k,
        };
        let tp = phi_p + self.psi0_p + g.pinion.angular_pitch() * k as f64;
        let tg = phi_g + self.psi0_g + g.gear.angular_pitch() * gear_tooth as f64;
        (tp, tg)
    }

    /// The helix's turn of each tooth at slice `zeta` ([`SliceTwist`]).
    pub(crate) fn slice_twist(&self, zeta: f64) -> SliceTwist {
        let g = self.geo;
        let z_m = zeta * g.params.normal_module_m;
        SliceTwist {
            pinion: (g.pinion.twist_rate * z_m).sin_cos(),
            gear: (g.gear.twist_rate * z_m).sin_cos(),
        }
    }

    /// Solves one combination of pieces; returns up to two trial normals.
    fn trials(
        &self,
        pp: Piece,
        pg: Piece,
        tp: Turn,
        tg: Turn,
        center_g: [f64; 2],
        buf: &mut [Option<Trial>; 2],
    ) {
        *buf = [None, None];
        let a1 = tp.apply(pp.anchor());
        let ag = tg.apply(pg.anchor());
        let a2 = [center_g[0] + ag[0], center_g[1] + ag[1]];
        let d = [a2[0] - a1[0], a2[1] - a1[1]];
        // Anchors are a gear's size apart at most: no overflow, and `hypot`'s scaling is not
        // needed.
        let dist = (d[0] * d[0] + d[1] * d[1]).sqrt();
        if dist <= 0.0 {
            return;
        }
        let s = (pp.offset() + pg.offset()) / dist;
        if !(-1.0..=1.0).contains(&s) {
            return;
        }
        let delta = d[1].atan2(d[0]);
        let asin = s.asin();
        // ν = δ + a and ν = δ + π − a with δ the direction of d and a = asin s (cos a ≥ 0):
        // their sines and cosines by the angle-addition formulas, without `sin_cos`.
        let (sd, cd) = (d[1] / dist, d[0] / dist);
        let ca = ((1.0 - s) * (1.0 + s)).sqrt();
        let candidates = [
            (delta + asin, sd * ca + cd * s, cd * ca - sd * s),
            (delta + PI - asin, cd * s - sd * ca, -cd * ca - sd * s),
        ];
        for (slot, (nu, sn, cn)) in buf.iter_mut().zip(candidates) {
            // The pinion's outward normal must point towards the gear side.
            if cn * center_g[0] + sn * center_g[1] <= 0.0 {
                continue;
            }
            let mid_p = 0.5 * (pp.nu_min() + pp.nu_max());
            let mid_g = 0.5 * (pg.nu_min() + pg.nu_max());
            let nu_p_local = wrap_near(nu - tp.angle, mid_p);
            let nu_g_local = wrap_near(nu + PI - tg.angle, mid_g);
            *slot = Some(Trial {
                nu,
                sin_nu: sn,
                cos_nu: cn,
                nu_p_local,
                nu_g_local,
                side_p: pp.step_towards(nu_p_local),
                side_g: pg.step_towards(nu_g_local),
            });
        }
    }

    /// Builds the contact record of a valid trial.
    #[allow(clippy::too_many_arguments)]
    fn build(
        &self,
        side: FlankSide,
        pp: Piece,
        pg: Piece,
        tr: &Trial,
        tp: Turn,
        tg: Turn,
        zeta: f64,
        center_g: [f64; 2],
    ) -> ContactPoint {
        let g = self.geo;
        let (s, c) = (tr.sin_nu, tr.cos_nu);
        let n = [c, s];
        let m = [s, -c];
        let a1 = tp.apply(pp.anchor());
        let ag = tg.apply(pg.anchor());
        let a2 = [center_g[0] + ag[0], center_g[1] + ag[1]];
        let d = [a2[0] - a1[0], a2[1] - a1[1]];
        let l1 = pp.reach(tr.nu_p_local);
        let l2 = pg.reach(tr.nu_g_local);
        let (k1, k2) = (pp.offset(), pg.offset());
        let p1 = [a1[0] + k1 * m[0] + l1 * n[0], a1[1] + k1 * m[1] + l1 * n[1]];
        let p2 = [a2[0] - k2 * m[0] - l2 * n[0], a2[1] - k2 * m[1] - l2 * n[1]];
        let overlap = l1 + l2 - (d[0] * n[0] + d[1] * n[1]);
        let arm_p = p1[0] * m[0] + p1[1] * m[1];
        let r2 = [p2[0] - center_g[0], p2[1] - center_g[1]];
        let arm_g = -(r2[0] * m[0] + r2[1] * m[1]);
        let mn = g.params.normal_module_m;
        // Flank coordinates in the unmirrored tooth frame (η* uses x only, τ the normal angle).
        let flank_coords = |gear: &GearGeometry, piece: Piece, local: [f64; 2], nu_local: f64| {
            let nu = if piece.mirror { -nu_local } else { nu_local };
            let eta = (gear.eta_reference_x - local[0]) / mn;
            let tau = match piece.prim.kind {
                SegmentKind::Rounding | SegmentKind::Tip => (gear.nu_rounding_start - nu).max(0.0),
                _ => 0.0,
            };
            (eta, tau)
        };
        let (eta_p, tau_p) = flank_coords(&g.pinion, pp, tp.apply_inverse(p1), tr.nu_p_local);
        let (eta_g, tau_g) = flank_coords(&g.gear, pg, tg.apply_inverse(r2), tr.nu_g_local);
        ContactPoint {
            zeta,
            pair: 0,
            side,
            kind_p: pp.prim.kind,
            kind_g: pg.prim.kind,
            overlap_m: overlap,
            normal_angle: tr.nu,
            point_p: p1,
            point_g: p2,
            rho_p_m: l1,
            rho_g_m: l2,
            arm_p_m: arm_p,
            arm_g_m: arm_g,
            radius_p_m: (p1[0] * p1[0] + p1[1] * p1[1]).sqrt(),
            radius_g_m: (r2[0] * r2[0] + r2[1] * r2[1]).sqrt(),
            eta_star_p: eta_p,
            tau_p,
            eta_star_g: eta_g,
            tau_g,
        }
    }

    /// Driving-flank contact of pair `k` (relative to the reduced angles) at slice `zeta`.
    pub fn contact_fast(&self, phi_p: f64, phi_g: f64, k: i64, zeta: f64) -> Option<ContactPoint> {
        self.contact_fast_on(FlankSide::Drive, phi_p, phi_g, k, zeta)
    }

    /// Contact of pair `k` on flanks `side` at slice `zeta`: a walk over the pieces from the
    /// involute/involute combination towards the valid one (at most a few steps); `None` when
    /// the common normal runs off an active flank (the pair is out of mesh in this slice), with
    /// the exhaustive search as fallback if the walk does not settle.
    pub fn contact_fast_on(
        &self,
        side: FlankSide,
        phi_p: f64,
        phi_g: f64,
        k: i64,
        zeta: f64,
    ) -> Option<ContactPoint> {
        let (tp, tg) = self.theta(side, phi_p, phi_g, k, zeta);
        self.contact_walk(side, Turn::new(tp), Turn::new(tg), zeta, self.center_g)
    }

    /// [`Self::contact_fast_on`] with the teeth turned by `tp` and `tg` and the gear's centre
    /// in this slice at `center_g` (m).
    fn contact_walk(
        &self,
        side: FlankSide,
        tp: Turn,
        tg: Turn,
        zeta: f64,
        center_g: [f64; 2],
    ) -> Option<ContactPoint> {
        let mirror = side == FlankSide::Back;
        let fp = &self.geo.pinion.flank.primitives;
        let fg = &self.geo.gear.flank.primitives;
        let (mut i, mut j) = (0usize, 0usize);
        let mut buf = [None, None];
        for _ in 0..(2 * (fp.len() + fg.len())) {
            let pp = Piece { prim: &fp[i], mirror };
            let pg = Piece { prim: &fg[j], mirror };
            self.trials(pp, pg, tp, tg, center_g, &mut buf);
            // Pick the trial closest to valid.
            let best = buf.iter().flatten().min_by_key(|t| t.side_p.abs() + t.side_g.abs());
            let Some(t) = best else { break };
            if t.side_p == 0 && t.side_g == 0 {
                return Some(self.build(side, pp, pg, t, tp, tg, zeta, center_g));
            }
            let ni = (i as i64 + t.side_p as i64).clamp(0, fp.len() as i64 - 1) as usize;
            let nj = (j as i64 + t.side_g as i64).clamp(0, fg.len() as i64 - 1) as usize;
            if (ni, nj) == (i, j) {
                // The solution runs off the active flank: no contact in this slice (the test
                // `fast_walk_equals_exhaustive_search` checks this against the full search).
                return None;
            }
            i = ni;
            j = nj;
        }
        self.contact_search(side, tp, tg, zeta, center_g)
    }

    /// Driving-flank contact of pair `k` at slice `zeta` by trying every combination of pieces.
    pub fn contact_exhaustive(
        &self,
        phi_p: f64,
        phi_g: f64,
        k: i64,
        zeta: f64,
    ) -> Option<ContactPoint> {
        self.contact_exhaustive_on(FlankSide::Drive, phi_p, phi_g, k, zeta)
    }

    /// Contact of pair `k` on flanks `side` at slice `zeta` by trying every combination of
    /// pieces (reference implementation; used as fallback and in tests).
    pub fn contact_exhaustive_on(
        &self,
        side: FlankSide,
        phi_p: f64,
        phi_g: f64,
        k: i64,
        zeta: f64,
    ) -> Option<ContactPoint> {
        let (tp, tg) = self.theta(side, phi_p, phi_g, k, zeta);
        self.contact_search(side, Turn::new(tp), Turn::new(tg), zeta, self.center_g)
    }

    /// [`Self::contact_exhaustive_on`] with the teeth turned by `tp` and `tg` and the gear's
    /// centre in this slice at `center_g` (m).
    fn contact_search(
        &self,
        side: FlankSide,
        tp: Turn,
        tg: Turn,
        zeta: f64,
        center_g: [f64; 2],
    ) -> Option<ContactPoint> {
        let mirror = side == FlankSide::Back;
        let mut best: Option<ContactPoint> = None;
        let mut buf = [None, None];
        for prim_p in &self.geo.pinion.flank.primitives {
            for prim_g in &self.geo.gear.flank.primitives {
                let pp = Piece { prim: prim_p, mirror };
                let pg = Piece { prim: prim_g, mirror };
                self.trials(pp, pg, tp, tg, center_g, &mut buf);
                for t in buf.iter().flatten() {
                    if t.side_p == 0 && t.side_g == 0 {
                        let c = self.build(side, pp, pg, t, tp, tg, zeta, center_g);
                        if best.is_none_or(|b| c.overlap_m > b.overlap_m) {
                            best = Some(c);
                        }
                    }
                }
            }
        }
        best
    }
}
