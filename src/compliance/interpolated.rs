//! Global compliance α* by direct interpolation of an FE [`InfluenceGrid`].
//!
//! α*(obs, load) is a function of four coordinates: the profile coordinate p and ζ of the
//! observation point and of the load point (p = [`FlankCoord::profile`], which continues η*
//! over the tip rounding with τ). [`InterpolatedInfluence`] interpolates the grid values with the
//! tensor product of one-dimensional cubic Hermite interpolants, one per coordinate:
//!
//! ```text
//! α(p, ζ, p_F, ζ_F) = Σ_{a,b,c,d} w_a(p) · w_b(ζ) · w_c(p_F) · w_d(ζ_F) · α*[(a,b), (c,d)]
//! ```
//!
//! On an interval [x_i, x_{i+1}] of an axis with h = x_{i+1} − x_i and t = (x − x_i)/h the 1D
//! interpolant is `v_i·h00(t) + h·d_i·h10(t) + v_{i+1}·h01(t) + h·d_{i+1}·h11(t)` (cubic Hermite
//! basis) with node slopes d_k from the three-point, second-order finite-difference formula on the
//! non-uniform grid (centred inside, one-sided at the two end nodes; a two-node axis is linear).
//! This is the non-uniform generalisation of the Catmull–Rom spline: C¹, exact at the nodes,
//! reproduces quadratics, and its error is O(h³) for smooth data. Every weight w is a linear
//! combination of at most four neighbouring node values, so one evaluation touches at most
//! 4⁴ = 256 grid values and allocates nothing.
//!
//! **Outside the grid** each coordinate is clamped to the grid's range (constant extrapolation
//! along that axis): points beyond the last row or column get the values of the boundary.
//!
//! Because the same 1D weights are used for observation and load axes, symmetric data
//! (α*[i, j] = α*[j, i], Maxwell–Betti) give a symmetric interpolant (up to rounding).
//!
//! Tooth offsets that are not in [`InfluenceGrid::teeth`] have α* = 0.

use std::fmt;

use faer::Mat;
use serde::{Deserialize, Serialize};

use super::{Compliance, FlankCoord, InfluenceGrid};

/// An influence grid that failed [`InfluenceGrid::validate`]; the message names the problem.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InvalidGrid(pub String);

impl fmt::Display for InvalidGrid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "invalid influence grid: {}", self.0)
    }
}

impl std::error::Error for InvalidGrid {}

impl TryFrom<InfluenceGrid> for InterpolatedInfluence {
    type Error = InvalidGrid;

    fn try_from(grid: InfluenceGrid) -> Result<Self, InvalidGrid> {
        Self::new(grid)
    }
}

impl From<InterpolatedInfluence> for InfluenceGrid {
    fn from(i: InterpolatedInfluence) -> Self {
        i.grid
    }
}

/// Slope stencil of one node: d_k = Σ coefficient · v_index (unused entries have coefficient 0).
type Stencil = [(usize, f64); 3];

/// One interpolation axis: nodes and the finite-difference slope stencil of every node.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Axis {
    nodes: Vec<f64>,
    slopes: Vec<Stencil>,
}

/// The interpolation weights of one coordinate value: `w[k]` multiplies node `start + k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Weights {
    pub(crate) start: usize,
    pub(crate) width: usize,
    pub(crate) w: [f64; 4],
}

impl Axis {
    /// Builds the slope stencils; `nodes` must be strictly increasing with ≥ 2 entries.
    pub(crate) fn new(nodes: &[f64]) -> Self {
        let n = nodes.len();
        let x = nodes;
        let mut slopes = Vec::with_capacity(n);
        if n == 2 {
            let c = 1.0 / (x[1] - x[0]);
            slopes.push([(0, -c), (1, c), (0, 0.0)]);
            slopes.push([(0, -c), (1, c), (0, 0.0)]);
        } else {
            for k in 0..n {
                let s = if k == 0 {
                    let (h1, h2) = (x[1] - x[0], x[2] - x[1]);
                    [
                        (0, -(2.0 * h1 + h2) / (h1 * (h1 + h2))),
                        (1, (h1 + h2) / (h1 * h2)),
                        (2, -h1 / (h2 * (h1 + h2))),
                    ]
                } else if k == n - 1 {
                    let (h1, h2) = (x[k] - x[k - 1], x[k - 1] - x[k - 2]);
                    [
                        (k, (2.0 * h1 + h2) / (h1 * (h1 + h2))),
                        (k - 1, -(h1 + h2) / (h1 * h2)),
                        (k - 2, h1 / (h2 * (h1 + h2))),
                    ]
                } else {
                    let (h1, h2) = (x[k] - x[k - 1], x[k + 1] - x[k]);
                    [
                        (k - 1, -h2 / (h1 * (h1 + h2))),
                        (k, (h2 - h1) / (h1 * h2)),
                        (k + 1, h1 / (h2 * (h1 + h2))),
                    ]
                };
                slopes.push(s);
            }
        }
        Self { nodes: nodes.to_vec(), slopes }
    }

