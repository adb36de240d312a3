//! The gear bodies off their nominal bearing axes: the small rigid displacement of each body
//! (its pose) and how the contact search sees it — a specification.
//!
//! # Pose
//! Each gear body's small displacement from its nominal bearing axis, at its centre at
//! mid-face, in the housing frame of [`super::forces`] (origin on the pinion axis in the end
//! face ζ = 0, `x` towards the gear axis, `z` along the pinion axis): translation
//! `u = (u_x, u_y, u_z)` (m) and tilts `θ = (θ_x, θ_y)` (rad, right-handed about the frame's x
//! and y axes through that centre). The rotation about the body's own axis stays its angle φ.
//! The rates ([`super::MeshState::rate_p`], [`super::MeshState::rate_g`]) are u̇ (m/s) and θ̇ (rad/s). All
//! zero by default, and then every result is the rigid-bearing model's bit for bit. A positive
//! gear `u_x` opens the centre distance.
//!
//! A material point at r of a body with pose (u, θ) moves by d(r) = u + θ × (r − c), c the
//! body's centre (pinion (0, 0, b/2), gear (a, 0, b/2)); small rotations commute, so this is
//! exact to first order in the pose.
//!
//! # The gear seen from the pinion
//! Only the relative motion of the two bodies changes the contact. The mesh is evaluated in the
//! frame that moves with the pinion body, where the pinion is at its nominal place and the gear
//! is displaced by the relative field d_g(r) − d_p(r) = U + Θ × (r − c_g) with
//!
//! ```text
//! U = u_g − u_p − θ_p × (c_g − c_p) = (u_gx − u_px, u_gy − u_py, u_gz − u_pz + θ_py·a)
//! Θ = θ_g − θ_p
//! ```
//!
//! so translating both bodies by the same vector, or tilting both by the same angle about a
//! common point, changes nothing.
//!
//! # The contact on the displaced geometry
//! The contact search ([`crate::contact`]) works in transverse slices z = ζ·m_n of the pinion.
//! In slice z the gear is displaced
//! * **in its plane** by the offset of its axis there,
//!   `o(z) = (U_x + Θ_y·(z − b/2), U_y − Θ_x·(z − b/2))`: the gear's centre in that slice is
//!   (a + o_x, o_y), and the common normal, the overlap, the contact points, the moment arms and
//!   the radii of curvature are those of the true flanks at that centre. So the centre distance,
//!   the operating pressure angle and the backlash of every slice follow the pose exactly (no
//!   projection): a gear moved by Δa along x opens the driving flanks by Δa·sin α_wt and the
//!   back flanks by as much;
//! * **along its axis** by w(ρ) = U_z + Θ_x·ρ_y − Θ_y·ρ_x at a transverse offset ρ from its
//!   (displaced) axis. The gear's flank is a helicoid: the gear's section in the plane z is its
//!   body's section at z − w, which is the section at z turned by −ω_g·w (ω_g the gear's twist
//!   rate, [`crate::geometry`]). The search turns the gear's tooth by −ω_g·w_ref with w_ref the
//!   value at the operating pitch point ρ = (−r_wg, 0) (r_wg = r_bg/cos α_wt),
//!   w_ref = U_z + Θ_y·r_wg, and then
//!   corrects the overlap of each contact for the difference at its own point P2:
//!   Δ += −s_g·ω_g·(w(P2 − c) − w_ref) (∂Δ/∂Θg = s_g, the gear's moment arm). The correction
//!   is of order |Θ|·|P2 − pitch point|·tan β_b, its error of second order.
//!
//! # What is first order
//! The slices stay the pinion's: both faces are taken over ζ ∈ [0, b₀] of the pinion. A
//! relative axial shift w moves the gear's face ends by w; the strip of width |w| at one end,
//! counted as in mesh, carries a share of order |w|/b of the load (1 % for w = 0.05·m_n =
//! 150 µm on Table 1's b = 15 mm). The gear's compliance is looked up at the pinion's ζ (the same
//! shift, w/m_n in ζ). The tilt of the transverse sections (cos Θ − 1) is of second order.
//! The torques M_F,g and M_D,g are taken about the z axis of the pinion's frame; about the
//! gear's own axis, tilted by Θ relative to it, they differ by Θ_y·M_x − Θ_x·M_y (the relative
//! tilt times the tilting moments on the gear), which is not added.
//!
//! # Forces
//! The contact forces are found in the pinion's frame ([`super::forces`]), with the moments
//! about the displaced centres: the gear's moment is moved from c_g to c_g + U by
//! M ← M − U × F_g. The frame's tilt θ_p then turns every vector into the housing frame:
//! v ← v + θ_p × v (with θ_p = (θ_px, θ_py, 0)).
//!
//! # Damping (Eq. 14)
//! Eq. 14 damps the rate of the approach along the plane of action, φ̇p·r_bp + φ̇g·r_bg. The
//! body motion adds the rate of the relative displacement at the pitch point at mid-face
//! projected on the driving flanks' normal n = (sin α_wt, cos α_wt) (the pinion's outward
//! normal on the plane of action), with the axial part through the helix:
//!
//! ```text
//! ḋ_pose = −(U̇_x·sin α_wt + U̇_y·cos α_wt) − r_bg·ω_g·(U̇_z + Θ̇_y·r_wg)
//! ```
//!
//! (the tilt rates' in-plane parts are zero at mid-face; their moment about the face is not
//! damped, as the paper's Eq. 14 damps only the mean approach).
//!
//! # Jacobian
//! The full model's Jacobian ([`super::MeshJacobian::pose`]) holds the exact derivatives of the
//! torques with respect to every pose and rate component, at rest and at any pose within the
//! bounds (module docs of `model/jacobian.rs`, "Body poses"). The table evaluates a pose with
//! its pose sensitivities (`table/pose.rs`, built at the first posed state), but its Jacobian
//! refuses one; with friction the pose columns are not provided (`None`).
//!
//! # Bounds
//! Small displacements: every translation component within ±[`MAX_TRANSLATION_MN`]·m_n and
//! every tilt within ±[`MAX_TRANSLATION_MN`]·m_n/b (the tilt moves a face end by at most half
//! that) per body; every rate within 2·10⁵ rad/s (the largest speed of the mesh state,
//! [`super::validity::MAX_STATE_SPEED_RAD_S`]) times that bound: the speed of a vibration of
//! that amplitude at that frequency, which keeps the damping torque finite. A pose or rate
//! beyond it is an error naming the component by its interface name (`u_g_x`, …,
//! [`INPUT_NAMES`]) with the value and the limit. Soft supports deflect by tens of
//! micrometres; the bounds are 150 µm, 0.01 rad, 30 m/s and 2 000 rad/s for Table 1
//! (m_n = 3 mm, b = 15 mm).

