//! Single tooth-pair stiffness at the pitch point under a uniform line load, in the convention
//! of ISO 6336-1 (c′, N/(mm·µm)).
//!
//! # The load case
//! Tooth pair 0 is turned so that its contact line passes the pitch point at mid face:
//! φp = −ϑ_p·b/2 with ϑ_p the pinion's helix twist rate (rad/m), and φg from TE = 0. At this
//! position the whole line lies on the involutes, well inside the path of contact. It is cut
//! into `slices` equal axial slices (ζ_i at the slice centres, contact-line length per slice
//! w = m_n·Δζ/cos β_b) and loaded with a uniform load intensity q (N per m of contact line)
//! that carries the whole torque T = |`torque_nm`| (the argument, N·m) on this one pair: the transverse
//! force at the pinion base circle is F_bt = T/r_bp, the normal force F_n = F_bt/cos β_b and
//! the contact-line length L = b/cos β_b, so
//!
//! ```text
//! q = F_n/L = F_bt/b = T/(r_bp·b).
//! ```
//!
//! # The deflection
//! The normal approach of slice i (along the contact normal, in the normal section, as the
//! second line of Eq. 12) is
//!
//! ```text
//! u_i = Σ_j (α*_p(i, j) + α*_g(i, j))·q·w + u_c,p(q, ρ_n,i) + u_c,g(q, ρ_n,i),
//! ```
//!
//! the global part from the same-tooth compliance of both gears (neighbour teeth unloaded) and
//! the Weber–Banaschek local part of both flanks with the same depth h
//! ([`super::hertz::LocalContact::deformation`]) and the normal-section radii of curvature
//! ρ_n = ρ_t/cos β_b (ρ_t the transverse radii of the contact). The mean over the slices is ū.
//!
//! # ISO convention
//! ISO 6336-1 defines c′ as the force per unit face width, in the transverse plane along the
//! line of action, divided by the deflection along that line. By the first line of Eq. 12 a
//! normal approach u corresponds to a displacement u/cos β_b along the transverse line of
//! action, and the transverse force per unit face width is F_bt/b = q (above), so
//!
//! ```text
//! c′ = q / (ū/cos β_b) = q·cos β_b/ū      [N/m²; 1 N/(mm·µm) = 10⁹ N/m²].
//! ```
//!
//! # Table 1, and ISO 6336-1
//! With the embedded data (T = 100 N·m, q = 155.5 N/mm, interpolated grids) the mean normal
//! approach is 30.6 µm: pinion global 10.19 µm (33 %), gear global 18.63 µm (61 %), local
//! 1.76 µm (6 %); δ_t = 31.0 µm and c′ = 5.02 N/(mm·µm). The fitted formula gives 5.01;
//! 50 to 400 slices agree to 10⁻⁴. The refined mesh
//! ([`super::fe::gear_mesh::GearMeshDensity::refined`]) changes the pair compliance by +0.9 %
//! (c′ = 4.97; pinion global +1.4 %, gear global +0.7 %).
//!
//! Method B of ISO 6336-1 gives, for z_n = 31.4/49.2, x = 0, h_fP = 1.25·m_n, α_n = 20°:
//! q′ = 0.05743 mm·µm/N, c′_th = 1/q′ = 17.41, C_M = 0.8, C_R = 1 (solid discs), C_B = 0.975,
//! c′ = c′_th·C_M·C_R·C_B·cos β = 13.4 N/(mm·µm). Why this model is 2.7 times softer:
//! * **Body torsion to the bore.** The FE bodies are fixed at the 15 mm bore, so the global
//!   part contains both discs between the bore and the teeth. Fixed instead near the rim
//!   radius r_K = r_f − 2·m_n (bore r_K/1.06: teeth and rim only) the global parts are 3.76 µm
//!   (pinion) and 3.59 µm (gear) and c′ = 16.8 N/(mm·µm): the bodies carry 6.4 µm and 15.0 µm,
//!   70 % of the total. The annulus solution θ = T/(4πGb)·(r_i⁻² − r_K⁻²) accounts for
//!   4.8 µm and 12.2 µm of it (normal approach; the gear carries T·r_bg/r_bp); the rest is the
//!   web and rim under a load concentrated on one tooth. ISO's C_R = 1 stands for solid blanks
//!   whose body deformation is small; discs of 91 and 143 mm on a 15 mm bore are far from that.
//! * **Teeth and rim alone** (16.8) are 26 % stiffer than ISO's 13.4, an empirical value:
//!   C_M = 0.8 adapts the theoretical stiffness of solid gears (which includes some body) to
//!   measurements.
//! * **Local term and h.** The Weber–Banaschek approach of both flanks down to h = 0.2·m_n
//!   is 1.76 µm (6 %); the global part at depth h and the local part must use the same h.
//! * Tip relief and tip rounding play no part at the pitch point.
//!
//! The numbers come from `tests/compliance_data.rs` (the rim-fixed case from an ignored test
//! there, with the data of [`super::data::ComplianceData::compute_rim_fixed`], which the paper
//! run also uses for its sensitivity case "compliance referred to the rim").
//!
//! Units: SI inside (m, N, N/m, rad); the result also in N/(mm·µm).

