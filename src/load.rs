//! Load distribution along the instant lines of contact (paper §5, Eqs. 12–15).
//!
//! ## Equations
//! All simultaneous contact lines are cut into n slices i (all tooth pairs together). Slice i
//! has the length of contact line `w_i = m_n·Δζ_i / cos θ` (m, θ the base helix angle) and
//! carries the unknown load intensity `q_i ≥ 0` (N/m, force per unit length of contact line;
//! the slice force is `w_i·q_i`, N). The geometry gives the required normal approach
//! `d_i = Δ0t,i·m_n·cos θ` (m, first line of Eq. 12); d_i < 0 is an open gap. The discretised
//! second line of Eq. 12 defines the gap function
//!
//! ```text
//! g_i(q) = Σ_j C_ij·w_j·q_j + u_c,i(q_i) − d_i          (m)
//! ```
//!
//! with the global compliance `C_ij = α_p + α_g` (m/N, observation i, load j; it need not be
//! exactly symmetric) and the local Weber–Banaschek approach `u_c,i` of both flanks (m, the
//! `2·u_c` of Eq. 12, see [`crate::compliance::hertz`]; absent for a linear problem). Contact
//! is unilateral, so the load distribution is the solution of the complementarity problem
//!
//! ```text
//! q_i ≥ 0,  g_i(q) ≥ 0,  q_i·g_i(q) = 0   for every slice i,
//! ```
//!
//! i.e. on loaded slices the deformation equals the required approach, on unloaded slices the
//! gap stays open. Positive g is a gap, negative g a remaining penetration.
//!
//! After the solve: total normal force `F = Σ w_i·q_i` (N), torques (Eq. 13)
//! `M_F,k = Σ_i s_k,i·q_i·m_n·Δζ_i` ([`mesh_torque`]), damping torques (Eq. 14)
//! `M_D,k = d_mesh·(φ̇_p·g_p + φ̇_g·g_g)·g_k·Σ_j (ζ_e,j − ζ_b,j)` ([`damping_torques`]) and the
//! Hertz pressure (Eq. 15) `p_i = sqrt(q_i / (π·C_E·ρ_i))` ([`hertz_pressures`]).
//!
//! ## Method and why
//! A primal–dual active-set method, which is a semi-smooth Newton method on the complementarity
//! function `Φ_i = min(c_i·q_i, g_i)` with `c_i = C_ii·w_i` (m per N/m, which gives both
//! arguments the unit m), globalised by a backtracking line search on `Σ Φ_i²`:
//!
//! 1. the working set is `W = {i : g_i < c_i·q_i}`; slices outside W are set to q = 0. The
//!    first step of a solve takes instead `W = {i : q_i > 0 or g_i < 0}` (the start's loaded
//!    slices and the penetrating ones), which keeps a warm start's nearly right active set
//!    (on a Table 1 trajectory 2.4 instead of 2.9 factorisations per solve);
//! 2. the Newton system on W, `(C_WW·diag(w_W) + diag(u_c'))·δ_W = −g_W + C_WI·diag(w_I)·q_I`,
//!    is solved densely: when C is exactly symmetric, the system multiplied by diag(w_W) is
//!    symmetric and is factorised by Cholesky (half the work of LU); otherwise, or when that
//!    Cholesky meets a non-positive pivot, by LU with partial pivoting (faer, in a workspace
//!    sized once). A slice entering W (q = 0) whose step comes out ≤ 0 would need a tensile
//!    load: it is taken out of W and the system solved again;
//! 3. the step is projected onto q ≥ 0 and halved until the merit decreases (Armijo). If that
//!    fails, a few full steps are allowed anyway (a watchdog, at most 10 per solve), which lets
//!    the iteration leave a kink of the non-smooth merit; after that the solve stops with
//!    [`LoadError::Stalled`].
//!
//! Why this method: the exact active set usually changes by a few slices between successive
//! calls of a dynamic simulation, and the active-set Newton step then finds it within one or
//! two factorisations (warm start), whereas interior-point or projected-gradient methods need
//! many iterations irrespective of a good start. Near the solution it is Newton's method on the
//! true active set, so the final iterations converge quadratically to a tight residual, and the
//! loads of unloaded slices are exactly 0 (no barrier parameter leaves them slightly positive).
//! Global convergence is not proved for this combination; it is tested on thousands of random
//! positive definite (also non-symmetric) problems with and without the local term, and every
//! non-convergence ends in a typed error, never in NaN.
//!
//! The local term has du_c/dq = +∞ at q = 0 (logarithmic singularity). Loaded slices always
//! have q > 0 (the projection sets leaving slices to exactly 0 and removes them from W), so the
//! analytic derivative is finite wherever it is used. A slice entering W has q = 0; its diagonal
//! entry uses the secant slope `u_c(q̂)/q̂` at the linear load estimate `q̂ = −g_i/c_i > 0`
//! instead of the infinite tangent, which puts it on a finite positive load after one step.
//! Since u_c is concave in q, Newton iterates for such a slice approach the solution from
//! below, so a newly loaded slice starts smoothly from zero load.
//!
//! Well-posedness: the problem has exactly one solution when `C·diag(w)` is a P-matrix
//! (e.g. C positive definite, symmetric or not) and u_c is non-decreasing. The solver checks
//! the sign of the determinant of every LU-factorised working block; a non-positive one proves
//! that the matrix is not a P-matrix and is reported as [`LoadError::Indefinite`] (a pivot at
//! round-off level as [`LoadError::Singular`]). When no slice has d_i > 0, q = 0 is returned
//! exactly without any factorisation.
//!
//! That proof holds for the working set and slopes of the step that met it, not for the
//! problem: a cold first step puts every penetrating slice in W at once, with estimated secant
//! slopes, and under heavy overload that block of the smooth global kernel can be indefinite
//! although the loads that solve the problem leave some of those slices open. Before reporting
//! either error the solver therefore retries by continuation: it lowers every approach by the
//! same shift, d_i − (1 − k/K)·max d, and solves k = 1 … K from q = 0, each step from the
//! previous loads (K = 4, then 16). Slices then enter in the order a rising load would bring
//! them in, as when the transmission error grows. Only when that fails too is the first error
//! reported; a problem that was solved directly is never touched. Measured for β = 18.5°,
//! b = 10.7 mm (coarse FE, `tests/mesh.rs`): without the retry every cold solve from 1.3× the
//! nominal static TE up failed at its first step, while the same states solved from the
//! neighbouring state's loads up to 4.6×; with it the cold solves give those loads (F_n to
//! 1e-12 relative) up to the same limit, beyond which both fail.