use crate::error::ParamError;
use crate::geometry::PairGeometry;

/// The largest translation of a body, in units of m_n (and the largest tilt times b/m_n).
pub const MAX_TRANSLATION_MN: f64 = 0.05;

/// A gear body's small displacement from its nominal bearing axis at its centre at mid-face
/// (module docs), or its rate.
///
/// As a pose: translations m, tilts rad. As a rate: m/s and rad/s. Housing frame of
/// [`super::forces`]; tilts right-handed about the frame's x and y axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyPose {
    /// Translation along x (towards the gear axis), m (m/s as a rate).
    pub u_x: f64,
    /// Translation along y = z × x, m (m/s).
    pub u_y: f64,
    /// Translation along z (the pinion axis, towards ζ = b₀), m (m/s).
    pub u_z: f64,
    /// Tilt about x, rad (rad/s).
    pub th_x: f64,
    /// Tilt about y, rad (rad/s).
    pub th_y: f64,
}

impl BodyPose {
    /// The five components in the order u_x, u_y, u_z, th_x, th_y.
    #[inline]
    pub fn values(&self) -> [f64; 5] {
        [self.u_x, self.u_y, self.u_z, self.th_x, self.th_y]
    }

    /// A pose from the five components in the order of [`Self::values`].
    pub fn from_values(v: [f64; 5]) -> Self {
        Self { u_x: v[0], u_y: v[1], u_z: v[2], th_x: v[3], th_y: v[4] }
    }

    /// True when every component is zero (the rigid-bearing model).
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.u_x == 0.0
            && self.u_y == 0.0
            && self.u_z == 0.0
            && self.th_x == 0.0
            && self.th_y == 0.0
    }
}

/// The interface names of the twenty pose inputs, in the order pose_p, pose_g, rate_p,
/// rate_g (five components each, as [`BodyPose::values`]): the FMU input names of
/// `HelicalGearMesh`, the Python keywords and the names in error messages.
pub const INPUT_NAMES: [&str; 20] = [
    "u_p_x", "u_p_y", "u_p_z", "th_p_x", "th_p_y", "u_g_x", "u_g_y", "u_g_z", "th_g_x", "th_g_y",
    "v_p_x", "v_p_y", "v_p_z", "om_p_x", "om_p_y", "v_g_x", "v_g_y", "v_g_z", "om_g_x", "om_g_y",
];

