//! 3D finite elements (20-node serendipity hexahedra) for the global tooth deformation.
//!
//! Static, small-strain, isotropic linear elasticity: find u with K u = f, where
//! K = Σₑ ∫ Bᵀ D B dV is assembled from hex20 elements ([`element`]), the nodes of the bore
//! (or any other chosen set) are fixed at zero displacement by elimination ([`assembly`]), and
//! K_ff is factorised once by sparse Cholesky ([`solver`]) so that many load cases — columns of
//! an n × k block, e.g. unit loads at the flank nodes for an influence-coefficient matrix — are
//! solved by substitution only. When the loads sit on a few nodes and only a few nodes'
//! displacements are wanted, [`FeModel::solve_at_nodes`] substitutes over the part of the
//! factor that connects them only. [`FeModel::with_options`] can reuse the stiffness of
//! congruent elements ([`assembly::assemble_lower_congruent`]) and order the unknowns on the
//! node graph ([`ordering`]). Units are SI: m, N, Pa, N/m.
//!
//! Conventions used throughout:
//! - element node order: Abaqus C3D20 / VTK (8 corners, then 12 mid-edge nodes), see
//!   [`element`];
//! - global DOF of node n in direction d ∈ {0: x, 1: y, 2: z} is 3n + d ([`dof`]);
//! - fixed nodes have all three components zero; loads given on fixed DOFs are ignored (they go
//!   into the support reactions) and their displacements are returned as exactly 0;
//! - tied nodes ([`assembly::Tie`], the hanging nodes where elements of different size meet)
//!   move with their masters; a load on one goes to its masters, and its displacement is
//!   returned as the masters' weighted sum.
//!
//! Meshes are built from mapped structured blocks glued by node merging ([`mesh`]); the mesh
//! of a whole helical gear (teeth, fillets, web to the bore) is built by [`gear_mesh`].
//! Stresses at a point (in particular at a free surface) are recovered by [`stress`].
//!
//! ```
//! use helical_gear_mesh::compliance::fe::{FeModel, Material, Mesh, dof};
//! // A 0.1 × 0.02 × 0.02 m steel bar, clamped at x = 0, 5 N in z at one tip node.
//! let mesh = Mesh::structured_block([5, 1, 1], |u, v, w| [0.1 * u, 0.02 * v, 0.02 * w])?;
//! let fixed = mesh.nodes_where(|x| x[0] < 1e-9);
//! let tip = mesh.nodes_where(|x| x[0] > 0.1 - 1e-9)[0];
//! let model = FeModel::new(mesh, Material::new(206e9, 0.3)?, &fixed)?;
//! let mut f = faer::Mat::<f64>::zeros(model.dofs(), 1);
//! f[(dof(tip, 2), 0)] = 5.0;
//! let u = model.solve_block(f.as_ref())?;
//! assert!(u[(dof(tip, 2), 0)] > 0.0);
//! # Ok::<(), helical_gear_mesh::compliance::fe::FeError>(())
//! ```

pub mod assembly;
pub mod element;
pub mod error;
pub mod gear_mesh;
pub mod material;
pub mod mesh;
pub mod ordering;
pub mod solver;
pub mod stress;

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::Instant;

use faer::{Mat, MatRef};

pub use assembly::{DofMap, Tie};
pub use error::{FeError, JacobianError};
pub use material::Material;
pub use mesh::{Face, Mesh};
pub use solver::SparseCholesky;

/// Global DOF index of node `node` in direction `dir` (0: x, 1: y, 2: z): 3·node + dir.
pub const fn dof(node: usize, dir: usize) -> usize {
    3 * node + dir
}

/// Sizes and wall-clock times of an [`FeModel`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FeStats {
    /// Number of nodes.
    pub nodes: usize,
    /// Number of hex20 elements.
    pub elements: usize,
    /// Total DOFs, 3 × nodes.
    pub dofs: usize,
    /// Free (unknown) DOFs after elimination of the fixed nodes.
    pub free_dofs: usize,
    /// Stored non-zeros of K_ff (lower triangle with diagonal).
    pub stiffness_nonzeros: usize,
    /// Element stiffness computation and assembly, s.
    pub assembly_s: f64,
    /// Symbolic Cholesky analysis, s.
    pub symbolic_s: f64,
    /// Numeric Cholesky factorisation, s.
    pub numeric_s: f64,
    /// Accumulated time in [`FeModel::solve_block`] (gather, substitution, scatter), s.
    pub solve_s: f64,
    /// Accumulated number of load cases (right-hand-side columns) solved.
    pub solved_cases: usize,
}

