//! Global compliance α* from the fitted influence function of the paper (Eqs. 5–9).
//!
//! The influence function of one tooth, in the flank coordinates (η*, τ, ζ) of the observation
//! point and (η*_F, τ_F, ζ_F) of the load point (η*, ζ in units of m_n, τ in rad, b₀ = b/m_n):
//!
//! ```text
//! α = √(ψ(η*, τ, ζ)·ψ(η*_F, τ_F, ζ_F)) · Γ                                         (5)
//! ψ = A0 + A1·e^{A2 η*} + B0·τ + (A3 + A4·e^{A5 η*} + B1·τ)·e^{(A6 + A7 η*)·ζ}
//!        + (A8 + A9·e^{A10 η*} + B2·τ)·e^{(A11 + A12 η*)·(b₀ − ζ)}                 (6)
//! Γ = exp(−f·|ζ − ζ_F|^{C9})                                                      (7)
//! f = C1 + C2(η* + η*_F) + C3·η*η*_F + C4(η* + η*_F)/(1 + (ζ − ζ_F)²)
//!       + (C5 + C6(η* + η*_F) + C7·η*η*_F)·(b₀ − ζ − ζ_F)²
//!       + C8(η* + η*_F)·√(ψ·ψ_F)                                                   (8)
//! e_rel = (α − α*)/ψ(η*_F, τ_F, ζ_F)                                               (9)
//! ```
//!
//! **Reading of Eq. 5.** The extracted text of Eq. 5 places Γ ambiguously with respect to the
//! square root. This module uses α = √(ψ ψ_F)·Γ (Γ outside the root). Both readings agree at
//! ζ = ζ_F (Γ = 1) and differ only in the meaning of f and C9 (a factor 2 in f), so the family
//! of functions is the same up to that reparametrisation.
//!
//! **Scaling.** α, ψ and the constants A0, A1, A3, A4, A8, A9, B0, B1, B2 are dimensionless, in
//! units of the reference compliance [`FittedInfluence::alpha_ref`] (m/N; the mean of the
//! diagonal α*(i, i) of the fitted grid); η* and ζ are in units of m_n as given, τ in rad, so all
//! constants are O(1). If ψ·ψ_F ≤ 0 (possible only far outside the fitted range) α = 0.
//!
//! **Scope.** Eqs. 5–8 describe the compliance of the loaded tooth itself (observation and load
//! on the same tooth). The coupling to neighbouring teeth (tooth offset ≠ 0, through rim and web)
//! is not part of the formula: [`FittedInfluence`] delegates those offsets to an
//! [`InterpolatedInfluence`] of the neighbour blocks of the same grid.
//!
//! **Fitting** ([`FittedInfluence::fit`]): weighted non-linear least squares with the
//! residuals r = (α(θ) − α*)/α*(load, load) over the selected same-tooth pairs (see
//! [`PairSelection`] and [`FitOptions::max_tau`]; all pairs by default, optionally every
//! `pair_stride`-th pair of the row-major list plus all diagonal pairs), solved by
//! [`super::lm`] with an analytic Jacobian. The weight is the data's value at the load point, the
//! data counterpart of ψ(load) in Eq. 9, so the cost is Σ e_rel² up to that substitution. The
//! start is built in stages: (0) A0, A1, A2, B0 on the mid-face column of the diagonal, (1) all of
//! ψ on the diagonal (there Γ = 1 and α = ψ), with the edge terms started from the data's excess
//! at ζ = 0 and ζ = b₀, (2) C1…C9 with ψ fixed, C1 and C9 started from a log-log regression of
//! −ln(α*/√(ψψ_F)) against |ζ − ζ_F| on the profile-diagonal pairs, (3) all 25 together.
//!
//! **Domain of the formula.** At ζ = ζ_F, Γ = 1 whatever η* and η*_F are, so Eqs. 5–8 give
//! α = √(ψψ_F) between any two profile positions of one transverse section: the formula has no
//! decay along the profile. It is meant for α(ζ, ζ_F) along one instant contact line (Eq. 12),
//! on which η* changes little (for Table 1 by at most 0.38·m_n over the whole face width, about
//! one FE row spacing). [`PairSelection::SameRow`] fits exactly those pairs (observation and
//! load on one profile row); [`PairSelection::All`] also asks the formula for couplings across
//! the profile at equal ζ, where FE data at depth h fall well below √(ψψ_F) near the load.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::interpolated::{InterpolatedInfluence, InvalidGrid};
use super::lm::{Jacobian, LmError, LmOptions, levenberg_marquardt};
use super::{Compliance, FlankCoord, InfluenceGrid};

/// Number of constants of Eqs. 6–8 (A0…A12, B0…B2, C1…C9).
pub const PARAMETER_COUNT: usize = 25;

