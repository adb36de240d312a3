//! Detection of the periodic steady state of the transmission error.
//!
//! The gear model is integrated until the transmission error TE(t) repeats with the mesh
//! period T_m, or with a multiple k·T_m for a subharmonic response. [`SteadyState`] is fed TE
//! sample by sample on a uniform time grid with an integer number N of samples per mesh period
//! (`samples_per_period`), keeps the last 2·K·N samples in a ring buffer (K = `max_multiple`)
//! and checks periodicity every `check_interval` samples.
//!
//! # Tolerance rule
//!
//! At a check, for k = 1, 2, …, K (in this order, as long as at least 2·k·N samples have been
//! fed), let W_k be the last k·N samples x_j and
//!
//! * residual  r_k = max_{j ∈ W_k} |x_j − x_{j−k·N}|  (TE(t) − TE(t − k·T_m) over the last k
//!   periods),
//! * peak-to-peak  P_k = max_{W_k} x − min_{W_k} x,
//! * tolerance  τ_k = `rel_tol`·P_k + `abs_tol`.
//!
//! The check *passes with multiple k* for the smallest k with r_k ≤ τ_k; it fails if there is
//! none. The state is declared **steady** when `consecutive` successive checks have passed
//! with the same k (a check that fails, or passes with a different k, restarts the count).
//! The report ([`PeriodCheck`]) gives k, r_k, τ_k and max, min and mean of x over W_k.
//!
//! A decaying transient is thus accepted once its change over k periods is below τ_k; a
//! linear drift d per period is never accepted while d·k·N > τ_k for every k ≤ K; a
//! quasi-periodic signal is accepted only if one of the first K multiples happens to nearly
//! repeat it (keep K small, the default is 4).

use std::fmt;

/// Excitation periods a run to the steady state may integrate at least when the excitation
/// repeats only after P > 1 mesh periods (tooth deviations, [`crate::modifications`]): the
/// detector compares TE one period P apart, so it needs 2·P periods before its first check,
/// and one more P lets a transient of about one period decay first.
pub const EXCITATION_PERIODS_PER_RUN: usize = 3;

/// The cap of mesh periods of a run to the steady state for an excitation of period
/// `period_meshes` = P mesh periods: `max_periods` when P ≤ 1, otherwise
/// max(`max_periods`, [`EXCITATION_PERIODS_PER_RUN`]·P). The one rule behind
/// [`super::SteadyRunOptions::for_pair`] (the paper), the speed sweeps of the CLI and Python.
pub fn steady_max_periods(max_periods: usize, period_meshes: usize) -> usize {
    if period_meshes > 1 {
        max_periods.max(EXCITATION_PERIODS_PER_RUN.saturating_mul(period_meshes))
    } else {
        max_periods
    }
}

/// Options of [`SteadyState`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyOptions {
    /// Number N of samples per mesh period T_m (the sampling step is T_m/N), ≥ 1.
    pub samples_per_period: usize,
    /// Largest period multiple K tried (subharmonic order), ≥ 1. Default 4.
    pub max_multiple: usize,
    /// Relative tolerance, a fraction of the window's peak-to-peak TE (≥ 0). Default 1e-3.
    pub rel_tol: f64,
    /// Absolute floor of the tolerance, in the unit of TE (m for TE = φp·g_p + φg·g_g), ≥ 0.
    /// Default 1e-12 m.
    pub abs_tol: f64,
    /// Number of consecutive passing checks (with the same k) required, ≥ 1. Default 3.
    pub consecutive: usize,
    /// Samples between checks, ≥ 1; `None` (default) means N, i.e. once per mesh period.
    pub check_interval: Option<usize>,
}

impl SteadyOptions {
    /// Defaults (see the field docs) for `samples_per_period` samples per mesh period.
    pub fn new(samples_per_period: usize) -> Self {
        Self {
            samples_per_period,
            max_multiple: 4,
            rel_tol: 1e-3,
            abs_tol: 1e-12,
            consecutive: 3,
            check_interval: None,
        }
    }
}

