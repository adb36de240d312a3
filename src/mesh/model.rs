//! [`MeshModel`]: one evaluation of the mesh (contact → compliance → load → torques).
//!
//! # Model, workspace, warm start
//! An evaluation has three inputs besides the state, kept apart:
//!
//! * [`MeshModel`] — everything fixed once the pair and the options are: pair, geometry,
//!   options, both gears' compliances (and their kernels at the slice positions), the local
//!   contact, the slice positions ζ_k, the flank separation of the modifications, the validity
//!   range and d_mesh. Immutable after construction and `Send + Sync` (a static assertion
//!   below), so one model is shared by `Arc` between threads, sweeps and the table build; the
//!   heavy parts are themselves behind `Arc`s. d_mesh stays a model field: the FMUs' tunable
//!   `d_mesh` makes a copy with [`MeshModel::with_d_mesh`] (a few hundred bytes plus the slice
//!   positions; nothing is rebuilt).
//! * [`MeshWorkspace`] — scratch memory: contacts, slice data, the compliance matrix,
//!   interpolation scratch, the load solver's buffers, and what the last evaluation leaves
//!   for the caller to read (per-slice detail, per-pair sums of the table build, work
//!   counters). One per caller (thread); it never changes a result.
//! * [`WarmStart`] — the loads of the loaded slices of the previous evaluation with their keys
//!   (flank side, tooth pair, slice): a small plain value (compare, copy, serialise), the only
//!   history an evaluation sees.
//!
//! [`MeshModel::evaluate`] takes `&self`, the workspace and the warm start, and its result is
//! a function of (model, state, warm start) alone; the warm start changes it only at the load
//! solver's tolerance. [`FullMesh`] bundles an `Arc<MeshModel>` with one workspace and one
//! warm start as a [`MeshTorques`]; the table fidelity ([`super::table::TableMesh`]) and the
//! shells' [`super::Mesh`] build on it. This module knows nothing of the table.
//!
//! # Slices
//! The face width is cut into `n_line` equal axial slices (centres ζ_k, width Δζ = b₀/n_line),
//! the same for every tooth pair, with `n_line = ceil(slices / ceil(ε_α + ε_β))`: the paper's
//! 200 slices "in total" over its (at most) two simultaneous contact lines give 100 per line.
//! Only slices with a positive overlap enter the load problem: with a non-negative influence
//! matrix a slice with an open gap stays open whatever the other loads are, so leaving it out
//! is exact.
//!
//! The loaded axial extent of Eq. 14 (and the loaded contact length, its multiple
//! m_n/cos θ) is resolved within the slices: each end of a loaded run of slices is placed
//! where the required approach less the global deformation changes sign between the run's
//! last slice and the next (the module `model::extent`), not on the slice boundary. It
//! converges at second order in the slice width and is continuous in the state (but where a
//! line's loaded part reaches the face), and so are the damping torques and their wrench.
//!
//! # Load problem (Eq. 12)
//! Slice i: required normal approach d_i = Δ_i·cos θ, line length w_i = m_n·Δζ/cos θ, normal-
//! section radii ρ_n = ρ_t/cos θ (θ the base helix angle, ρ_t the transverse radius of the
//! contact module), global compliance C_ij = α*_p(i, j) + α*_g(i, j) from each gear's FE data
//! at the flank coordinates of the two slices, including the coupling between different tooth
//! pairs through the gear bodies (tooth offsets: pinion a − b, gear b − a for observation pair
//! a and load pair b), and the Weber–Banaschek local term of both flanks with the FE's depth h.
//!
//! # Assembly of the compliance matrix
//! The slices sit at fixed axial positions ζ_k; only their profile coordinates move with the
//! mesh position. With interpolated compliance the model therefore keeps, per gear, the FE
//! grid already interpolated to every ζ_k ([`SliceInfluence`], built once at construction,
//! 3.8 MB per gear for Table 1 at 200 slices), which leaves per matrix entry one 4 × 4
//! contraction (on 256-bit vectors where the CPU has AVX2, the same operations in the same
//! order as the portable code, so the same matrix bit for bit). This assembles the matrix 2–3 times faster than the general interpolation
//! ([`FullMesh::use_slice_kernel`] switches between them; the benchmark reports both).
//!
//! # Force and moments
//! Beside the torques each loaded slice's 3D force and its moments about both gears' centres
//! are summed ([`super::forces`]: along the pinion helicoid's normal at P1), with the damping
//! of Eq. 14 distributed by the loaded extent per flank side; the whole wrench of the last
//! evaluation, z components included, stays in the workspace ([`MeshWorkspace::wrench`]).
//!
//! # Corner contacts
//! Where the contact lies on the convex corner between involute and tip relief the transverse
//! radius of curvature is 0 and Eqs. 10, 11 and 15 have no meaning. The corner turns the normal
//! by only 1.3–1.4° (Table 1) while the Hertzian strip (half width L ≈ 0.1 mm on a radius of
//! ≈ 15 mm) spans ≈ 0.8°, so physically the strip covers both sides of the corner. The corner
//! is therefore given the mean of the radii of the two adjacent surfaces at that radius (the
//! roll lengths on the involute and on the relief base circle); its global compliance and
//! overlap are those of the exact corner point.
//!
//! # Back flanks
//! When TE falls below −(backlash along the line of action) the back flanks are searched with
//! the same construction on the mirrored flanks. Their compliance is the driving flank's under
//! the 180° rotation about the radial line in the mid-face plane that maps a tooth onto itself
//! with the flanks exchanged: ζ → b₀ − ζ and tooth offsets reversed. Driving and back flanks
//! are not coupled to each other (they are never loaded together unless the teeth are crushed).
//!
//! # No allocation in the steady path
//! Every buffer (contacts, slice data, compliance matrix, interpolation scratch, load-solver
//! workspace) lives in the [`MeshWorkspace`], the warm start's loads in the [`WarmStart`];
//! both are reused. After the first calls have grown them to the sizes a trajectory needs,
//! evaluations do not touch the heap (`tests/mesh_alloc.rs` counts allocations). A new
//! workspace is sized for two contact lines per flank side.
//!
//! # Validity range
//! Every evaluation (full or table, outputs or Jacobian) first checks the state against the
//! pair's [`ValidityRange`] (`super::validity`): |φp| beyond 2⁵³ pinion pitches is
//! [`MeshError::AngleOutOfRange`], TE outside [−j_t − 0.2·m_n, 0.2·m_n] is
//! [`MeshError::OutOfRange`] without a load-solver cause — before any contact search, so that
//! teeth that passed through each other are never reported "separated". Inside the range the
//! outputs are bit for bit those without the check.
//!
//! # Warm start
//! The loads of the previous call are kept with their keys (flank side, tooth pair, slice) in
//! the caller's [`WarmStart`]; a new call starts from them (zero for a slice not listed),
//! which makes the active set of a nearby state exact after one Newton step in dynamic use.
//! Keys and loads are in the contact search's ascending (side, pair, slice) order, so one
//! merge walk finds the matches. An unloaded state clears the warm start; a failed solve
//! leaves it as it was. A warm start read from outside (a restored state) is checked
//! ([`WarmStart::check`]: at most [`MAX_WARM_LOADS`] entries, keys ascending, loads finite
//! and > 0).
//!
//! # Cold start
//! Without a warm start (the first call, after an unloaded state, a full-fidelity unit's
//! communication step, which restarts cold, the first TE node of each table row) the load solver
//! would start from q = 0 and find the active set in many Newton steps. With at least
//! 64 slices in contact the evaluation first solves a coarse problem on every fourth slice of
//! each contact line (slice keys k ≡ 2 mod 4): the same approaches and Hertz radii, the rows
//! and columns of the assembled compliance matrix of those slices, and four times their line
//! length (each stands for four slices). That problem has a sixteenth of the matrix and a
//! 64th of the factorisation work. Its loads, interpolated linearly in k along each line
//! (held at the last coarse value beyond it), start the fine
//! solve, whose convergence test is unchanged: the result is the same solution, to the load
//! solver's tolerance, as from q = 0. Measured on the Table 1 benchmark states at 200
//! slices: 2.5 instead of 6.8 factorisations per cold solve, a cold evaluation about 1.6×
//! faster. When the coarse solve fails or loads nothing, the fine solve starts from q = 0
//! as before.

mod extent;
mod jacobian;

pub(crate) use jacobian::damping_rows;

use std::sync::Arc;

use faer::Mat;

use super::forces::{ForceFrame, MeshWrench};
use super::friction::{
    FrictionConst, FrictionSums, add_friction_jacobian, set_efficiency, slice_friction,
};
use super::pose::{RelativePose, approach_rate, to_housing};
use super::validity::ValidityRange;
use super::{MeshError, MeshOptions, MeshOutputs, MeshState, MeshTorques, SliceDetail};
use crate::compliance::data::RootStressData;
use crate::compliance::fitted::FittedInfluence;
use crate::compliance::hertz::LocalContact;
use crate::compliance::interpolated::{
    InterpolatedInfluence, MatrixWorkspace, SliceInfluence, SliceWeights,
};
use crate::compliance::root_stress::{LoadedSlice, RootStressWorkspace, SliceStress, root_stress};
use crate::compliance::{Compliance, FlankCoord};