/// The constants of Eqs. 6–8 (dimensionless scaled form, see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InfluenceParameters {
    /// A0…A12 (`a[k]` = A_k).
    pub a: [f64; 13],
    /// B0…B2 (`b[k]` = B_k).
    pub b: [f64; 3],
    /// C1…C9 (`c[k]` = C_{k+1}).
    pub c: [f64; 9],
}

impl InfluenceParameters {
    /// The constants as one array `[A0…A12, B0…B2, C1…C9]`.
    pub fn to_array(&self) -> [f64; PARAMETER_COUNT] {
        let mut x = [0.0; PARAMETER_COUNT];
        x[0..13].copy_from_slice(&self.a);
        x[13..16].copy_from_slice(&self.b);
        x[16..25].copy_from_slice(&self.c);
        x
    }

    /// Builds the constants from `[A0…A12, B0…B2, C1…C9]`; `None` unless exactly 25 values.
    pub fn from_slice(x: &[f64]) -> Option<Self> {
        if x.len() != PARAMETER_COUNT {
            return None;
        }
        let mut p = Self { a: [0.0; 13], b: [0.0; 3], c: [0.0; 9] };
        p.a.copy_from_slice(&x[0..13]);
        p.b.copy_from_slice(&x[13..16]);
        p.c.copy_from_slice(&x[16..25]);
        Some(p)
    }

    /// ψ(η*, τ, ζ) of Eq. 6 (dimensionless) for face width b₀ (units of m_n).
    pub fn psi(&self, eta_star: f64, tau: f64, zeta: f64, b0: f64) -> f64 {
        psi_grad(&self.to_array(), eta_star, tau, zeta, b0, None)
    }

    /// α of Eqs. 5, 7, 8 (dimensionless) between observation `obs` and load `load` on one tooth.
    pub fn alpha(&self, obs: FlankCoord, load: FlankCoord, b0: f64) -> f64 {
        let x = self.to_array();
        let po = psi_grad(&x, obs.eta_star, obs.tau, obs.zeta, b0, None);
        let pl = psi_grad(&x, load.eta_star, load.tau, load.zeta, b0, None);
        pair_alpha(&x, Pair::new(obs, load, b0), po, pl, None)
    }
}

/// Which same-tooth (observation, load) pairs of a grid enter the fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PairSelection {
    /// Every pair (observation and load anywhere on the flank).
    #[default]
    All,
    /// Pairs with observation and load on the same profile row (equal η* and τ): the pairs of
    /// one instant contact line, along which Eq. 12 evaluates α(ζ, ζ_F) (see the module docs).
    SameRow,
}

impl PairSelection {
    /// Whether grid points `obs` and `load` (indices of a grid with `columns` ζ columns) form a
    /// selected pair.
    pub fn selects(self, obs: usize, load: usize, columns: usize) -> bool {
        match self {
            PairSelection::All => true,
            PairSelection::SameRow => obs / columns == load / columns,
        }
    }
}

/// Settings of [`FittedInfluence::fit_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Use every `pair_stride`-th (observation, load) pair of the row-major list
    /// `k = obs·n + load` plus all diagonal pairs; 1 = all pairs. Choose a stride without a
    /// common factor with n + 1 to avoid aliasing along the diagonal.
    pub pair_stride: usize,
    /// Maximum Levenberg–Marquardt iterations of the final (all-parameter) stage.
    pub max_iterations: usize,
    /// Relative cost change per iteration below which every stage stops ([`LmOptions::cost_tol`]).
    /// The constants of Eqs. 6–8 are not all identifiable from data outside the family (some
    /// combinations drift along flat valleys, lowering the cost by ~1e-9 per iteration), so a
    /// tighter value only spends iterations.
    pub cost_tol: f64,
    /// Which pairs are fitted (before `pair_stride` thins them).
    pub pairs: PairSelection,
    /// Profile rows with τ above this value (rad) are left out of every stage of the fit, e.g.
    /// the rows of the tip rounding whose normals no contact can have. `f64::INFINITY`: all
    /// rows.
    pub max_tau: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            pair_stride: 1,
            max_iterations: 400,
            cost_tol: 1e-8,
            pairs: PairSelection::All,
            max_tau: f64::INFINITY,
        }
    }
}

/// Statistics of e_rel (Eq. 9) of a fitted influence against the same-tooth block of a grid
/// ([`FittedInfluence::deviation`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Deviation {
    /// Standard deviation of e_rel (dimensionless).
    pub std: f64,
    /// Mean of e_rel.
    pub mean: f64,
    /// Largest |e_rel|.
    pub max_abs: f64,
    /// Number of (observation, load) pairs compared.
    pub count: usize,
}