use super::error::ComplianceError;
use super::hertz::LocalContact;
use super::{Compliance, FlankCoord};
use crate::contact::{ContactSolver, FlankSide};
use crate::geometry::{PairGeometry, SegmentKind};

/// Result of [`pair_stiffness`]; all deflections are means over the slices of the contact line.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PairStiffness {
    /// c′ in the convention of ISO 6336-1, N/(mm·µm) (see the module docs).
    pub c_prime_n_per_mm_per_um: f64,
    /// Uniform load intensity q = F_bt/b, N per m of contact line.
    pub load_n_per_m: f64,
    /// Torque carried by the pair, N·m (on the pinion).
    pub torque_nm: f64,
    /// Pinion angle of the load case, rad.
    pub phi_p_rad: f64,
    /// Gear angle of the load case (TE = 0), rad.
    pub phi_g_rad: f64,
    /// Number of axial slices.
    pub slices: usize,
    /// Mean global normal deflection of the pinion tooth, m.
    pub u_global_p_m: f64,
    /// Mean global normal deflection of the gear tooth, m.
    pub u_global_g_m: f64,
    /// Mean local (Weber–Banaschek) normal approach of both flanks, m.
    pub u_local_m: f64,
    /// Mean total normal approach ū, m.
    pub u_total_m: f64,
    /// Smallest and largest total normal approach along the line, m.
    pub u_range_m: [f64; 2],
    /// Mean deflection along the transverse line of action, ū/cos β_b, m.
    pub delta_t_m: f64,
}

impl PairStiffness {
    /// Shares of the pinion's global, the gear's global and the local part in the mean total
    /// normal approach (they sum to 1).
    pub fn shares(&self) -> [f64; 3] {
        let u = self.u_total_m;
        [self.u_global_p_m / u, self.u_global_g_m / u, self.u_local_m / u]
    }
}

