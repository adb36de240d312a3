//! Levenberg–Marquardt non-linear least squares.
//!
//! Minimises the cost F(x) = ½·Σᵢ rᵢ(x)² over x ∈ ℝⁿ for m residuals rᵢ. Each iteration solves
//! the damped normal equations
//!
//! ```text
//! (JᵀJ + λ·D) δ = −Jᵀr,     D = diag(d₁ … dₙ),  dⱼ = max over iterations of (JᵀJ)ⱼⱼ
//! ```
//!
//! (Marquardt's scaling, kept non-decreasing as in Moré's MINPACK so that the damping cannot
//! collapse when a column of J momentarily vanishes) with a dense Cholesky factorisation. A step
//! is accepted when the gain ratio ρ = (F(x) − F(x+δ)) / (L(0) − L(δ)) of the actual to the
//! linear-model reduction is positive; λ is then multiplied by max(⅓, 1 − (2ρ − 1)³), otherwise
//! by ν (ν doubling after each rejection; Nielsen's update). A failed factorisation is retried
//! with a larger λ.
//!
//! Convergence (any of, checked after each accepted step unless stated):
//! * relative cost change (F_old − F_new) ≤ `cost_tol`·F_old,
//! * scaled gradient max_j |(Jᵀr)_j| / (‖J_j‖·‖r‖) ≤ `gradient_tol` (the cosine of the angle
//!   between r and a column of J, MINPACK's `gtol`; checked before each step),
//! * step ‖δ‖ ≤ `step_tol`·(‖x‖ + `step_tol`),
//! * F = 0.
//!
//! Residuals that are not finite at a trial point reject the step (λ grows); forward differences
//! fall back to a backward difference when the forward point is not finite; non-finite values at
//! the starting point or in the Jacobian are errors. No NaN is ever returned as a solution.

use std::fmt;

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// Settings of [`levenberg_marquardt`]; [`Default`] gives values suitable for well-scaled
/// problems with O(1) parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    /// Maximum number of iterations (Jacobian evaluations).
    pub max_iterations: usize,
    /// Tolerance on the relative decrease of the cost per accepted step.
    pub cost_tol: f64,
    /// Tolerance on the scaled gradient (cosine between r and the columns of J).
    pub gradient_tol: f64,
    /// Tolerance on the step length relative to ‖x‖.
    pub step_tol: f64,
    /// Initial damping λ₀ relative to the Marquardt scaling D.
    pub initial_lambda: f64,
    /// Relative step of forward differences, h_j = `fd_step`·max(|x_j|, 1) (used by
    /// [`Jacobian::ForwardDifference`]).
    pub fd_step: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            cost_tol: 1e-12,
            gradient_tol: 1e-10,
            step_tol: 1e-12,
            initial_lambda: 1e-3,
            fd_step: 1e-7,
        }
    }
}

/// How the Jacobian is obtained.
pub enum Jacobian<J> {
    /// Analytic Jacobian: `J(x, jac)` fills `jac` (row-major m × n, `jac[i*n + j]` = ∂rᵢ/∂xⱼ).
    Analytic(J),
    /// Forward differences of the residual function with step [`LmOptions::fd_step`].
    ForwardDifference,
}

/// Why the iteration stopped successfully.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// Relative cost change below `cost_tol`.
    CostChange,
    /// Scaled gradient below `gradient_tol`.
    Gradient,
    /// Step below `step_tol`.
    Step,
    /// The cost is exactly zero.
    ZeroCost,
}

/// Statistics of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmStats {
    /// Iterations performed (Jacobian evaluations).
    pub iterations: usize,
    /// Residual-function evaluations (including those of forward differences).
    pub residual_evaluations: usize,
    /// Cost ½‖r‖² at the start.
    pub initial_cost: f64,
    /// Cost ½‖r‖² at the returned point.
    pub cost: f64,
    /// Final damping λ (relative to D).
    pub lambda: f64,
    /// Why the iteration stopped (`None` only inside [`LmError::MaxIterations`]).
    pub termination: Option<Termination>,
}

/// Result of a successful run.
#[derive(Debug, Clone, PartialEq)]
pub struct LmSolution {
    /// Parameters at the minimum found.
    pub x: Vec<f64>,
    /// Statistics.
    pub stats: LmStats,
}

/// Failure of [`levenberg_marquardt`].
#[derive(Debug, Clone, PartialEq)]
pub enum LmError {
    /// Inconsistent input (dimensions, options, non-finite starting point); the message says which.
    InvalidInput(String),
    /// The residuals at the starting point are not finite.
    NonFiniteStart,
    /// The Jacobian contains a non-finite entry at the given iteration.
    NonFiniteJacobian {
        /// Iteration (0-based) at which it happened.
        iteration: usize,
    },
    /// No acceptable step could be found (damping grew beyond 1e16 relative to D).
    Stalled {
        /// Best parameters found.
        best: Vec<f64>,
        /// Statistics at the best point.
        stats: LmStats,
    },
    /// `max_iterations` reached before convergence.
    MaxIterations {
        /// Best parameters found (lowest cost; finite).
        best: Vec<f64>,
        /// Statistics at the best point.
        stats: LmStats,
    },
}

