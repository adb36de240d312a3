//! Exact partial derivatives of the full mesh model ([`MeshModel::jacobian`] at full
//! fidelity): the sensitivity of the load solution of Eq. 12 to the hub angles, with the
//! active set (the loaded slices) held fixed.
//!
//! # What depends on the angles
//! Every slice's contact point moves with the tooth rotation angles Θp = φp + const and
//! Θg = φg + const ([`crate::contact::ContactSolver`]). With A1, A2 the anchors of the two
//! flank pieces at the contact (gear axis for involute and relief, arc centre for rounding,
//! tip circle and corner), D = A2 − A1, n the pinion's outward normal at angle ν and
//! m = n rotated by −90°, the common-normal condition D·m(ν) = K1 + K2 gives by implicit
//! differentiation
//!
//! ```text
//! ∂ν/∂Θp = −(A1 − O_p)·n / (D·n),       ∂ν/∂Θg = (A2 − O_g)·n / (D·n)
//! ```
//!
//! (zero for two involutes: the line of action is fixed). From it, exactly:
//! * overlap Δ = L1 + L2 − D·n: ∂Δ/∂Θp = s_p, ∂Δ/∂Θg = s_g (the moment arms — the normal
//!   velocity of each flank at the contact), so ∂d_i/∂φ = s·cos θ;
//! * moment arms s_p = (A1 − O_p)·m + K1, s_g = K2 − (A2 − O_g)·m:
//!   ∂s_p/∂Θp = −(A1 − O_p)·n·(1 − ∂ν/∂Θp), ∂s_g/∂Θg = (A2 − O_g)·n·(1 − ∂ν/∂Θg), and the
//!   cross terms through ∂ν;
//! * flank coordinates: a point on a flank piece moves along the profile as
//!   dP/dν_local = −L·m (L the piece's normal reach), so ∂η*/∂Θ follows from the tooth-axis
//!   component of that motion and ∂τ = ∓(∂ν − ∂Θ) on the rounding; the profile coordinate p of
//!   the compliance grid follows ([`SliceInfluence::profile_rates`]);
//! * flank modifications ([`crate::modifications`]): the overlap is Δ − s(ζ, r_p, r_g), and
//!   the profile terms of s (crowning, slope, tip relief, deviation map) depend on the contact
//!   radii, which move with the flank points: dP_p = −L1·(∂ν − ∂Θp)·m relative to the pinion
//!   tooth, dP_g = L2·(∂ν − ∂Θg)·m relative to the gear tooth, so ∂r = (P − O)·dP/r and
//!   ∂d gains −(∂s/∂r_p·∂r_p + ∂s/∂r_g·∂r_g)·cos θ (lead terms, pitch deviations and
//!   misalignment do not move with the angles);
//! * radii of curvature: ∂L/∂ν_local = −K on an involute, 0 on an arc; the corner's radius
//!   (a fixed point of the tooth) does not change; with ρ = R/cos θ, R = ρ_p·ρ_g/(ρ_p + ρ_g):
//!   ∂ρ = R²·(∂ρ_p/ρ_p² + ∂ρ_g/ρ_g²)/cos θ.
//!
//! # Body poses
//! With the gear bodies off their axes ([`crate::mesh::pose`]) the contact of a slice is found
//! with the gear's centre at c = (a + o_x, o_y) and its tooth turned by −ω_g·w_ref; the rates
//! above hold with that centre (O_g = c). A translation dc of the centre in the slice moves
//! D = A2 − A1 by dc, so
//!
//! ```text
//! ∂ν/∂c = −m/(D·n),   ∂Δ/∂c = −n,   ∂s_p/∂c = (A1 − O_p)·n·∂ν/∂c,   ∂s_g/∂c = −(A2 − O_g)·n·∂ν/∂c
//! ```
//!
//! and the flank points slide along their profiles by ∂ν/∂c relative to both teeth (the
//! flank coordinates, radii and curvatures follow as for the angles). The relative pose
//! (U_x, U_y, U_z, Θ_x, Θ_y) enters each slice at height h = z − b/2 as
//! dc = (dU_x + h·dΘ_y, dU_y − h·dΘ_x) and as the gear tooth's turn
//! dΘg = −ω_g·(dU_z + r_wg·dΘ_y); the overlap's axial correction
//! −s_g·ω_g·(Θ_x·ρ_y − Θ_y·(ρ_x + r_wg)) (ρ = P2 − c) adds its explicit derivatives in Θ_x and
//! Θ_y and, in every direction, its rate through s_g and ρ (P2 − c turns with the tooth and
//! slides along the profile: ∂ρ = J·ρ·∂Θg + L2·(∂ν − ∂Θg)·m). The sensitivity system gets one
//! right-hand side per column (Θp, Θg and the five relative components); the body columns
//! follow from U = u_g − u_p + (0, 0, θ_py·a), Θ = θ_g − θ_p. The damping torques depend on the
//! pose rates through the approach rate of the body motion, linearly. Measured against central
//! differences of `evaluate` on Table 1 (50 slices, at rest and at a pose with every component
//! non-zero): within 1e-7 of each column group's largest entry (`tests/body_pose.rs`).
//!
//! Units: angles rad, lengths m, loads N/m, torques N·m; the signs are those of
//! [`MeshJacobian`]. Measured against central differences of `evaluate` on Table 1 (50
//! slices, light load to 15× nominal TE, tip and back-flank contacts): agreement to 1.4e-6 of
//! the row's largest entry beyond the rounding allowance of the differences
//! (`tests/mesh_jacobian.rs`).
//!
//! # The sensitivity system
//! On the loaded set A the solution satisfies g_i = Σ_j C_ij·w_j·q_j + u_c(q_i, ρ_i) − d_i = 0.
//! Differentiating with A fixed:
//!
//! ```text
//! (C_AA·diag(w_A) + diag(∂u_c/∂q))·∂q_A = ∂d_A − (∂C·w q)_A − diag(∂u_c/∂ρ)·∂ρ_A
//! ```
//!
//! with ∂C_ij = Σ_gears (∂α*/∂p_obs·∂p_i + ∂α*/∂p_load·∂p_j), from the derivative of the same
//! cubic Hermite interpolant that assembles C ([`SliceInfluence::weights_dp`]), and
//! ∂u_c/∂ρ = −(u_c − q·∂u_c/∂q)/ρ (Eq. 10 depends on ρ only through L ∝ √ρ). The matrix is
//! factorised once (LU) for both angle directions. Then
//! ∂M_F,k = m_n·Δζ·Σ_A (∂s_k,i·q_i + s_k,i·∂q_i).
//!
//! # The loaded extent
//! The damping torques follow the loaded extent E ([`super::extent`]), whose ends inside
//! their slices move with the state: x = Δζ·σ_i/(σ_i − σ_n) with σ_i = u_c(q_i) − g_i of the
//! run's last loaded slice (g_i = 0 held) and σ_n = −g_n of the open slice beyond, so
//!
//! ```text
//! ∂σ_i = ∂u_c/∂q·∂q_i + ∂u_c/∂ρ·∂ρ_i,     ∂σ_n = ∂d_n − (∂C·w q)_n − (C·w ∂q)_n
//! ```
//!
//! from the same ∂q and right-hand sides (the open rows' ∂d − ∂C·w q are formed beside the
//! loaded ones); without the local term σ_i = C_ii·w_i·q_i and ∂σ_i = ∂C_ii·w_i·q_i +
//! C_ii·w_i·∂q_i. Beyond an end outside the problem σ_n = d_n − d_i + σ_i, so
//! x = Δζ·σ_i/(d_i − d_n) needs ∂d_n of that slice's contact, found again by the contact
//! search. ∂E = Σ ∂x over the ends inside their bounds (a clamped end does not move), and
//! ∂M_D,k = d_mesh·rate·∂E·r_bk, the rate including the approach rate of the body motion.
//!
//! Nothing is neglected: every term is the exact derivative of the model as evaluated (at a
//! fixed active set and fixed contact-piece combination). Supported compliance
//! representations: interpolated with the slice kernel (the default) and Winkler; others
//! return [`MeshError::Unsupported`].