impl Deviation {
    /// Statistics of the values `e` (all zero for an empty list).
    fn of(e: &[f64]) -> Self {
        if e.is_empty() {
            return Self { std: 0.0, mean: 0.0, max_abs: 0.0, count: 0 };
        }
        let m = e.len() as f64;
        let mean = e.iter().sum::<f64>() / m;
        let var = e.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / m;
        let max_abs = e.iter().map(|v| v.abs()).fold(0.0, f64::max);
        Self { std: var.sqrt(), mean, max_abs, count: e.len() }
    }
}

/// Quality of a fit (Eq. 9) and solver statistics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// Standard deviation of e_rel (Eq. 9, with ψ(load) of the fitted formula) over all fitted
    /// pairs.
    pub sigma_e_rel: f64,
    /// Mean of e_rel over the fitted pairs.
    pub mean_e_rel: f64,
    /// Largest |e_rel| over the fitted pairs.
    pub max_abs_e_rel: f64,
    /// Number of fitted (observation, load) pairs.
    pub fitted_values: usize,
    /// Levenberg–Marquardt iterations of the stages 0 (mid-face ψ core), 1 (ψ on the diagonal),
    /// 2 (C with ψ fixed) and 3 (all constants).
    pub stage_iterations: [usize; 4],
    /// Final cost ½Σr² of the weighted residuals r = (α − α*)/α*(load, load).
    pub cost: f64,
    /// Whether the final stage met a convergence test (false: stopped at the iteration limit or
    /// stalled; the best point found is used).
    pub converged: bool,
}

/// Failure of [`FittedInfluence::fit`].
#[derive(Debug, Clone, PartialEq)]
pub enum FitError {
    /// The grid failed validation.
    Grid(InvalidGrid),
    /// Unusable input (face width, non-positive diagonal compliance, options).
    Input(String),
    /// The least-squares solver failed in the named stage.
    Solver {
        /// Stage 0–3 (see [`FitReport::stage_iterations`]).
        stage: usize,
        /// The solver's error.
        error: LmError,
    },
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FitError::Grid(e) => write!(f, "{e}"),
            FitError::Input(m) => write!(f, "influence fit: {m}"),
            FitError::Solver { stage, error } => write!(f, "influence fit, stage {stage}: {error}"),
        }
    }
}

impl std::error::Error for FitError {}

impl From<InvalidGrid> for FitError {
    fn from(e: InvalidGrid) -> Self {
        FitError::Grid(e)
    }
}

/// ψ of Eq. 6 and, if requested, its gradient with respect to `[A0…A12, B0…B2]`.
fn psi_grad(x: &[f64], e: f64, tau: f64, z: f64, b0: f64, g: Option<&mut [f64; 16]>) -> f64 {
    let a = &x[0..13];
    let b = &x[13..16];
    let e2 = (a[2] * e).exp();
    let e5 = (a[5] * e).exp();
    let e10 = (a[10] * e).exp();
    let ex1 = ((a[6] + a[7] * e) * z).exp();
    let zb = b0 - z;
    let ex2 = ((a[11] + a[12] * e) * zb).exp();
    let p1 = a[3] + a[4] * e5 + b[1] * tau;
    let p2 = a[8] + a[9] * e10 + b[2] * tau;
    if let Some(g) = g {
        *g = [
            1.0,
            e2,
            a[1] * e * e2,
            ex1,
            e5 * ex1,
            a[4] * e * e5 * ex1,
            p1 * z * ex1,
            p1 * e * z * ex1,
            ex2,
            e10 * ex2,
            a[9] * e * e10 * ex2,
            p2 * zb * ex2,
            p2 * e * zb * ex2,
            tau,
            tau * ex1,
            tau * ex2,
        ];
    }
    a[0] + a[1] * e2 + b[0] * tau + p1 * ex1 + p2 * ex2
}

/// Geometric quantities of one (observation, load) pair entering f and Γ.
#[derive(Debug, Clone, Copy)]
struct Pair {
    /// η* + η*_F.
    s: f64,
    /// η*·η*_F.
    p: f64,
    /// ζ − ζ_F.
    dz: f64,
    /// (b₀ − ζ − ζ_F)².
    q: f64,
}

impl Pair {
    fn new(o: FlankCoord, l: FlankCoord, b0: f64) -> Self {
        let w = b0 - o.zeta - l.zeta;
        Self {
            s: o.eta_star + l.eta_star,
            p: o.eta_star * l.eta_star,
            dz: o.zeta - l.zeta,
            q: w * w,
        }
    }
}

/// ψ-gradients of the two points of a pair, for the Jacobian.
struct PsiGrads<'a> {
    obs: &'a [f64; 16],
    load: &'a [f64; 16],
}

