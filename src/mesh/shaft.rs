//! A gear body's support derived from its shaft on elastic bearings — a specification.
//!
//! # Arrangement
//! The gear sits rigidly on a straight shaft along its axis (parallel to z in the housing frame
//! of [`super::forces`], the gear's centre at z_c = b/2). The shaft has the bending stiffness
//! EI (N·m², the same in both transverse planes) and runs in 2 … [`MAX_SHAFT_BEARINGS`]
//! bearings at positions z_i (m, same frame as `static --bearings`, [`super::bearings`]), each
//! a linear spring k_i (N/m) on the shaft's deflection in x and in y, and, where given, an
//! axial spring a_i (N/m). The shaft is massless: the gear body carries the mass
//! ([`super::supports::Support`]).
//!
//! # The stiffness at the gear centre
//! In the plane x–z the shaft deflects by w(z) = u_x, its slope is w′ = θ_y (a tilt θ_y moves a
//! point at height d above the centre by θ_y·d along x); in y–z, w = u_y and w′ = −θ_x. The
//! shaft is split at the bearings and at z_c into Euler–Bernoulli beam elements, exact for a
//! beam loaded at its nodes (cubic Hermite shape functions,
//!
//! ```text
//! K_e = EI/L³ · [ 12   6L  −12   6L
//!                 6L  4L²  −6L  2L²
//!                −12  −6L   12  −6L
//!                 6L  2L²  −6L  4L² ]
//! ```
//!
//! on (w₁, w₁′, w₂, w₂′)), with k_i added on w at each bearing's node. Unit loads at the gear
//! node give its flexibility C (2 × 2: force and moment against deflection and slope); its
//! inverse is the stiffness of the plane, K_p = C⁻¹ = [[k_uu, k_uθ], [k_uθ, k_θθ]]. The 5 × 5
//! stiffness in the order (u_x, u_y, u_z, θ_x, θ_y) is
//!
//! ```text
//! K[u_x][u_x] = K[u_y][u_y] = k_uu,    K[θ_y][θ_y] = K[θ_x][θ_x] = k_θθ,
//! K[u_x][θ_y] = k_uθ,   K[u_y][θ_x] = −k_uθ,   K[u_z][u_z] = Σ a_i
//! ```
//!
//! (the sign of the y–z coupling from w′ = −θ_x). Limits that check it: a stiff shaft gives
//! k_uu = Σk_i, k_uθ = Σk_i·d_i, k_θθ = Σk_i·d_i² with d_i = z_i − z_c; stiff bearings with
//! the gear midway between two at span L give k_uu = 48·EI/L³, k_θθ = 12·EI/L, k_uθ = 0
//! (`tests/supports.rs`).
//!
//! # Bearing forces
//! The shaft is massless, so its deflection is the static one for the gear node's: the
//! deflection at bearing i is w_i = g_i·(w_c, w_c′) with g_i the row of bearing i of the unit-load
//! solutions times K_p. The bearing exerts −k_i·w_i on the shaft in each plane and −a_i·u_z
//! axially: [`ShaftSupport::bearing_forces`]. Over the bearings these balance the force and the
//! moment the support exerts on the body.

use crate::error::ParamError;
use crate::mesh::BodyPose;

/// Most bearings of one shaft.
pub const MAX_SHAFT_BEARINGS: usize = 4;

/// One bearing of a shaft and the map from the gear node's deflection to its own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaftBearing {
    /// Position along the axis, m (housing frame; the gear's centre at b/2).
    pub z_m: f64,
    /// Radial stiffness, N/m (in x and in y).
    pub radial_n_per_m: f64,
    /// Axial stiffness, N/m (0: the bearing floats axially).
    pub axial_n_per_m: f64,
    /// The bearing's deflection per gear-node (deflection, slope) in one plane.
    g: [f64; 2],
}

/// A shaft on elastic bearings seen from its gear (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaftSupport {
    /// Bending stiffness EI, N·m².
    pub bending_stiffness_nm2: f64,
    /// The bearings (the first `n`).
    bearings: [Option<ShaftBearing>; MAX_SHAFT_BEARINGS],
    /// The 5 × 5 stiffness at the gear centre.
    stiffness: [[f64; 5]; 5],
}