use faer::Mat;
use faer::linalg::solvers::Solve;

use super::extent::Beyond;
use super::{GearCompliance, MeshModel, MeshWorkspace, Slice, WarmStart};
use crate::compliance::FlankCoord;
use crate::compliance::interpolated::{SliceInfluence, SliceWeights};
use crate::contact::RelativePose;
use crate::contact::{ContactPoint, ContactSolver, FlankSide, ReducedAngles};
use crate::geometry::{PairGeometry, SegmentKind};
use crate::mesh::{MeshError, MeshJacobian, MeshOutputs, MeshState};

/// The directions of a slice's geometric rates: the tooth angles Θp, Θg and a translation of
/// the gear's centre in the slice along x and y (`super::super::pose`).
const NDIR: usize = 4;

/// Derivatives of one slice's geometric quantities with respect to (Θp, Θg, c_x, c_y).
#[derive(Debug, Clone, Copy, Default)]
struct SliceRates {
    /// ∂Δ of the overlap (body-motion correction included), m/rad or m/m.
    overlap: [f64; NDIR],
    /// ∂s_p, ∂s_g, m/rad.
    arm_p: [f64; NDIR],
    arm_g: [f64; NDIR],
    /// ∂p of the pinion and gear profile coordinates, m_n/rad.
    prof_p: [f64; NDIR],
    prof_g: [f64; NDIR],
    /// ∂ρ of the reduced normal-section radius, m/rad.
    rho: [f64; NDIR],
    /// ∂r_p, ∂r_g of the contact radii on pinion and gear, m/rad (the profile
    /// modifications' separation depends on them).
    radius_p: [f64; NDIR],
    radius_g: [f64; NDIR],
    /// ∂(P2 − O_g), the gear contact point relative to the gear's centre, m/rad.
    rel_g: [[f64; 2]; NDIR],
}

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// True for the pieces anchored at the gear axis with offset ±g (involute and relief).
#[inline]
fn is_involute(k: SegmentKind) -> bool {
    matches!(k, SegmentKind::Involute | SegmentKind::Relief)
}