use crate::contact::{ContactPoint, ContactSolver, FlankSide, SliceTwist};
use crate::error::ParamError;
use crate::geometry::{PairGeometry, SegmentKind};
use crate::load::{
    HertzLocal, LoadProblem, LoadSettings, LoadSolver, LocalTerm as _, Start, damping_torques,
};
use crate::modifications::Separation;
use crate::params::GearPair;

/// Load-solver tolerances of the mesh model: gaps to 1e-15 m + 1e-12·max|d| (TE is of
/// order 1e-5 m, so the torque is converged to about 1e-11 relative; Newton's quadratic
/// convergence makes the tight tolerance cost at most one more iteration).
const LOAD_SETTINGS: LoadSettings =
    LoadSettings { abs_tol: 1e-15, rel_tol: 1e-12, max_iterations: 100 };

/// Tolerances of the coarse pre-solve of a cold start: only its active set and the size of its
/// loads matter (the fine solve converges to [`LOAD_SETTINGS`] from them).
const COARSE_SETTINGS: LoadSettings =
    LoadSettings { abs_tol: 1e-13, rel_tol: 1e-6, max_iterations: 50 };

/// The global compliance of one gear in the representation chosen by
/// [`MeshOptions::compliance`].
#[derive(Debug, Clone)]
pub enum GearCompliance {
    /// Interpolated FE influence grid.
    Interpolated(Arc<InterpolatedInfluence>),
    /// Fitted influence function (Eqs. 5–8), neighbours interpolated.
    Fitted(Arc<FittedInfluence>),
    /// A Winkler foundation: each slice deflects by `compliance`·q under its own load
    /// intensity q only (no spreading along the line, no neighbour teeth). A reference model
    /// (the uniform-stiffness-per-length idealisation behind ISO 6336's c′), not a tooth.
    Winkler {
        /// Deflection per load intensity, m/(N/m) = m²/N.
        compliance: f64,
        /// Depth h of the local term, m.
        depth_h: f64,
    },
}

impl GearCompliance {
    /// Depth h of Vedmar's division, m.
    pub fn depth(&self) -> f64 {
        match self {
            GearCompliance::Interpolated(c) => c.depth(),
            GearCompliance::Fitted(c) => c.depth(),
            GearCompliance::Winkler { depth_h, .. } => *depth_h,
        }
    }

    fn max_tooth_offset(&self) -> i32 {
        match self {
            GearCompliance::Interpolated(c) => c.max_tooth_offset(),
            GearCompliance::Fitted(c) => c.max_tooth_offset(),
            GearCompliance::Winkler { .. } => 0,
        }
    }

    /// Adds α*(obs_i, load_j, offset) to `out[(r0 + i, c0 + j)]`; `same` is true when obs and
    /// load are the same slices, `w` the contact-line length of a slice (m).
    #[allow(clippy::too_many_arguments)]
    fn add_block(
        &self,
        obs: &[FlankCoord],
        load: &[FlankCoord],
        offset: i32,
        same: bool,
        w: f64,
        ws: &mut MatrixWorkspace,
        out: &mut Mat<f64>,
        r0: usize,
        c0: usize,
    ) {
        if offset.abs() > self.max_tooth_offset() {
            return;
        }
        match self {
            GearCompliance::Winkler { compliance, .. } => {
                if same {
                    for i in 0..obs.len() {
                        out[(r0 + i, c0 + i)] += compliance / w;
                    }
                }
            }
            GearCompliance::Interpolated(c) => {
                c.add_matrix(obs, load, offset, ws, |i, j, v| out[(r0 + i, c0 + j)] += v);
            }
            GearCompliance::Fitted(c) => {
                for (i, &o) in obs.iter().enumerate() {
                    for (j, &l) in load.iter().enumerate() {
                        out[(r0 + i, c0 + j)] += c.alpha(o, l, offset);
                    }
                }
            }
        }
    }
}

/// One loaded-candidate slice of the current evaluation.
#[derive(Debug, Clone, Copy)]
struct Slice {
    contact: ContactPoint,
    /// Index of the axial slice (0 … n_line − 1).
    k: usize,
    /// Overlap (m, separation subtracted) of the same line's contact at slices k − 1 and
    /// k + 1, NaN where there is none.
    nb: [f64; 2],
}

/// The mesh model of a gear pair: everything that is fixed once the pair and the options are
/// (see the module docs of [`crate::mesh`] and of this file). Immutable, `Send + Sync`: share
/// it by [`Arc`] between threads and evaluate it with [`MeshModel::evaluate`], each caller with
/// its own [`MeshWorkspace`] and [`WarmStart`]. The heavy parts (geometry, FE compliances,
/// slice kernels, separation) are behind `Arc`s, so a clone (e.g. [`MeshModel::with_d_mesh`])
/// copies a few hundred bytes plus the slice positions.
#[derive(Clone)]
pub struct MeshModel {
    pair: GearPair,
    geo: Arc<PairGeometry>,
    options: MeshOptions,
    comp_p: GearCompliance,
    comp_g: GearCompliance,
    /// The interpolated compliances specialised to this model's slices (pinion, gear), when
    /// the compliance is [`GearCompliance::Interpolated`] on a grid that allows it.
    slice_comp: Option<Arc<[SliceInfluence; 2]>>,
    /// The root-stress influence of both gears at this model's slices, when the model was
    /// built from FE data ([`MeshModel::with_root_stress`]).
    root_stress: Option<Arc<[SliceStress; 2]>>,
    /// The root-stress data the kernel above was prepared from, kept for
    /// [`MeshModel::with_slices`].
    root_stress_data: Option<Arc<RootStressData>>,
    local: LocalContact,
    /// Mesh damping d_mesh of Eq. 14, N·s/m (a model field: [`MeshModel::with_d_mesh`]).
    d_mesh: f64,
    /// The validity range of the state (`super::validity`).
    validity: ValidityRange,
    zetas: Vec<f64>,
    /// The helix's turn of the teeth at each of `zetas` (for the contact search).
    twists: Vec<SliceTwist>,
    dzeta: f64,
    cos_theta: f64,
    /// Flank modifications and deviations ([`crate::modifications`]); `None` without any.
    separation: Option<Arc<Separation>>,
    /// The frame of the 3D force and moments ([`super::forces`]).
    frame: ForceFrame,
    /// The friction's constants ([`super::friction`]); `None` without friction.
    friction: Option<FrictionConst>,
}

// The model is shared between threads by `Arc` (Python, sweeps, the table build).
const _: () = {
    const fn shareable<T: Send + Sync>() {}
    shareable::<MeshModel>();
};

/// The scratch memory of full evaluations of one [`MeshModel`]: contacts, slice data, the
/// compliance matrix, interpolation scratch and the load solver's buffers, plus what the last
/// evaluation leaves for the caller (per-slice detail, per-pair sums, work counters). Allocated
/// once ([`MeshWorkspace::new`]), grown to the sizes a trajectory needs, then reused: the
/// steady path does not touch the heap. Its contents never change a result: only the model,
/// the state and the [`WarmStart`] do.
#[derive(Debug)]
pub struct MeshWorkspace {
    contacts: Vec<ContactPoint>,
    slices: Vec<Slice>,
    approach: Vec<f64>,
    line_length: Vec<f64>,
    rho: Vec<f64>,
    obs_p: Vec<FlankCoord>,
    obs_g: Vec<FlankCoord>,
    sw_p: Vec<SliceWeights>,
    sw_g: Vec<SliceWeights>,
    partial: Vec<f64>,
    cmat: Mat<f64>,
    start: Vec<f64>,
    solver: LoadSolver,
    /// The coarse pre-solve of a cold start ("Cold start" in the module docs).
    coarse: CoarseStart,
    detail: Vec<SliceDetail>,
    runs: Vec<(usize, usize)>,
    ws: MatrixWorkspace,
    stats: SolveStats,
    /// Keep the per-slice detail of the last evaluation ([`MeshOptions::detail`]).
    keep_detail: bool,
    /// Assemble with the ζ-precomputed kernel when the model has one.
    slice_kernel: bool,
    /// Start a cold solve from the coarse pre-solve (module docs, "Cold start").
    coarse_start: bool,
    /// Record the driving-flank outputs per tooth pair in `pair_sums` (table build).
    record_pairs: bool,
    /// Per loaded driving-flank tooth pair of the last full evaluation (when `record_pairs`).
    pair_sums: Vec<PairSum>,
    /// The whole wrench (z components included) of the last full evaluation.
    wrench: MeshWrench,
    /// ∫ζ·dζ over the loaded parts of the slices of the last full evaluation, m_n².
    first_moment: f64,
    /// Scratch memory of the root stress.
    root_stress: RootStressWorkspace,
    /// Loaded axial extent of each slice to either side of its centre (units of m_n).
    widths: Vec<[f64; 2]>,
    /// The overlap less the separation of each of `contacts`, m.
    overlaps: Vec<f64>,
}