impl FeStats {
    /// Symbolic plus numeric factorisation time, s.
    pub fn factorisation_s(&self) -> f64 {
        self.symbolic_s + self.numeric_s
    }

    /// Assembly, factorisation and solves together, s.
    pub fn total_s(&self) -> f64 {
        self.assembly_s + self.factorisation_s() + self.solve_s
    }
}

/// How [`FeModel::with_options`] assembles K_ff and orders its unknowns. The default is
/// [`FeModel::new`]'s: every element integrated, faer's AMD on the DOF graph.
#[derive(Debug, Clone, Copy, Default)]
pub struct ModelOptions<'a> {
    /// Elements whose stiffness is that of another turned about z
    /// ([`assembly::assemble_lower_congruent`], e.g.
    /// [`gear_mesh::GearMesh::layer_congruence`]); empty: every element integrated.
    pub congruent: &'a [Option<assembly::Congruent>],
    /// Order the unknowns by AMD on the node graph ([`ordering`]) instead of on the DOF graph.
    pub node_ordering: bool,
    /// Tied (hanging) nodes and their masters ([`assembly::Tie`]); empty: none.
    pub ties: &'a [Tie],
}

/// An assembled and factorised linear-elastic FE model, ready for block solves.
///
/// Immutable after construction except for the solve-time counters, which are atomic, so a
/// model can be shared between threads (`&FeModel` is `Sync`).
#[derive(Debug)]
pub struct FeModel {
    mesh: Mesh,
    material: Material,
    dof_map: DofMap,
    cholesky: SparseCholesky,
    stats: FeStats,
    solve_s_bits: AtomicU64,
    solved_cases: AtomicUsize,
}

impl FeModel {
    /// Validates the inputs, assembles K_ff with all DOFs of `fixed_nodes` eliminated, and
    /// factorises it.
    ///
    /// Errors: invalid material or mesh, a fixed node out of range, a connected part of the
    /// mesh without at least three fixed nodes off one line ([`FeError::Underconstrained`]), an
    /// element with non-positive Jacobian ([`FeError::NonPositiveJacobian`]), or a failed
    /// factorisation ([`FeError::NotPositiveDefinite`], [`FeError::Solver`]).
    pub fn new(mesh: Mesh, material: Material, fixed_nodes: &[usize]) -> Result<Self, FeError> {
        Self::with_options(mesh, material, fixed_nodes, &ModelOptions::default())
    }

    /// As [`FeModel::new`], assembled and ordered as `options` says. The same K_ff to
    /// rounding, and the same solution to rounding.
    pub fn with_options(
        mesh: Mesh,
        material: Material,
        fixed_nodes: &[usize],
        options: &ModelOptions<'_>,
    ) -> Result<Self, FeError> {
        material.validate()?;
        mesh.validate()?;
        let t0 = Instant::now();
        let dof_map = DofMap::with_ties(mesh.nodes.len(), fixed_nodes, options.ties)?;
        check_constraints(&mesh, fixed_nodes)?;
        let k = assembly::assemble_lower_congruent(&mesh, &material, &dof_map, options.congruent)?;
        let assembly_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let order = if options.node_ordering {
            Some(ordering::expand_to_free_dofs(&ordering::node_amd(&mesh, &dof_map)?, &dof_map)?)
        } else {
            None
        };
        let ordering_s = t1.elapsed().as_secs_f64();
        let (cholesky, mut times) = SparseCholesky::with_ordering(&k, order.as_deref())?;
        times.symbolic_s += ordering_s;
        let stats = FeStats {
            nodes: mesh.nodes.len(),
            elements: mesh.elements.len(),
            dofs: dof_map.dof_count(),
            free_dofs: dof_map.free_count(),
            stiffness_nonzeros: k.compute_nnz(),
            assembly_s,
            symbolic_s: times.symbolic_s,
            numeric_s: times.numeric_s,
            solve_s: 0.0,
            solved_cases: 0,
        };
        Ok(Self {
            mesh,
            material,
            dof_map,
            cholesky,
            stats,
            solve_s_bits: AtomicU64::new(0.0f64.to_bits()),
            solved_cases: AtomicUsize::new(0),
        })
    }