impl ShaftSupport {
    /// The support of a shaft of bending stiffness `ei` (N·m²) on `bearings` (z_m, radial,
    /// axial stiffness) for a gear centred at `center_z` (m); `key` names it in errors. The
    /// bearings must be 2 … [`MAX_SHAFT_BEARINGS`], at least 1 µm apart, with some axial
    /// stiffness among them.
    pub fn new(
        key: &str,
        ei: f64,
        bearings: &[(f64, f64, f64)],
        center_z: f64,
    ) -> Result<Self, ParamError> {
        if !(ei.is_finite() && ei > 0.0 && ei < 1e12) {
            return Err(ParamError::new(
                &format!("{key}.bending_stiffness_nm2"),
                ei,
                "finite, > 0 and < 1e12",
            ));
        }
        if !(2..=MAX_SHAFT_BEARINGS).contains(&bearings.len()) {
            return Err(ParamError::new(
                &format!("{key}.bearings"),
                bearings.len() as f64,
                format!("2 … {MAX_SHAFT_BEARINGS} bearings"),
            ));
        }
        for (i, &(z, k, a)) in bearings.iter().enumerate() {
            let name = |f: &str| format!("{key}.bearings[{i}].{f}");
            super::bearings::BEARING_Z_M.check(&name("z_m"), z)?;
            if !(k.is_finite() && k > 0.0 && k < 1e16) {
                return Err(ParamError::new(&name("radial_n_per_m"), k, "finite, > 0 and < 1e16"));
            }
            if !(a.is_finite() && (0.0..1e16).contains(&a)) {
                return Err(ParamError::new(&name("axial_n_per_m"), a, "finite, >= 0 and < 1e16"));
            }
            for (j, &(zj, _, _)) in bearings.iter().enumerate().take(i) {
                if (z - zj).abs() < super::bearings::MIN_BEARING_SPAN_M {
                    return Err(ParamError::new(
                        &name("z_m"),
                        z,
                        format!("at least 1 µm from bearing {j} (z = {zj} m)"),
                    ));
                }
            }
        }
        let axial: f64 = bearings.iter().map(|b| b.2).sum();
        if axial <= 0.0 {
            return Err(ParamError::new(
                &format!("{key}.bearings"),
                0.0,
                "some bearing with axial_n_per_m > 0 (the shaft must be held along its axis)",
            ));
        }
        // Nodes: the bearings and the gear centre, sorted; a bearing within 1 nm of the centre
        // shares its node.
        let mut zs: Vec<f64> = bearings.iter().map(|b| b.0).collect();
        zs.push(center_z);
        zs.sort_by(f64::total_cmp);
        zs.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let node = |z: f64| zs.iter().position(|&x| (x - z).abs() < 1e-9).expect("a node");
        let n = 2 * zs.len();
        let mut k = nalgebra::DMatrix::<f64>::zeros(n, n);
        for e in 0..zs.len() - 1 {
            let l = zs[e + 1] - zs[e];
            let c = ei / (l * l * l);
            let ke = [
                [12.0, 6.0 * l, -12.0, 6.0 * l],
                [6.0 * l, 4.0 * l * l, -6.0 * l, 2.0 * l * l],
                [-12.0, -6.0 * l, 12.0, -6.0 * l],
                [6.0 * l, 2.0 * l * l, -6.0 * l, 4.0 * l * l],
            ];
            for (r, row) in ke.iter().enumerate() {
                for (col, v) in row.iter().enumerate() {
                    k[(2 * e + r, 2 * e + col)] += c * v;
                }
            }
        }
        for b in bearings {
            let i = node(b.0);
            k[(2 * i, 2 * i)] += b.1;
        }
        let g = node(center_z);
        let mut f = nalgebra::DMatrix::<f64>::zeros(n, 2);
        f[(2 * g, 0)] = 1.0;
        f[(2 * g + 1, 1)] = 1.0;
        let singular = || {
            ParamError::new(
                &format!("{key}.bearings"),
                bearings.len() as f64,
                "bearings that hold the shaft (its stiffness matrix is singular)",
            )
        };
        let x = k.lu().solve(&f).ok_or_else(singular)?;
        let c = nalgebra::Matrix2::new(
            x[(2 * g, 0)],
            x[(2 * g, 1)],
            x[(2 * g + 1, 0)],
            x[(2 * g + 1, 1)],
        );
        let kp = c.try_inverse().ok_or_else(singular)?;
        // Symmetric by construction; averaged against round-off.
        let (kuu, kut, ktt) = (kp[(0, 0)], 0.5 * (kp[(0, 1)] + kp[(1, 0)]), kp[(1, 1)]);
        if !(kuu > 0.0 && ktt > 0.0 && kuu * ktt > kut * kut && kuu.is_finite() && ktt.is_finite())
        {
            return Err(singular());
        }
        let mut stiffness = [[0.0; 5]; 5];
        stiffness[0][0] = kuu;
        stiffness[1][1] = kuu;
        stiffness[2][2] = axial;
        stiffness[3][3] = ktt;
        stiffness[4][4] = ktt;
        stiffness[0][4] = kut;
        stiffness[4][0] = kut;
        stiffness[1][3] = -kut;
        stiffness[3][1] = -kut;
        let mut out = [None; MAX_SHAFT_BEARINGS];
        for (slot, &(z, kr, a)) in out.iter_mut().zip(bearings) {
            let i = node(z);
            let row = [x[(2 * i, 0)], x[(2 * i, 1)]];
            let gi = [
                row[0] * kp[(0, 0)] + row[1] * kp[(1, 0)],
                row[0] * kp[(0, 1)] + row[1] * kp[(1, 1)],
            ];
            *slot = Some(ShaftBearing { z_m: z, radial_n_per_m: kr, axial_n_per_m: a, g: gi });
        }
        Ok(Self { bending_stiffness_nm2: ei, bearings: out, stiffness })
    }

    /// The 5 × 5 stiffness at the gear centre (module docs).
    pub fn stiffness(&self) -> [[f64; 5]; 5] {
        self.stiffness
    }

    /// The bearings, in the order given.
    pub fn bearings(&self) -> impl Iterator<Item = &ShaftBearing> {
        self.bearings.iter().flatten()
    }

    /// The force (x, y, z; N) each bearing exerts on the shaft when the gear body has the pose
    /// `p` (module docs), in the order given.
    pub fn bearing_forces(&self, p: &BodyPose) -> impl Iterator<Item = [f64; 3]> + '_ {
        let axial: f64 = self.bearings().map(|b| b.axial_n_per_m).sum();
        let p = *p;
        self.bearings().map(move |b| {
            let wx = b.g[0] * p.u_x + b.g[1] * p.th_y;
            let wy = b.g[0] * p.u_y - b.g[1] * p.th_x;
            let share = if axial > 0.0 { b.axial_n_per_m } else { 0.0 };
            [-b.radial_n_per_m * wx, -b.radial_n_per_m * wy, -share * p.u_z]
        })
    }
}