impl MeshWorkspace {
    /// A workspace for `model`, its buffers sized for two contact lines per flank side; the
    /// detail as [`MeshOptions::detail`], the slice kernel on.
    pub fn new(model: &MeshModel) -> Self {
        let n_line = model.zetas.len();
        let cap = 4 * n_line;
        Self {
            contacts: Vec::with_capacity(cap),
            slices: Vec::with_capacity(cap),
            approach: Vec::with_capacity(cap),
            line_length: Vec::with_capacity(cap),
            rho: Vec::with_capacity(cap),
            obs_p: Vec::with_capacity(cap),
            obs_g: Vec::with_capacity(cap),
            sw_p: Vec::with_capacity(cap),
            sw_g: Vec::with_capacity(cap),
            partial: Vec::new(),
            cmat: Mat::zeros(0, 0),
            start: Vec::with_capacity(cap),
            solver: LoadSolver::with_settings(2 * n_line, LOAD_SETTINGS),
            coarse: CoarseStart::new(cap / COARSE_STRIDE + 8),
            detail: Vec::with_capacity(cap),
            runs: Vec::with_capacity(8),
            widths: Vec::with_capacity(cap),
            overlaps: Vec::with_capacity(cap),
            ws: MatrixWorkspace::default(),
            stats: SolveStats::default(),
            keep_detail: model.options.detail,
            slice_kernel: true,
            coarse_start: true,
            record_pairs: false,
            pair_sums: Vec::with_capacity(8),
            wrench: MeshWrench::default(),
            first_moment: 0.0,
            root_stress: model
                .root_stress
                .as_deref()
                .map_or_else(RootStressWorkspace::default, |k| {
                    RootStressWorkspace::with_capacity(k, 8)
                }),
        }
    }

    /// The force and moments of the last full evaluation with their z components (the
    /// reported outputs carry x and y of the moments; see [`super::forces`]).
    pub fn wrench(&self) -> &MeshWrench {
        &self.wrench
    }

    /// First axial moment Z₁ = ∫ζ·dζ over the loaded parts of the slices of the last full
    /// evaluation (`extent`), units of m_n² (the table carries it beside the extent for the
    /// damping's moments).
    pub fn first_moment(&self) -> f64 {
        self.first_moment
    }

    /// Per-slice detail of the last evaluation (empty unless the detail is on).
    pub fn slices(&self) -> &[SliceDetail] {
        &self.detail
    }

    /// True while the per-slice detail is kept.
    pub fn keep_detail(&self) -> bool {
        self.keep_detail
    }

    /// Turns the per-slice detail on or off (off also clears it).
    pub fn set_detail(&mut self, on: bool) {
        self.keep_detail = on;
        if !on {
            self.detail.clear();
        }
    }

    /// Work counters of the evaluations with this workspace so far.
    pub fn stats(&self) -> SolveStats {
        self.stats
    }

    /// Sets the work counters to zero.
    pub fn reset_stats(&mut self) {
        self.stats = SolveStats::default();
    }
}

/// Most entries of a [`WarmStart`]: the loaded slices of any model (at most 4000 slices over
/// the simultaneous contact lines, at most twice as many pairs in contact as lines, on either
/// flank side) stay below 2¹⁶. A warm start read from outside is refused beyond it.
pub const MAX_WARM_LOADS: usize = 65_536;

/// The load of one slice kept for the next evaluation: the slice's key (flank side, absolute
/// tooth pair, axial slice index) and its load intensity q (N/m, > 0).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WarmLoad {
    /// True on the back flanks.
    pub back: bool,
    /// Absolute tooth-pair number ([`crate::contact::ContactPoint::pair`]).
    pub pair: i64,
    /// Axial slice index, 0 … slices per line − 1.
    pub slice: u32,
    /// Load intensity q, N/m.
    pub q: f64,
}

impl WarmLoad {
    fn key(&self) -> (bool, i64, u32) {
        (self.back, self.pair, self.slice)
    }
}

/// The warm start of the load solver: the loaded slices of the previous evaluation with their
/// loads, in ascending (side, pair, slice) order. A plain value (compare, copy, serialise it);
/// the next full evaluation starts its Newton iteration from these loads (zero for slices not
/// listed). Empty: a cold start. The result of an evaluation is a function of (model, state,
/// warm start) alone; the warm start changes it only at the solver tolerance.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct WarmStart {
    loads: Vec<WarmLoad>,
}

impl WarmStart {
    /// A cold start (no loads).
    pub fn new() -> Self {
        Self::default()
    }

    /// The kept loads, in ascending (side, pair, slice) order.
    pub fn loads(&self) -> &[WarmLoad] {
        &self.loads
    }

    /// True for a cold start.
    pub fn is_empty(&self) -> bool {
        self.loads.is_empty()
    }

    /// Forgets the loads (a cold start next), keeping the memory.
    pub fn clear(&mut self) {
        self.loads.clear();
    }

    /// Makes `self` equal to `other`, reusing the memory (no allocation once grown).
    pub fn copy_from(&mut self, other: &WarmStart) {
        self.loads.clear();
        self.loads.extend_from_slice(&other.loads);
    }

    /// A warm start from loads given from outside (a deserialised state), checked: at most
    /// [`MAX_WARM_LOADS`] entries (checked before anything is reserved by the caller), keys
    /// strictly ascending, |pair| ≤ 2⁵³, loads finite and > 0. The error names the value and
    /// its limit.
    pub fn from_loads(loads: Vec<WarmLoad>) -> Result<Self, ParamError> {
        let w = Self { loads };
        w.check()?;
        Ok(w)
    }

    /// Checks the contents as [`WarmStart::from_loads`] does.
    pub fn check(&self) -> Result<(), ParamError> {
        if self.loads.len() > MAX_WARM_LOADS {
            return Err(ParamError::new(
                "warm start length",
                self.loads.len() as f64,
                format!("<= {MAX_WARM_LOADS} loaded slices"),
            ));
        }
        for (i, w) in self.loads.iter().enumerate() {
            if !(w.q.is_finite() && w.q > 0.0) {
                return Err(ParamError::new("warm start load", w.q, "finite and > 0 (N/m)"));
            }
            if w.pair.unsigned_abs() > 1 << 53 {
                return Err(ParamError::new("warm start pair", w.pair as f64, "|pair| <= 2^53"));
            }
            if i > 0 && self.loads[i - 1].key() >= w.key() {
                return Err(ParamError::new(
                    "warm start order",
                    i as f64,
                    "keys (side, pair, slice) strictly ascending",
                ));
            }
        }
        Ok(())
    }

    /// Bytes of the binary form: u32 count, then per load u8 side, i64 pair, u32 slice,
    /// f64 q (little endian).
    pub fn to_bytes(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&(self.loads.len() as u32).to_le_bytes());
        for w in &self.loads {
            out.push(u8::from(w.back));
            out.extend_from_slice(&w.pair.to_le_bytes());
            out.extend_from_slice(&w.slice.to_le_bytes());
            out.extend_from_slice(&w.q.to_le_bytes());
        }
    }

    /// Reads the binary form of [`WarmStart::to_bytes`] from the whole of `b`, checked as
    /// [`WarmStart::from_loads`] (the count against [`MAX_WARM_LOADS`] and the length of `b`
    /// before anything is reserved).
    pub fn from_bytes(b: &[u8]) -> Result<Self, String> {
        const ENTRY: usize = 1 + 8 + 4 + 8;
        let n = b.get(..4).ok_or("warm start truncated: no count")?;
        let n = u32::from_le_bytes(n.try_into().expect("4 bytes")) as usize;
        if n > MAX_WARM_LOADS {
            return Err(format!("warm start of {n} loads: at most {MAX_WARM_LOADS}"));
        }
        if b.len() != 4 + n * ENTRY {
            return Err(format!(
                "warm start of {n} loads takes {} bytes, given {}",
                4 + n * ENTRY,
                b.len()
            ));
        }
        let mut loads = Vec::with_capacity(n);
        for e in b[4..].chunks_exact(ENTRY) {
            let back = match e[0] {
                0 => false,
                1 => true,
                x => return Err(format!("warm start: side byte {x} (0 or 1)")),
            };
            loads.push(WarmLoad {
                back,
                pair: i64::from_le_bytes(e[1..9].try_into().expect("8 bytes")),
                slice: u32::from_le_bytes(e[9..13].try_into().expect("4 bytes")),
                q: f64::from_le_bytes(e[13..21].try_into().expect("8 bytes")),
            });
        }
        Self::from_loads(loads).map_err(|e| e.to_string())
    }
}

/// The driving-flank outputs of one tooth pair of a full evaluation (for the per-pair table
/// of [`super::table`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PairSum {
    /// Absolute tooth-pair number.
    pub pair: i64,
    /// M_F,p, M_F,g (N·m), F_n (N), loaded axial extent (units of m_n), p_max² (Pa²), the
    /// root stresses of the pair's pinion and gear teeth (Pa).
    pub values: [f64; 7],
    /// The pair's elastic force on the pinion (x, y, z, N) and its tilting moment about the
    /// pinion centre (x, y, N·m), [`super::forces`].
    pub wrench: [f64; 5],
    /// ∫ζ·dζ over the loaded parts of the pair's slices, m_n².
    pub first_moment: f64,
    /// True when a loaded contact of the pair lies on a tip.
    pub tip: bool,
}

/// Work counters of the full evaluations with a [`MeshWorkspace`] (since its creation or the last
/// [`MeshWorkspace::reset_stats`]): what the load solves cost.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolveStats {
    /// Load solves (full evaluations with at least one overlapping slice).
    pub solves: usize,
    /// Newton iterations, summed.
    pub iterations: usize,
    /// Matrix factorisations, summed.
    pub factorizations: usize,
    /// Gap-function evaluations (matrix–vector products), summed.
    pub evaluations: usize,
    /// Candidate slices (unknowns of the load problem), summed.
    pub slices: usize,
}