    /// Weights of the coordinate value `x` (clamped to the axis range; NaN maps to the first
    /// node).
    pub(crate) fn weights(&self, x: f64) -> Weights {
        let nodes = &self.nodes;
        let n = nodes.len();
        let (lo, hi) = (nodes[0], nodes[n - 1]);
        let x = if x >= lo { x.min(hi) } else { lo };
        let i = nodes.partition_point(|&v| v <= x).saturating_sub(1).min(n - 2);
        let h = nodes[i + 1] - nodes[i];
        let t = (x - nodes[i]) / h;
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = (t3 - 2.0 * t2 + t) * h;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = (t3 - t2) * h;
        let (start, width) = if n >= 4 { (i.saturating_sub(1).min(n - 4), 4) } else { (0, n) };
        let mut w = [0.0; 4];
        w[i - start] += h00;
        w[i + 1 - start] += h01;
        for &(k, c) in &self.slopes[i] {
            w[k - start] += h10 * c;
        }
        for &(k, c) in &self.slopes[i + 1] {
            w[k - start] += h11 * c;
        }
        Weights { start, width, w }
    }

    /// d/dx of the weights of [`Axis::weights`] at `x`: the derivative of the interpolant with
    /// respect to its coordinate; zero outside the axis range (constant extrapolation there).
    fn weights_dx(&self, x: f64) -> Weights {
        let nodes = &self.nodes;
        let n = nodes.len();
        let mut out = self.weights(x);
        if !(x >= nodes[0] && x <= nodes[n - 1]) {
            out.w = [0.0; 4];
            return out;
        }
        let i = nodes.partition_point(|&v| v <= x).saturating_sub(1).min(n - 2);
        let h = nodes[i + 1] - nodes[i];
        let t = (x - nodes[i]) / h;
        let t2 = t * t;
        let h00 = (6.0 * t2 - 6.0 * t) / h;
        let h10 = 3.0 * t2 - 4.0 * t + 1.0;
        let h01 = (-6.0 * t2 + 6.0 * t) / h;
        let h11 = 3.0 * t2 - 2.0 * t;
        let start = out.start;
        let mut w = [0.0; 4];
        w[i - start] += h00;
        w[i + 1 - start] += h01;
        for &(k, c) in &self.slopes[i] {
            w[k - start] += h10 * c;
        }
        for &(k, c) in &self.slopes[i + 1] {
            w[k - start] += h11 * c;
        }
        out.w = w;
        out
    }
}

/// Precomputed weights of one flank point (profile and ζ axes).
#[derive(Debug, Clone, Copy, PartialEq)]
struct PointWeights {
    row: Weights,
    col: Weights,
}

/// Tensor-product cubic interpolation of an [`InfluenceGrid`] (see the module docs).
///
/// Serialised as its grid; deserialisation validates the grid and rebuilds the interpolant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "InfluenceGrid", into = "InfluenceGrid")]
pub struct InterpolatedInfluence {
    grid: InfluenceGrid,
    rows: Axis,
    cols: Axis,
}

impl InterpolatedInfluence {
    /// Builds the interpolant; the grid must pass [`InfluenceGrid::validate`].
    pub fn new(grid: InfluenceGrid) -> Result<Self, InvalidGrid> {
        grid.validate().map_err(InvalidGrid)?;
        let rows = Axis::new(&grid.profile);
        let cols = Axis::new(&grid.zeta);
        Ok(Self { grid, rows, cols })
    }

    /// The interpolated grid.
    pub fn grid(&self) -> &InfluenceGrid {
        &self.grid
    }

    fn point_weights(&self, c: FlankCoord) -> PointWeights {
        let p = c.profile(self.grid.eta_star_rounding_start, self.grid.rounding_radius_mn);
        PointWeights { row: self.rows.weights(p), col: self.cols.weights(c.zeta) }
    }