//! Simplified Newton: within one solve C does not change, only the diagonal slopes u_c' of
//! the local term and the working set do. When the working set of a step equals that of the
//! held LU factors and the last step reduced the residual at least fourfold, the step reuses
//! those factors with the new right-hand side (O(m²) instead of O(m³)); the convergence test is
//! unchanged, so the result meets the same tolerance. A slower contraction switches back to a
//! fresh factorisation. On a Table 1 trajectory this cut the factorisations per solve from 4.3
//! to 2.9 (at 1.5 more cheap iterations). [`LoadReport::factorizations`] counts them.
//!
//! Bordered solves: a working set W that is the held factors' set H less a few slices R (at most 8)
//! is solved from those factors too, by the complementary-minor (capacitance) identity — the system
//! on H with the steps of R fixed (their loads moved to the right-hand side) and the rows of R
//! relaxed by multipliers, 1 + |R| solves with the held factors and an |R| × |R| elimination
//! (`LoadSolver::bordered_solve`). It serves the second pass of a step, after entering slices with
//! a non-positive step left W (the same matrix: an exact Newton step), and a simplified Newton step
//! under the rule above. det J_W = det J_H · det (J_H⁻¹)_RR, so the sign check of the factorisation
//! carries over when the small determinant is positive; otherwise W is factorised afresh. Where the
//! loaded ends of partly loaded contact lines move from state to state, W shrinks and grows by a
//! few slices over several Newton steps; measured on the Table 1 benchmark sweep (64 phases × 3
//! loads, warm) the factorisations per solve went from 3.2 to 2.4 at 200 slices and from 2.5 to 1.7
//! at 100.
//!
//! Cost: one factorisation of the working block per full iteration (O(m³), m loaded slices)
//! plus matrix–vector products (O(n²)) per line-search trial. The solver's own buffers are sized at
//! construction ([`LoadSolver::with_capacity`]) and reused; a warm start from the previous
//! solution of a nearby problem typically needs one iteration. The working block is copied
//! from C by runs of consecutive slices (the working set is usually one run per contact line),
//! contiguous memory instead of one indexed read per entry.
//!
//! ## Convergence test
//! With `tol = abs_tol + rel_tol·max_i |d_i|` (m): |g_i| ≤ tol on loaded slices (q_i > 0),
//! g_i ≥ −tol on unloaded slices, q_i ≥ 0 exactly. The reported residual is the largest of
//! these violations (m).

use std::fmt;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor as cholesky;
use faer::linalg::cholesky::llt::solve as cholesky_solve;
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Accum, ColMut, ColRef, Mat, MatRef, Par};

use crate::compliance::hertz::{self, HertzError, LocalContact};

/// Local (non-linear) contact approach of each slice: u_c,i(q) and du_c,i/dq.
///
/// Requirements: for q > 0 (N/m) return `(u, du_dq)` with u (m) finite and ≥ 0 and du_dq
/// (m²/N) finite and ≥ 0 (u non-decreasing); u_c,i(0) = 0 is assumed and the solver never
/// evaluates the term at q = 0. Non-finite or negative values are reported as
/// [`LoadError::LocalTerm`].
pub trait LocalTerm {
    /// u_c,i(q) (m) and du_c,i/dq (m²/N) of slice `slice` at load intensity `q` > 0 (N/m).
    fn eval(&self, slice: usize, q: f64) -> (f64, f64);
}

impl<F: Fn(usize, f64) -> (f64, f64)> LocalTerm for F {
    fn eval(&self, slice: usize, q: f64) -> (f64, f64) {
        self(slice, q)
    }
}

/// The Weber–Banaschek local term of both flanks ([`LocalContact::deformation`]) with one
/// reduced radius of curvature per slice.
#[derive(Debug, Clone, Copy)]
pub struct HertzLocal<'a> {
    contact: &'a LocalContact,
    rho: &'a [f64],
}

impl<'a> HertzLocal<'a> {
    /// `rho[i]`: reduced radius of curvature ρ = ρ_p·ρ_g/(ρ_p + ρ_g) of slice i, m, finite and
    /// positive (see [`hertz::reduced_radius`]), one per slice (a slice without a radius is
    /// reported by the solver as [`LoadError::LocalTerm`]). Errors on the first invalid radius,
    /// with its slice.
    pub fn new(contact: &'a LocalContact, rho: &'a [f64]) -> Result<Self, LoadError> {
        for (slice, &r) in rho.iter().enumerate() {
            if !(r.is_finite() && r > 0.0) {
                return Err(LoadError::Hertz {
                    slice,
                    source: HertzError::NonPositiveRadius { name: "rho", value: r },
                });
            }
        }
        Ok(Self { contact, rho })
    }
}

impl LocalTerm for HertzLocal<'_> {
    fn eval(&self, slice: usize, q: f64) -> (f64, f64) {
        match self.rho.get(slice).map(|&r| self.contact.deformation(q, r)) {
            Some(Ok(d)) => (d.total, d.d_total_dq),
            // Reported by the solver as a typed error (never reached with validated inputs).
            _ => (f64::NAN, f64::NAN),
        }
    }
}

/// One load-distribution problem (borrowed inputs; nothing is copied).
#[derive(Clone, Copy)]
pub struct LoadProblem<'a> {
    /// Required normal approach d_i = Δ_i·cos θ of each slice, m (negative: open gap).
    pub approach: &'a [f64],
    /// Length of contact line w_i = m_n·Δζ_i / cos θ of each slice, m (> 0).
    pub line_length: &'a [f64],
    /// Compliance C (n×n, m/N): C_ij is the normal approach at slice i due to a unit normal
    /// force at slice j (α_p + α_g). Diagonal entries must be > 0.
    pub compliance: MatRef<'a, f64>,
    /// Local contact approach u_c,i(q) (both flanks); `None` for a linear problem.
    pub local: Option<&'a dyn LocalTerm>,
}

/// Tolerances and iteration cap of [`LoadSolver`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadSettings {
    /// Absolute gap tolerance, m.
    pub abs_tol: f64,
    /// Gap tolerance relative to max_i |d_i| (dimensionless).
    pub rel_tol: f64,
    /// Maximum number of Newton iterations per solve.
    pub max_iterations: usize,
}

impl Default for LoadSettings {
    /// 1e-12 m + 1e-10·max|d|, at most 100 iterations.
    fn default() -> Self {
        Self { abs_tol: 1e-12, rel_tol: 1e-10, max_iterations: 100 }
    }
}

/// Where a solve starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start<'a> {
    /// From q = 0.
    Cold,
    /// From the solver's previous solution (its loads and hence its active set) when that had
    /// the same number of slices and succeeded; otherwise cold.
    Warm,
    /// From the given loads (N/m, one per slice; negative values are taken as 0).
    From(&'a [f64]),
}

/// Outcome of a successful solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadReport {
    /// Newton iterations used; 0 when nothing overlaps or the start was already converged.
    pub iterations: usize,
    /// Matrix factorisations (one per full Newton step, more when entering slices are
    /// rejected, none for a simplified-Newton step on held factors).
    pub factorizations: usize,
    /// Evaluations of the gap function g(q) (one per line-search trial, plus the start).
    pub evaluations: usize,
    /// Largest violation of the conditions (|g| on loaded, −g on unloaded slices), m.
    pub residual: f64,
    /// The tolerance that was met, m.
    pub tolerance: f64,
    /// Number of loaded slices (q > 0).
    pub active: usize,
    /// Total normal force F = Σ w_i·q_i, N.
    pub total_force: f64,
}