/// α of Eqs. 5, 7, 8 from ψ of both points; with `grad`, also ∂α/∂[A, B, C] (25 values).
fn pair_alpha(
    x: &[f64],
    pr: Pair,
    psi_o: f64,
    psi_l: f64,
    grad: Option<(&PsiGrads<'_>, &mut [f64; PARAMETER_COUNT])>,
) -> f64 {
    let c = &x[16..25];
    let prod = psi_o * psi_l;
    let sq = if prod > 0.0 { prod.sqrt() } else { 0.0 };
    let d = pr.dz.abs();
    let dpow = if d > 0.0 { d.powf(c[8]) } else { 0.0 };
    let lorentz = 1.0 / (1.0 + pr.dz * pr.dz);
    let basis = [1.0, pr.s, pr.p, pr.s * lorentz, pr.q, pr.s * pr.q, pr.p * pr.q, pr.s * sq];
    let f: f64 = basis.iter().zip(&c[0..8]).map(|(u, v)| u * v).sum();
    let gamma = (-f * dpow).exp();
    let alpha = sq * gamma;
    if let Some((pg, g)) = grad {
        if sq > 0.0 {
            // ∂α/∂θ_ψ = Γ·∂S/∂θ·(1 − S·d^{C9}·C8·s).
            let factor = gamma * (1.0 - sq * dpow * c[7] * pr.s) / (2.0 * sq);
            for ((gk, &dob), &dlo) in g[..16].iter_mut().zip(pg.obs).zip(pg.load) {
                *gk = factor * (psi_l * dob + psi_o * dlo);
            }
        } else {
            g[..16].iter_mut().for_each(|v| *v = 0.0);
        }
        let common = -alpha * dpow;
        for k in 0..8 {
            g[16 + k] = common * basis[k];
        }
        g[24] = if d > 0.0 { common * f * d.ln() } else { 0.0 };
    }
    alpha
}

/// The fitting problem: points, selected pairs, scaled data and weights.
struct Problem {
    points: Vec<FlankCoord>,
    pairs: Vec<(usize, usize)>,
    geom: Vec<Pair>,
    y: Vec<f64>,
    w: Vec<f64>,
    b0: f64,
}

impl Problem {
    /// Residuals (and the Jacobian columns `free` if `jac` is given) at the full vector `x`.
    fn eval(&self, x: &[f64], r: &mut [f64], jac: Option<(&mut [f64], &[usize])>) {
        let np = self.points.len();
        let mut psi = vec![0.0; np];
        let mut dpsi = vec![[0.0; 16]; np];
        let want = jac.is_some();
        for (i, c) in self.points.iter().enumerate() {
            psi[i] = psi_grad(x, c.eta_star, c.tau, c.zeta, self.b0, want.then_some(&mut dpsi[i]));
        }
        match jac {
            None => {
                for (k, &(i, j)) in self.pairs.iter().enumerate() {
                    let a = pair_alpha(x, self.geom[k], psi[i], psi[j], None);
                    r[k] = (a - self.y[k]) * self.w[k];
                }
            }
            Some((jm, free)) => {
                let nf = free.len();
                let mut g = [0.0; PARAMETER_COUNT];
                for (k, &(i, j)) in self.pairs.iter().enumerate() {
                    let pg = PsiGrads { obs: &dpsi[i], load: &dpsi[j] };
                    let a = pair_alpha(x, self.geom[k], psi[i], psi[j], Some((&pg, &mut g)));
                    r[k] = (a - self.y[k]) * self.w[k];
                    for (col, &p) in free.iter().enumerate() {
                        jm[k * nf + col] = g[p] * self.w[k];
                    }
                }
            }
        }
    }
}

/// Runs LM over the parameters `free` of the full vector `x` (others fixed) for `m` residuals
/// given by `eval(full, r, jac)`. Accepts the best point on the iteration limit or a stall.
fn solve_subset<E>(
    x: &mut [f64],
    free: &[usize],
    m: usize,
    eval: E,
    max_iterations: usize,
    cost_tol: f64,
    stage: usize,
) -> Result<(usize, f64, bool), FitError>
where
    E: Fn(&[f64], &mut [f64], Option<(&mut [f64], &[usize])>),
{
    let base = x.to_vec();
    let full = |v: &[f64]| {
        let mut f = base.clone();
        for (k, &p) in free.iter().enumerate() {
            f[p] = v[k];
        }
        f
    };
    let x0: Vec<f64> = free.iter().map(|&p| x[p]).collect();
    let opts = LmOptions { max_iterations, cost_tol, ..LmOptions::default() };
    let result = levenberg_marquardt(
        &x0,
        m,
        |v: &[f64], r: &mut [f64]| eval(&full(v), r, None),
        Jacobian::Analytic(|v: &[f64], j: &mut [f64]| {
            let mut r = vec![0.0; m];
            eval(&full(v), &mut r, Some((j, free)));
        }),
        &opts,
    );
    let (best, stats, converged) = match result {
        Ok(s) => (s.x, s.stats, s.stats.termination.is_some()),
        Err(LmError::MaxIterations { best, stats }) | Err(LmError::Stalled { best, stats }) => {
            (best, stats, false)
        }
        Err(error) => return Err(FitError::Solver { stage, error }),
    };
    for (k, &p) in free.iter().enumerate() {
        x[p] = best[k];
    }
    Ok((stats.iterations, stats.cost, converged))
}

/// α* of one gear from the fitted formula of Eqs. 5–8 for the loaded tooth, and from
/// interpolation of the FE neighbour blocks for other teeth (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedInfluence {
    /// The fitted constants (scaled, dimensionless form).
    pub params: InfluenceParameters,
    /// Face width b₀ = b/m_n used in Eqs. 6 and 8.
    pub b0: f64,
    /// Reference compliance, m/N: α* = `alpha_ref`·α.
    pub alpha_ref: f64,
    /// Depth h of Vedmar's division, m.
    pub depth_h: f64,
    /// Interpolant of the grid for tooth offsets ≠ 0 (`None` if the grid has tooth 0 only).
    neighbours: Option<InterpolatedInfluence>,
}

