//! Explicit integrators for first-order ODE systems y' = f(t, y).
//!
//! * [`Rk4`]: the classical four-stage Runge–Kutta method, order 4, fixed step.
//! * [`Dopri5`]: the Dormand–Prince 5(4) embedded pair with local extrapolation (the solution
//!   is advanced with the 5th-order formula, the 4th-order one only estimates the error),
//!   first-same-as-last, PI step-size control and the 4th-order continuous extension (dense
//!   output).
//!
//! Conventions shared by both:
//! * the system is an [`OdeSystem`]; its state is a flat `&[f64]` of length [`OdeSystem::dim`],
//!   in whatever SI units the system uses (for the gear model: rad and rad/s);
//! * time `t` is in seconds (any unit works as long as the system agrees);
//! * the state `y` is updated in place: on entry it is the state at `t0`, on return the state
//!   at the time reached;
//! * a failure of the right-hand side (for example a non-converged mesh-torque load solver) is
//!   returned by the system as [`OdeError::Rhs`] and propagated unchanged; a non-finite state or
//!   derivative is reported as [`OdeError::NonFinite`] naming the time and the component. No
//!   integrator ever returns a NaN state silently, and none panics on bad input.
//! * neither integrator allocates after construction: all stage vectors live in the
//!   integrator struct, which acts as the workspace and can be reused for many calls.

use std::error::Error;
use std::fmt;
use std::ops::ControlFlow;

/// A first-order system y' = f(t, y) of fixed dimension.
///
/// `rhs` may keep internal state (`&mut self`), e.g. a warm start for an iterative load solver,
/// but the integrators assume that f is a function of (t, y) only: they evaluate it at trial
/// points that may be rejected (DOPRI5) and never in a guaranteed time order.
pub trait OdeSystem {
    /// Number of state components n (length of `y` and `dydt`).
    fn dim(&self) -> usize;

    /// Writes f(t, y) into `dydt` (both of length [`Self::dim`]).
    ///
    /// Return [`OdeError::Rhs`] (see [`OdeError::rhs`]) when the derivative cannot be computed;
    /// the integrator stops and passes the error on. Writing non-finite values into `dydt` is
    /// detected by the integrators and reported as [`OdeError::NonFinite`].
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError>;
}

impl<S: OdeSystem + ?Sized> OdeSystem for &mut S {
    fn dim(&self) -> usize {
        (**self).dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError> {
        (**self).rhs(t, y, dydt)
    }
}

/// An [`OdeSystem`] made from a closure `f(t, y, dydt)` and a dimension.
///
/// ```
/// use helical_gear_mesh::dynamics::integrators::{FnSystem, OdeError, Rk4};
/// // Harmonic oscillator y0' = y1, y1' = -y0.
/// let mut sys = FnSystem::new(2, |_t: f64, y: &[f64], d: &mut [f64]| -> Result<(), OdeError> {
///     d[0] = y[1];
///     d[1] = -y[0];
///     Ok(())
/// });
/// let mut rk4 = Rk4::new(2);
/// let mut y = [1.0, 0.0];
/// rk4.integrate(&mut sys, 0.0, 1.0, 100, &mut y, |_, _, _| std::ops::ControlFlow::Continue(()))
///     .unwrap();
/// assert!((y[0] - 1f64.cos()).abs() < 1e-9);
/// ```
pub struct FnSystem<F> {
    dim: usize,
    f: F,
}

impl<F> FnSystem<F>
where
    F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), OdeError>,
{
    /// Wraps the closure `f(t, y, dydt)` as a system of dimension `dim`.
    pub fn new(dim: usize, f: F) -> Self {
        Self { dim, f }
    }
}

impl<F> OdeSystem for FnSystem<F>
where
    F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), OdeError>,
{
    fn dim(&self) -> usize {
        self.dim
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), OdeError> {
        (self.f)(t, y, dydt)
    }
}

/// Which quantity was found non-finite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// A component of the state y (the initial state, a stage state or the new state).
    State,
    /// A component of the derivative f(t, y) returned by the system.
    Derivative,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Quantity::State => "state",
            Quantity::Derivative => "derivative",
        })
    }
}