    /// The mesh (m).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The material.
    pub fn material(&self) -> Material {
        self.material
    }

    /// Total number of DOFs, 3 × nodes; the row count of load and displacement blocks.
    pub fn dofs(&self) -> usize {
        self.dof_map.dof_count()
    }

    /// The numbering of free DOFs (fixed DOFs eliminated).
    pub fn dof_map(&self) -> &DofMap {
        &self.dof_map
    }

    /// Whether global DOF `dof` is fixed (true also for a DOF that does not exist; false for a
    /// tied node's DOF, which moves with its masters).
    pub fn is_fixed(&self, dof: usize) -> bool {
        self.dof_map.free_index(dof).is_none() && self.dof_map.tie(dof / 3).is_none()
    }

    /// Sizes and timings, including the solve time accumulated so far.
    pub fn stats(&self) -> FeStats {
        FeStats {
            solve_s: f64::from_bits(self.solve_s_bits.load(Ordering::Relaxed)),
            solved_cases: self.solved_cases.load(Ordering::Relaxed),
            ..self.stats
        }
    }

    /// Displacements (m) for a block of load cases.
    ///
    /// `loads` is dofs() × k: column j holds the nodal forces (N) of load case j at global DOFs
    /// 3n + d. Returns the dofs() × k displacement block; fixed DOFs are exactly zero and loads
    /// on them are ignored; a tied node's load goes to its masters and its displacement is
    /// theirs interpolated. Errors: wrong row count or a non-finite load.
    pub fn solve_block(&self, loads: MatRef<'_, f64>) -> Result<Mat<f64>, FeError> {
        let t0 = Instant::now();
        let n = self.dofs();
        if loads.nrows() != n {
            return Err(FeError::LoadShape { rows: loads.nrows(), expected: n });
        }
        let k = loads.ncols();
        for j in 0..k {
            for i in 0..n {
                if !loads[(i, j)].is_finite() {
                    return Err(FeError::NonFiniteLoad { row: i, col: j });
                }
            }
        }
        let mut x = Mat::<f64>::zeros(self.dof_map.free_count(), k);
        for j in 0..k {
            for g in 0..n {
                for (fi, w) in self.dof_map.unknowns_of(g) {
                    x[(fi, j)] += w * loads[(g, j)];
                }
            }
        }
        self.cholesky.solve_in_place(x.as_mut())?;
        let mut u = Mat::<f64>::zeros(n, k);
        for j in 0..k {
            for g in 0..n {
                u[(g, j)] = self.dof_map.unknowns_of(g).map(|(fi, w)| w * x[(fi, j)]).sum();
            }
        }
        let dt = t0.elapsed().as_secs_f64();
        // The closure always returns Some, so the update cannot fail.
        let _ = self.solve_s_bits.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |b| {
            Some((f64::from_bits(b) + dt).to_bits())
        });
        self.solved_cases.fetch_add(k, Ordering::Relaxed);
        Ok(u)
    }

    /// Displacements (m) at the nodes `nodes` for load cases given sparsely: `loads[c]` lists
    /// the (global DOF, force in N) pairs of load case c. Returns the (3·nodes.len()) × k
    /// block whose row 3i + d is the displacement of `nodes[i]` in direction d; fixed DOFs are
    /// exactly zero and loads on them are ignored; tied nodes as in [`FeModel::solve_block`].
    /// The values are those of [`FeModel::solve_block`] at these DOFs, computed by the selected solve of
    /// [`solver`] (only the substitution steps that reach the loads or the wanted DOFs).
    /// Errors: a DOF or node out of range, or a non-finite load.
    pub fn solve_at_nodes(
        &self,
        loads: &[Vec<(usize, f64)>],
        nodes: &[usize],
    ) -> Result<Mat<f64>, FeError> {
        let t0 = Instant::now();
        let n = self.dofs();
        let mut free_loads = Vec::with_capacity(loads.len());
        for (c, col) in loads.iter().enumerate() {
            let mut fc = Vec::with_capacity(col.len());
            for &(g, v) in col {
                if g >= n {
                    return Err(FeError::LoadShape { rows: g + 1, expected: n });
                }
                if !v.is_finite() {
                    return Err(FeError::NonFiniteLoad { row: g, col: c });
                }
                fc.extend(self.dof_map.unknowns_of(g).map(|(fi, w)| (fi, w * v)));
            }
            free_loads.push(fc);
        }
        // Each wanted free DOF once; each output row a weighted sum of them (one term for an
        // untied node, the masters for a tied one).
        let mut wanted = Vec::with_capacity(3 * nodes.len());
        let mut position = std::collections::HashMap::new();
        let mut terms: Vec<(usize, usize, f64)> = Vec::with_capacity(3 * nodes.len());
        for (i, &node) in nodes.iter().enumerate() {
            if node >= self.mesh.nodes.len() {
                return Err(FeError::InvalidInput(format!(
                    "solve_at_nodes: node {node} ≥ {} nodes",
                    self.mesh.nodes.len()
                )));
            }
            for d in 0..3 {
                for (fi, w) in self.dof_map.unknowns_of(dof(node, d)) {
                    let p = *position.entry(fi).or_insert_with(|| {
                        wanted.push(fi);
                        wanted.len() - 1
                    });
                    terms.push((3 * i + d, p, w));
                }
            }
        }
        let x = self.cholesky.solve_selected(&free_loads, &wanted)?;
        let k = loads.len();
        let mut u = Mat::<f64>::zeros(3 * nodes.len(), k);
        for j in 0..k {
            for &(r, p, w) in &terms {
                u[(r, j)] += w * x[(p, j)];
            }
        }
        let dt = t0.elapsed().as_secs_f64();
        // The closure always returns Some, so the update cannot fail.
        let _ = self.solve_s_bits.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |b| {
            Some((f64::from_bits(b) + dt).to_bits())
        });
        self.solved_cases.fetch_add(k, Ordering::Relaxed);
        Ok(u)
    }

    /// Displacements (m) for one load case given as a slice of dofs() nodal forces (N).
    pub fn solve(&self, loads: &[f64]) -> Result<Vec<f64>, FeError> {
        let f = MatRef::from_column_major_slice(loads, loads.len(), 1);
        let u = self.solve_block(f)?;
        Ok((0..u.nrows()).map(|i| u[(i, 0)]).collect())
    }
}