/// The twenty pose inputs of `state` in the order of [`INPUT_NAMES`].
pub fn inputs_of(state: &super::MeshState) -> [f64; 20] {
    let mut v = [0.0; 20];
    for (k, b) in [state.pose_p, state.pose_g, state.rate_p, state.rate_g].iter().enumerate() {
        v[5 * k..5 * k + 5].copy_from_slice(&b.values());
    }
    v
}

/// Sets the poses and rates of `state` from twenty values in the order of [`INPUT_NAMES`].
pub fn set_inputs(state: &mut super::MeshState, v: &[f64; 20]) {
    let part = |k: usize| {
        BodyPose::from_values([v[5 * k], v[5 * k + 1], v[5 * k + 2], v[5 * k + 3], v[5 * k + 4]])
    };
    (state.pose_p, state.pose_g, state.rate_p, state.rate_g) = (part(0), part(1), part(2), part(3));
}

pub(crate) use crate::contact::RelativePose;

impl RelativePose {
    /// U and Θ of the gear `g` relative to the pinion `p` for centre distance `a` (m). The
    /// same map takes the rates to the relative rates.
    pub fn new(p: &BodyPose, g: &BodyPose, a: f64) -> Self {
        Self {
            u: [g.u_x - p.u_x, g.u_y - p.u_y, g.u_z - p.u_z + p.th_y * a],
            th: [g.th_x - p.th_x, g.th_y - p.th_y],
        }
    }

    /// An upper bound (m) of the change of any slice's overlap the pose can make: the axis
    /// offset at either face end plus the axial displacement within the gear's tip circle
    /// turned into an angle and back along the flank's moment arm.
    pub fn overlap_reach(&self, geo: &PairGeometry) -> f64 {
        let b = geo.params.face_width_m;
        let hb = 0.5 * b * (self.th[0].abs() + self.th[1].abs());
        let plane = self.u[0].abs() + self.u[1].abs() + hb;
        let ra = geo.gear.ra;
        let axial = self.u[2].abs() + ra * (self.th[0].abs() + self.th[1].abs());
        plane + axial * (geo.gear.twist_rate * ra).abs()
    }
}

/// Checks both poses and their rates: finite, and each pose component within its bound (module
/// docs, "Bounds"). The error names the component by its interface name ([`INPUT_NAMES`],
/// `u_g_x`, …), with the value and the limit.
pub(crate) fn check(geo: &PairGeometry, state: &super::MeshState) -> Result<(), ParamError> {
    let mn = geo.params.normal_module_m;
    let b = geo.params.face_width_m;
    let u_max = MAX_TRANSLATION_MN * mn;
    let th_max = u_max / b;
    let w = super::validity::MAX_STATE_SPEED_RAD_S;
    for (k, (name, v)) in INPUT_NAMES.iter().zip(inputs_of(state)).enumerate() {
        let (lim, what) = match (k < 10, k % 5 < 3) {
            (true, true) => (u_max, "m (0.05·m_n)"),
            (true, false) => (th_max, "rad (0.05·m_n/b)"),
            (false, true) => (w * u_max, "m/s (2e5 rad/s times the translation bound)"),
            (false, false) => (w * th_max, "rad/s (2e5 rad/s times the tilt bound)"),
        };
        if !(v.is_finite() && v.abs() <= lim) {
            return Err(ParamError::new(
                name,
                v,
                format!("finite, |value| <= {lim:.4e} {what}: a small motion of the gear body"),
            ));
        }
    }
    Ok(())
}

/// Turns the wrench found in the pinion's frame into the housing frame (module docs,
/// "Forces"): the gear's moment about its displaced centre, then every vector turned by the
/// pinion's tilt.
pub(crate) fn to_housing(w: &mut super::MeshWrench, rel: &RelativePose, pose_p: &BodyPose) {
    let fg = [-w.force_p[0], -w.force_p[1], -w.force_p[2]];
    for (m, d) in w.moment_g.iter_mut().zip(cross(rel.u, fg)) {
        *m -= d;
    }
    let th = [pose_p.th_x, pose_p.th_y, 0.0];
    for v in [&mut w.force_p, &mut w.moment_p, &mut w.moment_g] {
        let t = cross(th, *v);
        for (c, d) in v.iter_mut().zip(t) {
            *c += d;
        }
    }
}

/// The rate of the approach the body motion adds at the pitch point at mid-face, along the
/// driving flanks' normal (module docs, "Damping"), m/s, from the relative rates `rate`.
pub(crate) fn approach_rate(geo: &PairGeometry, rate: &RelativePose) -> f64 {
    let (s, c) = geo.alpha_wt.sin_cos();
    let r_wg = geo.gear.rb / c;
    -(rate.u[0] * s + rate.u[1] * c)
        - geo.gear.rb * geo.gear.twist_rate * (rate.u[2] + rate.th[1] * r_wg)
}

#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