    fn block(&self, tooth_offset: i32) -> Option<&[f64]> {
        let t = self.grid.teeth.iter().position(|&k| k == tooth_offset)?;
        self.grid.alpha.get(t).map(|b| b.as_slice())
    }

    /// α*, m/N, for many observation and load points at once: returns the row-major
    /// `obs.len() × load.len()` matrix (`out[i * load.len() + j]` = α*(`obs[i]`, `load[j]`)).
    ///
    /// Faster than calling [`Compliance::alpha`] per pair: the observation weights are
    /// contracted once per observation point. Equal to it up to rounding.
    pub fn matrix(&self, obs: &[FlankCoord], load: &[FlankCoord], tooth_offset: i32) -> Vec<f64> {
        let mut out = vec![0.0; obs.len() * load.len()];
        let mut ws = MatrixWorkspace::default();
        self.add_matrix(obs, load, tooth_offset, &mut ws, |i, j, v| out[i * load.len() + j] = v);
        out
    }

    /// Like [`InterpolatedInfluence::matrix`], but hands each value to `put(i, j, α*)` and keeps
    /// its scratch memory in `ws`, so repeated calls of at most the same sizes do not allocate.
    pub fn add_matrix(
        &self,
        obs: &[FlankCoord],
        load: &[FlankCoord],
        tooth_offset: i32,
        ws: &mut MatrixWorkspace,
        mut put: impl FnMut(usize, usize, f64),
    ) {
        let Some(block) = self.block(tooth_offset) else {
            return;
        };
        let n = self.grid.points();
        let nc = self.grid.zeta.len();
        ws.load.clear();
        ws.load.extend(load.iter().map(|&c| self.point_weights(c)));
        ws.partial.clear();
        ws.partial.resize(n, 0.0);
        for (i, &o) in obs.iter().enumerate() {
            let ow = self.point_weights(o);
            ws.partial.iter_mut().for_each(|v| *v = 0.0);
            for a in 0..ow.row.width {
                for b in 0..ow.col.width {
                    let w = ow.row.w[a] * ow.col.w[b];
                    if w == 0.0 {
                        continue;
                    }
                    let g = (ow.row.start + a) * nc + ow.col.start + b;
                    for (p, &v) in ws.partial.iter_mut().zip(&block[g * n..(g + 1) * n]) {
                        *p += w * v;
                    }
                }
            }
            for (j, l) in ws.load.iter().enumerate() {
                let mut s = 0.0;
                for c in 0..l.row.width {
                    let base = (l.row.start + c) * nc + l.col.start;
                    let mut sr = 0.0;
                    for d in 0..l.col.width {
                        sr += l.col.w[d] * ws.partial[base + d];
                    }
                    s += l.row.w[c] * sr;
                }
                put(i, j, s);
            }
        }
    }
}

/// The interpolation weights of one slice for [`SliceInfluence`]: profile-row weights of the
/// slice's own profile coordinate and the ζ weights of its axial slice, both four wide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceWeights {
    /// Axial slice index k (ζ = ζ_k of [`SliceInfluence::zetas`]).
    k: usize,
    /// First of the four grid rows.
    row: usize,
    /// Row weights.
    row_w: [f64; 4],
    /// Grid index of (row, first of the four columns).
    base: usize,
    /// Outer product row_w ⊗ col_w, row-major.
    w16: [f64; 16],
}

/// An [`InterpolatedInfluence`] specialised to a fixed set of axial slice positions ζ_k, for
/// assembling many-slice compliance matrices quickly.
///
/// A mesh model evaluates α* only at the centres ζ_k of its axial slices (only the profile
/// coordinate moves with the mesh position), so the ζ interpolation of the load point can be
/// done once: for every tooth offset t, slice k and grid row r this keeps
///
/// ```text
/// B[t][k][r][g] = Σ_d w_d(ζ_k) · α*_t[g, (r, c_k + d)]      (g: observation grid point)
/// ```
///
/// A matrix block then costs, per load slice, the contraction of four rows of B with the load
/// point's row weights (4·n_grid multiply-adds, contiguous), and per entry one 4 × 4 product
/// with the observation point's weights (16 multiply-adds on contiguous quadruples) — against
/// 16·n_grid and a bounds-checked, variable-width loop per load in
/// [`InterpolatedInfluence::add_matrix`]. The values are the same interpolant, equal up to
/// rounding. Memory: teeth × slices × rows × n_grid values (3.8 MB per gear for Table 1 at 100
/// slices per line).
///
/// Requires at least four nodes on both grid axes ([`SliceInfluence::new`] returns `None`
/// otherwise; [`InterpolatedInfluence::add_matrix`] handles any grid).
#[derive(Debug, Clone)]
pub struct SliceInfluence {
    zetas: Vec<f64>,
    teeth: Vec<i32>,
    rows: Axis,
    cols: usize,
    points: usize,
    col_w: Vec<Weights>,
    b: Vec<f64>,
    eta_star_rounding_start: f64,
    rounding_radius_mn: f64,
}