impl FittedInfluence {
    /// Fits Eqs. 5–8 to the same-tooth block of `grid` (all pairs) for face width `b0` (units
    /// of m_n); see [`FittedInfluence::fit_with`].
    pub fn fit(grid: &InfluenceGrid, b0: f64) -> Result<(Self, FitReport), FitError> {
        Self::fit_with(grid, b0, &FitOptions::default())
    }

    /// Fits Eqs. 5–8 to the same-tooth block of `grid` for face width `b0` (units of m_n) with
    /// the given options; the staged procedure is described in the module docs.
    pub fn fit_with(
        grid: &InfluenceGrid,
        b0: f64,
        options: &FitOptions,
    ) -> Result<(Self, FitReport), FitError> {
        grid.validate().map_err(InvalidGrid)?;
        if !(b0.is_finite() && b0 > 0.0) {
            return Err(FitError::Input(format!("face width b0 = {b0} must be > 0")));
        }
        if options.pair_stride == 0 || options.max_iterations == 0 {
            return Err(FitError::Input("pair_stride and max_iterations must be ≥ 1".into()));
        }
        if !(options.cost_tol.is_finite() && options.cost_tol >= 0.0) {
            return Err(FitError::Input(format!("cost_tol = {} must be ≥ 0", options.cost_tol)));
        }
        if options.max_tau.is_nan() {
            return Err(FitError::Input("max_tau is NaN".into()));
        }
        let row_used: Vec<bool> = grid.tau.iter().map(|&t| t <= options.max_tau).collect();
        if row_used.iter().filter(|&&u| u).count() < 2 {
            return Err(FitError::Input(format!(
                "max_tau = {} rad leaves fewer than 2 of the {} profile rows (τ = {:?})",
                options.max_tau,
                grid.tau.len(),
                grid.tau
            )));
        }
        let t0 = grid
            .teeth
            .iter()
            .position(|&t| t == 0)
            .ok_or_else(|| FitError::Input("grid has no tooth-0 block".into()))?;
        let n = grid.points();
        let nc = grid.zeta.len();
        let used = |i: usize| row_used[i / nc];
        let diag: Vec<f64> = (0..n).map(|i| grid.value(t0, i, i)).collect();
        if let Some(i) = (0..n).filter(|&i| used(i)).find(|&i| diag[i] <= 0.0) {
            return Err(FitError::Input(format!(
                "diagonal compliance α*({i}, {i}) = {:e} m/N must be > 0",
                diag[i]
            )));
        }
        let used_pts: Vec<usize> = (0..n).filter(|&i| used(i)).collect();
        let alpha_ref = used_pts.iter().map(|&i| diag[i]).sum::<f64>() / used_pts.len() as f64;
        let dscaled: Vec<f64> = diag.iter().map(|v| v / alpha_ref).collect();
        let points: Vec<FlankCoord> = (0..n).map(|i| grid.coord(i)).collect();
        let mut x = vec![0.0; PARAMETER_COUNT];

        // Stage 0: ψ core on the mid-face column.
        let mid = (0..nc)
            .min_by(|&a, &b| {
                (grid.zeta[a] - 0.5 * b0).abs().total_cmp(&(grid.zeta[b] - 0.5 * b0).abs())
            })
            .unwrap_or(0);
        let mid_pts: Vec<usize> =
            (0..grid.profile.len()).filter(|&r| row_used[r]).map(|r| grid.index(r, mid)).collect();
        let core_eval = |v: &[f64], r: &mut [f64], jac: Option<(&mut [f64], &[usize])>| {
            let mut g = [0.0; 16];
            let nf = jac.as_ref().map_or(0, |(_, f)| f.len());
            let mut jac = jac;
            for (k, &i) in mid_pts.iter().enumerate() {
                let c = points[i];
                let psi = psi_grad(v, c.eta_star, c.tau, 0.5 * b0, b0, Some(&mut g));
                r[k] = (psi - dscaled[i]) / dscaled[i];
                if let Some((jm, free)) = jac.as_mut() {
                    for (col, &p) in free.iter().enumerate() {
                        jm[k * nf + col] = g[p] / dscaled[i];
                    }
                }
            }
        };
        let core_free = [0, 1, 2, 13];
        let mut best_core: Option<(f64, Vec<f64>, usize)> = None;
        let dmin = used_pts.iter().map(|&i| dscaled[i]).fold(f64::INFINITY, f64::min);
        for a2 in [-2.0, -1.0, -0.5, -0.2] {
            let mut xt = vec![0.0; PARAMETER_COUNT];
            xt[0] = 0.5 * dmin;
            xt[1] = 0.5;
            xt[2] = a2;
            xt[6] = -2.0;
            xt[11] = -2.0;
            let (it, cost, _) = solve_subset(
                &mut xt,
                &core_free,
                mid_pts.len(),
                core_eval,
                100,
                options.cost_tol,
                0,
            )?;
            if best_core.as_ref().is_none_or(|b| cost < b.0) {
                best_core = Some((cost, xt, it));
            }
        }
        let (_, core, it0) =
            best_core.ok_or_else(|| FitError::Input("no profile rows to fit".into()))?;
        x.copy_from_slice(&core);

        // Stage 1: all of ψ on the diagonal, edge terms from the excess at ζ = 0 and ζ = b₀.
        let rows: Vec<usize> = (0..grid.profile.len()).filter(|&r| row_used[r]).collect();
        let core_at = |i: usize| {
            let c = points[i];
            x[0] + x[1] * (x[2] * c.eta_star).exp() + x[13] * c.tau
        };
        let mean_excess = |col: usize| {
            rows.iter()
                .map(|&r| dscaled[grid.index(r, col)] - core_at(grid.index(r, col)))
                .sum::<f64>()
                / rows.len() as f64
        };
        let decay = |edge: usize, next: usize| {
            let (e0, e1) = (mean_excess(edge), mean_excess(next));
            let dz = (grid.zeta[next] - grid.zeta[edge]).abs();
            let ratio = e1 / e0;
            if e0 > 0.0 && ratio > 0.0 && ratio < 1.0 && dz > 0.0 { ratio.ln() / dz } else { -2.0 }
        };
        let (e_lo, e_hi) = (mean_excess(0), mean_excess(nc - 1));
        let (k_lo, k_hi) = (decay(0, 1), decay(nc - 1, nc - 2));
        let floor = 0.02;
        x[3] = e_lo.max(floor);
        x[4] = 0.1 * x[3];
        x[5] = x[2];
        x[6] = k_lo;
        x[8] = e_hi.max(floor);
        x[9] = 0.1 * x[8];
        x[10] = x[2];
        x[11] = k_hi;
        let diag_eval = |v: &[f64], r: &mut [f64], jac: Option<(&mut [f64], &[usize])>| {
            let mut g = [0.0; 16];
            let nf = jac.as_ref().map_or(0, |(_, f)| f.len());
            let mut jac = jac;
            for (k, &i) in used_pts.iter().enumerate() {
                let c = points[i];
                let psi = psi_grad(v, c.eta_star, c.tau, c.zeta, b0, Some(&mut g));
                r[k] = (psi - dscaled[i]) / dscaled[i];
                if let Some((jm, free)) = jac.as_mut() {
                    for (col, &p) in free.iter().enumerate() {
                        jm[k * nf + col] = g[p] / dscaled[i];
                    }
                }
            }
        };
        let psi_free: Vec<usize> = (0..16).collect();
        let (it1, _, _) =
            solve_subset(&mut x, &psi_free, used_pts.len(), diag_eval, 300, options.cost_tol, 1)?;

        // Selected pairs and the scaled data.
        let mut pairs = Vec::new();
        for &i in &used_pts {
            for &j in &used_pts {
                let k = i * n + j;
                if options.pairs.selects(i, j, nc)
                    && (i == j || k.is_multiple_of(options.pair_stride))
                {
                    pairs.push((i, j));
                }
            }
        }
        let block = &grid.alpha[t0];
        let problem = Problem {
            geom: pairs.iter().map(|&(i, j)| Pair::new(points[i], points[j], b0)).collect(),
            y: pairs.iter().map(|&(i, j)| block[i * n + j] / alpha_ref).collect(),
            w: pairs.iter().map(|&(_, j)| 1.0 / dscaled[j]).collect(),
            points: points.clone(),
            pairs,
            b0,
        };
        let m = problem.pairs.len();

        // Stage 2: C with ψ fixed; C1, C9 from a log-log regression on same-row pairs.
        let psi_now: Vec<f64> =
            points.iter().map(|c| psi_grad(&x, c.eta_star, c.tau, c.zeta, b0, None)).collect();
        let (mut sx, mut sy, mut sxx, mut sxy, mut cnt) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (k, &(i, j)) in problem.pairs.iter().enumerate() {
            let same_row = i / nc == j / nc;
            let d = problem.geom[k].dz.abs();
            let prod = psi_now[i] * psi_now[j];
            if !same_row || d <= 0.0 || prod <= 0.0 {
                continue;
            }
            let ratio = problem.y[k] / prod.sqrt();
            if ratio > 0.0 && ratio < 1.0 {
                let (lx, ly) = (d.ln(), (-ratio.ln()).ln());
                if ly.is_finite() {
                    sx += lx;
                    sy += ly;
                    sxx += lx * lx;
                    sxy += lx * ly;
                    cnt += 1.0;
                }
            }
        }
        let (mut c1, mut c9) = (1.0, 1.5);
        let den = cnt * sxx - sx * sx;
        if cnt >= 3.0 && den > 0.0 {
            let slope = (cnt * sxy - sx * sy) / den;
            let icpt = (sy - slope * sx) / cnt;
            if slope.is_finite() && icpt.is_finite() {
                c9 = slope.clamp(0.5, 3.0);
                c1 = ((sy - c9 * sx) / cnt).exp().clamp(1e-3, 1e3);
            }
        }
        x[16] = c1;
        x[24] = c9;
        let full_eval =
            |v: &[f64], r: &mut [f64], jac: Option<(&mut [f64], &[usize])>| problem.eval(v, r, jac);
        let c_free: Vec<usize> = (16..25).collect();
        let (it2, _, _) = solve_subset(&mut x, &c_free, m, full_eval, 300, options.cost_tol, 2)?;

        // Stage 3: everything.
        let all: Vec<usize> = (0..PARAMETER_COUNT).collect();
        let (it3, cost, converged) =
            solve_subset(&mut x, &all, m, full_eval, options.max_iterations, options.cost_tol, 3)?;

        let params = InfluenceParameters::from_slice(&x)
            .ok_or_else(|| FitError::Input("internal parameter count".into()))?;
        let psi_fit: Vec<f64> =
            points.iter().map(|c| psi_grad(&x, c.eta_star, c.tau, c.zeta, b0, None)).collect();
        let mut e = Vec::with_capacity(m);
        for (k, &(i, j)) in problem.pairs.iter().enumerate() {
            let a = pair_alpha(&x, problem.geom[k], psi_fit[i], psi_fit[j], None);
            e.push((a - problem.y[k]) / psi_fit[j]);
        }
        let stats = Deviation::of(&e);
        if !(stats.std.is_finite() && stats.max_abs.is_finite()) {
            return Err(FitError::Input(
                "fitted ψ is not positive at every grid point; the data do not follow Eqs. 5–8"
                    .into(),
            ));
        }
        let neighbours = if grid.teeth.iter().any(|&t| t != 0) {
            Some(InterpolatedInfluence::new(grid.clone())?)
        } else {
            None
        };
        let fitted = Self { params, b0, alpha_ref, depth_h: grid.depth_h, neighbours };
        let report = FitReport {
            sigma_e_rel: stats.std,
            mean_e_rel: stats.mean,
            max_abs_e_rel: stats.max_abs,
            fitted_values: m,
            stage_iterations: [it0, it1, it2, it3],
            cost,
            converged,
        };
        Ok((fitted, report))
    }