/// Errors of the integrators (and of systems' right-hand sides).
#[derive(Debug)]
#[non_exhaustive]
pub enum OdeError {
    /// The system could not evaluate f(t, y) at time `t`; `source` is the system's own error
    /// (recover it with [`Error::source`] and `downcast_ref`).
    Rhs {
        /// Time of the failed evaluation, s.
        t: f64,
        /// The underlying error.
        source: Box<dyn Error + Send + Sync + 'static>,
    },
    /// Component `component` of the state or of the derivative at time `t` is NaN or infinite.
    NonFinite {
        /// Time at which the value occurred (for a stage: the stage time), s.
        t: f64,
        /// Index of the offending component (0-based).
        component: usize,
        /// The offending value.
        value: f64,
        /// Whether it was a state or a derivative component.
        quantity: Quantity,
    },
    /// The adaptive step size fell below the minimum step allowed (option `h_min`, or the
    /// round-off limit 16·ε·|t|) at time `t`: the problem is too stiff or singular there.
    StepSizeTooSmall {
        /// Time at which the step collapsed, s.
        t: f64,
        /// The step size that would have been needed, s.
        h: f64,
        /// The minimum step in force, s.
        h_min: f64,
    },
    /// More than `max_steps` steps (accepted plus rejected) were needed; `t` is the time reached.
    TooManySteps {
        /// Time reached, s.
        t: f64,
        /// The limit that was hit.
        max_steps: usize,
    },
    /// A slice has the wrong length.
    DimensionMismatch {
        /// Which argument (e.g. `"y"`).
        what: &'static str,
        /// Length required (the system dimension).
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// An argument or option is out of range.
    InvalidInput {
        /// Name of the argument or option (e.g. `"rtol"`).
        name: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// Dense output was requested at `t` outside the step [`t_start`, `t_end`].
    ///
    /// [`t_start`]: Dopri5Step::t_start
    /// [`t_end`]: Dopri5Step::t_end
    OutsideStep {
        /// Requested time, s.
        t: f64,
        /// Start of the step, s.
        t_start: f64,
        /// End of the step, s.
        t_end: f64,
    },
}

impl OdeError {
    /// Wraps a system's own error as a right-hand-side failure at time `t`.
    pub fn rhs(t: f64, source: impl Into<Box<dyn Error + Send + Sync + 'static>>) -> Self {
        OdeError::Rhs { t, source: source.into() }
    }
}

impl fmt::Display for OdeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OdeError::Rhs { t, source } => {
                write!(f, "right-hand side failed at t = {t:e} s: {source}")
            }
            OdeError::NonFinite { t, component, value, quantity } => {
                write!(f, "non-finite {quantity} component {component} = {value} at t = {t:e} s")
            }
            OdeError::StepSizeTooSmall { t, h, h_min } => write!(
                f,
                "step size {h:e} s fell below the minimum step {h_min:e} s at t = {t:e} s \
                 (stiff or singular problem, or tolerances too tight)"
            ),
            OdeError::TooManySteps { t, max_steps } => {
                write!(f, "more than {max_steps} steps needed; stopped at t = {t:e} s")
            }
            OdeError::DimensionMismatch { what, expected, found } => {
                write!(f, "`{what}` has length {found}, expected {expected}")
            }
            OdeError::InvalidInput { name, value, allowed } => {
                write!(f, "invalid `{name}` = {value}: allowed {allowed}")
            }
            OdeError::OutsideStep { t, t_start, t_end } => write!(
                f,
                "dense output requested at t = {t:e} s outside the step [{t_start:e}, {t_end:e}] s"
            ),
        }
    }
}

impl Error for OdeError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        match self {
            OdeError::Rhs { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}

/// Returns an error naming the first non-finite component of `v`. On the hot path (every
/// stage of every step) one branch-free pass: 0·x is ±0 for a finite x and NaN for an
/// infinite or NaN one, so the sum of them is 0 exactly when every component is finite.
#[inline]
fn check_finite(t: f64, v: &[f64], quantity: Quantity) -> Result<(), OdeError> {
    if v.iter().fold(0.0, |s, &x| s + 0.0 * x) == 0.0 {
        return Ok(());
    }
    non_finite(t, v, quantity)
}

/// The error of [`check_finite`] for a `v` with a non-finite component.
#[cold]
#[inline(never)]
fn non_finite(t: f64, v: &[f64], quantity: Quantity) -> Result<(), OdeError> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(component) => Err(OdeError::NonFinite { t, component, value: v[component], quantity }),
    }
}

fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), OdeError> {
    if expected == found {
        Ok(())
    } else {
        Err(OdeError::DimensionMismatch { what, expected, found })
    }
}

/// Evaluates f(t, y) into `dydt`, checks it is finite and counts the evaluation.
fn eval<S: OdeSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    y: &[f64],
    dydt: &mut [f64],
    count: &mut usize,
) -> Result<(), OdeError> {
    *count += 1;
    sys.rhs(t, y, dydt)?;
    check_finite(t, dydt, Quantity::Derivative)
}