/// Errors of the load solver and its helpers.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadError {
    /// An input has the wrong length (`name`: `"line_length"`, `"compliance"`, `"start"`, …).
    DimensionMismatch {
        /// Input name.
        name: &'static str,
        /// Required length (number of slices).
        expected: usize,
        /// Found length.
        found: usize,
    },
    /// A non-finite entry (NaN or ±∞) in a vector input (`"approach"`, `"line_length"`,
    /// `"start"`, `"load"`, `"arm"`, …).
    NonFinite {
        /// Input name.
        name: &'static str,
        /// Index of the entry.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A non-finite entry of the compliance matrix C.
    NonFiniteCompliance {
        /// Row (observation slice).
        row: usize,
        /// Column (load slice).
        col: usize,
        /// The value, m/N.
        value: f64,
    },
    /// An entry that must be > 0 is not (`"line_length"`, or `"compliance diagonal"`).
    NonPositive {
        /// Input name.
        name: &'static str,
        /// Index of the entry.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The local term returned a non-finite value or a negative one (u or du/dq).
    LocalTerm {
        /// Slice.
        slice: usize,
        /// Load intensity it was evaluated at, N/m.
        q: f64,
        /// Returned u_c, m.
        u: f64,
        /// Returned du_c/dq, m²/N.
        du_dq: f64,
    },
    /// The Newton matrix of the working set is (numerically) singular.
    Singular {
        /// Iteration at which it happened.
        iterations: usize,
        /// Residual reached, m.
        residual: f64,
        /// Size of the working set.
        working_set: usize,
    },
    /// The Newton matrix of the working set has a non-positive determinant: C·diag(w) is not
    /// a P-matrix (e.g. C indefinite), so the contact problem is ill-posed.
    Indefinite {
        /// Iteration at which it happened.
        iterations: usize,
        /// Residual reached, m.
        residual: f64,
        /// Size of the working set.
        working_set: usize,
    },
    /// The line search could not decrease the merit function.
    Stalled {
        /// Iteration at which it happened.
        iterations: usize,
        /// Residual reached, m.
        residual: f64,
    },
    /// The iteration cap was reached.
    NoConvergence {
        /// Iterations performed.
        iterations: usize,
        /// Residual reached, m.
        residual: f64,
        /// Tolerance required, m.
        tolerance: f64,
    },
    /// A Hertz formula failed for a slice (Eq. 15 or the local term's radius).
    Hertz {
        /// Slice.
        slice: usize,
        /// The underlying error.
        source: HertzError,
    },
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::DimensionMismatch { name, expected, found } => {
                write!(f, "load input `{name}` has length {found}, expected {expected}")
            }
            LoadError::NonFinite { name, index, value } => {
                write!(f, "load input `{name}`[{index}] = {value}: must be finite")
            }
            LoadError::NonFiniteCompliance { row, col, value } => {
                write!(f, "load input `compliance`[{row}, {col}] = {value} m/N: must be finite")
            }
            LoadError::NonPositive { name, index, value } => {
                write!(f, "load input `{name}`[{index}] = {value}: must be > 0")
            }
            LoadError::LocalTerm { slice, q, u, du_dq } => write!(
                f,
                "local contact term of slice {slice} at q = {q} N/m returned u = {u} m, \
                 du/dq = {du_dq} m²/N: must be finite and >= 0"
            ),
            LoadError::Singular { iterations, residual, working_set } => write!(
                f,
                "load solver: singular Newton matrix ({working_set} slices) at iteration \
                 {iterations}, residual {residual:e} m"
            ),
            LoadError::Indefinite { iterations, residual, working_set } => write!(
                f,
                "load solver: compliance is not positive definite (non-positive determinant on \
                 {working_set} slices) at iteration {iterations}, residual {residual:e} m"
            ),
            LoadError::Stalled { iterations, residual } => write!(
                f,
                "load solver: line search stalled at iteration {iterations}, residual \
                 {residual:e} m"
            ),
            LoadError::NoConvergence { iterations, residual, tolerance } => write!(
                f,
                "load solver: no convergence in {iterations} iterations, residual {residual:e} m \
                 > tolerance {tolerance:e} m"
            ),
            LoadError::Hertz { slice, source } => write!(f, "slice {slice}: {source}"),
        }
    }
}

impl std::error::Error for LoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LoadError::Hertz { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Per-slice state of one iterate.
#[derive(Debug, Clone, Default)]
struct Iterate {
    /// Load intensity, N/m.
    q: Vec<f64>,
    /// Gap g(q), m.
    g: Vec<f64>,
    /// du_c/dq at q (+∞ where q = 0 with a local term, 0 without), m²/N.
    du: Vec<f64>,
}

impl Iterate {
    fn resize(&mut self, n: usize) {
        self.q.resize(n, 0.0);
        self.g.resize(n, 0.0);
        self.du.resize(n, 0.0);
    }
}

/// Active-set Newton solver of the load distribution with its workspace.
///
/// The workspace is sized for `capacity` slices at construction; solves with n ≤ capacity do
/// not allocate (a larger n grows it once). The last solution is kept for warm starts.
pub struct LoadSolver {
    settings: LoadSettings,
    capacity: usize,
    /// Slices of the last successful solve (0: none).
    last_n: usize,
    evaluations: usize,
    factorizations: usize,
    cur: Iterate,
    trial: Iterate,
    /// Slice forces w_j·q_j, N.
    force: Vec<f64>,
    /// Newton step, N/m.
    delta: Vec<f64>,
    /// c_i = C_ii·w_i, m per N/m.
    scale: Vec<f64>,
    working: Vec<usize>,
    in_working: Vec<bool>,
    jac: Mat<f64>,
    rhs: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    stack: MemBuffer,
    /// Working set of the LU factors held in `jac`/`perm` (valid when `lu_valid`).
    lu_working: Vec<usize>,
    /// The working set as runs of consecutive slices: (position in W, first slice, length).
    runs: Vec<(usize, usize, usize)>,
    lu_valid: bool,
    /// Whether the next step may reuse the held LU factors (simplified Newton).
    chord: bool,
    /// Shifted approach d − (1 − k/K)·max d of the continuation retry, m.
    approach_part: Vec<f64>,
    /// Right-hand sides of a bordered solve: the extended right-hand side, then one unit
    /// column per slice held out ([`LoadSolver::bordered_solve`]).
    aux: Mat<f64>,
    /// Positions in the held LU's working set of the slices a bordered solve holds out.
    held_out: Vec<usize>,
}

impl fmt::Debug for LoadSolver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LoadSolver")
            .field("settings", &self.settings)
            .field("capacity", &self.capacity)
            .field("last_n", &self.last_n)
            .finish_non_exhaustive()
    }
}

/// Most slices a bordered solve holds out of the held LU factors' working set; beyond it the
/// working block is factorised afresh.
const MAX_HELD_OUT: usize = 8;

fn stack_req(n: usize) -> StackReq {
    let params = Default::default();
    factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, params)
        .or(solve::solve_in_place_scratch::<usize, f64>(n, MAX_HELD_OUT + 1, Par::Seq))
        .or(cholesky::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default()))
}

impl LoadSolver {
    /// A solver with default settings and a workspace for up to `capacity` slices.
    pub fn with_capacity(capacity: usize) -> Self {
        Self::with_settings(capacity, LoadSettings::default())
    }

    /// A solver with the given settings and a workspace for up to `capacity` slices.
    pub fn with_settings(capacity: usize, settings: LoadSettings) -> Self {
        let mut s = Self {
            settings,
            capacity: 0,
            last_n: 0,
            evaluations: 0,
            factorizations: 0,
            cur: Iterate::default(),
            trial: Iterate::default(),
            force: Vec::new(),
            delta: Vec::new(),
            scale: Vec::new(),
            working: Vec::new(),
            in_working: Vec::new(),
            jac: Mat::zeros(0, 0),
            rhs: Mat::zeros(0, 1),
            perm: Vec::new(),
            perm_inv: Vec::new(),
            stack: MemBuffer::new(stack_req(0)),
            lu_working: Vec::new(),
            runs: Vec::new(),
            lu_valid: false,
            chord: false,
            approach_part: Vec::new(),
            aux: Mat::zeros(0, MAX_HELD_OUT + 1),
            held_out: Vec::with_capacity(MAX_HELD_OUT),
        };
        s.reserve(capacity);
        s
    }

    /// The settings in use.
    pub fn settings(&self) -> &LoadSettings {
        &self.settings
    }

    /// Replaces the settings.
    pub fn set_settings(&mut self, settings: LoadSettings) {
        self.settings = settings;
    }