/// Checks that every connected part of the mesh has at least three fixed nodes not on one
/// straight line, so that the eliminated system has no rigid-body mode.
///
/// Distances below 1e-9 × (bounding-box diagonal) count as zero.
fn check_constraints(mesh: &Mesh, fixed_nodes: &[usize]) -> Result<(), FeError> {
    let nn = mesh.nodes.len();
    let mut parent: Vec<usize> = (0..nn).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for conn in &mesh.elements {
        let r0 = find(&mut parent, conn[0]);
        for &n in &conn[1..] {
            let r = find(&mut parent, n);
            if r != r0 {
                parent[r] = r0;
            }
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for x in &mesh.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    let eps =
        1e-9 * ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let sub = |a: &[f64; 3], b: &[f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    };
    // Per part (indexed by root): fixed count, first fixed node, a second one off the first,
    // and whether a third off their line exists.
    #[derive(Clone, Copy)]
    struct Part {
        fixed: usize,
        p0: Option<usize>,
        p1: Option<usize>,
        ok: bool,
    }
    let mut parts = vec![Part { fixed: 0, p0: None, p1: None, ok: false }; nn];
    let mut seen = vec![false; nn];
    for &n in fixed_nodes {
        if n >= nn || std::mem::replace(&mut seen[n], true) {
            continue;
        }
        let r = find(&mut parent, n);
        let p = &mut parts[r];
        p.fixed += 1;
        let x = &mesh.nodes[n];
        match (p.p0, p.p1) {
            (None, _) => p.p0 = Some(n),
            (Some(a), None) if norm(sub(x, &mesh.nodes[a])) > eps => p.p1 = Some(n),
            (Some(a), Some(b)) if !p.ok => {
                let (xa, xb) = (&mesh.nodes[a], &mesh.nodes[b]);
                let d = sub(xb, xa);
                let dist = norm(cross(d, sub(x, xa))) / norm(d);
                p.ok = dist > eps;
            }
            _ => {}
        }
    }
    // Report the part containing the lowest-numbered node.
    let mut size = vec![0usize; nn];
    for i in 0..nn {
        let r = find(&mut parent, i);
        size[r] += 1;
    }
    for i in 0..nn {
        let r = find(&mut parent, i);
        if !parts[r].ok {
            return Err(FeError::Underconstrained {
                example_node: i,
                part_nodes: size[r],
                fixed_nodes: parts[r].fixed,
            });
        }
    }
    Ok(())
}