/// `out = y + h·Σ_j a_j·k_j` component-wise, then checks `out` is finite (state at time `t`).
/// The sum is formed from 0 in the order of `terms` for every method's stages alike; the
/// number of terms is a constant, so each stage's loop is unrolled over them.
fn combine<const N: usize>(
    t: f64,
    out: &mut [f64],
    y: &[f64],
    h: f64,
    terms: &[(f64, &[f64]); N],
) -> Result<(), OdeError> {
    let n = out.len().min(y.len());
    let (out, y) = (&mut out[..n], &y[..n]);
    let ks: [&[f64]; N] = terms.map(|(_, k)| &k[..n]);
    for (i, (o, yi)) in out.iter_mut().zip(y).enumerate() {
        let mut s = 0.0;
        for (&(a, _), k) in terms.iter().zip(&ks) {
            s += a * k[i];
        }
        *o = yi + h * s;
    }
    check_finite(t, out, Quantity::State)
}

// ---------------------------------------------------------------------------------------------
// Classical RK4
// ---------------------------------------------------------------------------------------------

/// Classical fourth-order Runge–Kutta method with a fixed step (global error O(h⁴)).
///
/// One step from (t, y) with step h:
/// k₁ = f(t, y), k₂ = f(t + h/2, y + h/2·k₁), k₃ = f(t + h/2, y + h/2·k₂),
/// k₄ = f(t + h, y + h·k₃), y ← y + h/6·(k₁ + 2k₂ + 2k₃ + k₄).
///
/// The struct is the workspace (four stage vectors and one trial state, allocated once in
/// [`Rk4::new`]); [`Rk4::step`] and [`Rk4::integrate`] do not allocate. Negative steps
/// (integration backwards in time) are allowed.
#[derive(Debug, Clone)]
pub struct Rk4 {
    k1: Vec<f64>,
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    tmp: Vec<f64>,
    rhs_evals: usize,
}

impl Rk4 {
    /// Allocates the workspace for systems of dimension `dim`.
    pub fn new(dim: usize) -> Self {
        Self {
            k1: vec![0.0; dim],
            k2: vec![0.0; dim],
            k3: vec![0.0; dim],
            k4: vec![0.0; dim],
            tmp: vec![0.0; dim],
            rhs_evals: 0,
        }
    }

    /// Dimension this workspace was allocated for.
    pub fn dim(&self) -> usize {
        self.k1.len()
    }

    /// Total number of right-hand-side evaluations made with this workspace (4 per step).
    pub fn rhs_evals(&self) -> usize {
        self.rhs_evals
    }

    /// Advances `y` in place by one step from `t` to `t + h` (h in s, either sign).
    ///
    /// Errors: dimension mismatch, non-finite `t`, `h` or `y`, a failing or non-finite
    /// right-hand side, or a non-finite new state. On error `y` is left unchanged.
    pub fn step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &mut [f64],
    ) -> Result<(), OdeError> {
        let n = self.dim();
        check_len("y", sys.dim(), y.len())?;
        check_len("Rk4 workspace", sys.dim(), n)?;
        if !t.is_finite() {
            return Err(OdeError::InvalidInput { name: "t", value: t, allowed: "finite" });
        }
        if !h.is_finite() {
            return Err(OdeError::InvalidInput { name: "h", value: h, allowed: "finite" });
        }
        check_finite(t, y, Quantity::State)?;
        self.step_unchecked(sys, t, h, y)
    }

    fn step_unchecked<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &mut [f64],
    ) -> Result<(), OdeError> {
        let Self { k1, k2, k3, k4, tmp, rhs_evals } = self;
        let th = t + 0.5 * h;
        eval(sys, t, y, k1, rhs_evals)?;
        combine(th, tmp, y, 0.5 * h, &[(1.0, k1)])?;
        eval(sys, th, tmp, k2, rhs_evals)?;
        combine(th, tmp, y, 0.5 * h, &[(1.0, k2)])?;
        eval(sys, th, tmp, k3, rhs_evals)?;
        combine(t + h, tmp, y, h, &[(1.0, k3)])?;
        eval(sys, t + h, tmp, k4, rhs_evals)?;
        let h6 = h / 6.0;
        combine(t + h, tmp, y, h6, &[(1.0, k1), (2.0, k2), (2.0, k3), (1.0, k4)])?;
        y.copy_from_slice(tmp);
        Ok(())
    }

    /// Integrates from `t0` to `t1` with `n_steps` equal steps h = (t1 − t0)/n_steps.
    ///
    /// After every step `callback(i, t, y)` is called with the step number i = 1…n_steps, the
    /// time t = t0 + i·h (computed from i, not accumulated; the last one is exactly `t1`) and
    /// the new state. Returning [`ControlFlow::Break`] stops the integration after that step.
    ///
    /// Returns the time reached (`t1` unless the callback stopped early); `y` holds the state
    /// at that time. On error, `y` holds the state at the end of the last completed step.
    pub fn integrate<S, F>(
        &mut self,
        sys: &mut S,
        t0: f64,
        t1: f64,
        n_steps: usize,
        y: &mut [f64],
        mut callback: F,
    ) -> Result<f64, OdeError>
    where
        S: OdeSystem + ?Sized,
        F: FnMut(usize, f64, &[f64]) -> ControlFlow<()>,
    {
        check_len("y", sys.dim(), y.len())?;
        check_len("Rk4 workspace", sys.dim(), self.dim())?;
        if n_steps == 0 {
            return Err(OdeError::InvalidInput { name: "n_steps", value: 0.0, allowed: ">= 1" });
        }
        for (name, v) in [("t0", t0), ("t1", t1)] {
            if !v.is_finite() {
                return Err(OdeError::InvalidInput { name, value: v, allowed: "finite" });
            }
        }
        check_finite(t0, y, Quantity::State)?;
        let h = (t1 - t0) / n_steps as f64;
        let mut t = t0;
        for i in 1..=n_steps {
            self.step_unchecked(sys, t, h, y)?;
            t = if i == n_steps { t1 } else { t0 + i as f64 * h };
            if callback(i, t, y).is_break() {
                break;
            }
        }
        Ok(t)
    }
}