/// The single tooth-pair stiffness of `geo` at the pitch point (see the module docs) with the
/// global same-tooth compliances `pinion` and `gear` (their depths h are used for the local
/// term) and `slices` axial slices (≥ 2), loaded by the pinion torque `torque_nm` (N·m; its
/// magnitude counts, e.g. the drive line's `torque_nm`; Table 1: 100 N·m).
///
/// Errors: `slices` < 2, a zero or non-finite torque, a slice where pair 0 has no involute/involute contact
/// at the load position, or a failing local term.
pub fn pair_stiffness(
    geo: &PairGeometry,
    pinion: &dyn Compliance,
    gear: &dyn Compliance,
    slices: usize,
    torque_nm: f64,
) -> Result<PairStiffness, ComplianceError> {
    if slices < 2 {
        return Err(ComplianceError::Input(format!("slices = {slices}: allowed >= 2")));
    }
    let p = &geo.params;
    let torque = torque_nm.abs();
    if !(torque > 0.0 && torque.is_finite()) {
        return Err(ComplianceError::Input(format!(
            "torque_nm = {torque_nm:.3e}: the pair stiffness needs a non-zero finite torque"
        )));
    }
    let b = p.face_width_m;
    let cos_bb = geo.base_helix_angle.cos();
    let q = torque / (geo.pinion.rb * b);
    let phi_p = -geo.pinion.twist_rate * 0.5 * b;
    let phi_g = geo.phi_g_for_te(phi_p, 0.0);
    let solver = ContactSolver::new(geo);
    let zetas = solver.slice_zetas(slices);
    let mut all = Vec::new();
    solver.contacts_on(FlankSide::Drive, phi_p, phi_g, &zetas, &mut all);
    let mut line = Vec::with_capacity(slices);
    for &z in &zetas {
        let c = all
            .iter()
            .find(|c| c.pair == 0 && c.zeta == z)
            .filter(|c| c.kind_p == SegmentKind::Involute && c.kind_g == SegmentKind::Involute)
            .ok_or_else(|| {
                ComplianceError::Input(format!(
                    "no involute/involute contact of tooth pair 0 at ζ = {z} for φp = {phi_p} \
                     rad: the pitch-point load case does not fit this gear pair"
                ))
            })?;
        line.push(*c);
    }
    let obs_p: Vec<FlankCoord> = line
        .iter()
        .map(|c| FlankCoord { eta_star: c.eta_star_p, tau: c.tau_p, zeta: c.zeta })
        .collect();
    let obs_g: Vec<FlankCoord> = line
        .iter()
        .map(|c| FlankCoord { eta_star: c.eta_star_g, tau: c.tau_g, zeta: c.zeta })
        .collect();
    let w = b / slices as f64 / cos_bb;
    let local = LocalContact::new(&p.material_p, &p.material_g, pinion.depth(), gear.depth())?;
    let (mut sum_p, mut sum_g, mut sum_l) = (0.0, 0.0, 0.0);
    let (mut u_min, mut u_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, c) in line.iter().enumerate() {
        let (mut up, mut ug) = (0.0, 0.0);
        for j in 0..slices {
            up += pinion.alpha(obs_p[i], obs_p[j], 0);
            ug += gear.alpha(obs_g[i], obs_g[j], 0);
        }
        up *= q * w;
        ug *= q * w;
        let rho = super::hertz::reduced_radius(c.rho_p_m / cos_bb, c.rho_g_m / cos_bb)?;
        let ul = local.deformation(q, rho)?.total;
        let u = up + ug + ul;
        u_min = u_min.min(u);
        u_max = u_max.max(u);
        sum_p += up;
        sum_g += ug;
        sum_l += ul;
    }
    let n = slices as f64;
    let (u_p, u_g, u_l) = (sum_p / n, sum_g / n, sum_l / n);
    let u = u_p + u_g + u_l;
    if !(u.is_finite() && u > 0.0) {
        return Err(ComplianceError::InvalidData(format!(
            "mean normal approach {u} m under q = {q} N/m is not positive: invalid compliance"
        )));
    }
    Ok(PairStiffness {
        c_prime_n_per_mm_per_um: q * cos_bb / u * 1e-9,
        load_n_per_m: q,
        torque_nm: torque,
        phi_p_rad: phi_p,
        phi_g_rad: phi_g,
        slices,
        u_global_p_m: u_p,
        u_global_g_m: u_g,
        u_local_m: u_l,
        u_total_m: u,
        u_range_m: [u_min, u_max],
        delta_t_m: u / cos_bb,
    })
}