/// Errors of the steady-state detector.
#[derive(Debug, Clone, PartialEq)]
pub enum SteadyError {
    /// An option is out of range.
    InvalidOption {
        /// Field name of [`SteadyOptions`].
        name: &'static str,
        /// Its value.
        value: f64,
        /// Allowed range, in words.
        allowed: &'static str,
    },
    /// A fed sample is NaN or infinite.
    NonFiniteSample {
        /// Zero-based index of the sample since construction or the last reset.
        index: u64,
        /// The value.
        value: f64,
    },
}

impl fmt::Display for SteadyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SteadyError::InvalidOption { name, value, allowed } => {
                write!(f, "invalid steady-state option `{name}` = {value}: allowed {allowed}")
            }
            SteadyError::NonFiniteSample { index, value } => {
                write!(f, "non-finite transmission-error sample {index}: {value}")
            }
        }
    }
}

impl std::error::Error for SteadyError {}

/// Result of one periodicity check for one period multiple k (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodCheck {
    /// Period multiple k (the TE repeats after k mesh periods).
    pub period_multiple: usize,
    /// Residual r_k = max |TE(t) − TE(t − k·T_m)| over the last k periods (unit of TE).
    pub residual: f64,
    /// Tolerance τ_k = rel_tol·(max − min) + abs_tol (unit of TE).
    pub tolerance: f64,
    /// Maximum of TE over the last k periods.
    pub max: f64,
    /// Minimum of TE over the last k periods.
    pub min: f64,
    /// Mean of TE over the last k periods.
    pub mean: f64,
    /// Number of consecutive passing checks with this k, including this one (0 if the check
    /// failed).
    pub consecutive: usize,
    /// Number of samples fed when the check was made.
    pub samples_seen: u64,
}

/// Status after feeding a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SteadyStatus {
    /// Fewer than 2·N samples fed: no check possible yet.
    Collecting,
    /// The last check failed, or has not yet passed `consecutive` times in a row. The report is
    /// the passing multiple if any, otherwise the k with the smallest ratio r_k/τ_k.
    Transient(PeriodCheck),
    /// The last `consecutive` checks passed with the same multiple k.
    Steady(PeriodCheck),
}

impl SteadyStatus {
    /// True for [`SteadyStatus::Steady`].
    pub fn is_steady(&self) -> bool {
        matches!(self, SteadyStatus::Steady(_))
    }
}

/// Steady-state (periodicity) detector for a uniformly sampled transmission error.
///
/// Feed samples with [`SteadyState::push`]; checks run every `check_interval` samples and the
/// returned status is that of the most recent check (between checks it is repeated).
#[derive(Debug, Clone)]
pub struct SteadyState {
    opts: SteadyOptions,
    interval: usize,
    buf: Vec<f64>,
    /// Index in `buf` where the next sample is written.
    head: usize,
    seen: u64,
    since_check: usize,
    streak: usize,
    streak_k: usize,
    status: SteadyStatus,
}

impl SteadyState {
    /// Validates `opts` and allocates the ring buffer (2·K·N samples).
    pub fn new(opts: SteadyOptions) -> Result<Self, SteadyError> {
        let bad = |name, value, allowed| Err(SteadyError::InvalidOption { name, value, allowed });
        let n = opts.samples_per_period;
        if n == 0 {
            return bad("samples_per_period", 0.0, ">= 1");
        }
        if opts.max_multiple == 0 {
            return bad("max_multiple", 0.0, ">= 1");
        }
        if !(opts.rel_tol.is_finite() && opts.rel_tol >= 0.0) {
            return bad("rel_tol", opts.rel_tol, "finite and >= 0");
        }
        if !(opts.abs_tol.is_finite() && opts.abs_tol >= 0.0) {
            return bad("abs_tol", opts.abs_tol, "finite and >= 0");
        }
        if opts.consecutive == 0 {
            return bad("consecutive", 0.0, ">= 1");
        }
        let interval = opts.check_interval.unwrap_or(n);
        if interval == 0 {
            return bad("check_interval", 0.0, ">= 1");
        }
        let cap = match n.checked_mul(opts.max_multiple).and_then(|v| v.checked_mul(2)) {
            Some(c) if c <= 1 << 28 => c,
            _ => return bad("max_multiple", opts.max_multiple as f64, "2·K·N <= 2^28"),
        };
        Ok(Self {
            opts,
            interval,
            buf: vec![0.0; cap],
            head: 0,
            seen: 0,
            since_check: 0,
            streak: 0,
            streak_k: 0,
            status: SteadyStatus::Collecting,
        })
    }

