//! The 3D force and moments of the mesh on each gear: what the mesh does to the shafts.
//!
//! # Frame
//! Fixed to the housing, right-handed: origin on the pinion axis in the end face ζ = 0; `z`
//! along the pinion axis towards ζ = b₀ (z = ζ·m_n); `x` from the pinion axis to the gear axis
//! along the line of centres; `y = z × x`. The pinion centre at mid-face is (0, 0, b/2), the
//! gear centre (a, 0, b/2), a the operating centre distance, b the face width.
//!
//! This is the contact module's fixed transverse frame ([`crate::contact`]) extended by z: its
//! pinion axis is the origin, its gear axis the point (a, 0), and both the pinion tooth angle
//! Θp = φp + … and the gear tooth angle Θg = φg + … turn the profiles counter-clockwise in
//! (x, y), i.e. positive about +z. So both φp and φg are positive about +z; in normal drive φp
//! grows and φg falls. The helix twists the pinion's transverse profile by +ω_p·z
//! (ω_p = tan β/r_p, right hand) and the gear's by ω_g·z (ω_g = −tan β/r_g, left hand).
//!
//! # Outputs
//! `F_p` is the force of all contacts on the pinion (N), `F_g = −F_p` the force on the gear.
//! `M_p`, `M_g` are their moments about each gear's centre at mid-face (N·m). The component
//! about the gear's own axis (+z, the sense of its angle φ) is −(M_F + M_D) of that gear
//! (Eqs. 13–14; the torques enter Eqs. 2–3 with a minus sign). The x and y components are the
//! tilting moments, which [`super::MeshOutputs`] reports (`moment_p`, `moment_g`); the z
//! components are the torques already reported.
//!
//! # Elastic part (Eq. 13 in 3D)
//! The pinion flank is a helicoid: the transverse profile p(u) turned by ω_p·z,
//! X(u, z) = (Rot(ω_p·z)·p(u), z). Its tangents are (t, 0) (t the transverse tangent) and
//! ∂X/∂z = (ω_p·J·P, 1) (J the rotation by +90°, P the transverse position), so the normal
//! N = (n_t, N_z) must satisfy n_t·ω_p·J·P + N_z = 0:
//!
//! ```text
//! N_p ∝ (n_t, −ω_p·(P × n_t)_z) = (n_t, −ω_p·s_p)
//! ```
//!
//! with n_t the pinion's outward transverse normal and s_p = (P × n_t)_z its moment arm
//! ([`crate::contact::ContactPoint::arm_p_m`]; the same construction as the FE load direction in
//! `compliance/influence_fe.rs`). The axial-to-transverse ratio is ω_p·s_p = s_p/h_p
//! (h_p = 1/ω_p the lead parameter); on the involute s_p = r_bp and the ratio is
//! r_bp·tan β/r_p = tan β_b. The model's torque M_F,p = Σ s_p·q·m_n·Δζ means the transverse
//! force of a slice is q·m_n·Δζ along n_t, so the force of slice i on the pinion is
//!
//! ```text
//! F_i = −q_i·m_n·Δζ·(cos ν_i, sin ν_i, −ω_p·s_p,i)      at (P1_x, P1_y, ζ_i·m_n)
//! ```
//!
//! (ν the angle of n_t; the gear pushes the pinion flank inwards) and −F_i on the gear at the
//! same point. Its moment about the pinion axis is (P1 × F_i)_z = −q_i·m_n·Δζ·s_p,i: summed, −M_F,p
//! exactly as Eq. 13. About the gear axis the arm of P1 equals the arm of P2 (they differ along
//! n_t), so the z component on the gear is −M_F,g. Back flanks: the same construction with the
//! back flank's n_t and (negative) s_p; the helicoid is the same screw motion, so the formula is
//! unchanged and the axial force reverses with s_p. In normal drive (right-hand pinion) F_p
//! points −x (the mesh pushes the pinion away from the gear: F_x/F_y = tan α_wt on the involute),
//! −y (it resists the pinion's rotation) and +z (F_z/|F_t| = tan β_b). For contacts off the
//! involute (tip rounding, relief) the pinion flank's normal is used; the gear flank's helicoid
//! normal there differs by the (small) non-conjugacy of the surfaces, and Newton's third law is
//! kept by construction.
//!
//! # Damping part (Eq. 14)
//! Eq. 14 is a viscous force along the plane of action, f_D = d_mesh·(φ̇p·r_bp + φ̇g·r_bg)·E,
//! with E = Σ_i e_i the loaded axial extent (e_i the loaded part of slice i, units of m_n,
//! resolved within the slices: [`super::model`], "Slices"), acting at the base radii
//! (M_D,k = f_D·r_bk). It is distributed along the loaded parts of the lines (as E is
//! built), each share along the 3D normal of the plane of action of that slice's flank side,
//! at the operating pitch point (r_wp, 0) in the plane z = ζ·m_n:
//!
//! ```text
//! dF_D = −d_mesh·rate·dζ·(σ·sin α_wt, cos α_wt, −ω_p·r_bp)     at (r_wp, 0, ζ·m_n)
//! ```
//!
//! (σ = +1 driving flanks, −1 back flanks). The pitch point lies on both lines of action, at
//! arm r_wp·cos α_wt = r_bp from the pinion axis and r_wg·cos α_wt = r_bg from the gear axis, so
//! the moment about each axis is exactly −M_D of that gear whatever the distribution; the
//! distribution along the loaded parts puts the damping where the mesh is loaded, and the
//! point makes the damping wrench a function of the loaded extent E and its first axial
//! moment Z₁ = ∫ζ·dζ over the loaded parts alone (which the table carries beside E). With
//! f = d_mesh·rate and c = ζ·m_n − b/2:
//!
//! ```text
//! F_D = −f·E·(σ·sin α_wt, cos α_wt, −tan β_b)
//! M_D,x = f·cos α_wt·(m_n·Z₁ − E·b/2),   M_D,y = −f·σ·sin α_wt·(m_n·Z₁ − E·b/2) − r_wp·f·E·tan β_b
//! ```
//!
//! # Transfer between the centres
//! With F_g = −F_p and the centres C_p = (0, 0, b/2), C_g = (a, 0, b/2):
//! M_g = −M_p − (C_p − C_g) × F_p, i.e. M_g,x = −M_p,x, M_g,y = −M_p,y − a·F_p,z,
//! M_g,z = −M_p,z + a·F_p,y. The full model sums M_g from the contacts directly (the tests hold
//! it against this formula); the table, which carries the pinion's values only, uses it.