    /// Number of slices the workspace holds without allocating.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    fn reserve(&mut self, n: usize) {
        if n <= self.capacity {
            return;
        }
        for v in [&mut self.force, &mut self.delta, &mut self.scale, &mut self.approach_part] {
            v.resize(n, 0.0);
        }
        self.cur.resize(n);
        self.trial.resize(n);
        self.working.reserve(n);
        self.in_working.resize(n, false);
        self.jac = Mat::zeros(n, n);
        self.rhs = Mat::zeros(n, 1);
        self.aux = Mat::zeros(n, MAX_HELD_OUT + 1);
        self.perm.resize(n, 0);
        self.perm_inv.resize(n, 0);
        self.lu_working.reserve(n);
        self.runs.reserve(n);
        self.stack = MemBuffer::new(stack_req(n));
        self.capacity = n;
    }

    /// Load intensities q_i of the last successful solve, N/m (empty before the first one or
    /// after a failed one).
    pub fn load(&self) -> &[f64] {
        &self.cur.q[..self.last_n]
    }

    /// Gaps g_i of the last successful solve, m (≈ 0 on loaded slices, ≥ 0 on unloaded ones).
    pub fn gap(&self) -> &[f64] {
        &self.cur.g[..self.last_n]
    }

    /// Solves the load distribution of `problem` from `start`.
    ///
    /// On success the loads are available from [`LoadSolver::load`] and the report gives the
    /// iterations, the residual and the total force. Errors: invalid inputs (named), a
    /// singular or indefinite Newton matrix, a stalled line search or the iteration cap (with
    /// the residual reached). After an error [`LoadSolver::load`] is empty and a warm start
    /// falls back to a cold one.
    /// A singular or indefinite Newton matrix is retried by continuation in the approach before
    /// it is reported (see the module docs, "Well-posedness").
    pub fn solve(
        &mut self,
        problem: &LoadProblem<'_>,
        start: Start<'_>,
    ) -> Result<LoadReport, LoadError> {
        match self.solve_from(problem, start) {
            Err(e @ (LoadError::Indefinite { .. } | LoadError::Singular { .. })) => {
                self.solve_by_continuation(problem).map_err(|_| e)
            }
            r => r,
        }
    }

    /// The continuation retry of [`LoadSolver::solve`]: a pass of K = 4 steps, then one of 16
    /// (see [`LoadSolver::continuation_pass`]).
    fn solve_by_continuation(
        &mut self,
        problem: &LoadProblem<'_>,
    ) -> Result<LoadReport, LoadError> {
        let mut part = std::mem::take(&mut self.approach_part);
        part.resize(problem.approach.len(), 0.0);
        let result = self
            .continuation_pass(problem, &mut part, 4)
            .or_else(|_| self.continuation_pass(problem, &mut part, 16));
        self.approach_part = part;
        result
    }

    /// One continuation pass of `steps` = K steps: approaches d − (1 − k/K)·max d (into
    /// `part`) for k = 1 … K from q = 0, each from the previous loads. The report sums the
    /// pass's work; the first failing step's error ends it.
    fn continuation_pass(
        &mut self,
        problem: &LoadProblem<'_>,
        part: &mut [f64],
        steps: usize,
    ) -> Result<LoadReport, LoadError> {
        let d_max = problem.approach.iter().fold(0.0_f64, |m, &d| m.max(d));
        let (mut iterations, mut factorizations, mut evaluations) = (0, 0, 0);
        let mut last = None;
        for k in 1..=steps {
            let shift = d_max * (steps - k) as f64 / steps as f64;
            for (x, &d) in part.iter_mut().zip(problem.approach) {
                *x = d - shift;
            }
            let step = LoadProblem { approach: part, ..*problem };
            let start = if k == 1 { Start::Cold } else { Start::Warm };
            let r = self.solve_from(&step, start)?;
            iterations += r.iterations;
            factorizations += r.factorizations;
            evaluations += r.evaluations;
            last = Some(r);
        }
        let r = last.expect("a pass has at least one step");
        Ok(LoadReport { iterations, factorizations, evaluations, ..r })
    }

    /// [`LoadSolver::solve`] without the continuation retry.
    fn solve_from(
        &mut self,
        problem: &LoadProblem<'_>,
        start: Start<'_>,
    ) -> Result<LoadReport, LoadError> {
        let n = validate(problem)?;
        if let Start::From(q0) = start {
            if q0.len() != n {
                return Err(LoadError::DimensionMismatch {
                    name: "start",
                    expected: n,
                    found: q0.len(),
                });
            }
            check_finite("start", q0)?;
        }
        let warm = matches!(start, Start::Warm) && self.last_n == n;
        self.last_n = 0;
        self.reserve(n);
        let d = problem.approach;
        let d_max = d.iter().fold(0.0_f64, |m, &x| m.max(x.abs()));
        let tol = self.settings.abs_tol + self.settings.rel_tol * d_max;

        if d.iter().all(|&x| x <= 0.0) {
            // q = 0 satisfies all conditions exactly: g = −d ≥ 0.
            self.cur.q[..n].fill(0.0);
            for (g, &di) in self.cur.g[..n].iter_mut().zip(d) {
                *g = -di;
            }
            self.last_n = n;
            return Ok(LoadReport {
                iterations: 0,
                factorizations: 0,
                evaluations: 0,
                residual: 0.0,
                tolerance: tol,
                active: 0,
                total_force: 0.0,
            });
        }

        for i in 0..n {
            self.scale[i] = problem.compliance[(i, i)] * problem.line_length[i];
        }
        let symmetric = is_symmetric(problem.compliance);
        match start {
            Start::From(q0) => {
                for (q, &v) in self.cur.q[..n].iter_mut().zip(q0) {
                    *q = v.max(0.0);
                }
            }
            Start::Warm if warm => {}
            _ => self.cur.q[..n].fill(0.0),
        }
        evaluate(problem, &mut self.cur, &mut self.force)?;
        self.evaluations = 1;

        let mut iterations = 0;
        let mut watchdog = WATCHDOG_STEPS;
        self.lu_valid = false;
        self.chord = false;
        self.factorizations = 0;
        let mut last_residual = f64::INFINITY;
        loop {
            let residual = violation(&self.cur, d.len());
            // Simplified Newton: the held factors may serve the next step while the residual
            // falls at least fourfold per step (see the module docs).
            self.chord = self.lu_valid && residual <= 0.25 * last_residual;
            last_residual = residual;
            if residual <= tol {
                self.last_n = n;
                let active = self.cur.q[..n].iter().filter(|&&q| q > 0.0).count();
                return Ok(LoadReport {
                    iterations,
                    factorizations: self.factorizations,
                    evaluations: self.evaluations,
                    residual,
                    tolerance: tol,
                    active,
                    total_force: total_force(&self.cur.q[..n], problem.line_length),
                });
            }
            if iterations >= self.settings.max_iterations {
                return Err(LoadError::NoConvergence { iterations, residual, tolerance: tol });
            }
            iterations += 1;
            self.newton_step(problem, symmetric, iterations, residual)?;
            self.line_search(problem, iterations, residual, tol, &mut watchdog)?;
        }
    }

    /// Working set and Newton step `delta` (N/m) for all slices.
    fn newton_step(
        &mut self,
        problem: &LoadProblem<'_>,
        symmetric: bool,
        iterations: usize,
        residual: f64,
    ) -> Result<(), LoadError> {
        let n = problem.approach.len();
        self.working.clear();
        for i in 0..n {
            // The first step of a solve keeps every slice the start loads (and adds the
            // penetrating ones): a warm start's active set is usually nearly right, and
            // dropping slices whose gap opened only a little costs an extra factorisation.
            let active = if iterations == 1 {
                self.cur.q[i] > 0.0 || self.cur.g[i] < 0.0
            } else {
                self.cur.g[i] < self.scale[i] * self.cur.q[i]
            };
            self.in_working[i] = active;
            if active {
                self.working.push(i);
            } else {
                self.delta[i] = -self.cur.q[i];
            }
        }
        // An entering slice (q = 0) whose Newton step is not positive would need a tensile
        // load: it leaves W and the system is solved again (at most |W| times).
        let mut pass = 0;
        loop {
            let m = self.working.len();
            if m == 0 {
                return Ok(());
            }
            // A second pass solves with the matrix of the first (the iterate has not moved).
            self.solve_working(problem, symmetric, iterations, residual, pass > 0)?;
            pass += 1;
            let before = m;
            let (delta, q, in_working) = (&self.delta, &self.cur.q, &mut self.in_working);
            self.working.retain(|&i| {
                let keep = q[i] > 0.0 || delta[i] > 0.0;
                in_working[i] = keep;
                keep
            });
            for i in 0..n {
                if !self.in_working[i] {
                    self.delta[i] = -self.cur.q[i];
                }
            }
            if self.working.len() == before {
                return Ok(());
            }
        }
    }

    /// One factorisation and solve on the working set; the step goes to `delta`. With
    /// `same_matrix` the held factors are of this iterate's Newton matrix on a superset of the
    /// working set (a later pass of [`LoadSolver::newton_step`]).
    fn solve_working(
        &mut self,
        problem: &LoadProblem<'_>,
        symmetric: bool,
        iterations: usize,
        residual: f64,
        same_matrix: bool,
    ) -> Result<(), LoadError> {
        let m = self.working.len();
        if !symmetric && self.lu_valid && (self.chord || same_matrix) {
            if self.working == self.lu_working {
                self.fill_rhs(problem);
                self.lu_resolve(m);
                return self.take_step(iterations, residual);
            }
            if self.bordered_solve(problem) {
                return self.take_step(iterations, residual);
            }
        }
        self.lu_valid = false;
        self.factorizations += 1;
        if symmetric {
            self.fill_system(problem, true)?;
            if self.cholesky_solve(m) {
                return self.take_step(iterations, residual);
            }
            // Not positive definite (or singular): the LU below tells which.
        }
        self.fill_system(problem, false)?;
        self.lu_solve(m, iterations, residual)?;
        self.lu_working.clear();
        self.lu_working.extend_from_slice(&self.working);
        self.lu_valid = true;
        self.take_step(iterations, residual)
    }

    /// Right-hand side of the Newton system on the working set (unscaled): −g_W, plus the
    /// loads of slices leaving W (set to 0), which move to the right-hand side.
    fn fill_rhs(&mut self, problem: &LoadProblem<'_>) {
        let m = self.working.len();
        newton_rhs(
            problem,
            &self.cur,
            &self.in_working,
            &self.working,
            &mut self.rhs.col_as_slice_mut(0)[..m],
        );
    }

    /// Solves with the LU factors held from an earlier step of this solve.
    fn lu_resolve(&mut self, m: usize) {
        let jac = self.jac.as_ref().submatrix(0, 0, m, m);
        let perm = faer::perm::PermRef::new_checked(&self.perm[..m], &self.perm_inv[..m], m);
        let stack = MemStack::new(&mut self.stack);
        let rhs = self.rhs.as_mut().submatrix_mut(0, 0, m, 1);
        solve::solve_in_place(jac, jac, perm, rhs, Par::Seq, stack);
    }

    /// The Newton step on a working set W that is the held LU factors' set H less at most
    /// [`MAX_HELD_OUT`] slices R, from those factors (no factorisation). The loads of R move to
    /// the right-hand side as for any slice outside W (a slice leaving W is set to zero load),
    /// so the system on W is the system on H with x_R = 0 and the rows of R relaxed by
    /// multipliers y,
    ///
    /// ```text
    /// J_H·x = r + E_R·y,   x_R = 0   ⇒   x = J_H⁻¹r + Z·y,  Z = J_H⁻¹E_R,  Z_RR·y = −(J_H⁻¹r)_R
    /// ```
    ///
    /// with r the right-hand side of [`LoadSolver::fill_rhs`] at the rows of H: 1 + |R| solves
    /// with the held factors and a |R| × |R| elimination instead of an O(|W|³) factorisation. Z_RR
    /// = (J_H⁻¹)_RR is the complementary minor: det J_W = det J_H · det Z_RR, so a positive det
    /// Z_RR keeps the P-matrix check of the factorisation of H valid for W. Returns false, leaving
    /// the step to a fresh factorisation, when W is no such subset, when det Z_RR is not clearly
    /// positive or when a value is not finite. The solution goes to `rhs` in the order of W.
    fn bordered_solve(&mut self, problem: &LoadProblem<'_>) -> bool {
        let big = self.lu_working.len();
        let m = self.working.len();
        if m >= big || big - m > MAX_HELD_OUT {
            return false;
        }
        self.held_out.clear();
        for (a, &i) in self.lu_working.iter().enumerate() {
            if !self.in_working[i] {
                self.held_out.push(a);
            }
        }
        if big - self.held_out.len() != m {
            return false; // a slice of W is not in H
        }
        let k = self.held_out.len();
        newton_rhs(
            problem,
            &self.cur,
            &self.in_working,
            &self.lu_working,
            &mut self.aux.col_as_slice_mut(0)[..big],
        );
        for (col, &a) in self.held_out.iter().enumerate() {
            let e = &mut self.aux.col_as_slice_mut(col + 1)[..big];
            e.fill(0.0);
            e[a] = 1.0;
        }
        let jac = self.jac.as_ref().submatrix(0, 0, big, big);
        let perm = faer::perm::PermRef::new_checked(&self.perm[..big], &self.perm_inv[..big], big);
        let stack = MemStack::new(&mut self.stack);
        let rhs = self.aux.as_mut().submatrix_mut(0, 0, big, k + 1);
        solve::solve_in_place(jac, jac, perm, rhs, Par::Seq, stack);
        // Z_RR·y = −(J_H⁻¹r)_R by elimination with partial pivoting.
        let mut zrr = [[0.0; MAX_HELD_OUT]; MAX_HELD_OUT];
        let mut y = [0.0; MAX_HELD_OUT];
        for (p, &a) in self.held_out.iter().enumerate() {
            for (col, z) in zrr[p].iter_mut().enumerate().take(k) {
                *z = self.aux[(a, col + 1)];
            }
            y[p] = -self.aux[(a, 0)];
        }
        let scale =
            zrr.iter().take(k).flat_map(|r| r[..k].iter()).fold(0.0_f64, |x, v| x.max(v.abs()));
        let mut positive = true;
        for col in 0..k {
            let piv = (col..k).max_by(|&a, &b| zrr[a][col].abs().total_cmp(&zrr[b][col].abs()));
            let piv = piv.unwrap_or(col);
            // Also a NaN pivot (the comparison is then false).
            if zrr[piv][col].abs().partial_cmp(&(1e3 * f64::EPSILON * scale))
                != Some(std::cmp::Ordering::Greater)
            {
                return false;
            }
            if piv != col {
                zrr.swap(piv, col);
                y.swap(piv, col);
                positive = !positive;
            }
            if zrr[col][col] < 0.0 {
                positive = !positive;
            }
            let pivot_row = zrr[col];
            for r in col + 1..k {
                let f = zrr[r][col] / pivot_row[col];
                for (x, &p) in zrr[r][col..k].iter_mut().zip(&pivot_row[col..k]) {
                    *x -= f * p;
                }
                y[r] -= f * y[col];
            }
        }
        if !positive {
            return false;
        }
        for col in (0..k).rev() {
            let mut v = y[col];
            for cc in col + 1..k {
                v -= zrr[col][cc] * y[cc];
            }
            y[col] = v / zrr[col][col];
        }
        let mut b = 0;
        for (a, &i) in self.lu_working.iter().enumerate() {
            if !self.in_working[i] {
                continue;
            }
            let mut x = self.aux[(a, 0)];
            for (col, &yc) in y.iter().enumerate().take(k) {
                x += self.aux[(a, col + 1)] * yc;
            }
            if !x.is_finite() {
                return false;
            }
            self.rhs[(b, 0)] = x;
            b += 1;
        }
        true
    }

    /// Newton matrix and right-hand side on the working set. Unscaled: rows of
    /// `C_WW·diag(w_W) + diag(u_c')`; scaled (symmetric C): both sides multiplied by diag(w_W),
    /// which makes the matrix `diag(w)·C·diag(w) + diag(w·u_c')` symmetric.
    fn fill_system(&mut self, problem: &LoadProblem<'_>, scaled: bool) -> Result<(), LoadError> {
        let c = problem.compliance;
        let w = problem.line_length;
        let m = self.working.len();
        // The working set as runs of consecutive slices (usually a few: one per contact line
        // or less), so that each column is copied run by run from contiguous memory.
        self.runs.clear();
        for (a, &i) in self.working.iter().enumerate() {
            match self.runs.last_mut() {
                Some((_, i0, len)) if *i0 + *len == i => *len += 1,
                _ => self.runs.push((a, i, 1)),
            }
        }
        for (b, &j) in self.working.iter().enumerate() {
            let dst = &mut self.jac.col_as_slice_mut(b)[..m];
            match column(c, j) {
                Some(src) => {
                    let wj = w[j];
                    for &(a0, i0, len) in &self.runs {
                        for (x, &v) in dst[a0..a0 + len].iter_mut().zip(&src[i0..i0 + len]) {
                            *x = v * wj;
                        }
                    }
                }
                None => {
                    for (x, &i) in dst.iter_mut().zip(&self.working) {
                        *x = c[(i, j)] * w[j];
                    }
                }
            }
        }
        self.fill_rhs(problem);
        for (a, &i) in self.working.iter().enumerate() {
            let q = self.cur.q[i];
            let slope = if q > 0.0 {
                self.cur.du[i]
            } else {
                match problem.local {
                    None => 0.0,
                    Some(local) => {
                        // Secant of u_c from 0 to the linear load estimate (q = 0 and g < 0 here).
                        let q_hat = -self.cur.g[i] / self.scale[i];
                        let (u, du) = local.eval(i, q_hat);
                        check_local(i, q_hat, u, du)?;
                        u / q_hat
                    }
                }
            };
            self.jac[(a, a)] += slope;
        }
        if scaled {
            for b in 0..m {
                let col = &mut self.jac.col_as_slice_mut(b)[..m];
                for (x, &i) in col.iter_mut().zip(&self.working) {
                    *x *= w[i];
                }
            }
            for (a, &i) in self.working.iter().enumerate() {
                self.rhs[(a, 0)] *= w[i];
            }
        }
        Ok(())
    }

    /// Cholesky factorisation and solve of the scaled symmetric system; `false` when a pivot is
    /// not clearly positive (the matrix is then left overwritten).
    fn cholesky_solve(&mut self, m: usize) -> bool {
        let mut jac = self.jac.as_mut().submatrix_mut(0, 0, m, m);
        let max_diag = (0..m).fold(0.0_f64, |x, a| x.max(jac[(a, a)].abs()));
        let stack = MemStack::new(&mut self.stack);
        let ok = cholesky::cholesky_in_place(
            jac.as_mut(),
            Default::default(),
            Par::Seq,
            stack,
            Default::default(),
        )
        .is_ok();
        // L_aa² is the pivot; require it well above round-off of the largest diagonal entry.
        if !ok || !(0..m).all(|a| jac[(a, a)] * jac[(a, a)] > 1e3 * f64::EPSILON * max_diag) {
            return false;
        }
        let stack = MemStack::new(&mut self.stack);
        let rhs = self.rhs.as_mut().submatrix_mut(0, 0, m, 1);
        cholesky_solve::solve_in_place(jac.as_ref(), rhs, Par::Seq, stack);
        true
    }

    /// LU factorisation with partial pivoting and solve; singular and non-P-matrix checks.
    fn lu_solve(&mut self, m: usize, iterations: usize, residual: f64) -> Result<(), LoadError> {
        let mut jac = self.jac.as_mut().submatrix_mut(0, 0, m, m);
        let max_abs = jac.as_ref().norm_max();
        let stack = MemStack::new(&mut self.stack);
        let (info, perm) = factor::lu_in_place(
            jac.as_mut(),
            &mut self.perm[..m],
            &mut self.perm_inv[..m],
            Par::Seq,
            stack,
            Default::default(),
        );
        let mut negative = info.transposition_count % 2 == 1;
        let mut min_pivot = f64::INFINITY;
        for a in 0..m {
            let p = jac[(a, a)];
            if !p.is_finite() {
                return Err(LoadError::Singular { iterations, residual, working_set: m });
            }
            min_pivot = min_pivot.min(p.abs());
            if p < 0.0 {
                negative = !negative;
            }
        }
        // Also catches a NaN maximum (comparison false).
        if min_pivot.partial_cmp(&(1e3 * f64::EPSILON * max_abs))
            != Some(std::cmp::Ordering::Greater)
        {
            return Err(LoadError::Singular { iterations, residual, working_set: m });
        }
        if negative {
            return Err(LoadError::Indefinite { iterations, residual, working_set: m });
        }
        let stack = MemStack::new(&mut self.stack);
        let rhs = self.rhs.as_mut().submatrix_mut(0, 0, m, 1);
        solve::solve_in_place(jac.as_ref(), jac.as_ref(), perm, rhs, Par::Seq, stack);
        Ok(())
    }

    /// Copies the working-set solution into `delta`.
    fn take_step(&mut self, iterations: usize, residual: f64) -> Result<(), LoadError> {
        let m = self.working.len();
        for (a, &i) in self.working.iter().enumerate() {
            let v = self.rhs[(a, 0)];
            if !v.is_finite() {
                return Err(LoadError::Singular { iterations, residual, working_set: m });
            }
            self.delta[i] = v;
        }
        Ok(())
    }

    /// Backtracking on the projected path max(0, q + α·δ) with the merit Σ min(c·q, g)².
    fn line_search(
        &mut self,
        problem: &LoadProblem<'_>,
        iterations: usize,
        residual: f64,
        tol: f64,
        watchdog: &mut usize,
    ) -> Result<(), LoadError> {
        let n = problem.approach.len();
        let theta0 = merit(&self.cur, &self.scale[..n]);
        let mut alpha = 1.0;
        for _ in 0..30 {
            for i in 0..n {
                self.trial.q[i] = (self.cur.q[i] + alpha * self.delta[i]).max(0.0);
            }
            evaluate(problem, &mut self.trial, &mut self.force)?;
            self.evaluations += 1;
            let theta = merit(&self.trial, &self.scale[..n]);
            if theta <= (1.0 - 1e-4 * alpha) * theta0 || violation(&self.trial, n) <= tol {
                std::mem::swap(&mut self.cur, &mut self.trial);
                return Ok(());
            }
            alpha *= 0.5;
        }
        // Watchdog: a limited number of full (non-monotone) steps, which lets the pure
        // active-set iteration leave a non-stationary kink of the merit function.
        if *watchdog == 0 {
            return Err(LoadError::Stalled { iterations, residual });
        }
        *watchdog -= 1;
        for i in 0..n {
            self.trial.q[i] = (self.cur.q[i] + self.delta[i]).max(0.0);
        }
        evaluate(problem, &mut self.trial, &mut self.force)?;
        self.evaluations += 1;
        std::mem::swap(&mut self.cur, &mut self.trial);
        Ok(())
    }
}