impl SolveStats {
    fn add(&mut self, r: &crate::load::LoadReport, n: usize) {
        self.solves += 1;
        self.iterations += r.iterations;
        self.factorizations += r.factorizations;
        self.evaluations += r.evaluations;
        self.slices += n;
    }
}

impl std::fmt::Debug for MeshModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshModel")
            .field("options", &self.options)
            .field("slices_per_line", &self.zetas.len())
            .finish_non_exhaustive()
    }
}

/// Total number of slices [`MeshOptions::slices`]: 10 (a coarse line of 5 slices) … 4000
/// (the dense load problem grows with its square).
pub const SLICES: crate::params::Bounds<i64> = crate::params::Bounds::new(10, 4000, "");

/// Checks the options the model itself uses ([`SLICES`]); the table's size is the table's
/// own check (`mesh::table::check_table_size`), made beside this one before any compliance
/// data are computed.
pub(crate) fn check_options(o: &MeshOptions) -> Result<(), ParamError> {
    SLICES.check_int("slices", i64::try_from(o.slices).unwrap_or(i64::MAX))?;
    o.friction.check()
}

impl MeshModel {
    /// Builds the model of `pair` with `options` and the given global compliances of pinion and
    /// gear (both must use the same depth h). Validates the pair (geometry) and the options the
    /// model uses. The fidelity and the table options are not the model's: a table is built
    /// over a model by [`super::Mesh`] ([`super::table::TableMesh`]).
    pub fn with_compliance(
        pair: &GearPair,
        options: MeshOptions,
        pinion: GearCompliance,
        gear: GearCompliance,
    ) -> Result<Self, MeshError> {
        check_options(&options)?;
        let geo = PairGeometry::new(pair)?;
        let (hp, hg) = (pinion.depth(), gear.depth());
        let local = LocalContact::new(&pair.material_p, &pair.material_g, hp, hg)
            .map_err(|e| MeshError::Compliance(format!("local contact: {e}")))?;
        let (zetas, dzeta) = slice_centres(&geo, options.slices);
        let twists = slice_twists(&geo, &zetas);
        let slice_comp = slice_kernel(&pinion, &gear, &zetas);
        let cos_theta = geo.base_helix_angle.cos();
        let validity = ValidityRange::of(&geo);
        let separation = Separation::new(&geo).map(Arc::new);
        let frame = ForceFrame::new(&geo);
        let friction = options.friction.is_on().then(|| FrictionConst::new(&geo, options.friction));
        Ok(Self {
            pair: pair.clone(),
            geo: Arc::new(geo),
            options,
            comp_p: pinion,
            comp_g: gear,
            slice_comp,
            root_stress: None,
            root_stress_data: None,
            local,
            d_mesh: pair.d_mesh_n_s_per_m,
            validity,
            zetas,
            twists,
            dzeta,
            cos_theta,
            separation,
            frame,
            friction,
        })
    }

    /// The same model with the root-stress influence `data` (of this pair's FE run) prepared
    /// for its slices, so that evaluations report the tooth-root stress
    /// ([`MeshOutputs::root_stress_p`]). Errors: data of another pair or invalid grids.
    pub fn with_root_stress(self, data: &RootStressData) -> Result<Self, MeshError> {
        self.with_shared_root_stress(&Arc::new(data.clone()))
    }

    /// [`MeshModel::with_root_stress`] with data shared by `Arc` (kept, not copied).
    pub(crate) fn with_shared_root_stress(
        mut self,
        data: &Arc<RootStressData>,
    ) -> Result<Self, MeshError> {
        if data.key != crate::compliance::data::ComplianceKey::of(&self.pair) {
            return Err(MeshError::Compliance(
                "the root-stress data belong to another gear pair".into(),
            ));
        }
        let one = |g| {
            SliceStress::new(g, &self.zetas)
                .map_err(|e| MeshError::Compliance(format!("root stress: {e}")))
        };
        self.root_stress = Some(Arc::new([one(&data.pinion)?, one(&data.gear)?]));
        self.root_stress_data = Some(data.clone());
        Ok(self)
    }

    /// The same model at `slices` total slices ([`MeshOptions::slices`]): the slice centres,
    /// the slice kernels and the root-stress kernel prepared again for them, everything else
    /// shared. The table is built from such a model at [`MeshOptions::table_slices`]. A clone
    /// when `slices` is the model's own. Errors: `slices` outside [`SLICES`].
    pub fn with_slices(&self, slices: usize) -> Result<Self, MeshError> {
        if slices == self.options.slices {
            return Ok(self.clone());
        }
        let options = MeshOptions { slices, ..self.options };
        check_options(&options)?;
        let (zetas, dzeta) = slice_centres(&self.geo, slices);
        let twists = slice_twists(&self.geo, &zetas);
        let slice_comp = slice_kernel(&self.comp_p, &self.comp_g, &zetas);
        let model = Self {
            options,
            zetas,
            twists,
            dzeta,
            slice_comp,
            root_stress: None,
            root_stress_data: None,
            ..self.clone()
        };
        match &self.root_stress_data {
            Some(data) => model.with_shared_root_stress(data),
            None => Ok(model),
        }
    }

    /// True when evaluations report the tooth-root stress ([`MeshModel::with_root_stress`]).
    pub fn has_root_stress(&self) -> bool {
        self.root_stress.is_some()
    }

    /// The same model with another separation (the table build uses the periodic part of the
    /// modifications).
    pub(crate) fn with_separation(&self, separation: Option<Arc<Separation>>) -> Self {
        Self { separation, ..self.clone() }
    }

    /// Flank modifications and deviations as a separation; `None` without any.
    pub(crate) fn separation(&self) -> Option<&Arc<Separation>> {
        self.separation.as_ref()
    }

    /// The gear-pair parameters.
    pub fn pair(&self) -> &GearPair {
        &self.pair
    }

    /// The validated geometry.
    pub fn geometry(&self) -> &PairGeometry {
        &self.geo
    }

    /// The options the model was built with.
    pub fn options(&self) -> &MeshOptions {
        &self.options
    }

    /// Axial slices per contact line.
    pub fn slices_per_line(&self) -> usize {
        self.zetas.len()
    }

    /// True when the ζ-precomputed compliance kernel ([`SliceInfluence`]) exists for this
    /// model (interpolated compliance on a grid with at least four nodes per axis).
    pub fn has_slice_kernel(&self) -> bool {
        self.slice_comp.is_some()
    }

    /// The range of states in which the model holds (`super::validity`); evaluations outside
    /// it are errors.
    pub fn validity(&self) -> &ValidityRange {
        &self.validity
    }

    /// Checks `state` against the validity range: a NaN or infinite component
    /// ([`MeshError::NonFinite`]), |φp| beyond the exact range ([`MeshError::AngleOutOfRange`])
    /// or TE outside [TE_min, TE_max] ([`MeshError::OutOfRange`], no load-solver cause).
    #[inline]
    pub fn check_state(&self, state: &MeshState) -> Result<(), MeshError> {
        self.check_state_te(state).map(|_| ())
    }

    /// [`Self::check_state`], returning the state's TE (m) on success.
    #[inline(always)]
    pub fn check_state_te(&self, state: &MeshState) -> Result<f64, MeshError> {
        check_state(state)?;
        self.check_angle(state.phi_p)?;
        let te = self.geo.transmission_error(state.phi_p, state.phi_g);
        self.check_te(te, state.phi_p)?;
        Ok(te)
    }

    #[inline]
    fn check_angle(&self, phi_p: f64) -> Result<(), MeshError> {
        if self.validity.contains_phi_p(phi_p) {
            return Ok(());
        }
        self.angle_error(phi_p)
    }

    #[cold]
    fn angle_error(&self, phi_p: f64) -> Result<(), MeshError> {
        Err(MeshError::AngleOutOfRange {
            name: "phi_p",
            value: phi_p,
            bound: self.validity.phi_p_max,
        })
    }

    /// TE (m) of a state at pinion angle `phi_p` (rad, within the exact range) against the
    /// validity range.
    #[inline]
    fn check_te(&self, te: f64, phi_p: f64) -> Result<(), MeshError> {
        if self.validity.contains_te(te) {
            return Ok(());
        }
        self.te_error(te, phi_p)
    }

    #[cold]
    fn te_error(&self, te: f64, phi_p: f64) -> Result<(), MeshError> {
        let v = &self.validity;
        let phase = crate::numeric::Pitch::of_teeth(self.geo.pinion.z).reduce(phi_p).0;
        Err(MeshError::OutOfRange {
            te,
            phase,
            range: (v.te_min, v.te_max),
            max_overlap: v.required_overlap(te),
            module: self.pair.normal_module_m,
            cause: None,
        })
    }

    /// Mesh damping d_mesh of Eq. 14, N·s/m.
    pub fn d_mesh(&self) -> f64 {
        self.d_mesh
    }