use super::MeshOutputs;
use crate::contact::{ContactPoint, FlankSide};
use crate::geometry::PairGeometry;

/// The constants of the mesh's frame and of its planes of action (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceFrame {
    /// Operating centre distance a, m (the gear axis is at x = a).
    pub center_distance: f64,
    /// Half the face width, b/2, m (the centres' z).
    pub half_face: f64,
    /// Normal module m_n, m (z = ζ·m_n).
    pub module: f64,
    /// Twist rate of the pinion's helicoid ω_p = tan β/r_p, rad/m (positive: right hand).
    pub twist_p: f64,
    /// Operating pitch radius of the pinion r_wp = r_bp/cos α_wt, m.
    pub pitch_radius_p: f64,
    /// sin α_wt, cos α_wt of the operating transverse pressure angle.
    pub sin_cos_wt: (f64, f64),
    /// tan β_b taken as ω_p·r_bp (the plane of action's axial-to-transverse ratio, signed by
    /// the pinion's hand).
    pub tan_beta_b: f64,
}

impl ForceFrame {
    /// The frame of `geo`.
    pub fn new(geo: &PairGeometry) -> Self {
        let sin_cos_wt = geo.alpha_wt.sin_cos();
        Self {
            center_distance: geo.center_distance,
            half_face: 0.5 * geo.params.face_width_m,
            module: geo.params.normal_module_m,
            twist_p: geo.pinion.twist_rate,
            pitch_radius_p: geo.pinion.rb / sin_cos_wt.1,
            sin_cos_wt,
            tan_beta_b: geo.pinion.twist_rate * geo.pinion.rb,
        }
    }
}

/// `r × f`.
#[inline]
fn cross(r: [f64; 3], f: [f64; 3]) -> [f64; 3] {
    [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
}

/// The force of the mesh on the pinion and the moments on both gears, summed over contacts
/// (see the module docs): the force on the gear is −`force_p`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeshWrench {
    /// Force on the pinion F_p (x, y, z), N.
    pub force_p: [f64; 3],
    /// Moment of F_p about the pinion centre (0, 0, b/2) (x, y, z), N·m.
    pub moment_p: [f64; 3],
    /// Moment of F_g = −F_p about the gear centre (a, 0, b/2) (x, y, z), N·m.
    pub moment_g: [f64; 3],
}