/// Non-monotone full steps allowed per solve after a failed line search.
const WATCHDOG_STEPS: usize = 10;

/// Whether C is exactly (bitwise) symmetric.
fn is_symmetric(c: MatRef<'_, f64>) -> bool {
    let n = c.nrows();
    (0..n).all(|j| match column(c, j) {
        Some(col) => (j + 1..n).all(|i| col[i] == c[(j, i)]),
        None => (j + 1..n).all(|i| c[(i, j)] == c[(j, i)]),
    })
}

/// The Newton right-hand side at the rows `rows`: −g_i, plus the loads of the slices outside the
/// working set (`in_working` false), which move to the right-hand side when their step sets
/// them to zero; into `dst` (one entry per row).
fn newton_rhs(
    problem: &LoadProblem<'_>,
    cur: &Iterate,
    in_working: &[bool],
    rows: &[usize],
    dst: &mut [f64],
) {
    let c = problem.compliance;
    let w = problem.line_length;
    for (x, &i) in dst.iter_mut().zip(rows) {
        *x = -cur.g[i];
    }
    for k in 0..problem.approach.len() {
        let fk = w[k] * cur.q[k];
        if in_working[k] || fk == 0.0 {
            continue;
        }
        match column(c, k) {
            Some(src) => {
                for (x, &i) in dst.iter_mut().zip(rows) {
                    *x += src[i] * fk;
                }
            }
            None => {
                for (x, &i) in dst.iter_mut().zip(rows) {
                    *x += c[(i, k)] * fk;
                }
            }
        }
    }
}