/// Geometric rates of contact `c` with tooth angles (`tp`, `tg`) (see the module docs);
/// `rates_p`, `rates_g` map (∂η*, ∂τ) to ∂p of each gear's compliance grid.
#[allow(clippy::too_many_arguments)]
fn contact_rates(
    geo: &PairGeometry,
    c: &ContactPoint,
    (tp, tg): (f64, f64),
    cg: [f64; 2],
    obs: [FlankCoord; 2],
    rates: [(f64, f64); 2],
    cos_theta: f64,
) -> SliceRates {
    let (sn, cn) = c.normal_angle.sin_cos();
    let n = [cn, sn];
    let m = [sn, -cn];
    let (l1, l2) = (c.rho_p_m, c.rho_g_m);
    let a1 = if is_involute(c.kind_p) {
        [0.0, 0.0]
    } else {
        [c.point_p[0] - l1 * n[0], c.point_p[1] - l1 * n[1]]
    };
    let ag = if is_involute(c.kind_g) {
        [0.0, 0.0]
    } else {
        [c.point_g[0] + l2 * n[0] - cg[0], c.point_g[1] + l2 * n[1] - cg[1]]
    };
    let d = [cg[0] + ag[0] - a1[0], cg[1] + ag[1] - a1[1]];
    let dn = dot(d, n);
    let (a1n, agn) = (dot(a1, n), dot(ag, n));
    // A translation dc of the gear's centre moves D by dc: ∂ν = −dc·m/(D·n), ∂Δ = −dc·n.
    let dnu = [-a1n / dn, agn / dn, -m[0] / dn, -m[1] / dn];
    let dtp = [1.0, 0.0, 0.0, 0.0];
    let dtg = [0.0, 1.0, 0.0, 0.0];
    let mirror = if c.side == FlankSide::Back { -1.0 } else { 1.0 };
    let mn = geo.params.normal_module_m;
    let e_p = [tp.cos(), tp.sin()];
    let e_g = [tg.cos(), tg.sin()];
    let (mep, meg) = (dot(m, e_p), dot(m, e_g));
    let k1 = if is_involute(c.kind_p) { c.arm_p_m } else { 0.0 };
    let k2 = if is_involute(c.kind_g) { c.arm_g_m } else { 0.0 };
    let rp = super::flank_radius(geo, true, c);
    let rg = super::flank_radius(geo, false, c);
    let corner_p = c.kind_p == SegmentKind::ReliefCorner || c.rho_p_m <= 0.0;
    let corner_g = c.kind_g == SegmentKind::ReliefCorner || c.rho_g_m <= 0.0;
    let rt = 1.0 / (1.0 / rp + 1.0 / rg);
    let mut r =
        SliceRates { overlap: [c.arm_p_m, c.arm_g_m, -n[0], -n[1]], ..SliceRates::default() };
    let rel = [c.point_g[0] - cg[0], c.point_g[1] - cg[1]];
    for j in 0..NDIR {
        let (up, ug) = (dnu[j] - dtp[j], dnu[j] - dtg[j]);
        r.arm_p[j] = -a1n * dtp[j] + a1n * dnu[j];
        r.arm_g[j] = agn * dtg[j] - agn * dnu[j];
        let deta_p = l1 * mep * up / mn;
        let deta_g = -l2 * meg * ug / mn;
        let dtau_p = if obs[0].tau > 0.0 { -mirror * up } else { 0.0 };
        let dtau_g = if obs[1].tau > 0.0 { -mirror * ug } else { 0.0 };
        r.prof_p[j] = rates[0].0 * deta_p + rates[0].1 * dtau_p;
        r.prof_g[j] = rates[1].0 * deta_g + rates[1].1 * dtau_g;
        let drp = if corner_p { 0.0 } else { -k1 * up };
        let drg = if corner_g { 0.0 } else { -k2 * ug };
        r.rho[j] = rt * rt * (drp / (rp * rp) + drg / (rg * rg)) / cos_theta;
        // The flank points move along their profiles relative to the tooth by
        // dP_p = −L1·(∂ν − ∂Θp)·m and dP_g = L2·(∂ν − ∂Θg)·m, which changes their radii by
        // (P − O)·dP/r.
        let (pp, pg) = (c.point_p, [c.point_g[0] - cg[0], c.point_g[1] - cg[1]]);
        if c.radius_p_m > 0.0 {
            r.radius_p[j] = -l1 * up * dot(pp, m) / c.radius_p_m;
        }
        if c.radius_g_m > 0.0 {
            r.radius_g[j] = l2 * ug * dot(pg, m) / c.radius_g_m;
        }
        // P2 − O_g turns with the gear tooth and slides along the profile.
        r.rel_g[j] = [-rel[1] * dtg[j] + l2 * ug * m[0], rel[0] * dtg[j] + l2 * ug * m[1]];
    }
    r
}