impl MeshWrench {
    /// The wrench of a force `force` on the pinion at `point` (m, frame of the module docs).
    #[inline]
    pub fn of_force(frame: &ForceFrame, point: [f64; 3], force: [f64; 3]) -> Self {
        let rp = [point[0], point[1], point[2] - frame.half_face];
        let rg = [point[0] - frame.center_distance, point[1], point[2] - frame.half_face];
        let fg = [-force[0], -force[1], -force[2]];
        Self { force_p: force, moment_p: cross(rp, force), moment_g: cross(rg, fg) }
    }

    /// The elastic wrench of one slice: transverse force `transverse_n` = q·m_n·Δζ (N) along
    /// the contact's normal, on the pinion flank's helicoid normal at (P1, ζ·m_n).
    #[inline]
    pub fn of_contact(frame: &ForceFrame, c: &ContactPoint, transverse_n: f64) -> Self {
        let (s, co) = c.normal_angle.sin_cos();
        let force =
            [-transverse_n * co, -transverse_n * s, transverse_n * frame.twist_p * c.arm_p_m];
        let point = [c.point_p[0], c.point_p[1], c.zeta * frame.module];
        Self::of_force(frame, point, force)
    }

    /// The damping wrench of Eq. 14 (module docs) on one flank side: `f` = d_mesh·rate (N per
    /// unit of extent, signed as the rate of TE), `extent` E = ΣΔζ and `first_moment`
    /// Z₁ = Σζ·Δζ of the loaded slices of that side (units of m_n, m_n²).
    pub fn of_damping(
        frame: &ForceFrame,
        side: FlankSide,
        f: f64,
        extent: f64,
        first_moment: f64,
    ) -> Self {
        let sigma = if side == FlankSide::Back { -1.0 } else { 1.0 };
        let (sin_wt, cos_wt) = frame.sin_cos_wt;
        let fe = f * extent;
        let force = [-fe * sigma * sin_wt, -fe * cos_wt, fe * frame.tan_beta_b];
        // Σ f·Δζ·(ζ·m_n − b/2): the lever of the axial distribution about mid-face.
        let lever = f * (frame.module * first_moment - extent * frame.half_face);
        let moment_p = [
            lever * cos_wt,
            -lever * sigma * sin_wt - frame.pitch_radius_p * force[2],
            frame.pitch_radius_p * force[1],
        ];
        let pinion = Self { force_p: force, moment_p, moment_g: [0.0; 3] };
        Self { moment_g: pinion.transferred_moment_g(frame), ..pinion }
    }

    /// The wrench from the pinion's force and moment alone, the gear's moment by the transfer
    /// formula M_g = −M_p − (C_p − C_g) × F_p (module docs).
    pub fn from_pinion(frame: &ForceFrame, force_p: [f64; 3], moment_p: [f64; 3]) -> Self {
        let w = Self { force_p, moment_p, moment_g: [0.0; 3] };
        Self { moment_g: w.transferred_moment_g(frame), ..w }
    }

    /// M_g by the transfer formula from this wrench's F_p and M_p, N·m.
    pub fn transferred_moment_g(&self, frame: &ForceFrame) -> [f64; 3] {
        let a = frame.center_distance;
        [
            -self.moment_p[0],
            -self.moment_p[1] - a * self.force_p[2],
            -self.moment_p[2] + a * self.force_p[1],
        ]
    }

    /// Adds `other` component by component.
    #[inline]
    pub fn add(&mut self, other: &Self) {
        for k in 0..3 {
            self.force_p[k] += other.force_p[k];
            self.moment_p[k] += other.moment_p[k];
            self.moment_g[k] += other.moment_g[k];
        }
    }

    /// Writes the reported components into `out`: `force_p`, `force_g` = −`force_p`, and the
    /// tilting moments (x, y) of `moment_p` and `moment_g`.
    pub fn write(&self, out: &mut MeshOutputs) {
        out.force_p = self.force_p;
        out.force_g = [-self.force_p[0], -self.force_p[1], -self.force_p[2]];
        out.moment_p = [self.moment_p[0], self.moment_p[1]];
        out.moment_g = [self.moment_g[0], self.moment_g[1]];
    }
}