    /// The options in force.
    pub fn options(&self) -> &SteadyOptions {
        &self.opts
    }

    /// Forgets all samples and checks (keeps the options and the buffer).
    pub fn reset(&mut self) {
        self.head = 0;
        self.seen = 0;
        self.since_check = 0;
        self.streak = 0;
        self.streak_k = 0;
        self.status = SteadyStatus::Collecting;
    }

    /// Number of samples fed since construction or the last reset.
    pub fn samples_seen(&self) -> u64 {
        self.seen
    }

    /// Status of the most recent check.
    pub fn status(&self) -> SteadyStatus {
        self.status
    }

    /// Feeds the next TE sample (the grid step is T_m/N) and returns the status, updated if a
    /// check was due. A non-finite sample is rejected with an error and not stored.
    pub fn push(&mut self, te: f64) -> Result<SteadyStatus, SteadyError> {
        if !te.is_finite() {
            return Err(SteadyError::NonFiniteSample { index: self.seen, value: te });
        }
        self.buf[self.head] = te;
        self.head = (self.head + 1) % self.buf.len();
        self.seen += 1;
        self.since_check += 1;
        let n = self.opts.samples_per_period as u64;
        if self.seen >= 2 * n && self.since_check >= self.interval {
            self.since_check = 0;
            self.check();
        }
        Ok(self.status)
    }

    /// Sample fed `back` samples ago (0 = most recent); requires back < min(seen, capacity).
    fn ago(&self, back: usize) -> f64 {
        let cap = self.buf.len();
        self.buf[(self.head + cap - 1 - back) % cap]
    }

    /// Residual and window statistics for multiple k.
    fn evaluate(&self, k: usize) -> PeriodCheck {
        let lag = k * self.opts.samples_per_period;
        let mut residual: f64 = 0.0;
        let (mut max, mut min, mut sum) = (f64::NEG_INFINITY, f64::INFINITY, 0.0);
        for back in 0..lag {
            let x = self.ago(back);
            residual = residual.max((x - self.ago(back + lag)).abs());
            max = max.max(x);
            min = min.min(x);
            sum += x;
        }
        PeriodCheck {
            period_multiple: k,
            residual,
            tolerance: self.opts.rel_tol * (max - min) + self.opts.abs_tol,
            max,
            min,
            mean: sum / lag as f64,
            consecutive: 0,
            samples_seen: self.seen,
        }
    }

    fn check(&mut self) {
        let n = self.opts.samples_per_period as u64;
        let k_avail = (self.seen / (2 * n)).min(self.opts.max_multiple as u64) as usize;
        let mut best: Option<(f64, PeriodCheck)> = None;
        let mut pass: Option<PeriodCheck> = None;
        for k in 1..=k_avail {
            let c = self.evaluate(k);
            if c.residual <= c.tolerance {
                pass = Some(c);
                break;
            }
            let ratio = c.residual / c.tolerance;
            if best.is_none_or(|(r, _)| ratio < r) {
                best = Some((ratio, c));
            }
        }
        self.status = match (pass, best) {
            (Some(mut c), _) => {
                if self.streak > 0 && self.streak_k == c.period_multiple {
                    self.streak += 1;
                } else {
                    self.streak = 1;
                    self.streak_k = c.period_multiple;
                }
                c.consecutive = self.streak;
                if self.streak >= self.opts.consecutive {
                    SteadyStatus::Steady(c)
                } else {
                    SteadyStatus::Transient(c)
                }
            }
            (None, Some((_, c))) => {
                self.streak = 0;
                self.streak_k = 0;
                SteadyStatus::Transient(c)
            }
            (None, None) => SteadyStatus::Collecting,
        };
    }
}

#[cfg(test)]
mod tests {
    //! Synthetic transmission-error signals.