/// Calls `f(a0, a1, b0, b1, offset_p, offset_g)` for every coupled block of the compliance
/// matrix, as [`MeshModel::evaluate_full`] assembles it.
fn for_each_block(
    slices: &[Slice],
    runs: &[(usize, usize)],
    coupling: bool,
    mut f: impl FnMut(usize, usize, usize, usize, i32, i32),
) {
    for &(a0, a1) in runs {
        for &(b0, b1) in runs {
            let (ca, cb) = (&slices[a0].contact, &slices[b0].contact);
            if ca.side != cb.side {
                continue;
            }
            let d = (ca.pair - cb.pair) as i32;
            if d != 0 && !coupling {
                continue;
            }
            let mirror = if ca.side == FlankSide::Back { -1 } else { 1 };
            f(a0, a1, b0, b1, mirror * d, -mirror * d);
        }
    }
}

impl MeshModel {
    /// Full evaluation ([`MeshModel::evaluate`], same arguments) with the exact partial
    /// derivatives of the outputs (module docs).
    pub fn jacobian(
        &self,
        state: &MeshState,
        ws: &mut MeshWorkspace,
        warm: &mut WarmStart,
    ) -> Result<(MeshOutputs, MeshJacobian), MeshError> {
        let out = self.evaluate(state, ws, warm)?;
        let mut jac = MeshJacobian { pose: Some(Box::default()), ..MeshJacobian::default() };
        let n = ws.slices.len();
        let q: Vec<f64> = if n == 0 { Vec::new() } else { ws.solver.load()[..n].to_vec() };
        let active: Vec<usize> = (0..n).filter(|&i| q[i] > 0.0).collect();
        if active.is_empty() {
            return Ok((out, jac));
        }
        let kernel = if ws.slice_kernel { self.slice_comp.as_ref() } else { None };
        let sc = match (kernel, &self.comp_p, &self.comp_g) {
            (Some(sc), _, _) => Some(sc.clone()),
            (None, GearCompliance::Winkler { .. }, GearCompliance::Winkler { .. }) => None,
            _ => {
                return Err(MeshError::Unsupported(
                    "mesh Jacobian at full fidelity with this compliance representation \
                     (needs the interpolated slice kernel or Winkler)",
                ));
            }
        };
        let geo = self.geo.clone();
        let cs = ContactSolver::new(&geo);
        let red: ReducedAngles = cs.reduce(state.phi_p, state.phi_g);
        let nl = self.zetas.len();
        let ct = self.cos_theta;
        // The gear body relative to the pinion's (zero at rest; `super::super::pose`).
        let a = geo.center_distance;
        let rel = RelativePose::new(&state.pose_p, &state.pose_g, a);
        let b = geo.params.face_width_m;
        let tw = geo.gear.twist_rate;
        let r_wg = geo.gear.rb / geo.alpha_wt.cos();
        let w_ref = rel.axial([-r_wg, 0.0]);
        let mn = geo.params.normal_module_m;

        // Geometric rates of a contact, by column (module docs, "Body poses").
        let rates_of = |c: &ContactPoint, obs: [FlankCoord; 2], pr: [(f64, f64); 2]| {
            let (tp, tg) = cs.tooth_angles(c.side, &red, c.pair, c.zeta);
            let h = c.zeta * mn - 0.5 * b;
            let o = rel.axis_offset(c.zeta * mn, b);
            let cg = [a + o[0], o[1]];
            let base = contact_rates(&geo, c, (tp, tg - tw * w_ref), cg, obs, pr, ct);
            ColRates::of(&base, c, cg, &rel, [tw, r_wg, h])
        };
        // ∂d of a contact with rates `r`: the overlap's, less the separation's of the profile
        // modifications, which moves with the contact's roll position.
        let approach_rate = |c: &ContactPoint, r: &ColRates| -> [f64; NCOL] {
            let mut d = r.overlap.map(|v| v * ct);
            if let Some(sep) = &self.separation
                && c.side == FlankSide::Drive
            {
                let (dsp, dsg) = sep.radial_rates(c.zeta, c.radius_p_m, c.radius_g_m);
                for (j, v) in d.iter_mut().enumerate() {
                    *v -= (dsp * r.radius_p[j] + dsg * r.radius_g[j]) * ct;
                }
            }
            d
        };
        let rates: Vec<ColRates> = ws
            .slices
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let pr = match &sc {
                    Some(sc) => {
                        [sc[0].profile_rates(ws.obs_p[i]), sc[1].profile_rates(ws.obs_g[i])]
                    }
                    None => [(0.0, 0.0); 2],
                };
                rates_of(&s.contact, [ws.obs_p[i], ws.obs_g[i]], pr)
            })
            .collect();

        // Right-hand sides: ∂d − (∂C·w q) − ∂u_c/∂ρ·∂ρ, per column; every row gets the first
        // two terms (an open slice's ∂g for the loaded extent), the loaded rows the third.
        let mut rhs = Mat::<f64>::zeros(n, NCOL);
        let mut dd = Mat::<f64>::zeros(n, NCOL);
        // ∂C_ii·w_i·q_i (the loaded extent without the local term).
        let mut dc_diag = Mat::<f64>::zeros(n, NCOL);
        for i in 0..n {
            let d = approach_rate(&ws.slices[i].contact, &rates[i]);
            for j in 0..NCOL {
                rhs[(i, j)] = d[j];
                dd[(i, j)] = d[j];
            }
        }
        if let Some(sc) = &sc {
            let wq: Vec<f64> = (0..n).map(|j| ws.line_length[j] * q[j]).collect();
            for (g, sw) in [(0usize, &ws.sw_p), (1, &ws.sw_g)] {
                let dsw: Vec<SliceWeights> = ws
                    .slices
                    .iter()
                    .enumerate()
                    .map(|(i, s)| {
                        let kc = if s.contact.side == FlankSide::Back { nl - 1 - s.k } else { s.k };
                        let o = if g == 0 { ws.obs_p[i] } else { ws.obs_g[i] };
                        sc[g].weights_dp(o, kc)
                    })
                    .collect();
                let (d_obs, d_load) =
                    derivative_blocks(&sc[g], g, &ws.slices, &ws.runs, self, sw, &dsw, n);
                for j in 0..NCOL {
                    let dp =
                        |i: usize| if g == 0 { rates[i].prof_p[j] } else { rates[i].prof_g[j] };
                    for i in 0..n {
                        let mut s = 0.0;
                        for &k in &active {
                            s += (d_obs[(i, k)] * dp(i) + d_load[(i, k)] * dp(k)) * wq[k];
                        }
                        rhs[(i, j)] -= s;
                        if !self.options.local_contact {
                            dc_diag[(i, j)] += (d_obs[(i, i)] + d_load[(i, i)]) * dp(i) * wq[i];
                        }
                    }
                }
            }
        }
        if self.options.local_contact {
            for &i in &active {
                let d = self.local.deformation(q[i], ws.rho[i]).map_err(|e| {
                    MeshError::Load(crate::load::LoadError::Hertz { slice: i, source: e })
                })?;
                let du_drho = -(d.total - q[i] * d.d_total_dq) / ws.rho[i];
                for j in 0..NCOL {
                    rhs[(i, j)] -= du_drho * rates[i].rho[j];
                }
            }
        }

        // The Newton matrix of the loaded set at the solution.
        let m = active.len();
        let kmat = Mat::<f64>::from_fn(m, m, |a, b| {
            let (i, k) = (active[a], active[b]);
            let mut v = ws.cmat[(i, k)] * ws.line_length[k];
            if a == b && self.options.local_contact {
                v += self.local.deformation(q[i], ws.rho[i]).map_or(0.0, |d| d.d_total_dq);
            }
            v
        });
        let rhs_a = Mat::<f64>::from_fn(m, NCOL, |a, j| rhs[(active[a], j)]);
        let dq = kmat.partial_piv_lu().solve(&rhs_a);

        // The loaded extent (`super::extent`) and its rates: each end inside its slice moves
        // with σ of its loaded slice and with σ (or the approach) beyond it.
        let gap = ws.solver.gap();
        let local_on = self.options.local_contact;
        let sigma = |i: usize| {
            if local_on {
                self.local.deformation(q[i], ws.rho[i]).map_or(f64::NAN, |d| d.total) - gap[i]
            } else {
                ws.cmat[(i, i)] * ws.line_length[i] * q[i]
            }
        };
        let (mut widths, mut ends) = (Vec::with_capacity(n), Vec::new());
        super::extent::resolve(
            &ws.slices,
            &q,
            gap,
            &ws.approach,
            sigma,
            (self.dzeta, nl, ct),
            &mut widths,
            Some(&mut ends),
        );
        let extent: f64 = widths.iter().map(|w| w[0] + w[1]).sum();
        let pose = (!state.bodies_at_rest()).then_some(rel);
        let mut side_contacts: [Option<Vec<ContactPoint>>; 2] = [None, None];
        let mut d_extent = [0.0; NCOL];
        for e in &ends {
            let i = e.slice;
            let ai = active.binary_search(&i).map_err(|_| {
                MeshError::Unsupported("mesh Jacobian: an end of a loaded run on an open slice")
            })?;
            let d_sigma: [f64; NCOL] = if local_on {
                let d = self.local.deformation(q[i], ws.rho[i]).map_err(|e| {
                    MeshError::Load(crate::load::LoadError::Hertz { slice: i, source: e })
                })?;
                let du_drho = -(d.total - q[i] * d.d_total_dq) / ws.rho[i];
                std::array::from_fn(|j| d.d_total_dq * dq[(ai, j)] + du_drho * rates[i].rho[j])
            } else {
                std::array::from_fn(|j| {
                    dc_diag[(i, j)] + ws.cmat[(i, i)] * ws.line_length[i] * dq[(ai, j)]
                })
            };
            let d_beyond: [f64; NCOL] = match e.beyond {
                // −∂g_n = ∂d_n − ∂C·w q − C·w ∂q on row n.
                Beyond::Candidate(nn) => std::array::from_fn(|j| {
                    let mut v = rhs[(nn, j)];
                    for (a2, &k) in active.iter().enumerate() {
                        v -= ws.cmat[(nn, k)] * ws.line_length[k] * dq[(a2, j)];
                    }
                    v
                }),
                // ∂d_i − ∂d_n, with the neighbour's contact found again.
                Beyond::Outside => {
                    let sl = &ws.slices[i];
                    let side = sl.contact.side;
                    let list = side_contacts[usize::from(side == FlankSide::Back)]
                        .get_or_insert_with(|| {
                            let mut v = Vec::new();
                            let slices = (&self.zetas[..], &self.twists[..]);
                            cs.contacts_posed(
                                side,
                                state.phi_p,
                                state.phi_g,
                                slices,
                                pose.as_ref(),
                                &mut v,
                            );
                            v
                        });
                    let k = if e.toward == 0 { sl.k - 1 } else { sl.k + 1 };
                    let c = list
                        .iter()
                        .find(|c| c.pair == sl.contact.pair && self.slice_index(c.zeta) == k)
                        .ok_or(MeshError::Unsupported(
                            "mesh Jacobian: the contact beyond a loaded run is not found again",
                        ))?;
                    let z = if side == FlankSide::Back { geo.b0() - c.zeta } else { c.zeta };
                    let obs = [
                        FlankCoord { eta_star: c.eta_star_p, tau: c.tau_p, zeta: z },
                        FlankCoord { eta_star: c.eta_star_g, tau: c.tau_g, zeta: z },
                    ];
                    let ddn = approach_rate(c, &rates_of(c, obs, [(0.0, 0.0); 2]));
                    std::array::from_fn(|j| dd[(i, j)] - ddn[j])
                }
            };
            for j in 0..NCOL {
                d_extent[j] += e.rate(self.dzeta, d_sigma[j], d_beyond[j]);
            }
        }
        let [de_p, de_g, de_pose @ ..] = d_extent;
        damping_rows(self, state, extent, [de_p, de_g], Some(de_pose), &mut jac);

        let axial = self.pair.normal_module_m * self.dzeta;
        let mut d_rel = [[0.0; 5]; 2];
        for j in 0..NCOL {
            let (mut dp, mut dg) = (0.0, 0.0);
            for (a, &i) in active.iter().enumerate() {
                let c = &ws.slices[i].contact;
                dp += (rates[i].arm_p[j] * q[i] + c.arm_p_m * dq[(a, j)]) * axial;
                dg += (rates[i].arm_g[j] * q[i] + c.arm_g_m * dq[(a, j)]) * axial;
            }
            if j < 2 {
                jac.d[MeshJacobian::M_F_P][j] = dp;
                jac.d[MeshJacobian::M_F_G][j] = dg;
            } else {
                d_rel[0][j - 2] = dp;
                d_rel[1][j - 2] = dg;
            }
        }
        if let Some(p) = &mut jac.pose {
            for (row, d) in [MeshJacobian::M_F_P, MeshJacobian::M_F_G].into_iter().zip(d_rel) {
                (p.d_pose_p[row], p.d_pose_g[row]) = body_columns(d, a);
            }
        }
        if jac.d.iter().flatten().any(|v| !v.is_finite()) || jac.pose.iter().any(|p| !p.is_finite())
        {
            return Err(MeshError::Unsupported(
                "mesh Jacobian: singular sensitivity system (degenerate contact)",
            ));
        }
        Ok((out, jac))
    }
}

