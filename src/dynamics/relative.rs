//! Relative coordinates of a unit's state: the continuous states a Model Exchange master
//! integrates.
//!
//! A unit ([`super::unit::DriveUnit`]) keeps the absolute angles and rates of its bodies. Those
//! are poor states for an importer's error control: the angles grow without bound (φp ≈ 530 rad
//! after one second at 532 rad/s) while the quantities that carry the physics are tiny
//! differences of them — the transmission error TE = g_p·φp + g_g·φg is about 10⁻⁵ m against
//! g_p·φp ≈ 16 m, and the shaft twists φ₁ − φp about 10⁻³ rad. A solver that controls
//! `rtol·|x| + atol` per component (CVode, DASSL, Dymola's and Simulink's solvers) then
//! allows an error in φg that is far larger than TE itself, whatever the nominal values say.
//! In relative coordinates every small quantity is a state of its own and the tolerances act
//! where the physics is:
//!
//! ```text
//! Pair, Stage (4):  x = (φp, TE, φ̇p, v_TE)                      v_TE = g_p·φ̇p + g_g·φ̇g
//! Drive (8):        x = (φp, θ₁, TE, θ₂, φ̇p, θ̇₁, v_TE, θ̇₂)     θ₁ = φ₁ − φp, θ₂ = φg − φ₂
//! ```
//!
//! (angles rad, TE m, rates rad/s and m/s; θ₁ is the twist of the pinion shaft, positive when
//! the drive end leads, θ₂ that of the gear shaft, positive when the gear leads its load end).
//! The map is linear and constant, x = T·y with T = diag(P, P) on the position and the rate
//! halves, so the state derivative is ẋ = T·ẏ and a linearisation transforms exactly:
//! A_x = T·A·T⁻¹, B_x = T·B, C_x = C·T⁻¹, D_x = D ([`RelativeCoordinates::linearization`]).
//! Going back, φg = (TE − g_p·φp)/g_g loses only the rounding of g_p·φp (≈ 10⁻¹⁵ m in TE).
//!
//! Nominal values ([`RelativeCoordinates::nominals`]) scale each component to its size in
//! nominal running: 1 rad for φp, the static twists and TE under the nominal torque for the
//! small angles, those times the fastest linearised frequency for their rates, and the nominal
//! speed for φ̇p.
//!
//! The coordinates are typed ([`PAIR_STATES`], [`DRIVE_STATES`]: [`UnitQuantity`] values in
//! coordinate order); the names an interface gives them (the FMUs' state variables) are that
//! interface's.

use super::integrators::{OdeError, OdeSystem};
use super::kind::{UnitKind, UnitLinearization, UnitQuantity};
use super::model::N_STATES;

/// The relative coordinates of the Pair and the Stage, in order: (φp, TE, φ̇p, v_TE).
pub const PAIR_STATES: [UnitQuantity; 4] =
    [UnitQuantity::PhiP, UnitQuantity::Te, UnitQuantity::WP, UnitQuantity::VTe];
/// The relative coordinates of the Drive, in order: (φp, θ₁, TE, θ₂, φ̇p, θ̇₁, v_TE, θ̇₂).
pub const DRIVE_STATES: [UnitQuantity; 8] = [
    UnitQuantity::PhiP,
    UnitQuantity::Theta1,
    UnitQuantity::Te,
    UnitQuantity::Theta2,
    UnitQuantity::WP,
    UnitQuantity::WTheta1,
    UnitQuantity::VTe,
    UnitQuantity::WTheta2,
];

/// The linear map between a unit's absolute state and its relative coordinates (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativeCoordinates {
    kind: UnitKind,
    /// Base radius of the pinion g_p, m (> 0).
    g_p: f64,
    /// Base radius of the gear g_g, m (> 0).
    g_g: f64,
}

impl RelativeCoordinates {
    /// The map for a unit of `kind` with base radii `g_p`, `g_g` (m, finite and > 0; TE =
    /// g_p·φp + g_g·φg). Panics on invalid radii (they come from a validated gear pair).
    pub fn new(kind: UnitKind, g_p: f64, g_g: f64) -> Self {
        assert!(g_p.is_finite() && g_p > 0.0 && g_g.is_finite() && g_g > 0.0, "base radii");
        Self { kind, g_p, g_g }
    }

    /// Number of states (that of the kind).
    pub fn n(&self) -> usize {
        self.kind.n_states()
    }