    use std::f64::consts::PI;

    use super::*;

    /// The run-length rule: unchanged cap for a mesh-periodic excitation, at least 3·P for
    /// P > 1, never lowered, no overflow.
    #[test]
    fn steady_max_periods_is_three_excitation_periods_at_least() {
        assert_eq!(steady_max_periods(3000, 1), 3000);
        assert_eq!(steady_max_periods(3000, 0), 3000);
        assert_eq!(steady_max_periods(3000, 30), 3000);
        assert_eq!(steady_max_periods(3000, 1410), 4230);
        assert_eq!(steady_max_periods(10, 47), 141);
        assert_eq!(steady_max_periods(5, usize::MAX), usize::MAX);
    }

    /// Feeds x(t_i), t_i = i/N (mesh period T_m = 1), for `periods` periods; returns every status.
    fn run(
        opts: SteadyOptions,
        periods: usize,
        x: impl Fn(f64) -> f64,
    ) -> Vec<(f64, SteadyStatus)> {
        let n = opts.samples_per_period;
        let mut det = SteadyState::new(opts).unwrap();
        (0..periods * n)
            .map(|i| {
                let t = i as f64 / n as f64;
                (t, det.push(x(t)).unwrap())
            })
            .collect()
    }

    fn first_steady(statuses: &[(f64, SteadyStatus)]) -> Option<(f64, usize)> {
        statuses.iter().find_map(|(t, s)| match s {
            SteadyStatus::Steady(c) => Some((*t, c.period_multiple)),
            _ => None,
        })
    }

    fn opts(n: usize, rel_tol: f64) -> SteadyOptions {
        SteadyOptions {
            rel_tol,
            abs_tol: 1e-12,
            consecutive: 3,
            max_multiple: 4,
            ..SteadyOptions::new(n)
        }
    }

    #[test]
    fn decaying_transient_is_detected_once_it_has_decayed_not_before() {
        // x = periodic part + A·e^(−t/τ). At a check after the sample at t, the k = 1 residual
        // |x(t') − x(t' − 1)| is largest at the window's first sample t' = t − 1 + 1/N:
        // A·(1 − e^(−1/τ))·e^(−(t − 2 + 1/N)/τ).
        let n = 50;
        let (a, tau, rel_tol) = (1.0, 2.0, 1e-3);
        let periodic = |t: f64| (2.0 * PI * t).sin() + 0.3 * (4.0 * PI * t + 1.0).sin();
        let x = |t: f64| periodic(t) + a * (-t / tau).exp();
        let statuses = run(opts(n, rel_tol), 30, x);
        // Peak-to-peak of the periodic part (sampled), for the predicted detection time.
        let p = {
            let v: Vec<f64> = (0..n).map(|i| periodic(i as f64 / n as f64)).collect();
            v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
        };
        let residual =
            |t: f64| a * (1.0 - (-1.0 / tau).exp()) * (-(t - 2.0 + 1.0 / n as f64) / tau).exp();
        // First time at which the criterion can hold (transient's own share of the window's
        // peak-to-peak neglected: it only makes the prediction slightly early).
        let t_pass = statuses.iter().map(|s| s.0).find(|&t| residual(t) <= rel_tol * p).unwrap();
        let (t_steady, k) = first_steady(&statuses).expect("steady state detected");
        eprintln!(
            "transient: criterion first holds at t ≈ {t_pass:.2} T_m, steady declared at \
             {t_steady:.2} T_m with k = {k}"
        );
        assert_eq!(k, 1);
        assert!(t_steady >= t_pass, "declared before the transient decayed");
        // Three consecutive checks, one per period: at most about 3 periods later.
        assert!(t_steady <= t_pass + 3.0, "declared too late");
        // Before: every status is Collecting or Transient, and no check passes before t_pass.
        for (t, s) in &statuses {
            if *t < t_steady {
                assert!(!s.is_steady());
            }
            if let SteadyStatus::Transient(c) = s
                && *t < t_pass
            {
                assert!(c.residual > c.tolerance, "check passed at t = {t}");
            }
        }
        match statuses.last().unwrap().1 {
            SteadyStatus::Steady(c) => {
                assert!(c.residual <= c.tolerance);
                assert!((c.tolerance - (rel_tol * (c.max - c.min) + 1e-12)).abs() < 1e-15);
                assert!(c.consecutive >= 3);
                // Window statistics of the (now practically periodic) signal.
                assert!((c.max - c.min - p).abs() < 1e-3 * p);
                let mean: f64 =
                    (0..n).map(|i| periodic(i as f64 / n as f64)).sum::<f64>() / n as f64;
                assert!((c.mean - mean).abs() < 1e-3);
            }
            s => panic!("not steady at the end: {s:?}"),
        }
    }