    /// The same model with d_mesh (N·s/m, in [0, [`crate::params::D_MESH_MAX_N_S_PER_M`]]):
    /// a cheap copy (the heavy parts are shared), for the FMUs' tunable `d_mesh`.
    pub fn with_d_mesh(&self, d_mesh: f64) -> Result<Self, MeshError> {
        crate::params::check_d_mesh(d_mesh)?;
        Ok(Self { d_mesh, ..self.clone() })
    }

    /// Evaluates the mesh at `state` by the full contact search and load solve (the state
    /// checked against the validity range as by [`Self::check_state`]), with the scratch
    /// memory `ws` and the warm start `warm`, which it replaces by this evaluation's loads
    /// (cleared on an unloaded state; left as it was on an error). The outputs depend on
    /// (model, state, `warm`) only.
    pub fn evaluate(
        &self,
        state: &MeshState,
        ws: &mut MeshWorkspace,
        warm: &mut WarmStart,
    ) -> Result<MeshOutputs, MeshError> {
        check_state(state)?;
        self.check_angle(state.phi_p)?;
        let geo = self.geo.clone();
        let cs = ContactSolver::new(&geo);
        let red = cs.reduce(state.phi_p, state.phi_g);
        let te = red.te;
        self.check_te(te, state.phi_p)?;
        // The gear body relative to the pinion's (`super::pose`); `None`: rigid bearings.
        let posed = if state.bodies_at_rest() {
            None
        } else {
            super::pose::check(&geo, state)?;
            let a = geo.center_distance;
            Some((
                RelativePose::new(&state.pose_p, &state.pose_g, a),
                RelativePose::new(&state.rate_p, &state.rate_g, a),
            ))
        };
        let reach = posed.map_or(0.0, |(p, _)| p.overlap_reach(&geo));
        ws.slices.clear();
        let nl = self.zetas.len();
        // Drive flanks only when TE > 0 and back flanks only below −backlash: the actual
        // flanks lie inside the full involutes, whose overlap is TE (resp. −TE − backlash).
        // Flank modifications (material added) can let the driving flanks touch below TE = 0.
        // A body pose moves every overlap by at most `reach`.
        let tol = 1e-12 - self.separation.as_ref().map_or(0.0, |s| s.min_bound()) + reach;
        for (side, active) in [
            (FlankSide::Drive, te > -tol),
            (FlankSide::Back, te < -geo.backlash_te + 1e-12 + reach),
        ] {
            if !active {
                continue;
            }
            let pose = posed.as_ref().map(|(p, _)| p);
            let slices = (&self.zetas[..], &self.twists[..]);
            cs.contacts_posed(side, state.phi_p, state.phi_g, slices, pose, &mut ws.contacts);
            // The overlaps less the separation, once per contact: a candidate's neighbours'
            // are read for its loaded extent (`extent`).
            ws.overlaps.clear();
            ws.overlaps.extend(ws.contacts.iter().map(|c| match &self.separation {
                Some(sep) => c.overlap_m - sep.of_contact(c),
                None => c.overlap_m,
            }));
            for (j, (c, &overlap)) in ws.contacts.iter().zip(&ws.overlaps).enumerate() {
                if overlap > 0.0 {
                    let k = self.slice_index(c.zeta);
                    // Contacts come by pair, then slice: a neighbour is next in the list.
                    let nb_at = |jj: Option<usize>, kk: Option<usize>| match (jj, kk) {
                        (Some(jj), Some(kk)) => ws
                            .contacts
                            .get(jj)
                            .filter(|n| n.pair == c.pair && self.slice_index(n.zeta) == kk)
                            .map_or(f64::NAN, |_| ws.overlaps[jj]),
                        _ => f64::NAN,
                    };
                    let nb = [
                        nb_at(j.checked_sub(1), k.checked_sub(1)),
                        nb_at(Some(j + 1), (k + 1 < nl).then_some(k + 1)),
                    ];
                    let contact = ContactPoint { overlap_m: overlap, ..*c };
                    ws.slices.push(Slice { contact, k, nb });
                }
            }
        }
        let n = ws.slices.len();
        let mut out = MeshOutputs { te, separated: true, ..MeshOutputs::default() };
        if ws.keep_detail {
            ws.detail.clear();
        }
        ws.pair_sums.clear();
        ws.wrench = MeshWrench::default();
        ws.first_moment = 0.0;
        if n == 0 {
            warm.loads.clear();
            return Ok(out);
        }

        // Slice data.
        let kernel = if ws.slice_kernel { self.slice_comp.as_deref() } else { None };
        let mn = self.pair.normal_module_m;
        let ct = self.cos_theta;
        let b0 = geo.b0();
        ws.approach.clear();
        ws.line_length.clear();
        ws.rho.clear();
        ws.obs_p.clear();
        ws.obs_g.clear();
        for s in &ws.slices {
            let c = &s.contact;
            ws.approach.push(c.overlap_m * ct);
            ws.line_length.push(mn * self.dzeta / ct);
            let rp = flank_radius(&geo, true, c);
            let rg = flank_radius(&geo, false, c);
            ws.rho.push(1.0 / (1.0 / rp + 1.0 / rg) / ct);
            let z = if c.side == FlankSide::Back { b0 - c.zeta } else { c.zeta };
            ws.obs_p.push(FlankCoord { eta_star: c.eta_star_p, tau: c.tau_p, zeta: z });
            ws.obs_g.push(FlankCoord { eta_star: c.eta_star_g, tau: c.tau_g, zeta: z });
        }
        if let Some(sc) = kernel {
            // Back flanks: ζ → b₀ − ζ is slice n_line − 1 − k (the slice centres are symmetric).
            ws.sw_p.clear();
            ws.sw_g.clear();
            for (i, s) in ws.slices.iter().enumerate() {
                let kc = if s.contact.side == FlankSide::Back { nl - 1 - s.k } else { s.k };
                ws.sw_p.push(sc[0].weights(ws.obs_p[i], kc));
                ws.sw_g.push(sc[1].weights(ws.obs_g[i], kc));
            }
        }

        // Compliance matrix, block by block (runs of equal side and pair).
        ws.cmat.resize_with(n, n, |_, _| 0.0);
        ws.cmat.fill(0.0);
        runs(&ws.slices, &mut ws.runs);
        for ra in 0..ws.runs.len() {
            let (a0, a1) = ws.runs[ra];
            for rb in 0..ws.runs.len() {
                let (b0r, b1r) = ws.runs[rb];
                let (ca, cb) = (&ws.slices[a0].contact, &ws.slices[b0r].contact);
                if ca.side != cb.side {
                    continue;
                }
                let d = (ca.pair - cb.pair) as i32;
                if d != 0 && !self.options.neighbour_coupling {
                    continue;
                }
                let mirror = if ca.side == FlankSide::Back { -1 } else { 1 };
                let same = a0 == b0r;
                let w = mn * self.dzeta / ct;
                if let Some(sc) = kernel {
                    for (gear, sw, offset) in
                        [(&sc[0], &ws.sw_p, mirror * d), (&sc[1], &ws.sw_g, -mirror * d)]
                    {
                        gear.add_block(
                            &sw[a0..a1],
                            &sw[b0r..b1r],
                            offset,
                            &mut ws.partial,
                            &mut ws.cmat,
                            (a0, b0r),
                        );
                    }
                    continue;
                }
                self.comp_p.add_block(
                    &ws.obs_p[a0..a1],
                    &ws.obs_p[b0r..b1r],
                    mirror * d,
                    same,
                    w,
                    &mut ws.ws,
                    &mut ws.cmat,
                    a0,
                    b0r,
                );
                self.comp_g.add_block(
                    &ws.obs_g[a0..a1],
                    &ws.obs_g[b0r..b1r],
                    -mirror * d,
                    same,
                    w,
                    &mut ws.ws,
                    &mut ws.cmat,
                    a0,
                    b0r,
                );
            }
        }

        // Warm start from the previous loads with the same keys. Slices and kept keys are both
        // in ascending (side, pair, slice) order (the contact search's order), so one merge
        // walk finds the matches.
        ws.start.clear();
        let mut any = false;
        let mut cursor = 0;
        for s in &ws.slices {
            let key = (s.contact.side == FlankSide::Back, s.contact.pair, s.k as u32);
            while cursor < warm.loads.len() && warm.loads[cursor].key() < key {
                cursor += 1;
            }
            let q = match warm.loads.get(cursor) {
                Some(w) if w.key() == key => w.q,
                _ => 0.0,
            };
            any |= q > 0.0;
            ws.start.push(q);
        }
        let hertz = HertzLocal::new(&self.local, &ws.rho)?;
        let problem = LoadProblem {
            approach: &ws.approach,
            line_length: &ws.line_length,
            compliance: ws.cmat.as_ref(),
            local: if self.options.local_contact { Some(&hertz) } else { None },
        };
        let any = any
            || ws.coarse_start
                && ws.coarse.estimate(
                    &ws.slices,
                    &ws.approach,
                    &ws.line_length,
                    &ws.rho,
                    &ws.cmat,
                    self.options.local_contact.then_some(&self.local),
                    &mut ws.start,
                );
        let start = if any { Start::From(&ws.start) } else { Start::Cold };
        let report = match ws.solver.solve(&problem, start) {
            Ok(r) => r,
            Err(e) => {
                let range = (self.validity.te_min, self.validity.te_max);
                return Err(load_failure(e, &geo, te, red.phi_p, range, &ws.slices));
            }
        };
        ws.stats.add(&report, n);
        let q = ws.solver.load();

        // Loaded extent of each slice, resolved within the slices (`extent`).
        let local_on = self.options.local_contact;
        let sigma = |i: usize| -> f64 {
            if local_on {
                hertz.eval(i, q[i]).0 - ws.solver.gap()[i]
            } else {
                ws.cmat[(i, i)] * ws.line_length[i] * q[i]
            }
        };
        extent::resolve(
            &ws.slices,
            q,
            ws.solver.gap(),
            &ws.approach,
            sigma,
            (self.dzeta, nl, ct),
            &mut ws.widths,
            None,
        );

        // Outputs.
        let axial = mn * self.dzeta;
        let mut pairs: [(bool, i64); 8] = [(false, 0); 8];
        let mut n_pairs = 0usize;
        let mut extent = 0.0;
        // Elastic wrench, and extent and first axial moment per flank side (driving, back)
        // for the damping's (module docs of `forces`).
        let mut wrench = MeshWrench::default();
        let mut side_extent = [[0.0; 2]; 2];
        warm.loads.clear();
        for (i, s) in ws.slices.iter().enumerate() {
            let c = &s.contact;
            if q[i] > 0.0 {
                out.m_f_p += c.arm_p_m * q[i] * axial;
                out.m_f_g += c.arm_g_m * q[i] * axial;
                out.f_n += q[i] * ws.line_length[i];
                let [wl, wr] = ws.widths[i];
                out.contact_length += ws.line_length[i] * (wl + wr) / self.dzeta;
                extent += wl + wr;
                let slice_wrench = MeshWrench::of_contact(&self.frame, c, q[i] * axial);
                wrench.add(&slice_wrench);
                let se = &mut side_extent[usize::from(c.side == FlankSide::Back)];
                se[0] += wl + wr;
                se[1] += c.zeta * (wl + wr) + 0.5 * (wr * wr - wl * wl);
                let key = (c.side == FlankSide::Back, c.pair);
                if !pairs[..n_pairs].contains(&key) && n_pairs < pairs.len() {
                    pairs[n_pairs] = key;
                    n_pairs += 1;
                }
                out.tip_contact |= on_tip(c);
                out.back_contact |= c.side == FlankSide::Back;
                if self.options.pressure {
                    let p = self.local.max_pressure(q[i], ws.rho[i]).unwrap_or(0.0);
                    out.p_max = out.p_max.max(p);
                }
                warm.loads.push(WarmLoad {
                    back: c.side == FlankSide::Back,
                    pair: c.pair,
                    slice: s.k as u32,
                    q: q[i],
                });
                if ws.record_pairs && c.side == FlankSide::Drive {
                    // Slices come in ascending (side, pair, slice) order: pairs are contiguous.
                    if ws.pair_sums.last().is_none_or(|p| p.pair != c.pair) {
                        ws.pair_sums.push(PairSum {
                            pair: c.pair,
                            values: [0.0; 7],
                            wrench: [0.0; 5],
                            first_moment: 0.0,
                            tip: false,
                        });
                    }
                    let ps = ws.pair_sums.last_mut().expect("pushed above");
                    ps.values[0] += c.arm_p_m * q[i] * axial;
                    ps.values[1] += c.arm_g_m * q[i] * axial;
                    ps.values[2] += q[i] * ws.line_length[i];
                    ps.values[3] += wl + wr;
                    let (f, m) = (&slice_wrench.force_p, &slice_wrench.moment_p);
                    for (acc, v) in ps.wrench.iter_mut().zip([f[0], f[1], f[2], m[0], m[1]]) {
                        *acc += v;
                    }
                    ps.first_moment += c.zeta * (wl + wr) + 0.5 * (wr * wr - wl * wl);
                    if self.options.pressure {
                        let p = self.local.max_pressure(q[i], ws.rho[i]).unwrap_or(0.0);
                        ps.values[4] = ps.values[4].max(p * p);
                    }
                    ps.tip |= on_tip(c);
                }
            }
            if ws.keep_detail {
                let pressure = if self.options.pressure && q[i] > 0.0 {
                    self.local.max_pressure(q[i], ws.rho[i]).unwrap_or(0.0)
                } else {
                    0.0
                };
                ws.detail.push(SliceDetail {
                    zeta: c.zeta,
                    pair: c.pair,
                    back: c.side == FlankSide::Back,
                    overlap_m: c.overlap_m,
                    q_n_per_m: q[i],
                    pressure_pa: pressure,
                    kind: kind_name(c.kind_p, c.kind_g),
                    tip: on_tip(c),
                    sliding_speed_m_s: 0.0,
                    friction_n: 0.0,
                });
            }
        }
        out.n_pairs = n_pairs as u32;
        out.separated = n_pairs == 0;
        if let Some(fc) = &self.friction {
            // Friction at every loaded slice (module docs of `friction`), with μ from the
            // elastic torque.
            let mu = fc.mu(out.m_f_p, state.w_p);
            let v0 = fc.friction.regularisation_speed_m_s;
            let mut sums = FrictionSums::default();
            for (i, s) in ws.slices.iter().enumerate() {
                if q[i] > 0.0 {
                    let sf = slice_friction(
                        &self.frame,
                        &s.contact,
                        q[i] * axial,
                        state.w_p,
                        state.w_g,
                        v0,
                    );
                    sums.add(&sf, mu);
                    if ws.keep_detail {
                        ws.detail[i].sliding_speed_m_s = sf.sliding_speed;
                        ws.detail[i].friction_n = mu * sf.force;
                    }
                }
            }
            wrench.add(&sums.wrench);
            (out.m_r_p, out.m_r_g) = sums.torques();
            out.m_f_p += out.m_r_p;
            out.m_f_g += out.m_r_g;
            out.p_loss = sums.loss;
            out.q_p = sums.heat_p;
            out.q_g = sums.loss - sums.heat_p;
        }
        // Eq. 14 damps the approach rate, which the body motion adds to (`super::pose`,
        // "Damping"): as a gear speed, φ̇g + ḋ_pose/r_bg.
        let damped = match &posed {
            None => *state,
            Some((_, rate)) => {
                MeshState { w_g: state.w_g + approach_rate(&geo, rate) / geo.gear.rb, ..*state }
            }
        };
        (out.m_d_p, out.m_d_g) = self.damping_for(&damped, extent);
        for (side, [e, z1]) in [FlankSide::Drive, FlankSide::Back].into_iter().zip(side_extent) {
            if let Some(w) = self.damping_wrench(&damped, side, e, z1) {
                wrench.add(&w);
            }
        }
        if let Some((pose, _)) = &posed {
            to_housing(&mut wrench, pose, &state.pose_p);
        }
        wrench.write(&mut out);
        set_efficiency(&mut out, state);
        ws.wrench = wrench;
        ws.first_moment = side_extent[0][1] + side_extent[1][1];
        if let Some(kernel) = self.root_stress.as_deref() {
            let loaded = ws.slices.iter().enumerate().map(|(i, s)| LoadedSlice {
                back: s.contact.side == FlankSide::Back,
                pair: s.contact.pair,
                k: if s.contact.side == FlankSide::Back { nl - 1 - s.k } else { s.k },
                pinion: ws.obs_p[i],
                gear: ws.obs_g[i],
                force: q[i] * ws.line_length[i],
            });
            (out.root_stress_p, out.root_stress_g) =
                root_stress(kernel, loaded, &mut ws.root_stress);
            for ps in &mut ws.pair_sums {
                [ps.values[5], ps.values[6]] = ws.root_stress.pair_stress(false, ps.pair);
            }
        }
        Ok(out)
    }