    /// Builds a fitted influence from known constants (no neighbour coupling), e.g. the paper's
    /// or a cached fit. `b0` in units of m_n, `alpha_ref` in m/N, `depth_h` in m.
    pub fn from_parameters(
        params: InfluenceParameters,
        b0: f64,
        alpha_ref: f64,
        depth_h: f64,
    ) -> Self {
        Self { params, b0, alpha_ref, depth_h, neighbours: None }
    }

    /// Builds a fitted influence from known constants (e.g. a cached fit) with the coupling to
    /// neighbouring teeth interpolated from the neighbour blocks of `grid` (tooth offsets ≠ 0;
    /// its tooth-0 block is not used). `b0` in units of m_n, `alpha_ref` in m/N; the depth h
    /// is the grid's. Errors if the grid fails validation.
    pub fn with_neighbours(
        params: InfluenceParameters,
        b0: f64,
        alpha_ref: f64,
        grid: InfluenceGrid,
    ) -> Result<Self, InvalidGrid> {
        let depth_h = grid.depth_h;
        let neighbours = if grid.teeth.iter().any(|&t| t != 0) {
            Some(InterpolatedInfluence::new(grid)?)
        } else {
            grid.validate().map_err(InvalidGrid)?;
            None
        };
        Ok(Self { params, b0, alpha_ref, depth_h, neighbours })
    }