/// ∂α*/∂p_obs and ∂α*/∂p_load of gear `g` (0 pinion, 1 gear) for all slice pairs (n × n, m/N
/// per m_n), assembled block by block as the compliance matrix.
#[allow(clippy::too_many_arguments)]
fn derivative_blocks(
    sc: &SliceInfluence,
    g: usize,
    slices: &[Slice],
    runs: &[(usize, usize)],
    model: &MeshModel,
    sw: &[SliceWeights],
    dsw: &[SliceWeights],
    n: usize,
) -> (Mat<f64>, Mat<f64>) {
    let mut d_obs = Mat::<f64>::zeros(n, n);
    let mut d_load = Mat::<f64>::zeros(n, n);
    let mut partial = Vec::new();
    for_each_block(slices, runs, model.options.neighbour_coupling, |a0, a1, b0, b1, op, og| {
        let off = if g == 0 { op } else { og };
        sc.add_block(&dsw[a0..a1], &sw[b0..b1], off, &mut partial, &mut d_obs, (a0, b0));
        sc.add_block(&sw[a0..a1], &dsw[b0..b1], off, &mut partial, &mut d_load, (a0, b0));
    });
    (d_obs, d_load)
}

/// Fills the damping rows of `jac` for Eq. 14 as [`MeshModel::damping_for`] computes it, with
/// loaded extent `extent` (units of m_n, > 0) and its derivatives `d_extent` with respect to
/// (φp, φg) (per rad) and, when given, `d_extent_pose` with respect to the relative pose
/// (U_x, U_y, U_z per m, Θ_x, Θ_y per rad).
pub(crate) fn damping_rows(
    model: &MeshModel,
    state: &MeshState,
    extent: f64,
    d_extent: [f64; 2],
    d_extent_pose: Option<[f64; 5]>,
    jac: &mut MeshJacobian,
) {
    if !model.options().damping || extent <= 0.0 {
        return;
    }
    let (rb_p, rb_g) = (model.geometry().pinion.rb, model.geometry().gear.rb);
    let d = model.d_mesh();
    // The damped rate: TE's, plus the approach rate of the body motion.
    let mut rate = state.w_p * rb_p + state.w_g * rb_g;
    if !state.bodies_at_rest() {
        let a = model.geometry().center_distance;
        let body = RelativePose::new(&state.rate_p, &state.rate_g, a);
        rate += crate::mesh::pose::approach_rate(model.geometry(), &body);
    }
    for (row, rb_k) in [(MeshJacobian::M_D_P, rb_p), (MeshJacobian::M_D_G, rb_g)] {
        jac.d[row][MeshJacobian::W_P] = d * rb_p * extent * rb_k;
        jac.d[row][MeshJacobian::W_G] = d * rb_g * extent * rb_k;
        jac.d[row][MeshJacobian::PHI_P] = d * rate * d_extent[0] * rb_k;
        jac.d[row][MeshJacobian::PHI_G] = d * rate * d_extent[1] * rb_k;
    }
    // The body motion's approach rate (`super::super::pose`, "Damping"): linear in the
    // relative rates (U̇_x, U̇_y, U̇_z, Θ̇_x, Θ̇_y).
    if let Some(p) = &mut jac.pose {
        let geo = model.geometry();
        let (sin_wt, cos_wt) = geo.alpha_wt.sin_cos();
        let k = -rb_g * geo.gear.twist_rate;
        let r_wg = rb_g / cos_wt;
        let da = [-sin_wt, -cos_wt, k, 0.0, k * r_wg];
        for (row, rb_k) in [(MeshJacobian::M_D_P, rb_p), (MeshJacobian::M_D_G, rb_g)] {
            let g = da.map(|v| d * v * extent * rb_k);
            (p.d_rate_p[row], p.d_rate_g[row]) = body_columns(g, geo.center_distance);
            if let Some(de) = d_extent_pose {
                let g = de.map(|v| d * rate * v * rb_k);
                (p.d_pose_p[row], p.d_pose_g[row]) = body_columns(g, geo.center_distance);
            }
        }
    }
}