// ---------------------------------------------------------------------------------------------
// Dormand–Prince 5(4)
// ---------------------------------------------------------------------------------------------

// Butcher tableau of Dormand & Prince (1980), RK5(4)7M.
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
// 5th-order weights (= last row of A, which makes the method FSAL).
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
// Error weights b − b̂ (5th minus embedded 4th order).
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Continuous extension (Shampine 1986 / Hairer–Nørsett–Wanner II.6): weights of the 4th-degree
// term of the dense-output polynomial.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Absolute tolerance: one value for all components or one per component.
#[derive(Debug, Clone, PartialEq)]
pub enum AbsTol {
    /// The same absolute tolerance for every component (in the component's unit).
    Scalar(f64),
    /// One absolute tolerance per component (length = system dimension).
    PerComponent(Vec<f64>),
}

impl From<f64> for AbsTol {
    fn from(v: f64) -> Self {
        AbsTol::Scalar(v)
    }
}

impl AbsTol {
    fn get(&self, i: usize) -> f64 {
        match self {
            AbsTol::Scalar(a) => *a,
            AbsTol::PerComponent(v) => v[i],
        }
    }
}

/// Options of [`Dopri5`].
///
/// Error control: a step from y to y₁ with embedded error estimate e is accepted when
/// `err = sqrt( (1/n)·Σᵢ (eᵢ / scᵢ)² ) ≤ 1`, with `scᵢ = atolᵢ + rtol·max(|yᵢ|, |y₁ᵢ|)`.
/// The new step is `h·clamp(safety·err^(−α)·err_prev^β, fac_min, fac_max)` with
/// α = 0.2 − 0.75·β (PI controller; β = 0 gives the classical I controller `err^(−1/5)`),
/// and after a rejection the step is not allowed to grow in the next step.
#[derive(Debug, Clone, PartialEq)]
pub struct Dopri5Options {
    /// Relative tolerance (dimensionless, ≥ 0). Default 1e-6.
    pub rtol: f64,
    /// Absolute tolerance, in the units of the state components (≥ 0; `rtol` and `atol` must
    /// not both vanish for a component). Default 1e-9.
    pub atol: AbsTol,
    /// Initial step, s; `None` (default) chooses it from f(t0, y0) (one extra evaluation).
    pub h_init: Option<f64>,
    /// Smallest step allowed, s (≥ 0). Default 0: only the round-off limit 16·ε·|t| applies.
    /// The final step shortened to land exactly on `t1` is exempt.
    pub h_min: f64,
    /// Largest step allowed, s; `None` (default) means |t1 − t0|.
    pub h_max: Option<f64>,
    /// Maximum number of step attempts (accepted plus rejected) per call. Default 100 000.
    pub max_steps: usize,
    /// Safety factor of the step-size controller, in (0, 1). Default 0.9.
    pub safety: f64,
    /// Smallest step-size ratio h_new/h, in (0, 1]. Default 0.2.
    pub fac_min: f64,
    /// Largest step-size ratio h_new/h, ≥ 1. Default 10.
    pub fac_max: f64,
    /// PI-controller exponent β on the previous error, in [0, 0.2). Default 0.04.
    pub beta: f64,
}

impl Default for Dopri5Options {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: AbsTol::Scalar(1e-9),
            h_init: None,
            h_min: 0.0,
            h_max: None,
            max_steps: 100_000,
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 10.0,
            beta: 0.04,
        }
    }
}