    /// e_rel of Eq. 9, (α − α*)/ψ(load) with α and ψ of this formula and α* of the tooth-0
    /// block of `grid`, over the grid pairs (observation `i`, load `j`) for which
    /// `select(i, j)` is true. Errors if the grid fails validation or has no tooth-0 block.
    pub fn deviation(
        &self,
        grid: &InfluenceGrid,
        select: impl Fn(usize, usize) -> bool,
    ) -> Result<Deviation, InvalidGrid> {
        grid.validate().map_err(InvalidGrid)?;
        let t0 = grid
            .teeth
            .iter()
            .position(|&t| t == 0)
            .ok_or_else(|| InvalidGrid("no tooth-0 block".into()))?;
        let n = grid.points();
        let mut e = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if select(i, j) {
                    let (o, l) = (grid.coord(i), grid.coord(j));
                    let a = self.alpha(o, l, 0);
                    e.push((a - grid.value(t0, i, j)) / self.psi(l));
                }
            }
        }
        Ok(Deviation::of(&e))
    }

    /// Interpolant used for tooth offsets ≠ 0, if any.
    pub fn neighbours(&self) -> Option<&InterpolatedInfluence> {
        self.neighbours.as_ref()
    }

    /// ψ of Eq. 6 at `c`, m/N (i.e. scaled by [`FittedInfluence::alpha_ref`]).
    pub fn psi(&self, c: FlankCoord) -> f64 {
        self.alpha_ref * self.params.psi(c.eta_star, c.tau, c.zeta, self.b0)
    }
}