impl fmt::Display for LmError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LmError::InvalidInput(m) => write!(f, "least squares: invalid input: {m}"),
            LmError::NonFiniteStart => {
                write!(f, "least squares: residuals not finite at the starting point")
            }
            LmError::NonFiniteJacobian { iteration } => {
                write!(f, "least squares: non-finite Jacobian at iteration {iteration}")
            }
            LmError::Stalled { stats, .. } => write!(
                f,
                "least squares: no decreasing step found after {} iterations (cost {:e})",
                stats.iterations, stats.cost
            ),
            LmError::MaxIterations { stats, .. } => write!(
                f,
                "least squares: not converged in {} iterations (cost {:e})",
                stats.iterations, stats.cost
            ),
        }
    }
}

impl std::error::Error for LmError {}

fn half_sq(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|v| v * v).sum::<f64>()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// Minimises ½‖r(x)‖² from `x0` for `m` residuals.
///
/// `residuals(x, r)` fills r (length m); `jacobian` gives ∂r/∂x, see [`Jacobian`]. Returns the
/// minimiser with statistics or an [`LmError`]; on [`LmError::MaxIterations`] and
/// [`LmError::Stalled`] the best point found is included.
pub fn levenberg_marquardt<R, J>(
    x0: &[f64],
    m: usize,
    mut residuals: R,
    mut jacobian: Jacobian<J>,
    opts: &LmOptions,
) -> Result<LmSolution, LmError>
where
    R: FnMut(&[f64], &mut [f64]),
    J: FnMut(&[f64], &mut [f64]),
{
    let n = x0.len();
    if n == 0 || m == 0 {
        return Err(LmError::InvalidInput(format!("n = {n} parameters, m = {m} residuals")));
    }
    if x0.iter().any(|v| !v.is_finite()) {
        return Err(LmError::InvalidInput("starting point not finite".into()));
    }
    let positive = |v: f64| v.is_finite() && v >= 0.0;
    if !(positive(opts.cost_tol)
        && positive(opts.gradient_tol)
        && positive(opts.step_tol)
        && opts.initial_lambda.is_finite()
        && opts.initial_lambda > 0.0
        && opts.fd_step.is_finite()
        && opts.fd_step > 0.0)
    {
        return Err(LmError::InvalidInput("tolerances must be ≥ 0, λ₀ and fd_step > 0".into()));
    }

    let mut x = x0.to_vec();
    let mut r = vec![0.0; m];
    residuals(&x, &mut r);
    let mut evaluations = 1;
    if r.iter().any(|v| !v.is_finite()) {
        return Err(LmError::NonFiniteStart);
    }
    let mut cost = half_sq(&r);
    let mut stats = LmStats {
        iterations: 0,
        residual_evaluations: 0,
        initial_cost: cost,
        cost,
        lambda: opts.initial_lambda,
        termination: None,
    };
    let mut jac = vec![0.0; m * n];
    let mut r_trial = vec![0.0; m];
    let mut x_trial = vec![0.0; n];
    let mut scale = vec![0.0_f64; n];
    let mut lambda = opts.initial_lambda;
    let mut nu = 2.0;

    let finish = |stats: &mut LmStats,
                  it: usize,
                  ev: usize,
                  cost: f64,
                  lambda: f64,
                  t: Option<Termination>| {
        stats.iterations = it;
        stats.residual_evaluations = ev;
        stats.cost = cost;
        stats.lambda = lambda;
        stats.termination = t;
    };

    for iteration in 0..opts.max_iterations {
        if cost == 0.0 {
            finish(&mut stats, iteration, evaluations, cost, lambda, Some(Termination::ZeroCost));
            return Ok(LmSolution { x, stats });
        }
        // Jacobian.
        match &mut jacobian {
            Jacobian::Analytic(jf) => jf(&x, &mut jac),
            Jacobian::ForwardDifference => {
                for j in 0..n {
                    let h = opts.fd_step * x[j].abs().max(1.0);
                    x_trial.copy_from_slice(&x);
                    x_trial[j] += h;
                    let mut h = x_trial[j] - x[j];
                    residuals(&x_trial, &mut r_trial);
                    evaluations += 1;
                    if r_trial.iter().any(|v| !v.is_finite()) {
                        // Forward point outside the domain: use a backward difference.
                        x_trial[j] = x[j] - h;
                        h = x_trial[j] - x[j];
                        residuals(&x_trial, &mut r_trial);
                        evaluations += 1;
                    }
                    for i in 0..m {
                        jac[i * n + j] = (r_trial[i] - r[i]) / h;
                    }
                }
            }
        }
        if jac.iter().any(|v| !v.is_finite()) {
            return Err(LmError::NonFiniteJacobian { iteration });
        }
        // Normal equations: JᵀJ (upper triangle mirrored) and g = Jᵀr.
        let mut jtj = vec![0.0; n * n];
        let mut g = vec![0.0; n];
        for i in 0..m {
            let row = &jac[i * n..(i + 1) * n];
            let ri = r[i];
            for a in 0..n {
                let ja = row[a];
                if ja == 0.0 {
                    continue;
                }
                g[a] += ja * ri;
                for b in a..n {
                    jtj[a * n + b] += ja * row[b];
                }
            }
        }
        for a in 0..n {
            for b in 0..a {
                jtj[a * n + b] = jtj[b * n + a];
            }
        }
        let max_diag = (0..n).map(|a| jtj[a * n + a]).fold(0.0_f64, f64::max);
        let floor = 1e-12 * max_diag.max(f64::MIN_POSITIVE);
        for a in 0..n {
            scale[a] = scale[a].max(jtj[a * n + a]).max(floor);
        }
        // Scaled gradient test.
        let rn = norm(&r);
        let gscaled = (0..n)
            .map(|a| {
                let cn = jtj[a * n + a].sqrt();
                if cn > 0.0 { g[a].abs() / (cn * rn) } else { 0.0 }
            })
            .fold(0.0_f64, f64::max);
        if gscaled <= opts.gradient_tol {
            finish(&mut stats, iteration, evaluations, cost, lambda, Some(Termination::Gradient));
            return Ok(LmSolution { x, stats });
        }

        // Inner loop: find an acceptable damping.
        loop {
            if lambda > 1e16 {
                finish(&mut stats, iteration + 1, evaluations, cost, lambda, None);
                return Err(LmError::Stalled { best: x, stats });
            }
            let a_mat = Mat::<f64>::from_fn(n, n, |p, q| {
                jtj[p * n + q] + if p == q { lambda * scale[p] } else { 0.0 }
            });
            let Ok(llt) = a_mat.llt(Side::Lower) else {
                lambda *= 10.0;
                continue;
            };
            let rhs = Mat::<f64>::from_fn(n, 1, |p, _| -g[p]);
            let delta_m = llt.solve(&rhs);
            let delta: Vec<f64> = (0..n).map(|p| delta_m[(p, 0)]).collect();
            if delta.iter().any(|v| !v.is_finite()) {
                lambda *= 10.0;
                continue;
            }
            for p in 0..n {
                x_trial[p] = x[p] + delta[p];
            }
            residuals(&x_trial, &mut r_trial);
            evaluations += 1;
            let trial_ok = r_trial.iter().all(|v| v.is_finite());
            let new_cost = if trial_ok { half_sq(&r_trial) } else { f64::INFINITY };
            // Predicted reduction of the linear model: ½ δᵀ(λDδ − g).
            let predicted: f64 =
                0.5 * (0..n).map(|p| delta[p] * (lambda * scale[p] * delta[p] - g[p])).sum::<f64>();
            let actual = cost - new_cost;
            let rho = if predicted > 0.0 { actual / predicted } else { -1.0 };
            if trial_ok && actual > 0.0 && rho > 0.0 {
                let step = norm(&delta);
                let xn = norm(&x);
                std::mem::swap(&mut x, &mut x_trial);
                std::mem::swap(&mut r, &mut r_trial);
                let old_cost = cost;
                cost = new_cost;
                lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                lambda = lambda.max(1e-15);
                nu = 2.0;
                let term = if cost == 0.0 {
                    Some(Termination::ZeroCost)
                } else if old_cost - cost <= opts.cost_tol * old_cost {
                    Some(Termination::CostChange)
                } else if step <= opts.step_tol * (xn + opts.step_tol) {
                    Some(Termination::Step)
                } else {
                    None
                };
                if term.is_some() {
                    finish(&mut stats, iteration + 1, evaluations, cost, lambda, term);
                    return Ok(LmSolution { x, stats });
                }
                break;
            }
            // Rejected: a tiny step that cannot reduce the cost means we are at the minimum.
            let step = norm(&delta);
            if trial_ok && step <= opts.step_tol * (norm(&x) + opts.step_tol) {
                finish(
                    &mut stats,
                    iteration + 1,
                    evaluations,
                    cost,
                    lambda,
                    Some(Termination::Step),
                );
                return Ok(LmSolution { x, stats });
            }
            lambda *= nu;
            nu *= 2.0;
        }
    }
    finish(&mut stats, opts.max_iterations, evaluations, cost, lambda, None);
    Err(LmError::MaxIterations { best: x, stats })
}

/// [`levenberg_marquardt`] with a forward-difference Jacobian.
pub fn levenberg_marquardt_fd<R>(
    x0: &[f64],
    m: usize,
    residuals: R,
    opts: &LmOptions,
) -> Result<LmSolution, LmError>
where
    R: FnMut(&[f64], &mut [f64]),
{
    levenberg_marquardt(
        x0,
        m,
        residuals,
        Jacobian::<fn(&[f64], &mut [f64])>::ForwardDifference,
        opts,
    )
}