impl SliceInfluence {
    /// Precomputes the ζ-contracted data for the slice centres `zetas` (units of m_n); `None`
    /// when an axis of the grid has fewer than four nodes.
    pub fn new(interp: &InterpolatedInfluence, zetas: &[f64]) -> Option<Self> {
        let g = &interp.grid;
        let (nr, nc, n) = (g.profile.len(), g.zeta.len(), g.points());
        if nr < 4 || nc < 4 {
            return None;
        }
        let col_w: Vec<Weights> = zetas.iter().map(|&z| interp.cols.weights(z)).collect();
        let nk = zetas.len();
        let mut b = vec![0.0; g.teeth.len() * nk * nr * n];
        for (t, block) in g.alpha.iter().enumerate() {
            for (k, cw) in col_w.iter().enumerate() {
                for r in 0..nr {
                    let dst = &mut b[((t * nk + k) * nr + r) * n..][..n];
                    for (d, &wd) in cw.w.iter().enumerate().take(cw.width) {
                        let load = r * nc + cw.start + d;
                        for (obs, x) in dst.iter_mut().enumerate() {
                            *x += wd * block[obs * n + load];
                        }
                    }
                }
            }
        }
        Some(Self {
            zetas: zetas.to_vec(),
            teeth: g.teeth.clone(),
            rows: interp.rows.clone(),
            cols: nc,
            points: n,
            col_w,
            b,
            eta_star_rounding_start: g.eta_star_rounding_start,
            rounding_radius_mn: g.rounding_radius_mn,
        })
    }

    /// The slice centres ζ_k (units of m_n).
    pub fn zetas(&self) -> &[f64] {
        &self.zetas
    }

    /// The weights of a point at profile position of `c` on axial slice `k` (the ζ of `c` is
    /// ignored: it is ζ_k). Panics if `k` is out of range.
    pub fn weights(&self, c: FlankCoord, k: usize) -> SliceWeights {
        let p = c.profile(self.eta_star_rounding_start, self.rounding_radius_mn);
        let rw = self.rows.weights(p);
        let cw = self.col_w[k];
        let mut w16 = [0.0; 16];
        for a in 0..4 {
            for d in 0..4 {
                w16[a * 4 + d] = rw.w[a] * cw.w[d];
            }
        }
        SliceWeights { k, row: rw.start, row_w: rw.w, base: rw.start * self.cols + cw.start, w16 }
    }

    /// The weights of the derivative with respect to the profile coordinate p
    /// ([`FlankCoord::profile`], units of m_n) at the point of [`SliceInfluence::weights`]:
    /// used in place of either point's weights in [`SliceInfluence::add_block`] they give
    /// ∂α*/∂p of that point, m/N per m_n (zero where p is outside the grid).
    pub fn weights_dp(&self, c: FlankCoord, k: usize) -> SliceWeights {
        let p = c.profile(self.eta_star_rounding_start, self.rounding_radius_mn);
        let rw = self.rows.weights_dx(p);
        let cw = self.col_w[k];
        let mut w16 = [0.0; 16];
        for a in 0..4 {
            for d in 0..4 {
                w16[a * 4 + d] = rw.w[a] * cw.w[d];
            }
        }
        SliceWeights { k, row: rw.start, row_w: rw.w, base: rw.start * self.cols + cw.start, w16 }
    }

    /// (∂p/∂η*, ∂p/∂τ) of the profile coordinate at `c` ([`FlankCoord::profile`]): (1, 0)
    /// below the rounding, (0, −ρ_r/m_n) on it (units of m_n per m_n and per rad).
    pub fn profile_rates(&self, c: FlankCoord) -> (f64, f64) {
        if c.tau > 0.0 { (0.0, -self.rounding_radius_mn) } else { (1.0, 0.0) }
    }