    /// The coordinates in order ([`PAIR_STATES`], [`DRIVE_STATES`]).
    pub fn states(&self) -> &'static [UnitQuantity] {
        match self.kind {
            UnitKind::Pair | UnitKind::Stage => &PAIR_STATES,
            UnitKind::Drive => &DRIVE_STATES,
        }
    }

    /// P (half × half, row-major): the position (and, identically, the rate) block of T.
    fn p(&self) -> ([f64; 16], usize) {
        let (gp, gg) = (self.g_p, self.g_g);
        let mut p = [0.0; 16];
        match self.kind {
            UnitKind::Pair | UnitKind::Stage => {
                // (φp, φg) → (φp, TE)
                p[0] = 1.0;
                p[2] = gp;
                p[3] = gg;
                (p, 2)
            }
            UnitKind::Drive => {
                // (φ1, φp, φg, φ2) → (φp, θ1, TE, θ2)
                let h = 4;
                p[1] = 1.0;
                p[h] = 1.0;
                p[h + 1] = -1.0;
                p[2 * h + 1] = gp;
                p[2 * h + 2] = gg;
                p[3 * h + 2] = 1.0;
                p[3 * h + 3] = -1.0;
                (p, 4)
            }
        }
    }

    /// P⁻¹ (half × half, row-major).
    fn p_inv(&self) -> ([f64; 16], usize) {
        let (gp, gg) = (self.g_p, self.g_g);
        let mut q = [0.0; 16];
        match self.kind {
            UnitKind::Pair | UnitKind::Stage => {
                // φp = x0, φg = (x1 − g_p·x0)/g_g
                q[0] = 1.0;
                q[2] = -gp / gg;
                q[3] = 1.0 / gg;
                (q, 2)
            }
            UnitKind::Drive => {
                // φ1 = x0 + x1, φp = x0, φg = (x2 − g_p·x0)/g_g, φ2 = φg − x3
                let h = 4;
                q[0] = 1.0;
                q[1] = 1.0;
                q[h] = 1.0;
                q[2 * h] = -gp / gg;
                q[2 * h + 2] = 1.0 / gg;
                q[3 * h] = -gp / gg;
                q[3 * h + 2] = 1.0 / gg;
                q[3 * h + 3] = -1.0;
                (q, 4)
            }
        }
    }

    /// x = T·y for a state or a state derivative (`y`, `x` of length [`Self::n`]).
    pub fn to_relative(&self, y: &[f64], x: &mut [f64]) {
        apply_blocks(self.p(), y, x);
    }

    /// y = T⁻¹·x (`x`, `y` of length [`Self::n`]).
    pub fn to_absolute(&self, x: &[f64], y: &mut [f64]) {
        apply_blocks(self.p_inv(), x, y);
    }

    /// T as a dense n × n row-major matrix.
    pub fn t(&self) -> Vec<f64> {
        dense(self.p())
    }

    /// T⁻¹ as a dense n × n row-major matrix.
    pub fn t_inv(&self) -> Vec<f64> {
        dense(self.p_inv())
    }

    /// Nominal magnitudes of the components (same units as the coordinates, all > 0): 1 rad
    /// for φp; the static twists θ₁ = M/c₁, θ₂ = M·(z_g/z_p)/c₂ and the static TE ≈
    /// M/(g_p·k) under the nominal torque `torque` (N·m) with mesh stiffness `k` (N/m) and
    /// shaft stiffnesses `c1`, `c2` (N·m/rad); those times `omega_fast` (rad/s) for their
    /// rates; `w_nominal` (rad/s) for φ̇p. Non-positive or non-finite inputs fall back to 1
    /// for the affected entries.
    #[allow(clippy::too_many_arguments)]
    pub fn nominals(
        &self,
        torque: f64,
        ratio: f64,
        k: f64,
        c1: f64,
        c2: f64,
        omega_fast: f64,
        w_nominal: f64,
        out: &mut [f64],
    ) {
        let pos = |v: f64| if v.is_finite() && v > 0.0 { v } else { 1.0 };
        let te = pos(torque.abs() / (self.g_p * k));
        let th1 = pos(torque.abs() / c1);
        let th2 = pos(torque.abs() * ratio / c2);
        let w = pos(omega_fast);
        let wp = pos(w_nominal.abs());
        let v: Vec<f64> = match self.kind {
            UnitKind::Pair | UnitKind::Stage => vec![1.0, te, wp, pos(te * w)],
            UnitKind::Drive => {
                vec![1.0, th1, te, th2, wp, pos(th1 * w), pos(te * w), pos(th2 * w)]
            }
        };
        out.copy_from_slice(&v);
    }

    /// The linearisation `lin` (in absolute states) in relative coordinates: A_x = T·A·T⁻¹,
    /// B_x = T·B, C_x = C·T⁻¹, D_x = D.
    pub fn linearization(&self, lin: &UnitLinearization) -> UnitLinearization {
        let n = lin.n_x;
        assert_eq!(n, self.n(), "linearisation of another kind");
        let t = self.t();
        let ti = self.t_inv();
        let a = matmul(&matmul(&t, &lin.a, n, n, n), &ti, n, n, n);
        let b = matmul(&t, &lin.b, n, n, lin.n_u);
        let c = matmul(&lin.c, &ti, lin.n_y, n, n);
        UnitLinearization { a, b, c, ..lin.clone() }
    }
}