/// Column `j` of `c` as a slice when its rows are contiguous.
fn column(c: MatRef<'_, f64>, j: usize) -> Option<&[f64]> {
    c.col(j).try_as_col_major().map(|col| col.as_slice())
}

fn check_finite(name: &'static str, v: &[f64]) -> Result<(), LoadError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(LoadError::NonFinite { name, index, value: v[index] }),
        None => Ok(()),
    }
}

fn check_local(slice: usize, q: f64, u: f64, du_dq: f64) -> Result<(), LoadError> {
    if u.is_finite() && u >= 0.0 && du_dq.is_finite() && du_dq >= 0.0 {
        Ok(())
    } else {
        Err(LoadError::LocalTerm { slice, q, u, du_dq })
    }
}

/// Checks sizes, finiteness and signs; returns n.
fn validate(p: &LoadProblem<'_>) -> Result<usize, LoadError> {
    let n = p.approach.len();
    if p.line_length.len() != n {
        return Err(LoadError::DimensionMismatch {
            name: "line_length",
            expected: n,
            found: p.line_length.len(),
        });
    }
    let c = p.compliance;
    if c.nrows() != n || c.ncols() != n {
        let found = if c.nrows() != n { c.nrows() } else { c.ncols() };
        return Err(LoadError::DimensionMismatch { name: "compliance", expected: n, found });
    }
    check_finite("approach", p.approach)?;
    check_finite("line_length", p.line_length)?;
    if let Some(index) = p.line_length.iter().position(|&x| x <= 0.0) {
        return Err(LoadError::NonPositive {
            name: "line_length",
            index,
            value: p.line_length[index],
        });
    }
    for j in 0..n {
        let bad = match column(c, j) {
            Some(col) => col.iter().position(|v| !v.is_finite()),
            None => (0..n).position(|i| !c[(i, j)].is_finite()),
        };
        if let Some(i) = bad {
            return Err(LoadError::NonFiniteCompliance { row: i, col: j, value: c[(i, j)] });
        }
    }
    for i in 0..n {
        if c[(i, i)] <= 0.0 {
            return Err(LoadError::NonPositive {
                name: "compliance diagonal",
                index: i,
                value: c[(i, i)],
            });
        }
    }
    Ok(n)
}