impl Dopri5Options {
    /// Default options with relative tolerance `rtol` and scalar absolute tolerance `atol`.
    pub fn with_tolerances(rtol: f64, atol: f64) -> Self {
        Self { rtol, atol: AbsTol::Scalar(atol), ..Self::default() }
    }

    fn validate(&self, dim: usize) -> Result<(), OdeError> {
        let bad = |name, value, allowed| Err(OdeError::InvalidInput { name, value, allowed });
        if !(self.rtol.is_finite() && self.rtol >= 0.0) {
            return bad("rtol", self.rtol, "finite and >= 0");
        }
        match &self.atol {
            AbsTol::Scalar(a) => {
                if !(a.is_finite() && *a >= 0.0) {
                    return bad("atol", *a, "finite and >= 0");
                }
                if *a == 0.0 && self.rtol == 0.0 {
                    return bad("atol", *a, "> 0 when rtol = 0");
                }
            }
            AbsTol::PerComponent(v) => {
                check_len("atol", dim, v.len())?;
                for a in v {
                    if !(a.is_finite() && *a >= 0.0) {
                        return bad("atol", *a, "finite and >= 0");
                    }
                    if *a == 0.0 && self.rtol == 0.0 {
                        return bad("atol", *a, "> 0 when rtol = 0");
                    }
                }
            }
        }
        if let Some(h) = self.h_init
            && !(h.is_finite() && h > 0.0)
        {
            return bad("h_init", h, "finite and > 0");
        }
        if !(self.h_min.is_finite() && self.h_min >= 0.0) {
            return bad("h_min", self.h_min, "finite and >= 0");
        }
        if let Some(h) = self.h_max
            && !(h > 0.0 && h >= self.h_min)
        {
            return bad("h_max", h, "> 0 and >= h_min");
        }
        if self.max_steps == 0 {
            return bad("max_steps", 0.0, ">= 1");
        }
        if !(self.safety > 0.0 && self.safety < 1.0) {
            return bad("safety", self.safety, "in (0, 1)");
        }
        if !(self.fac_min > 0.0 && self.fac_min <= 1.0) {
            return bad("fac_min", self.fac_min, "in (0, 1]");
        }
        if !(self.fac_max >= 1.0 && self.fac_max.is_finite()) {
            return bad("fac_max", self.fac_max, "finite and >= 1");
        }
        if !(self.beta >= 0.0 && self.beta < 0.2) {
            return bad("beta", self.beta, "in [0, 0.2)");
        }
        Ok(())
    }
}

/// Step statistics of one [`Dopri5::integrate`] call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dopri5Stats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error estimate above tolerance).
    pub rejected: usize,
    /// Right-hand-side evaluations, including the one at t0 and the one of the initial-step
    /// heuristic.
    pub rhs_evals: usize,
    /// Smallest accepted step, s (the last step, shortened to land on `t1`, included);
    /// +∞ if no step was accepted.
    pub h_min_used: f64,
    /// Largest accepted step, s; 0 if no step was accepted.
    pub h_max_used: f64,
    /// Step size the controller proposes for a following step, s (use it as
    /// [`Dopri5Options::h_init`] to continue an integration without a new start-up).
    pub h_next: f64,
    /// Time reached, s (`t1` unless the callback stopped the integration).
    pub t_end: f64,
}

impl Dopri5Stats {
    fn new(t0: f64) -> Self {
        Self {
            accepted: 0,
            rejected: 0,
            rhs_evals: 0,
            h_min_used: f64::INFINITY,
            h_max_used: 0.0,
            h_next: f64::NAN,
            t_end: t0,
        }
    }
}

/// An accepted DOPRI5 step as seen by the callback of [`Dopri5::integrate`]: its interval,
/// end state and dense output.
pub struct Dopri5Step<'a> {
    t_start: f64,
    t_end: f64,
    y_start: &'a [f64],
    y_end: &'a [f64],
    /// Dense-output coefficients: [y₁ − y₀, h·k₁ − (y₁ − y₀), (y₁ − y₀) − h·k₇ − (h·k₁ − (y₁ − y₀)),
    /// h·Σ dᵢ kᵢ].
    cont: &'a [Vec<f64>; 4],
}