    /// Adds α*(obs_i, load_j, `tooth_offset`) (m/N) to `out[(r0 + i, c0 + j)]` for every
    /// observation slice i and load slice j, with `(r0, c0) = at`. `partial` is scratch memory (resized to the grid
    /// size). Panics if the block does not fit into `out`.
    pub fn add_block(
        &self,
        obs: &[SliceWeights],
        load: &[SliceWeights],
        tooth_offset: i32,
        partial: &mut Vec<f64>,
        out: &mut Mat<f64>,
        at: (usize, usize),
    ) {
        self.add_block_with(obs, load, tooth_offset, partial, out, at, true);
    }

    /// The same block as [`SliceInfluence::add_block`], always by the portable kernel (tests
    /// compare the two kernels bit for bit).
    #[doc(hidden)]
    pub fn add_block_portable(
        &self,
        obs: &[SliceWeights],
        load: &[SliceWeights],
        tooth_offset: i32,
        partial: &mut Vec<f64>,
        out: &mut Mat<f64>,
        at: (usize, usize),
    ) {
        self.add_block_with(obs, load, tooth_offset, partial, out, at, false);
    }

    /// [`SliceInfluence::add_block`], on the AVX2 kernel when `vectorised` and the CPU has it.
    #[allow(clippy::too_many_arguments)]
    fn add_block_with(
        &self,
        obs: &[SliceWeights],
        load: &[SliceWeights],
        tooth_offset: i32,
        partial: &mut Vec<f64>,
        out: &mut Mat<f64>,
        at: (usize, usize),
        vectorised: bool,
    ) {
        let Some(t) = self.teeth.iter().position(|&k| k == tooth_offset) else {
            return;
        };
        if obs.is_empty() || load.is_empty() {
            return;
        }
        // Only the grid rows the observation slices touch are needed in the partial sums.
        let nc = self.cols;
        let lo = obs.iter().map(|o| o.row).min().unwrap_or(0) * nc;
        let hi = (obs.iter().map(|o| o.row).max().unwrap_or(0) + 4) * nc;
        partial.clear();
        partial.resize(self.points, 0.0);
        #[cfg(target_arch = "x86_64")]
        {
            if vectorised && std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2 (checked just above).
                unsafe { self.block_avx2(obs, load, t, lo, hi, partial, out, at) };
                return;
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = vectorised;
        self.block_kernel(obs, load, t, lo, hi, partial, out, at);
    }

    /// [`SliceInfluence::block_kernel`]'s loops compiled for AVX2, with the entries' 4 × 4
    /// contractions on 256-bit vectors, four observation slices at a time ([`entries4_avx`],
    /// the remainder by [`entry_avx`]): the same operations in the same order, so the same
    /// rounding (no fused multiply-adds) and the same matrix, bit for bit.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn block_avx2(
        &self,
        obs: &[SliceWeights],
        load: &[SliceWeights],
        t: usize,
        lo: usize,
        hi: usize,
        partial: &mut [f64],
        out: &mut Mat<f64>,
        at: (usize, usize),
    ) {
        let nc = self.cols;
        let (r0, c0) = at;
        for (j, l) in load.iter().enumerate() {
            self.partial_sums(l, t, lo, hi, partial);
            let col = &mut out.col_as_slice_mut(c0 + j)[r0..r0 + obs.len()];
            let mut chunks = col.chunks_exact_mut(4);
            let mut os = obs.chunks_exact(4);
            for (x, o) in (&mut chunks).zip(&mut os) {
                // SAFETY: the CPU has AVX2 (this function's contract); every window
                // `o.base .. o.base + 3·nc + 4` lies in `partial` (the grid's points), and `x`
                // holds 4 values.
                unsafe { entries4_avx(partial, nc, [&o[0], &o[1], &o[2], &o[3]], x) };
            }
            for (x, o) in chunks.into_remainder().iter_mut().zip(os.remainder()) {
                // SAFETY: as above; the window holds 3·nc + 4 values.
                *x += unsafe { entry_avx(&partial[o.base..o.base + 3 * nc + 4], nc, &o.w16) };
            }
        }
    }