    /// The damping part of the wrench (Eq. 14 distributed as in the module docs of
    /// [`super::forces`]) on flank side `side` with loaded extent `extent` (m_n) and first
    /// axial moment `first_moment` (m_n²) at `state`; `None` when damping is off or nothing
    /// is loaded on that side.
    pub(crate) fn damping_wrench(
        &self,
        state: &MeshState,
        side: FlankSide,
        extent: f64,
        first_moment: f64,
    ) -> Option<MeshWrench> {
        if !self.options.damping || extent <= 0.0 {
            return None;
        }
        let g = &self.geo;
        let rate = state.w_p * g.pinion.rb + state.w_g * g.gear.rb;
        let f = self.d_mesh * rate;
        Some(MeshWrench::of_damping(&self.frame, side, f, extent, first_moment))
    }

    /// The frame of the 3D force and moments ([`super::forces`]).
    pub fn force_frame(&self) -> &ForceFrame {
        &self.frame
    }

    /// The friction's constants; `None` without friction ([`super::friction`]).
    pub fn friction(&self) -> Option<&FrictionConst> {
        self.friction.as_ref()
    }

    /// The friction sums of the last evaluation in `ws` for the table's nodes
    /// ([`super::table`]): μ = 1, the pinion at +1 rad/s and the gear at the rigid ratio,
    /// pure Coulomb (the direction of the sliding, no regularisation):
    /// [M_R,p, M_R,g, F_x, F_y, F_z, M_x, M_y of the pinion, L, L_p] with L = Σ F·|v_t| (W
    /// per rad/s) and L_p its share that heats the pinion. Zero without friction.
    pub(crate) fn unit_friction(&self, ws: &MeshWorkspace) -> [f64; FRICTION_NODE] {
        let Some(fc) = &self.friction else { return [0.0; FRICTION_NODE] };
        let q = ws.solver.load();
        let axial = self.pair.normal_module_m * self.dzeta;
        let mut sums = FrictionSums::default();
        for (s, &qi) in ws.slices.iter().zip(q) {
            if qi > 0.0 {
                let sf = slice_friction(&self.frame, &s.contact, qi * axial, 1.0, fc.ratio, 0.0);
                sums.add(&sf, 1.0);
            }
        }
        let (rp, rg) = sums.torques();
        let (f, m) = (sums.wrench.force_p, sums.wrench.moment_p);
        [rp, rg, f[0], f[1], f[2], m[0], m[1], sums.loss, sums.heat_p]
    }