    #[test]
    fn period_two_signal_is_detected_with_k_two_never_one() {
        // Subharmonic response: a component at half the mesh frequency, period 2·T_m.
        let n = 40;
        let x = |t: f64| (2.0 * PI * t).sin() + 0.2 * (PI * t + 0.3).sin();
        let statuses = run(opts(n, 1e-6), 20, x);
        for (_, s) in &statuses {
            if let SteadyStatus::Steady(c) | SteadyStatus::Transient(c) = s
                && c.residual <= c.tolerance
            {
                assert_eq!(c.period_multiple, 2, "{s:?}");
            }
        }
        let (t, k) = first_steady(&statuses).expect("detected");
        assert_eq!(k, 2);
        // k = 2 needs 4 periods of samples; then 3 consecutive checks, one per period.
        assert!((t - (6.0 - 1.0 / n as f64)).abs() < 1e-9, "t = {t}");
        if let SteadyStatus::Steady(c) = statuses.last().unwrap().1 {
            assert!(c.residual < 1e-12);
            assert!(c.max > 1.0 && c.min < -1.0);
        } else {
            panic!("not steady at the end");
        }
    }

    #[test]
    fn slowly_drifting_signal_is_never_steady() {
        // Drift of 0.5 % of the peak-to-peak per period, tolerance 0.1 %.
        let statuses = run(opts(50, 1e-3), 200, |t| (2.0 * PI * t).sin() + 0.01 * t);
        assert!(first_steady(&statuses).is_none());
        assert!(matches!(statuses.last().unwrap().1, SteadyStatus::Transient(_)));
    }

    #[test]
    fn quasi_periodic_signal_is_never_steady() {
        // A second frequency incommensurate with the mesh frequency (ratio √2).
        let x = |t: f64| (2.0 * PI * t).sin() + 0.3 * (2.0 * PI * 2f64.sqrt() * t).sin();
        let statuses = run(opts(50, 1e-3), 200, x);
        assert!(first_steady(&statuses).is_none());
    }

    #[test]
    fn constant_signal_is_steady_through_the_absolute_floor() {
        let statuses = run(opts(10, 1e-3), 6, |_| 3.0e-6);
        let (_, k) = first_steady(&statuses).unwrap();
        assert_eq!(k, 1);
    }

    #[test]
    fn status_before_two_periods_is_collecting_and_bad_input_is_rejected() {
        let mut det = SteadyState::new(opts(10, 1e-3)).unwrap();
        for i in 0..19 {
            assert_eq!(det.push(i as f64).unwrap(), SteadyStatus::Collecting);
        }
        assert!(matches!(det.push(0.0).unwrap(), SteadyStatus::Transient(_)));
        assert!(matches!(det.push(f64::NAN), Err(SteadyError::NonFiniteSample { index: 20, .. })));
        assert_eq!(det.samples_seen(), 20);
        det.reset();
        assert_eq!(det.samples_seen(), 0);
        assert_eq!(det.status(), SteadyStatus::Collecting);

        assert!(SteadyState::new(SteadyOptions::new(0)).is_err());
        assert!(
            SteadyState::new(SteadyOptions { rel_tol: -1.0, ..SteadyOptions::new(10) }).is_err()
        );
        assert!(
            SteadyState::new(SteadyOptions { consecutive: 0, ..SteadyOptions::new(10) }).is_err()
        );
        assert!(
            SteadyState::new(SteadyOptions { max_multiple: 0, ..SteadyOptions::new(10) }).is_err()
        );
    }
}