/// The derivatives with respect to each body's pose components (u_x, u_y, u_z, th_x, th_y) from
/// those with respect to the relative pose `g` = ∂/∂(U_x, U_y, U_z, Θ_x, Θ_y), with U = u_g −
/// u_p + (0, 0, θ_py·a) and Θ = θ_g − θ_p (`super::super::pose`): (pinion, gear).
fn body_columns(g: [f64; 5], a: f64) -> ([f64; 5], [f64; 5]) {
    let p = [-g[0], -g[1], -g[2], -g[3], -g[4] + a * g[2]];
    (p, g)
}

/// Number of columns of the sensitivity system: Θp, Θg and the relative pose (U_x, U_y, U_z,
/// Θ_x, Θ_y).
const NCOL: usize = 7;

/// One slice's geometric rates by column of the sensitivity system.
#[derive(Debug, Clone, Copy, Default)]
struct ColRates {
    overlap: [f64; NCOL],
    arm_p: [f64; NCOL],
    arm_g: [f64; NCOL],
    prof_p: [f64; NCOL],
    prof_g: [f64; NCOL],
    rho: [f64; NCOL],
    radius_p: [f64; NCOL],
    radius_g: [f64; NCOL],
}

impl ColRates {
    /// The columns from the rates `r` in the directions (Θp, Θg, c_x, c_y) of contact `c` in a
    /// slice where the gear's centre is at `cg`, at height h above mid-face, for the relative
    /// pose `rel`; `k` = [ω_g, r_wg, h]. Module docs, "Body poses".
    fn of(r: &SliceRates, c: &ContactPoint, cg: [f64; 2], rel: &RelativePose, k: [f64; 3]) -> Self {
        let [tw, r_wg, h] = k;
        // Each column as a combination of the four directions.
        let coef: [[f64; NDIR]; NCOL] = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, -tw, 0.0, 0.0],
            [0.0, 0.0, 0.0, -h],
            [0.0, -tw * r_wg, h, 0.0],
        ];
        let comb = |f: &[f64; NDIR]| -> [f64; NCOL] {
            coef.map(|cf| cf.iter().zip(f).map(|(a, b)| a * b).sum())
        };
        // The axial correction −s_g·ω_g·(w(ρ) − w_ref), w(ρ) − w_ref = Θ_x·ρ_y − Θ_y·(ρ_x + r_wg):
        // its rate in each direction through s_g and ρ, and its explicit pose derivatives.
        let rho = [c.point_g[0] - cg[0], c.point_g[1] - cg[1]];
        let dw = rel.th[0] * rho[1] - rel.th[1] * (rho[0] + r_wg);
        let mut ov = r.overlap;
        for (j, o) in ov.iter_mut().enumerate() {
            let drho = r.rel_g[j];
            *o -= tw * (r.arm_g[j] * dw + c.arm_g_m * (rel.th[0] * drho[1] - rel.th[1] * drho[0]));
        }
        let mut overlap = comb(&ov);
        overlap[5] -= c.arm_g_m * tw * rho[1];
        overlap[6] += c.arm_g_m * tw * (rho[0] + r_wg);
        Self {
            overlap,
            arm_p: comb(&r.arm_p),
            arm_g: comb(&r.arm_g),
            prof_p: comb(&r.prof_p),
            prof_g: comb(&r.prof_g),
            rho: comb(&r.rho),
            radius_p: comb(&r.radius_p),
            radius_g: comb(&r.radius_g),
        }
    }
}