    /// The axial slice (0 … n_line − 1) that holds ζ (units of m_n).
    fn slice_index(&self, zeta: f64) -> usize {
        ((zeta / self.dzeta) as usize).min(self.zetas.len() - 1)
    }

    /// Damping torques (Eq. 14) for a loaded axial extent `extent` (Σ(ζ_e − ζ_b), units of
    /// m_n) at `state`, N·m; zero when damping is off.
    #[inline]
    pub(crate) fn damping_for(&self, state: &MeshState, extent: f64) -> (f64, f64) {
        if !self.options.damping || extent <= 0.0 {
            return (0.0, 0.0);
        }
        let [dp, dg] = damping_torques(
            self.d_mesh,
            state.w_p,
            state.w_g,
            self.geo.pinion.rb,
            self.geo.gear.rb,
            extent,
        );
        (dp, dg)
    }

    /// Contact-line length per unit of loaded axial extent: w/(m_n·Δζ) = 1/cos θ·m_n, m.
    #[inline]
    pub(crate) fn length_per_extent(&self) -> f64 {
        self.pair.normal_module_m / self.cos_theta
    }
}

/// Number of friction values per table node ([`MeshModel::unit_friction`]).
pub(crate) const FRICTION_NODE: usize = 9;

/// A [`MeshModel`] at full fidelity with its own [`MeshWorkspace`] and [`WarmStart`]: the
/// shared model plus what one caller needs to evaluate it, as a [`MeshTorques`]. Each
/// evaluation starts from the loads of the previous one (see [`WarmStart`]); a clone shares
/// the model and starts with a fresh workspace and a cold start.
#[derive(Debug)]
pub struct FullMesh {
    model: Arc<MeshModel>,
    ws: MeshWorkspace,
    warm: WarmStart,
}

impl Clone for FullMesh {
    fn clone(&self) -> Self {
        let mut f = Self::new(self.model.clone());
        f.ws.keep_detail = self.ws.keep_detail;
        f.ws.slice_kernel = self.ws.slice_kernel;
        f
    }
}

impl FullMesh {
    /// The model with a new workspace and a cold start.
    pub fn new(model: Arc<MeshModel>) -> Self {
        let ws = MeshWorkspace::new(&model);
        Self { model, ws, warm: WarmStart::default() }
    }

    /// The shared model.
    pub fn model(&self) -> &Arc<MeshModel> {
        &self.model
    }

    /// The workspace (detail, per-pair sums and work counters of the last evaluations).
    pub fn workspace(&self) -> &MeshWorkspace {
        &self.ws
    }

    /// The workspace, mutable (detail and counters switched there).
    pub fn workspace_mut(&mut self) -> &mut MeshWorkspace {
        &mut self.ws
    }

    /// The warm start the next evaluation starts from.
    pub fn warm(&self) -> &WarmStart {
        &self.warm
    }

    /// Replaces the warm start (copied, no allocation once grown).
    pub fn set_warm(&mut self, warm: &WarmStart) {
        self.warm.copy_from(warm);
    }

    /// Multiplies every load of the warm start by `factor` (> 0, finite; otherwise nothing
    /// changes): the start of a state whose loads are expected to scale so, as along a TE axis
    /// where the load grows nearly in proportion to the distance from the onset.
    pub(crate) fn scale_warm(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            for w in &mut self.warm.loads {
                w.q *= factor;
            }
        }
    }

    /// Full evaluation at `state` ([`MeshModel::evaluate`]).
    pub fn evaluate(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.model.evaluate(state, &mut self.ws, &mut self.warm)
    }

    /// Full evaluation with the exact partial derivatives ([`MeshModel::jacobian`]).
    pub fn jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, super::MeshJacobian), MeshError> {
        let (out, mut jac) = self.model.jacobian(state, &mut self.ws, &mut self.warm)?;
        if self.model.friction.is_some() {
            // The friction torques' derivatives by central differences (`friction` module
            // docs), from the loads of this state.
            let saved = self.warm.clone();
            let r = add_friction_jacobian(&mut |s| self.evaluate(s), state, &mut jac);
            self.warm.copy_from(&saved);
            r?;
            // The friction's pose derivatives are not part of those differences.
            jac.pose = None;
        }
        Ok((out, jac))
    }

    /// Sets d_mesh, N·s/m ([`MeshModel::with_d_mesh`]; the model is copied when shared).
    pub fn set_d_mesh(&mut self, d_mesh: f64) -> Result<(), MeshError> {
        self.model = Arc::new(self.model.with_d_mesh(d_mesh)?);
        Ok(())
    }

    /// Switches the ζ-precomputed compliance kernel ([`SliceInfluence`]) on or off; off, the
    /// compliance matrix is assembled by the general interpolation
    /// ([`InterpolatedInfluence::add_matrix`]), which gives the same values up to rounding at
    /// two to three times the cost. For benchmarks and cross-checks; on by default whenever
    /// the model has the kernel. Returns whether the kernel is now in use.
    pub fn use_slice_kernel(&mut self, on: bool) -> bool {
        self.ws.slice_kernel = on;
        on && self.model.has_slice_kernel()
    }

    /// Switches the coarse pre-solve of a cold start on or off (module docs, "Cold start");
    /// off, a cold solve starts from q = 0. Either way the solution is the same to the load
    /// solver's tolerance. For benchmarks and cross-checks; on by default.
    pub fn use_coarse_start(&mut self, on: bool) {
        self.ws.coarse_start = on;
    }

    /// The per-tooth-pair driving-flank outputs of the last evaluation (recorded only when
    /// switched on by the table build).
    pub(crate) fn pair_sums(&self) -> &[PairSum] {
        &self.ws.pair_sums
    }

    /// Records the per-pair sums (table build).
    pub(crate) fn record_pairs(&mut self, on: bool) {
        self.ws.record_pairs = on;
    }
}

impl MeshTorques for FullMesh {
    fn evaluation_slices(&self) -> usize {
        self.model().options().slices
    }

    fn forget_history(&mut self) {
        self.warm.clear();
    }

    fn warm_start(&self, out: &mut WarmStart) {
        out.copy_from(&self.warm);
    }

    fn set_warm_start(&mut self, warm: &WarmStart) {
        self.warm.copy_from(warm);
    }

    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.evaluate(state)
    }

    fn base_radii(&self) -> (f64, f64) {
        (self.model.geo.pinion.rb, self.model.geo.gear.rb)
    }

    fn te_range(&self) -> (f64, f64) {
        (self.model.validity.te_min, self.model.validity.te_max)
    }

    fn has_friction(&self) -> bool {
        self.model.friction.is_some()
    }

    /// Exact partial derivatives from the load solution's sensitivity (see the `jacobian`
    /// module docs).
    fn mesh_jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, super::MeshJacobian), MeshError> {
        self.jacobian(state)
    }
}

/// The error of a failed load solve: an ill-posed problem (non-P compliance or a singular
/// Newton matrix) means the state lies outside the model's range ([`MeshError::OutOfRange`],
/// with TE, the mesh phase and the largest overlap against the module); any other failure is
/// passed on as it is.
fn load_failure(
    e: crate::load::LoadError,
    geo: &PairGeometry,
    te: f64,
    phase: f64,
    range: (f64, f64),
    slices: &[Slice],
) -> MeshError {
    use crate::load::LoadError;
    match e {
        LoadError::Indefinite { .. } | LoadError::Singular { .. } => {
            let max_overlap = slices.iter().map(|s| s.contact.overlap_m).fold(0.0, f64::max);
            MeshError::OutOfRange {
                te,
                phase,
                range,
                max_overlap,
                module: geo.params.normal_module_m,
                cause: Some(e),
            }
        }
        e => MeshError::Load(e),
    }
}

/// Rejects a state with a NaN or infinite component, naming it, and speeds beyond
/// ±[`super::validity::MAX_STATE_SPEED_RAD_S`] (whose damping torque would overflow).
#[inline]
fn check_state(state: &MeshState) -> Result<(), MeshError> {
    let max = super::validity::MAX_STATE_SPEED_RAD_S;
    if state.phi_p.is_finite()
        && state.phi_g.is_finite()
        && state.w_p.abs() <= max
        && state.w_g.abs() <= max
    {
        return Ok(());
    }
    state_error(state)
}

