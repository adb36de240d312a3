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
struct Axis {
    nodes: Vec<f64>,
    slopes: Vec<Stencil>,
}

/// The interpolation weights of one coordinate value: `w[k]` multiplies node `start + k`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Weights {
    start: usize,
    width: usize,
    w: [f64; 4],
}

impl Axis {
    /// Builds the slope stencils; `nodes` must be strictly increasing with ≥ 2 entries.
    fn new(nodes: &[f64]) -> Self {
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
    fn weights(&self, x: f64) -> Weights {
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