/// g = C·(w∘q) + u_c(q) − d and du_c/dq at `it.q` (first n entries).
fn evaluate(p: &LoadProblem<'_>, it: &mut Iterate, force: &mut [f64]) -> Result<(), LoadError> {
    let n = p.approach.len();
    for ((f, &q), &w) in force[..n].iter_mut().zip(&it.q[..n]).zip(p.line_length) {
        *f = w * q;
    }
    compliance_times(p.compliance, &force[..n], &mut it.g[..n]);
    for i in 0..n {
        let q = it.q[i];
        let (u, du) = match p.local {
            None => (0.0, 0.0),
            Some(_) if q == 0.0 => (0.0, f64::INFINITY),
            Some(local) => {
                let (u, du) = local.eval(i, q);
                check_local(i, q, u, du)?;
                (u, du)
            }
        };
        it.g[i] += u - p.approach[i];
        it.du[i] = du;
    }
    Ok(())
}

/// g = C·f (m) for the compliance C (m/N) and the slice forces f (N), over the columns whose
/// force is not zero: an unloaded slice (q = 0) adds nothing (on the Table 1 sweep about a
/// third of the candidate slices are unloaded). Columns are taken four at a time,
/// g_i += (f_a·C_ia + f_b·C_ib) + (f_c·C_ic + f_d·C_id), so g is read and written once per four
/// columns. C is the validated n × n compliance (`validate`); a matrix whose columns are not
/// contiguous takes faer's product.
fn compliance_times(c: MatRef<'_, f64>, f: &[f64], g: &mut [f64]) {
    let n = g.len();
    let col = |j: usize| column(c, j).map(|v| &v[..n]);
    if n > 0 && col(0).is_none() {
        faer::linalg::matmul::matmul(
            ColMut::from_slice_mut(g),
            Accum::Replace,
            c,
            ColRef::from_slice(f),
            1.0,
            Par::Seq,
        );
        return;
    }
    g.fill(0.0);
    let mut quad: [(f64, &[f64]); 4] = [(0.0, &[]); 4];
    let mut k = 0;
    for (j, &fj) in f.iter().enumerate() {
        let Some(cj) = col(j).filter(|_| fj != 0.0) else { continue };
        quad[k] = (fj, cj);
        k += 1;
        if k == 4 {
            let [(fa, ca), (fb, cb), (fc, cc), (fd, cd)] = quad;
            for ((((gi, &a), &b), &c), &d) in g.iter_mut().zip(ca).zip(cb).zip(cc).zip(cd) {
                *gi += (fa * a + fb * b) + (fc * c + fd * d);
            }
            k = 0;
        }
    }
    for &(fa, ca) in &quad[..k] {
        for (gi, &x) in g.iter_mut().zip(ca) {
            *gi += fa * x;
        }
    }
}

/// Largest violation: |g| where q > 0, max(−g, 0) where q = 0 (m).
fn violation(it: &Iterate, n: usize) -> f64 {
    it.q[..n]
        .iter()
        .zip(&it.g[..n])
        .map(|(&q, &g)| if q > 0.0 { g.abs() } else { (-g).max(0.0) })
        .fold(0.0, f64::max)
}

/// Σ min(c_i·q_i, g_i)², m².
fn merit(it: &Iterate, scale: &[f64]) -> f64 {
    scale
        .iter()
        .zip(&it.q)
        .zip(&it.g)
        .map(|((&c, &q), &g)| {
            let phi = (c * q).min(g);
            phi * phi
        })
        .sum()
}

/// Total normal force F = Σ w_i·q_i, N (`q` in N/m, `line_length` w in m; extra entries of
/// the longer slice are ignored).
pub fn total_force(q: &[f64], line_length: &[f64]) -> f64 {
    q.iter().zip(line_length).map(|(&q, &w)| q * w).sum()
}

fn check_len(name: &'static str, expected: usize, v: &[f64]) -> Result<(), LoadError> {
    if v.len() == expected {
        Ok(())
    } else {
        Err(LoadError::DimensionMismatch { name, expected, found: v.len() })
    }
}

/// Torque of the contact forces on one gear (Eq. 13): M = Σ_i s_i·q_i·m_n·Δζ_i, N·m.
///
/// `q` load intensity per slice, N/m; `arm` moment arm s_i of the normal force about that
/// gear's axis, m (the base radius for contact in the plane of action; signed as produced by
/// [`crate::contact`]); `axial_length` m_n·Δζ_i, m (the axial extent of the slice, not the
/// contact-line length w_i). Errors: length mismatch or a non-finite entry.
pub fn mesh_torque(q: &[f64], arm: &[f64], axial_length: &[f64]) -> Result<f64, LoadError> {
    check_len("arm", q.len(), arm)?;
    check_len("axial_length", q.len(), axial_length)?;
    check_finite("load", q)?;
    check_finite("arm", arm)?;
    check_finite("axial_length", axial_length)?;
    Ok(q.iter().zip(arm).zip(axial_length).map(|((&q, &s), &l)| s * q * l).sum())
}