/// The error of a state [`check_state`] refuses (kept out of the hot path).
#[cold]
fn state_error(state: &MeshState) -> Result<(), MeshError> {
    for (name, v) in
        [("phi_p", state.phi_p), ("phi_g", state.phi_g), ("w_p", state.w_p), ("w_g", state.w_g)]
    {
        if !v.is_finite() {
            return Err(MeshError::NonFinite { name, value: v });
        }
    }
    for (name, v) in [("w_p", state.w_p), ("w_g", state.w_g)] {
        if v.abs() > super::validity::MAX_STATE_SPEED_RAD_S {
            return Err(MeshError::Param(crate::error::ParamError::new(
                name,
                v,
                "|speed| <= 2e5 rad/s (the validity range of the mesh state: twice the largest \
                 nominal speed 1e5 rad/s)",
            )));
        }
    }
    Ok(())
}

/// The slice centres ζ_k (units of m_n) and the slice width Δζ of `slices` total slices
/// ([`MeshOptions::slices`]): each contact line cut into `slices / ceil(ε_α + ε_β)` (at least
/// two) equal axial slices over the face width b₀.
fn slice_centres(geo: &PairGeometry, slices: usize) -> (Vec<f64>, f64) {
    let lines = (geo.eps_alpha + geo.eps_beta).ceil().max(1.0) as usize;
    let n_line = slices.div_ceil(lines).max(2);
    let dzeta = geo.b0() / n_line as f64;
    ((0..n_line).map(|i| (i as f64 + 0.5) * dzeta).collect(), dzeta)
}

/// The helix's turn of the teeth at each of the slice centres `zetas`
/// ([`ContactSolver::slice_twist`]).
fn slice_twists(geo: &PairGeometry, zetas: &[f64]) -> Vec<SliceTwist> {
    let cs = ContactSolver::new(geo);
    zetas.iter().map(|&z| cs.slice_twist(z)).collect()
}

/// The compliance kernel of both gears at the slice centres `zetas`, when both compliances are
/// interpolated on grids that allow it ([`SliceInfluence::new`]).
fn slice_kernel(
    pinion: &GearCompliance,
    gear: &GearCompliance,
    zetas: &[f64],
) -> Option<Arc<[SliceInfluence; 2]>> {
    let (GearCompliance::Interpolated(p), GearCompliance::Interpolated(g)) = (pinion, gear) else {
        return None;
    };
    Some(Arc::new([SliceInfluence::new(p, zetas)?, SliceInfluence::new(g, zetas)?]))
}

/// Runs of consecutive slices with equal side and pair: `(start, end)` index ranges, into
/// `out` (cleared first).
/// Every `COARSE_STRIDE`-th slice of a contact line enters the coarse pre-solve of a cold
/// start (module docs, "Cold start").
const COARSE_STRIDE: usize = 4;

/// Fewest slices for which a cold start pre-solves on the coarse slices: below, the coarse
/// problem would hold too few slices per line to say anything about the active set.
const COARSE_MIN_SLICES: usize = 16 * COARSE_STRIDE;

/// Buffers of the coarse pre-solve of a cold start: the chosen slices, their problem data and
/// their own load solver (sized once; reused).
#[derive(Debug)]
struct CoarseStart {
    idx: Vec<usize>,
    approach: Vec<f64>,
    line_length: Vec<f64>,
    rho: Vec<f64>,
    cmat: Mat<f64>,
    solver: LoadSolver,
}

impl CoarseStart {
    fn new(capacity: usize) -> Self {
        Self {
            idx: Vec::with_capacity(capacity),
            approach: Vec::with_capacity(capacity),
            line_length: Vec::with_capacity(capacity),
            rho: Vec::with_capacity(capacity),
            cmat: Mat::zeros(0, 0),
            solver: LoadSolver::with_settings(capacity, COARSE_SETTINGS),
        }
    }

    /// Fills `start` (one load per slice, N/m) with the loads of the coarse problem on every
    /// [`COARSE_STRIDE`]-th slice of each contact line (slice keys k ≡ stride/2 mod stride;
    /// line length × stride, the compliance the rows and columns of `cmat` of those slices),
    /// interpolated linearly in k along each line between the coarse slices of the same
    /// (side, pair) and held constant beyond the last (every slice of the problem overlaps).
    /// Returns false, leaving `start` as it was, when there are too few slices, the coarse
    /// problem is unloaded or its solve fails (the caller then starts cold).
    #[allow(clippy::too_many_arguments)]
    fn estimate(
        &mut self,
        slices: &[Slice],
        approach: &[f64],
        line_length: &[f64],
        rho: &[f64],
        cmat: &Mat<f64>,
        local: Option<&LocalContact>,
        start: &mut [f64],
    ) -> bool {
        let n = slices.len();
        if n < COARSE_MIN_SLICES {
            return false;
        }
        self.idx.clear();
        self.idx.extend((0..n).filter(|&i| slices[i].k % COARSE_STRIDE == COARSE_STRIDE / 2));
        let m = self.idx.len();
        if m == 0 {
            return false;
        }
        self.approach.clear();
        self.line_length.clear();
        self.rho.clear();
        for &i in &self.idx {
            self.approach.push(approach[i]);
            self.line_length.push(COARSE_STRIDE as f64 * line_length[i]);
            self.rho.push(rho[i]);
        }
        self.cmat.resize_with(m, m, |_, _| 0.0);
        for (c, &j) in self.idx.iter().enumerate() {
            for (r, &i) in self.idx.iter().enumerate() {
                self.cmat[(r, c)] = cmat[(i, j)];
            }
        }
        let hertz = match local.map(|l| HertzLocal::new(l, &self.rho)) {
            Some(Ok(h)) => Some(h),
            Some(Err(_)) => return false,
            None => None,
        };
        let problem = LoadProblem {
            approach: &self.approach,
            line_length: &self.line_length,
            compliance: self.cmat.as_ref(),
            local: hertz.as_ref().map(|h| h as &dyn crate::load::LocalTerm),
        };
        if self.solver.solve(&problem, Start::Cold).is_err() {
            return false;
        }
        let q = self.solver.load();
        if !q.iter().any(|&x| x > 0.0) {
            return false;
        }
        // Interpolation along each line: fine slice i lies between coarse slices c − 1 and c
        // of its (side, pair) when their keys bracket its key.
        let line = |s: &Slice| (s.contact.side == FlankSide::Back, s.contact.pair);
        let mut c = 0;
        for (i, s) in slices.iter().enumerate() {
            while c < m && self.idx[c] < i {
                c += 1;
            }
            let before = c.checked_sub(1).filter(|&b| line(&slices[self.idx[b]]) == line(s));
            let after = (c < m && line(&slices[self.idx[c]]) == line(s)).then_some(c);
            let value = match (before, after) {
                (Some(b), Some(a)) => {
                    let (kb, ka) = (slices[self.idx[b]].k as f64, slices[self.idx[a]].k as f64);
                    let t = if ka > kb { (s.k as f64 - kb) / (ka - kb) } else { 0.0 };
                    q[b] + t * (q[a] - q[b])
                }
                (Some(b), None) => q[b],
                (None, Some(a)) => q[a],
                (None, None) => 0.0,
            };
            start[i] = value.max(0.0);
        }
        true
    }
}

fn runs(slices: &[Slice], out: &mut Vec<(usize, usize)>) {
    out.clear();
    let mut start = 0;
    for i in 1..=slices.len() {
        let brk = i == slices.len()
            || slices[i].contact.pair != slices[start].contact.pair
            || slices[i].contact.side != slices[start].contact.side;
        if brk {
            out.push((start, i));
            start = i;
        }
    }
}

/// Transverse radius of curvature of one flank at a contact, m; at the involute/relief corner
/// the mean of the two adjacent surfaces' radii (see the module docs).
fn flank_radius(geo: &PairGeometry, pinion: bool, c: &ContactPoint) -> f64 {
    let (kind, rho, r, g) = if pinion {
        (c.kind_p, c.rho_p_m, c.radius_p_m, &geo.pinion)
    } else {
        (c.kind_g, c.rho_g_m, c.radius_g_m, &geo.gear)
    };
    if kind == SegmentKind::ReliefCorner || rho <= 0.0 {
        let roll = |rb: f64| (r * r - rb * rb).max(0.0).sqrt();
        let v = 0.5 * (roll(g.rb) + roll(g.rb_relief));
        if v > 0.0 { v } else { g.rb.max(1e-6) }
    } else {
        rho
    }
}

/// True if the contact lies on the tip rounding or the tip circle of either flank.
fn on_tip(c: &ContactPoint) -> bool {
    let tip = |k: SegmentKind| matches!(k, SegmentKind::Rounding | SegmentKind::Tip);
    tip(c.kind_p) || tip(c.kind_g)
}

/// Static name of a contact kind (pinion/gear), for the per-slice detail.
fn kind_name(p: SegmentKind, g: SegmentKind) -> &'static str {
    use SegmentKind::*;
    match (p, g) {
        (Involute, Involute) => "involute/involute",
        (Involute, ReliefCorner) => "involute/relief_corner",
        (Involute, Relief) => "involute/relief",
        (Involute, Rounding) => "involute/rounding",
        (Involute, Tip) => "involute/tip",
        (ReliefCorner, Involute) => "relief_corner/involute",
        (Relief, Involute) => "relief/involute",
        (Rounding, Involute) => "rounding/involute",
        (Tip, Involute) => "tip/involute",
        _ => "other",
    }
}