/// Applies diag(P, P) (P of size h × h in a 4 × 4 array) to `y`.
fn apply_blocks((p, h): ([f64; 16], usize), y: &[f64], x: &mut [f64]) {
    for half in 0..2 {
        let o = half * h;
        for i in 0..h {
            x[o + i] = (0..h).map(|j| p[i * h + j] * y[o + j]).sum();
        }
    }
}

fn dense((p, h): ([f64; 16], usize)) -> Vec<f64> {
    let n = 2 * h;
    let mut m = vec![0.0; n * n];
    for half in 0..2 {
        let o = half * h;
        for i in 0..h {
            for j in 0..h {
                m[(o + i) * n + o + j] = p[i * h + j];
            }
        }
    }
    m
}

/// (r × k)·(k × c), row-major.
fn matmul(a: &[f64], b: &[f64], r: usize, k: usize, c: usize) -> Vec<f64> {
    let mut m = vec![0.0; r * c];
    for i in 0..r {
        for l in 0..k {
            let x = a[i * k + l];
            if x != 0.0 {
                for j in 0..c {
                    m[i * c + j] += x * b[l * c + j];
                }
            }
        }
    }
    m
}

/// An ODE system in absolute coordinates y seen in relative coordinates x = T·y:
/// ẋ = T·f(t, T⁻¹·x). Integrating this with an error-controlled method (DOPRI5) puts the
/// tolerances on φp, TE and the shaft twists (module doc) instead of on the absolute angles,
/// whose `rtol·|φ|` would allow TE errors far larger than TE. No allocation: the absolute
/// state and derivative live in fixed arrays.
pub struct InRelative<'a, S: ?Sized> {
    sys: &'a mut S,
    rel: RelativeCoordinates,
    y: [f64; N_STATES],
    dy: [f64; N_STATES],
}

impl<'a, S: OdeSystem + ?Sized> InRelative<'a, S> {
    /// `sys` (of dimension `rel.n()`) in the coordinates of `rel`.
    pub fn new(sys: &'a mut S, rel: RelativeCoordinates) -> Self {
        Self { sys, rel, y: [0.0; N_STATES], dy: [0.0; N_STATES] }
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for InRelative<'_, S> {
    fn dim(&self) -> usize {
        self.rel.n()
    }

    fn rhs(&mut self, t: f64, x: &[f64], dxdt: &mut [f64]) -> Result<(), OdeError> {
        let n = self.rel.n();
        if x.len() != n || dxdt.len() != n || self.sys.dim() != n {
            return Err(OdeError::DimensionMismatch {
                what: "relative state",
                expected: n,
                found: if x.len() != n { x.len() } else { dxdt.len().min(self.sys.dim()) },
            });
        }
        self.rel.to_absolute(x, &mut self.y[..n]);
        self.sys.rhs(t, &self.y[..n], &mut self.dy[..n])?;
        self.rel.to_relative(&self.dy[..n], dxdt);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_and_its_inverse_are_inverse() {
        for kind in [UnitKind::Pair, UnitKind::Stage, UnitKind::Drive] {
            let r = RelativeCoordinates::new(kind, 0.031, 0.052);
            let n = r.n();
            let (t, ti) = (r.t(), r.t_inv());
            let id = matmul(&t, &ti, n, n, n);
            for i in 0..n {
                for j in 0..n {
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((id[i * n + j] - e).abs() < 1e-14, "{kind:?} ({i},{j})");
                }
            }
            let y: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 * 0.37).collect();
            let (mut x, mut back) = (vec![0.0; n], vec![0.0; n]);
            r.to_relative(&y, &mut x);
            r.to_absolute(&x, &mut back);
            for (a, b) in y.iter().zip(&back) {
                assert!((a - b).abs() < 1e-14);
            }
            let te = x[r.states().iter().position(|&s| s == UnitQuantity::Te).unwrap()];
            let (pp, pg) = match kind {
                UnitKind::Drive => (y[1], y[2]),
                _ => (y[0], y[1]),
            };
            assert!((te - (0.031 * pp + 0.052 * pg)).abs() < 1e-15);
        }
    }
}