impl Compliance for FittedInfluence {
    fn alpha(&self, obs: FlankCoord, load: FlankCoord, tooth_offset: i32) -> f64 {
        if tooth_offset == 0 {
            self.alpha_ref * self.params.alpha(obs, load, self.b0)
        } else {
            self.neighbours.as_ref().map_or(0.0, |n| n.alpha(obs, load, tooth_offset))
        }
    }

    fn depth(&self) -> f64 {
        self.depth_h
    }

    fn max_tooth_offset(&self) -> i32 {
        self.neighbours.as_ref().map_or(0, |n| n.max_tooth_offset())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic gradient of α with respect to all 25 constants against central differences.
    #[test]
    fn analytic_gradient_matches_finite_differences() {
        let x: [f64; PARAMETER_COUNT] = [
            0.3, 1.2, -0.8, 0.3, 0.2, -0.5, -1.5, 0.2, 0.25, 0.2, -0.5, -1.5, 0.2, 0.5, 0.1, 0.1,
            0.8, 0.1, -0.02, 0.1, 0.01, 0.03, -0.01, 0.1, 1.6,
        ];
        let b0 = 5.0;
        let o = FlankCoord { eta_star: 0.4, tau: 0.15, zeta: 1.3 };
        let l = FlankCoord { eta_star: 1.7, tau: 0.0, zeta: 3.1 };
        let eval = |x: &[f64], grad: Option<&mut [f64; PARAMETER_COUNT]>| {
            let (mut go, mut gl) = ([0.0; 16], [0.0; 16]);
            let po = psi_grad(x, o.eta_star, o.tau, o.zeta, b0, Some(&mut go));
            let pl = psi_grad(x, l.eta_star, l.tau, l.zeta, b0, Some(&mut gl));
            let pg = PsiGrads { obs: &go, load: &gl };
            pair_alpha(x, Pair::new(o, l, b0), po, pl, grad.map(|g| (&pg, g)))
        };
        let mut g = [0.0; PARAMETER_COUNT];
        let a = eval(&x, Some(&mut g));
        assert!(a > 0.0);
        for k in 0..PARAMETER_COUNT {
            let h = 1e-6 * x[k].abs().max(1.0);
            let (mut xp, mut xm) = (x, x);
            xp[k] += h;
            xm[k] -= h;
            let fd = (eval(&xp, None) - eval(&xm, None)) / (2.0 * h);
            assert!((fd - g[k]).abs() <= 1e-7 * (1.0 + fd.abs()), "∂α/∂x[{k}]: {} vs {fd}", g[k]);
        }
    }
}