    /// The first contraction for load slice `l` of tooth block `t`: `partial[g]` = Σ_r
    /// w_r(p_load)·B[t][k_load][row + r][g] for the grid indices `lo..hi`.
    #[inline(always)]
    fn partial_sums(&self, l: &SliceWeights, t: usize, lo: usize, hi: usize, partial: &mut [f64]) {
        let (n, nr, nk) = (self.points, self.rows.nodes.len(), self.zetas.len());
        let rows = &self.b[((t * nk + l.k) * nr + l.row) * n..][..4 * n];
        let (b0, rest) = rows.split_at(n);
        let (b1, rest) = rest.split_at(n);
        let (b2, b3) = rest.split_at(n);
        let [w0, w1, w2, w3] = l.row_w;
        for ((((p, &a), &b), &c), &d) in partial[lo..hi]
            .iter_mut()
            .zip(&b0[lo..hi])
            .zip(&b1[lo..hi])
            .zip(&b2[lo..hi])
            .zip(&b3[lo..hi])
        {
            *p = w0 * a + w1 * b + w2 * c + w3 * d;
        }
    }

    /// The two contractions of [`SliceInfluence::add_block`] for tooth block `t`, with the
    /// partial sums restricted to grid indices `lo..hi` and each entry formed by [`entry`] from
    /// the partial sums of its 4 × 4 window (`3·nc + 4` values): the portable kernel, which
    /// [`SliceInfluence::block_avx2`] reproduces bit for bit.
    #[allow(clippy::too_many_arguments)]
    fn block_kernel(
        &self,
        obs: &[SliceWeights],
        load: &[SliceWeights],
        t: usize,
        lo: usize,
        hi: usize,
        partial: &mut [f64],
        out: &mut Mat<f64>,
        (r0, c0): (usize, usize),
    ) {
        let nc = self.cols;
        for (j, l) in load.iter().enumerate() {
            self.partial_sums(l, t, lo, hi, partial);
            let col = &mut out.col_as_slice_mut(c0 + j)[r0..r0 + obs.len()];
            for (x, o) in col.iter_mut().zip(obs) {
                *x += entry(&partial[o.base..o.base + 3 * nc + 4], nc, &o.w16);
            }
        }
    }
}

/// One matrix entry from the partial sums: Σ_a Σ_e w16[4a + e]·q[a·nc + e], summed per e over
/// a = 0…3 from zero, then (s₀ + s₁) + (s₂ + s₃).
#[inline(always)]
fn entry(q: &[f64], nc: usize, w16: &[f64; 16]) -> f64 {
    let mut s = [0.0; 4];
    for a in 0..4 {
        let v = &q[a * nc..a * nc + 4];
        let w = &w16[a * 4..a * 4 + 4];
        for e in 0..4 {
            s[e] += w[e] * v[e];
        }
    }
    (s[0] + s[1]) + (s[2] + s[3])
}

/// [`entry`] on 256-bit vectors: lane e accumulates s_e over a = 0…3 from zero with separate
/// multiplies and adds, and the horizontal add forms (s₀ + s₁) + (s₂ + s₃): the same value bit
/// for bit.
///
/// # Safety
/// The CPU must support AVX; `q` must hold at least `3·nc + 4` values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn entry_avx(q: &[f64], nc: usize, w16: &[f64; 16]) -> f64 {
    use std::arch::x86_64::{
        _mm_add_sd, _mm_cvtsd_f64, _mm256_add_pd, _mm256_castpd256_pd128, _mm256_extractf128_pd,
        _mm256_hadd_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd,
    };
    debug_assert!(q.len() >= 3 * nc + 4);
    let (qp, wp) = (q.as_ptr(), w16.as_ptr());
    let mut s = _mm256_setzero_pd();
    for a in 0..4 {
        // SAFETY: a·nc + 3 < 3·nc + 4 <= q.len(), and 4a + 3 < 16.
        let (v, w) = unsafe { (_mm256_loadu_pd(qp.add(a * nc)), _mm256_loadu_pd(wp.add(a * 4))) };
        s = _mm256_add_pd(s, _mm256_mul_pd(w, v));
    }
    // [s0 + s1, s0 + s1, s2 + s3, s2 + s3]
    let h = _mm256_hadd_pd(s, s);
    _mm_cvtsd_f64(_mm_add_sd(_mm256_castpd256_pd128(h), _mm256_extractf128_pd(h, 1)))
}