impl Dopri5Step<'_> {
    /// Start time of the step, s.
    pub fn t_start(&self) -> f64 {
        self.t_start
    }

    /// End time of the step, s.
    pub fn t_end(&self) -> f64 {
        self.t_end
    }

    /// Step size t_end − t_start, s.
    pub fn h(&self) -> f64 {
        self.t_end - self.t_start
    }

    /// State at the start of the step.
    pub fn y_start(&self) -> &[f64] {
        self.y_start
    }

    /// Accepted state at the end of the step (5th-order solution).
    pub fn y_end(&self) -> &[f64] {
        self.y_end
    }

    /// Component `i` of the dense output at time `t` in [t_start, t_end].
    ///
    /// The 4th-order continuous extension of DOPRI5, a polynomial of degree 4 in
    /// θ = (t − t_start)/h that interpolates y₀ at θ = 0 and y₁ at θ = 1 (both exactly: the
    /// polynomial is evaluated from the nearer end) and matches f at both ends. Its error is
    /// O(h⁵) locally, i.e. of the order of the step's error.
    pub fn dense_component(&self, i: usize, t: f64) -> Result<f64, OdeError> {
        if i >= self.y_end.len() {
            return Err(OdeError::InvalidInput {
                name: "component",
                value: i as f64,
                allowed: "< system dimension",
            });
        }
        let theta = self.theta(t)?;
        Ok(self.dense_at(i, theta))
    }

    /// Writes the dense output at time `t` in [t_start, t_end] into `out` (length n).
    /// See [`Self::dense_component`].
    pub fn dense_output(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        check_len("out", self.y_end.len(), out.len())?;
        let theta = self.theta(t)?;
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.dense_at(i, theta);
        }
        Ok(())
    }

    fn theta(&self, t: f64) -> Result<f64, OdeError> {
        let h = self.t_end - self.t_start;
        if !(t >= self.t_start && t <= self.t_end) {
            return Err(OdeError::OutsideStep { t, t_start: self.t_start, t_end: self.t_end });
        }
        if t == self.t_end {
            return Ok(1.0);
        }
        Ok(((t - self.t_start) / h).clamp(0.0, 1.0))
    }

    fn dense_at(&self, i: usize, theta: f64) -> f64 {
        let [dy, c3, c4, c5] = self.cont;
        let th1 = 1.0 - theta;
        let bubble = theta * th1 * (c3[i] + theta * (c4[i] + th1 * c5[i]));
        if theta <= 0.5 {
            self.y_start[i] + theta * dy[i] + bubble
        } else {
            self.y_end[i] - th1 * dy[i] + bubble
        }
    }
}

/// Dormand–Prince 5(4) adaptive integrator (order 5, embedded order-4 error estimate,
/// 7 stages, 6 right-hand-side evaluations per step thanks to FSAL) with dense output.
///
/// The struct holds the options and the workspace (stage vectors and dense-output
/// coefficients, allocated once in [`Dopri5::new`]). Integration is forward in time only
/// (`t1 ≥ t0`).
#[derive(Debug, Clone)]
pub struct Dopri5 {
    opts: Dopri5Options,
    k: [Vec<f64>; 7],
    y_new: Vec<f64>,
    y_stage: Vec<f64>,
    cont: [Vec<f64>; 4],
    stats: Dopri5Stats,
}

impl Dopri5 {
    /// Validates `opts` and allocates the workspace for systems of dimension `dim`.
    pub fn new(dim: usize, opts: Dopri5Options) -> Result<Self, OdeError> {
        opts.validate(dim)?;
        let v = || vec![0.0; dim];
        Ok(Self {
            opts,
            k: [v(), v(), v(), v(), v(), v(), v()],
            y_new: v(),
            y_stage: v(),
            cont: [v(), v(), v(), v()],
            stats: Dopri5Stats::new(0.0),
        })
    }

    /// Dimension this integrator was allocated for.
    pub fn dim(&self) -> usize {
        self.y_new.len()
    }

    /// The options in force.
    pub fn options(&self) -> &Dopri5Options {
        &self.opts
    }

    /// Sets the initial step of the next [`Self::integrate`] calls ([`Dopri5Options::h_init`]),
    /// s: `Some(h)` with h finite and > 0, or `None` for the automatic choice. Lets a caller
    /// continue with the step the controller proposed ([`Dopri5Stats::h_next`]) without
    /// building a new workspace.
    pub fn set_h_init(&mut self, h_init: Option<f64>) -> Result<(), OdeError> {
        if let Some(h) = h_init
            && !(h.is_finite() && h > 0.0)
        {
            return Err(OdeError::InvalidInput {
                name: "h_init",
                value: h,
                allowed: "finite and > 0",
            });
        }
        self.opts.h_init = h_init;
        Ok(())
    }

    /// Statistics of the last [`Self::integrate`] call, also after it returned an error.
    pub fn stats(&self) -> &Dopri5Stats {
        &self.stats
    }