/// Damping torques (Eq. 14) `[M_D,p, M_D,g]`, N·m:
/// M_D,k = d_mesh·(φ̇_p·g_p + φ̇_g·g_g)·g_k·Σ_j (ζ_e,j − ζ_b,j).
///
/// `d_mesh` as in the paper, N·s/m (per unit of the dimensionless contact extent);
/// `omega_p`, `omega_g` hub angular velocities φ̇, rad/s, in the crate's common sense (so that
/// φ̇_p·g_p + φ̇_g·g_g is the rate of the transmission error, m/s); `base_radius_p`,
/// `base_radius_g` g_p, g_g, m; `zeta_extent` Σ_j (ζ_e,j − ζ_b,j) over the pairs in contact,
/// in units of m_n (dimensionless, ≥ 0). A positive result opposes a growing transmission
/// error when subtracted from the respective equation of motion, as the paper does.
pub fn damping_torques(
    d_mesh: f64,
    omega_p: f64,
    omega_g: f64,
    base_radius_p: f64,
    base_radius_g: f64,
    zeta_extent: f64,
) -> [f64; 2] {
    let rate = omega_p * base_radius_p + omega_g * base_radius_g;
    let f = d_mesh * rate * zeta_extent;
    [f * base_radius_p, f * base_radius_g]
}

/// Maximum Hertz pressure of each slice (Eq. 15), Pa, written into `out`:
/// p_i = sqrt(q_i / (π·C_E·ρ_i)), C_E = (1 − ν_p²)/E_p + (1 − ν_g²)/E_g from `contact`.
///
/// `q` N/m (≥ 0); `rho_p`, `rho_g` radii of curvature of the pinion and gear flank in the
/// normal section, m (> 0, one may be +∞). Unloaded slices get p = 0. Errors: length
/// mismatch, or the Hertz error of the first invalid slice.
pub fn hertz_pressures(
    contact: &LocalContact,
    q: &[f64],
    rho_p: &[f64],
    rho_g: &[f64],
    out: &mut [f64],
) -> Result<(), LoadError> {
    let n = q.len();
    check_len("rho_p", n, rho_p)?;
    check_len("rho_g", n, rho_g)?;
    if out.len() != n {
        return Err(LoadError::DimensionMismatch { name: "out", expected: n, found: out.len() });
    }
    for (slice, p) in out.iter_mut().enumerate() {
        let rho = hertz::reduced_radius(rho_p[slice], rho_g[slice])
            .map_err(|source| LoadError::Hertz { slice, source })?;
        *p = contact
            .max_pressure(q[slice], rho)
            .map_err(|source| LoadError::Hertz { slice, source })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gap product over the loaded columns is the dense product C·f (zero forces
    /// included) to round-off, for 0 … 15 loaded columns (every remainder after the groups of
    /// four), and a matrix without contiguous columns (a transposed view) takes the dense
    /// product.
    #[test]
    fn compliance_times_is_the_dense_product() {
        let n = 23;
        let c = Mat::<f64>::from_fn(n, n, |i, j| 1.0 / (1.0 + (i as f64 - 0.7 * j as f64).abs()));
        for loaded in 0..n {
            let f: Vec<f64> = (0..n)
                .map(|j| if j % 3 != 1 && j < loaded { 1.0 + j as f64 } else { 0.0 })
                .collect();
            let mut dense = vec![0.0; n];
            faer::linalg::matmul::matmul(
                ColMut::from_slice_mut(&mut dense),
                Accum::Replace,
                c.as_ref(),
                ColRef::from_slice(&f),
                1.0,
                Par::Seq,
            );
            let scale = dense.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            let mut g = vec![f64::NAN; n];
            compliance_times(c.as_ref(), &f, &mut g);
            let mut t = vec![f64::NAN; n];
            let ct = c.transpose().to_owned();
            compliance_times(ct.transpose(), &f, &mut t);
            for i in 0..n {
                assert!(
                    (g[i] - dense[i]).abs() <= 1e-14 * scale,
                    "{loaded}: {} vs {}",
                    g[i],
                    dense[i]
                );
                assert!(
                    (t[i] - dense[i]).abs() <= 1e-14 * scale,
                    "{loaded}: {} vs {}",
                    t[i],
                    dense[i]
                );
            }
        }
    }

    /// A bordered solve from the factors of a working set H gives the Newton step on H less
    /// three slices (one entering at zero load, two leaving with loads that move to the
    /// right-hand side) as a fresh factorisation of the smaller block does, to round-off; and
    /// declines a set that is not a subset of H.
    #[test]
    fn bordered_solve_equals_a_fresh_factorisation() {
        let n = 30;
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        // Positive definite with a skew part: a P-matrix, not symmetric.
        let b = Mat::from_fn(n, n, |_, _| rnd() - 0.5);
        let sk = Mat::from_fn(n, n, |_, _| rnd() - 0.5);
        let c = Mat::from_fn(n, n, |i, j| {
            let bbt: f64 = (0..n).map(|k| b[(i, k)] * b[(j, k)]).sum();
            let diag = if i == j { 0.2 } else { 0.0 };
            1e-9 * (bbt / n as f64 + 0.3 * (sk[(i, j)] - sk[(j, i)]) + diag)
        });
        let w: Vec<f64> = (0..n).map(|_| 0.1e-3 + 1e-3 * rnd()).collect();
        let d = vec![1e-5; n];
        let p = LoadProblem { approach: &d, line_length: &w, compliance: c.as_ref(), local: None };
        let mut s = LoadSolver::with_capacity(n);
        for i in 0..n {
            let loaded = i < 20 || (24..28).contains(&i);
            s.cur.q[i] = if loaded { 1e4 * (1.0 + rnd()) } else { 0.0 };
            s.cur.g[i] = 1e-6 * (rnd() - 0.5);
        }
        let set = |s: &mut LoadSolver, slices: &[usize]| {
            s.working.clear();
            s.working.extend_from_slice(slices);
            s.in_working[..n].fill(false);
            for &i in slices {
                s.in_working[i] = true;
            }
        };
        let h: Vec<usize> = (0..26).collect();
        set(&mut s, &h);
        s.fill_system(&p, false).unwrap();
        s.lu_solve(h.len(), 1, 1.0).unwrap();
        s.lu_working.clone_from(&h);
        s.lu_valid = true;
        let sub: Vec<usize> = h.iter().copied().filter(|&i| ![3, 21, 25].contains(&i)).collect();
        set(&mut s, &sub);
        assert!(s.bordered_solve(&p));
        let m = sub.len();
        let bordered: Vec<f64> = (0..m).map(|a| s.rhs[(a, 0)]).collect();
        s.fill_system(&p, false).unwrap();
        s.lu_solve(m, 1, 1.0).unwrap();
        let scale = bordered.iter().fold(0.0_f64, |x, v| x.max(v.abs()));
        for (a, x) in bordered.iter().enumerate() {
            let fresh = s.rhs[(a, 0)];
            assert!((x - fresh).abs() <= 1e-10 * scale, "slice {}: {x:e} vs {fresh:e}", sub[a]);
        }
        // Slice 27 is not in H: no bordered solve.
        let mut not_sub = sub.clone();
        not_sub.push(27);
        set(&mut s, &not_sub);
        assert!(!s.bordered_solve(&p));
    }
}