/// Four consecutive entries of one column by [`entry_avx`]'s arithmetic, added to `x`: lane
/// e of each observation's vector accumulates s_e over a = 0…3 from zero, and the horizontal
/// sums of the four are formed together — `hadd` pairs (s₀ + s₁, s₂ + s₃) of two
/// observations, the 128-bit halves exchanged, one add — as (s₀ + s₁) + (s₂ + s₃) each: the
/// same values bit for bit as four calls of [`entry`], with one vector add into the column
/// instead of four scalar ones.
///
/// # Safety
/// The CPU must support AVX; `partial` must hold `o.base + 3·nc + 4` values for each `o`, and
/// `x` 4 values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn entries4_avx(partial: &[f64], nc: usize, o: [&SliceWeights; 4], x: &mut [f64]) {
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_hadd_pd, _mm256_loadu_pd, _mm256_mul_pd,
        _mm256_permute2f128_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    debug_assert!(x.len() >= 4);
    let sum = |o: &SliceWeights| -> __m256d {
        debug_assert!(partial.len() >= o.base + 3 * nc + 4);
        let (qp, wp) = (partial.as_ptr(), o.w16.as_ptr());
        let mut s = _mm256_setzero_pd();
        for a in 0..4 {
            // SAFETY: o.base + a·nc + 3 < o.base + 3·nc + 4 <= partial.len(), and 4a + 3 < 16.
            let (v, w) = unsafe {
                (_mm256_loadu_pd(qp.add(o.base + a * nc)), _mm256_loadu_pd(wp.add(a * 4)))
            };
            s = _mm256_add_pd(s, _mm256_mul_pd(w, v));
        }
        s
    };
    let (a, b, c, d) = (sum(o[0]), sum(o[1]), sum(o[2]), sum(o[3]));
    // [a0 + a1, b0 + b1, a2 + a3, b2 + b3] and the same for c, d.
    let (ab, cd) = (_mm256_hadd_pd(a, b), _mm256_hadd_pd(c, d));
    // [a0 + a1, b0 + b1, c0 + c1, d0 + d1] + [a2 + a3, b2 + b3, c2 + c3, d2 + d3]
    let lo = _mm256_permute2f128_pd::<0x20>(ab, cd);
    let hi = _mm256_permute2f128_pd::<0x31>(ab, cd);
    let e = _mm256_add_pd(lo, hi);
    // SAFETY: x holds at least 4 values.
    unsafe {
        let xp = x.as_mut_ptr();
        _mm256_storeu_pd(xp, _mm256_add_pd(_mm256_loadu_pd(xp), e));
    }
}

/// Scratch memory of [`InterpolatedInfluence::add_matrix`] (grows to the largest sizes used,
/// then is reused).
#[derive(Debug, Clone, Default)]
pub struct MatrixWorkspace {
    load: Vec<PointWeights>,
    partial: Vec<f64>,
}

impl Compliance for InterpolatedInfluence {
    fn alpha(&self, obs: FlankCoord, load: FlankCoord, tooth_offset: i32) -> f64 {
        let Some(block) = self.block(tooth_offset) else {
            return 0.0;
        };
        let n = self.grid.points();
        let nc = self.grid.zeta.len();
        let (o, l) = (self.point_weights(obs), self.point_weights(load));
        // Load weights as one 4 × 4 tensor (zero-padded), so the inner loops have fixed length.
        let mut lw = [[0.0; 4]; 4];
        for (row, &wc) in lw.iter_mut().zip(&l.row.w).take(l.row.width) {
            for (v, &wd) in row.iter_mut().zip(&l.col.w).take(l.col.width) {
                *v = wc * wd;
            }
        }
        let mut s = 0.0;
        for a in 0..o.row.width {
            for b in 0..o.col.width {
                let wab = o.row.w[a] * o.col.w[b];
                if wab == 0.0 {
                    continue;
                }
                let base = ((o.row.start + a) * nc + o.col.start + b) * n;
                let mut sab = 0.0;
                for (c, lwc) in lw.iter().enumerate().take(l.row.width) {
                    let lb = base + (l.row.start + c) * nc + l.col.start;
                    let vals = &block[lb..lb + l.col.width];
                    sab += vals.iter().zip(lwc).map(|(v, w)| v * w).sum::<f64>();
                }
                s += wab * sab;
            }
        }
        s
    }

    fn depth(&self) -> f64 {
        self.grid.depth_h
    }

    fn max_tooth_offset(&self) -> i32 {
        self.grid.teeth.iter().map(|t| t.abs()).max().unwrap_or(0)
    }
}