    /// Weighted RMS norm of `v` with scale atolᵢ + rtol·max(|aᵢ|, |bᵢ|).
    fn norm(&self, v: &[f64], a: &[f64], b: &[f64]) -> f64 {
        let n = v.len();
        if n == 0 {
            return 0.0;
        }
        let mut s = 0.0;
        for (i, ((vi, ai), bi)) in v.iter().zip(a).zip(b).enumerate() {
            let sc = self.opts.atol.get(i) + self.opts.rtol * ai.abs().max(bi.abs());
            // sc = 0 only for a zero component with atol = 0: an exact zero error is no error.
            let r = if *vi == 0.0 { 0.0 } else { vi / sc };
            s += r * r;
        }
        (s / n as f64).sqrt()
    }

    /// Initial step from the local behaviour of f (Hairer–Nørsett–Wanner, §II.4): a step with
    /// which an explicit Euler step would be about 1 % of the scale, refined with a second
    /// derivative estimate from one extra evaluation. Uses `k[1]`, `k[2]` as scratch.
    fn initial_step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        span: f64,
        h_max: f64,
    ) -> Result<f64, OdeError> {
        let d0 = self.norm(y0, y0, y0);
        let d1 = self.norm(&self.k[0], y0, y0);
        let mut h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
        h0 = h0.min(h_max).min(span);
        {
            let [k1, k2, k3, ..] = &mut self.k;
            combine(t0 + h0, k2, y0, h0, &[(1.0, k1)])?;
            eval(sys, t0 + h0, k2, k3, &mut self.stats.rhs_evals)?;
        }
        let mut diff = std::mem::take(&mut self.k[1]);
        for ((d, a), b) in diff.iter_mut().zip(&self.k[2]).zip(&self.k[0]) {
            *d = (a - b) / h0;
        }
        let d2 = self.norm(&diff, y0, y0);
        self.k[1] = diff;
        let dmax = d1.max(d2);
        let h1 = if dmax <= 1e-15 { (h0 * 1e-3).max(1e-6) } else { (0.01 / dmax).powf(0.2) };
        Ok((100.0 * h0).min(h1).min(h_max).min(span))
    }

    /// Integrates `sys` from `t0` to `t1` (t1 ≥ t0), updating `y` in place.
    ///
    /// After every accepted step `callback(&step)` is called; [`Dopri5Step`] gives the step's
    /// interval, end state and dense output (e.g. to sample the solution on a uniform grid).
    /// Returning [`ControlFlow::Break`] stops the integration after that step; `y` then holds
    /// that step's end state and [`Dopri5Stats::t_end`] its time.
    ///
    /// The last step is shortened (or stretched by at most 1 %) to end exactly on `t1`.
    ///
    /// Errors: invalid input, [`OdeError::NonFinite`] (first non-finite component of a state or
    /// derivative, with its time), [`OdeError::Rhs`] from the system,
    /// [`OdeError::StepSizeTooSmall`], [`OdeError::TooManySteps`]. On error `y` holds the state
    /// at the end of the last accepted step and [`Self::stats`] the statistics so far.
    pub fn integrate<S, F>(
        &mut self,
        sys: &mut S,
        t0: f64,
        t1: f64,
        y: &mut [f64],
        mut callback: F,
    ) -> Result<Dopri5Stats, OdeError>
    where
        S: OdeSystem + ?Sized,
        F: FnMut(&Dopri5Step<'_>) -> ControlFlow<()>,
    {
        self.stats = Dopri5Stats::new(t0);
        let n = self.dim();
        check_len("y", n, y.len())?;
        check_len("Dopri5 workspace", sys.dim(), n)?;
        for (name, v) in [("t0", t0), ("t1", t1)] {
            if !v.is_finite() {
                return Err(OdeError::InvalidInput { name, value: v, allowed: "finite" });
            }
        }
        if t1 < t0 {
            return Err(OdeError::InvalidInput { name: "t1", value: t1, allowed: ">= t0" });
        }
        check_finite(t0, y, Quantity::State)?;
        if t1 == t0 {
            return Ok(self.stats);
        }
        let span = t1 - t0;
        let h_max = self.opts.h_max.unwrap_or(span).min(span);
        let (safety, fac_min, fac_max) = (self.opts.safety, self.opts.fac_min, self.opts.fac_max);
        let beta = self.opts.beta;
        let alpha = 0.2 - 0.75 * beta;

        eval(sys, t0, y, &mut self.k[0], &mut self.stats.rhs_evals)?;
        let mut h = match self.opts.h_init {
            Some(h) => h.min(h_max),
            None => self.initial_step(sys, t0, y, span, h_max)?,
        };
        let mut t = t0;
        let mut err_prev: f64 = 1e-4;
        let mut rejected_last = false;
        let mut attempts = 0usize;

        while t < t1 {
            if attempts >= self.opts.max_steps {
                return Err(OdeError::TooManySteps { t, max_steps: self.opts.max_steps });
            }
            attempts += 1;
            h = h.min(h_max);
            let h_floor = self.opts.h_min.max(16.0 * f64::EPSILON * t.abs());
            if h < h_floor || h <= 0.0 {
                return Err(OdeError::StepSizeTooSmall { t, h, h_min: h_floor });
            }
            let last = t + 1.01 * h >= t1;
            if last {
                h = t1 - t;
            }
            let t_new = if last { t1 } else { t + h };

            let err = self.try_step(sys, t, h, t_new, y)?;

            if err <= 1.0 {
                self.stats.accepted += 1;
                self.stats.h_min_used = self.stats.h_min_used.min(h);
                self.stats.h_max_used = self.stats.h_max_used.max(h);
                self.fill_dense(h, y);
                let step = Dopri5Step {
                    t_start: t,
                    t_end: t_new,
                    y_start: y,
                    y_end: &self.y_new,
                    cont: &self.cont,
                };
                let flow = callback(&step);
                y.copy_from_slice(&self.y_new);
                self.k.swap(0, 6); // FSAL: f(t_new, y_new) is the next step's k1.
                t = t_new;
                self.stats.t_end = t;
                let mut fac = if err == 0.0 {
                    fac_max
                } else {
                    safety * err.powf(-alpha) * err_prev.powf(beta)
                };
                fac = fac.clamp(fac_min, fac_max);
                if rejected_last {
                    fac = fac.min(1.0);
                }
                err_prev = err.max(1e-4);
                rejected_last = false;
                h *= fac;
                self.stats.h_next = h.min(h_max);
                if flow.is_break() {
                    break;
                }
            } else {
                self.stats.rejected += 1;
                rejected_last = true;
                let fac = (safety * err.powf(-0.2)).clamp(fac_min, 1.0);
                h *= fac;
                self.stats.h_next = h;
            }
        }
        Ok(self.stats)
    }

    /// Computes the stages of a step of size `h` from (t, y), leaving the 5th-order solution in
    /// `y_new`, f(t + h, y_new) in `k[6]`, and returns the scaled error norm.
    fn try_step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        t_new: f64,
        y: &[f64],
    ) -> Result<f64, OdeError> {
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let ys = &mut self.y_stage;
        let ev = &mut self.stats.rhs_evals;
        combine(t + C2 * h, ys, y, h, &[(A21, k1)])?;
        eval(sys, t + C2 * h, ys, k2, ev)?;
        combine(t + C3 * h, ys, y, h, &[(A31, k1), (A32, k2)])?;
        eval(sys, t + C3 * h, ys, k3, ev)?;
        combine(t + C4 * h, ys, y, h, &[(A41, k1), (A42, k2), (A43, k3)])?;
        eval(sys, t + C4 * h, ys, k4, ev)?;
        combine(t + C5 * h, ys, y, h, &[(A51, k1), (A52, k2), (A53, k3), (A54, k4)])?;
        eval(sys, t + C5 * h, ys, k5, ev)?;
        combine(t_new, ys, y, h, &[(A61, k1), (A62, k2), (A63, k3), (A64, k4), (A65, k5)])?;
        eval(sys, t_new, ys, k6, ev)?;
        let yn = &mut self.y_new;
        combine(t_new, yn, y, h, &[(B1, k1), (B3, k3), (B4, k4), (B5, k5), (B6, k6)])?;
        eval(sys, t_new, yn, k7, ev)?;
        // Error estimate h·Σ eᵢkᵢ, stored in y_stage.
        for (i, e) in ys.iter_mut().enumerate() {
            *e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        let err = self.norm(&self.y_stage, y, &self.y_new);
        if err.is_nan() {
            // Only possible with overflow in the error sum: treat as a failed step.
            return Ok(f64::INFINITY);
        }
        Ok(err)
    }

    /// Dense-output coefficients of the accepted step (needs k1…k7, y, y_new).
    fn fill_dense(&mut self, h: f64, y: &[f64]) {
        let [k1, _, k3, k4, k5, k6, k7] = &self.k;
        let [dy, c3, c4, c5] = &mut self.cont;
        for i in 0..y.len() {
            let ydiff = self.y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            dy[i] = ydiff;
            c3[i] = bspl;
            c4[i] = ydiff - h * k7[i] - bspl;
            c5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
    }
}

/// Integrator of a stateful model (a unit) inside a communication step: the option every
/// interface offers (codes and names: [`crate::options`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrator {
    /// Classical RK4 on a grid tied to the mesh period (`rk4_steps_per_mesh_period`).
    Rk4 = 0,
    /// Adaptive Dormand–Prince 5(4) with `rtol`, `atol`.
    Dopri5 = 1,
}
