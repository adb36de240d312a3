//! Global stiffness assembly with Dirichlet constraints by elimination.
//!
//! Global DOF numbering: node n has DOFs 3n, 3n + 1, 3n + 2 for x, y, z. Fixed nodes have all
//! three displacement components held at zero; their DOFs are *eliminated*: the remaining
//! (free) DOFs are renumbered 0, 1, … in increasing global order ([`DofMap`]) and only the
//! free–free block K_ff of K = Σₑ Kₑ is assembled. No penalty terms are used, so the
//! conditioning of K_ff is that of the physical problem.
//!
//! K_ff is stored as a faer compressed-sparse-column matrix holding the **lower triangle**
//! (row ≥ column, diagonal included), the half read by the Cholesky factorisation. Its
//! pattern is built first from the node graph (two nodes couple when they share an element),
//! with sorted row indices; element matrices are then added in place. This costs one entry per
//! stored non-zero instead of one triplet per element-matrix entry (≈ 1830 per hex20 element,
//! several times the final non-zero count), which matters for gear meshes of 10⁵ DOFs.
//!
//! # Tied nodes
//! Where elements of different axial size meet (a fine element's face on half or a third of a
//! coarse element's face), the fine side has nodes that are not nodes of the coarse element:
//! *hanging* nodes. Each is tied to the coarse face ([`Tie`]): u_s = Σ_m w_m u_m for every
//! component alike, with w_m the coarse element's shape functions at the hanging node, so the
//! displacement field stays continuous across the interface (the serendipity face space
//! restricted to a part of the face cut at a constant face coordinate is in the fine face's
//! space). A tied node has no unknowns of its own: with T the map from the unknowns to all
//! DOFs (identity rows for untied DOFs, the weights for tied ones), the assembled matrix is
//! Tᵀ K T and a load on a tied node goes to its masters with the same weights (the virtual work
//! of the load is kept). An element holding a tied node couples all of its untied nodes and
//! all the masters of its tied ones; [`DofMap::element_nodes`] gives that list.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

use super::element::{self, DOFS, NODES};
use super::error::FeError;
use super::material::Material;
use super::mesh::Mesh;

/// Marker for a fixed (eliminated) DOF in [`DofMap`].
const FIXED: usize = usize::MAX;

/// A tied node (see the module docs): its displacement is Σ w·u over its masters, the same
/// weights for x, y and z.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// The tied (hanging) node.
    pub node: usize,
    /// (master node, weight) pairs; masters are not tied themselves. Weights are
    /// dimensionless (shape-function values, summing to 1 for an interpolation).
    pub masters: Vec<(usize, f64)>,
}

/// Numbering of the free DOFs after elimination of the fixed nodes and the tied nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    /// Global DOF → free index, or `FIXED` (a fixed or a tied node's DOF).
    free_of: Vec<usize>,
    /// Free index → global DOF.
    global_of: Vec<usize>,
    /// Node → index into `ties`, or `FIXED` (not tied).
    tie_of: Vec<usize>,
    /// Masters and weights of each tie, fixed masters left out (they do not move).
    ties: Vec<Vec<(usize, f64)>>,
}

impl DofMap {
    /// Numbering for a mesh of `nodes` nodes with all three DOFs of each node in `fixed_nodes`
    /// held at zero (duplicates allowed). Error: a fixed node index ≥ `nodes`.
    pub fn new(nodes: usize, fixed_nodes: &[usize]) -> Result<Self, FeError> {
        Self::with_ties(nodes, fixed_nodes, &[])
    }

    /// As [`DofMap::new`] with the nodes of `ties` tied to their masters. A tie of a fixed
    /// node is ignored (the node stays fixed). Errors: a node out of range, a node tied twice,
    /// a master that is tied itself or is the node, or a non-finite weight.
    pub fn with_ties(nodes: usize, fixed_nodes: &[usize], ties: &[Tie]) -> Result<Self, FeError> {
        let mut fixed = vec![false; nodes];
        for &n in fixed_nodes {
            *fixed.get_mut(n).ok_or(FeError::FixedNodeOutOfRange { node: n, nodes })? = true;
        }
        let mut tie_of = vec![FIXED; nodes];
        let mut lists = Vec::new();
        for t in ties {
            let bad = |why: &str| FeError::InvalidInput(format!("tie of node {}: {why}", t.node));
            if t.node >= nodes {
                return Err(bad(&format!("node out of range ({nodes} nodes)")));
            }
            if tie_of[t.node] != FIXED {
                return Err(bad("node tied twice"));
            }
            if t.masters.iter().any(|&(m, w)| m >= nodes || m == t.node || !w.is_finite()) {
                return Err(bad("a master out of range, the node itself, or a non-finite weight"));
            }
            if fixed[t.node] {
                continue;
            }
            tie_of[t.node] = lists.len();
            lists.push(t.masters.iter().copied().filter(|&(m, _)| !fixed[m]).collect::<Vec<_>>());
        }
        if let Some(t) = ties.iter().find(|t| t.masters.iter().any(|&(m, _)| tie_of[m] != FIXED)) {
            return Err(FeError::InvalidInput(format!(
                "tie of node {}: a master is tied itself",
                t.node
            )));
        }
        let mut free_of = vec![FIXED; 3 * nodes];
        let mut global_of = Vec::with_capacity(3 * nodes);
        for n in 0..nodes {
            if !fixed[n] && tie_of[n] == FIXED {
                for (i, slot) in free_of[3 * n..3 * n + 3].iter_mut().enumerate() {
                    *slot = global_of.len();
                    global_of.push(3 * n + i);
                }
            }
        }
        Ok(Self { free_of, global_of, tie_of, ties: lists })
    }

    /// The masters and weights of node `node` if it is tied (fixed masters left out).
    pub fn tie(&self, node: usize) -> Option<&[(usize, f64)]> {
        let t = *self.tie_of.get(node)?;
        self.ties.get(t).map(Vec::as_slice)
    }

    /// The unknowns global DOF `dof` moves with, as (free index, weight) pairs: itself with
    /// weight 1 when free, the same-direction DOFs of its node's masters when tied, none when
    /// fixed or out of range. A load on `dof` goes to these unknowns with these weights and its
    /// displacement is their weighted sum (Tᵀ and T of the module docs).
    pub fn unknowns_of(&self, dof: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let own = self.free_index(dof).map(|fi| (fi, 1.0));
        let masters = self.tie(dof / 3).unwrap_or(&[]);
        own.into_iter().chain(
            masters.iter().filter_map(move |&(m, w)| Some((self.free_index(3 * m + dof % 3)?, w))),
        )
    }

    /// Whether any node is tied.
    pub fn has_ties(&self) -> bool {
        !self.ties.is_empty()
    }

    /// The nodes an element with nodes `conn` couples in K_ff: its nodes, each tied node
    /// replaced by its masters, without fixed nodes, ascending and without repeats. Written to
    /// `out` (cleared first).
    pub fn element_nodes(&self, conn: &[usize], out: &mut Vec<usize>) {
        out.clear();
        for &n in conn {
            match self.tie(n) {
                Some(m) => out.extend(m.iter().map(|&(n, _)| n)),
                None if self.free_of[3 * n] != FIXED => out.push(n),
                None => {}
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Total number of DOFs (3 × nodes).
    pub fn dof_count(&self) -> usize {
        self.free_of.len()
    }

    /// Number of free DOFs.
    pub fn free_count(&self) -> usize {
        self.global_of.len()
    }

    /// Free index of global DOF `dof`, or `None` if it is fixed or does not exist.
    pub fn free_index(&self, dof: usize) -> Option<usize> {
        self.free_of.get(dof).copied().filter(|&i| i != FIXED)
    }

    /// Global DOF of each free index, ascending.
    pub fn free_dofs(&self) -> &[usize] {
        &self.global_of
    }
}

/// An element whose stiffness is that of another element turned about the z axis: its node
/// a sits at Rot_z(`angle`)·x_a(`source`) + t for one translation t (all 20 nodes, same order).
/// Then K_e = Q·K_source·Qᵀ with Q = diag(R, …, R), R the 3×3 rotation by `angle`: the strain
/// energy of a rigidly moved element is that of the original under the rotated displacements.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Congruent {
    /// The element whose stiffness is computed (an element with no congruence of its own).
    pub source: usize,
    /// Rotation about the z axis from `source` to this element, rad.
    pub angle: f64,
}

/// Assembles the lower triangle of the free–free stiffness block K_ff (N/m) of `mesh`.
///
/// The mesh must satisfy [`Mesh::validate`] and `dofs` must be built for its node count.
/// Errors: [`FeError::NonPositiveJacobian`] naming the first bad element, or an invalid mesh.
pub fn assemble_lower(
    mesh: &Mesh,
    material: &Material,
    dofs: &DofMap,
) -> Result<SparseColMat<usize, f64>, FeError> {
    assemble_lower_congruent(mesh, material, dofs, &[])
}

/// [`assemble_lower`] with element stiffnesses reused: element e with
/// `congruent[e] = Some(c)` gets Q·K_{c.source}·Qᵀ (see [`Congruent`]) instead of its own
/// Gauss integration; `congruent` may be shorter than the element list (the rest is
/// integrated). Each claimed congruence is checked on the node coordinates (every node within
/// 1e-9 of the element's size of the rotated and translated source node); an element that
/// fails the check, or whose source is itself congruent, is integrated. The result equals
/// [`assemble_lower`]'s up to rounding (≈ 1e-16 relative per entry).
pub fn assemble_lower_congruent(
    mesh: &Mesh,
    material: &Material,
    dofs: &DofMap,
    congruent: &[Option<Congruent>],
) -> Result<SparseColMat<usize, f64>, FeError> {
    material.validate()?;
    mesh.validate()?;
    if dofs.dof_count() != 3 * mesh.nodes.len() {
        return Err(FeError::InvalidInput(format!(
            "DOF map for {} DOFs used with a mesh of {} nodes",
            dofs.dof_count(),
            mesh.nodes.len()
        )));
    }
    let (col_ptr, row_idx) = lower_pattern(mesh, dofs);
    // Zeros written, not requested zeroed from the allocator: the first `+=` to a page of
    // calloc'd memory would fault twice (read of the shared zero page, then copy on write).
    let mut values = Vec::with_capacity(row_idx.len());
    values.resize(row_idx.len(), 0.0);
    // Stiffness of every source element (integrated once), keyed by element.
    let ne = mesh.elements.len();
    let mut source_slot = vec![usize::MAX; ne];
    let mut sources: Vec<Box<[[f64; DOFS]; DOFS]>> = Vec::new();
    let valid = |e: usize| -> Option<Congruent> {
        let c = (*congruent.get(e)?)?;
        if c.source >= ne || c.source == e || congruent.get(c.source).copied().flatten().is_some() {
            return None;
        }
        is_congruent(mesh, c.source, e, c.angle).then_some(c)
    };
    let plan: Vec<Option<Congruent>> = (0..ne).map(valid).collect();
    for c in plan.iter().flatten() {
        if source_slot[c.source] == usize::MAX {
            source_slot[c.source] = sources.len();
            let coords = element_coords(mesh, c.source);
            let mut ke = Box::new([[0.0; DOFS]; DOFS]);
            element::stiffness(&coords, material, &mut ke)
                .map_err(|err| err.in_element(c.source))?;
            sources.push(ke);
        }
    }
    let mut ke = [[0.0; DOFS]; DOFS];
    let mut base = [FIXED; NODES];
    let mut work = TiedWork::default();
    for (e, conn) in mesh.elements.iter().enumerate() {
        let (k, rot) = match plan[e] {
            Some(c) => (&*sources[source_slot[c.source]], Some(rotation(c.angle))),
            None if source_slot[e] != usize::MAX => (&*sources[source_slot[e]], None),
            None => {
                let coords = element_coords(mesh, e);
                element::stiffness(&coords, material, &mut ke).map_err(|err| err.in_element(e))?;
                (&ke, None)
            }
        };
        if dofs.has_ties() && conn.iter().any(|&n| dofs.tie_of[n] != FIXED) {
            scatter_tied(k, rot.as_ref(), conn, dofs, &mut work, &col_ptr, &row_idx, &mut values)?;
        } else {
            for (a, &n) in conn.iter().enumerate() {
                base[a] = dofs.free_of[3 * n];
            }
            scatter(|a, b| block(k, a, b, rot.as_ref()), &base, &col_ptr, &row_idx, &mut values)?;
        }
    }
    let n = dofs.free_count();
    let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Ok(SparseColMat::new(symbolic, values))
}

fn element_coords(mesh: &Mesh, e: usize) -> [[f64; 3]; NODES] {
    mesh.elements[e].map(|n| mesh.nodes[n])
}

/// Whether element `e`'s nodes are those of `source` turned by `angle` about z and translated.
fn is_congruent(mesh: &Mesh, source: usize, e: usize, angle: f64) -> bool {
    let (s, c) = angle.sin_cos();
    let xs = element_coords(mesh, source);
    let xe = element_coords(mesh, e);
    let turn = |p: [f64; 3]| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
    let r0 = turn(xs[0]);
    let t = [xe[0][0] - r0[0], xe[0][1] - r0[1], xe[0][2] - r0[2]];
    let size = xs.iter().fold(0.0f64, |m, p| {
        m.max((p[0] - xs[0][0]).abs()).max((p[1] - xs[0][1]).abs()).max((p[2] - xs[0][2]).abs())
    });
    let tol = 1e-9 * size;
    xs.iter().zip(xe.iter()).all(|(p, q)| {
        let r = turn(*p);
        (0..3).all(|k| (r[k] + t[k] - q[k]).abs() <= tol)
    })
}

/// The rotation by `angle` about z.
fn rotation(angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// The 3 × 3 block (a, b) of the element matrix `k`, turned to R·K_ab·Rᵀ when `rot` = R.
fn block(
    k: &[[f64; DOFS]; DOFS],
    a: usize,
    b: usize,
    rot: Option<&[[f64; 3]; 3]>,
) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        row.copy_from_slice(&k[3 * a + i][3 * b..3 * b + 3]);
    }
    let Some(r) = rot else { return m };
    // t = R·K_ab, then R·K_ab·Rᵀ.
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = r[i][0] * m[0][j] + r[i][1] * m[1][j] + r[i][2] * m[2][j];
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = t[i][0] * r[j][0] + t[i][1] * r[j][1] + t[i][2] * r[j][2];
        }
    }
    m
}

/// Adds the lower-triangle entries of an element matrix to `values`: `get(a, b)` is the 3 × 3
/// block of element nodes a and b (for an element matrix `k`, [`block`], turned by the
/// element's rotation), `base[a]` the free index of the x DOF of node a (its y, z DOFs
/// follow) or `FIXED`. The pattern of column jb + j (node b's DOF j) is that of column jb
/// without its first j rows, and a node's three rows are consecutive in it, so one search per
/// node pair places nine entries. Each entry receives one addition per element, in element
/// order.
fn scatter(
    get: impl Fn(usize, usize) -> [[f64; 3]; 3],
    base: &[usize],
    col_ptr: &[usize],
    row_idx: &[usize],
    values: &mut [f64],
) -> Result<(), FeError> {
    for (b, &jb) in base.iter().enumerate() {
        if jb == FIXED {
            continue;
        }
        let rows = &row_idx[col_ptr[jb]..col_ptr[jb + 1]];
        for (a, &ia) in base.iter().enumerate() {
            if ia == FIXED || ia < jb {
                continue;
            }
            let m = get(a, b);
            if ia == jb {
                // Column jb + j starts with its own diagonal: row jb + i sits at i − j.
                for j in 0..3 {
                    let s = col_ptr[jb + j];
                    for i in j..3 {
                        values[s + i - j] += m[i][j];
                    }
                }
            } else {
                let k0 = rows.binary_search(&ia).map_err(|_| {
                    FeError::Solver(format!("internal: entry ({ia}, {jb}) missing from pattern"))
                })?;
                for j in 0..3 {
                    let s = col_ptr[jb + j] + k0 - j;
                    for i in 0..3 {
                        values[s + i] += m[i][j];
                    }
                }
            }
        }
    }
    Ok(())
}

/// Scratch space of [`scatter_tied`], kept between elements.
#[derive(Default)]
struct TiedWork {
    /// The nodes the element couples ([`DofMap::element_nodes`]).
    nodes: Vec<usize>,
    /// Free index of each coupled node's x DOF.
    base: Vec<usize>,
    /// For each element node: (index into `nodes`, weight) of what it moves with.
    map: Vec<Vec<(usize, f64)>>,
    /// Blocks of Tᵀ K T, row-major over `nodes`.
    blocks: Vec<[[f64; 3]; 3]>,
}

/// [`scatter`] for an element holding tied nodes: its matrix `k` (turned by `rot`) becomes
/// Tᵀ K T over the nodes it couples (see the module docs), then is added.
#[allow(clippy::too_many_arguments)]
fn scatter_tied(
    k: &[[f64; DOFS]; DOFS],
    rot: Option<&[[f64; 3]; 3]>,
    conn: &[usize; NODES],
    dofs: &DofMap,
    w: &mut TiedWork,
    col_ptr: &[usize],
    row_idx: &[usize],
    values: &mut [f64],
) -> Result<(), FeError> {
    dofs.element_nodes(conn, &mut w.nodes);
    let m = w.nodes.len();
    let at = |nodes: &[usize], n: usize| {
        nodes
            .binary_search(&n)
            .map_err(|_| FeError::Solver(format!("internal: node {n} missing from its element")))
    };
    w.map.resize(NODES, Vec::new());
    for (a, &n) in conn.iter().enumerate() {
        w.map[a].clear();
        match dofs.tie(n) {
            Some(masters) => {
                for &(mn, wt) in masters {
                    let i = at(&w.nodes, mn)?;
                    w.map[a].push((i, wt));
                }
            }
            None if dofs.free_of[3 * n] != FIXED => {
                let i = at(&w.nodes, n)?;
                w.map[a].push((i, 1.0));
            }
            None => {}
        }
    }
    w.blocks.clear();
    w.blocks.resize(m * m, [[0.0; 3]; 3]);
    for a in 0..NODES {
        for b in 0..NODES {
            if w.map[a].is_empty() || w.map[b].is_empty() {
                continue;
            }
            let blk = block(k, a, b, rot);
            for &(ia, wa) in &w.map[a] {
                for &(ib, wb) in &w.map[b] {
                    let t = &mut w.blocks[ia * m + ib];
                    for (ti, bi) in t.iter_mut().zip(blk.iter()) {
                        for (tij, bij) in ti.iter_mut().zip(bi.iter()) {
                            *tij += wa * wb * bij;
                        }
                    }
                }
            }
        }
    }
    w.base.clear();
    w.base.extend(w.nodes.iter().map(|&n| dofs.free_of[3 * n]));
    let blocks = &w.blocks;
    scatter(|a, b| blocks[a * m + b], &w.base, col_ptr, row_idx, values)
}

/// The nodes each element couples ([`DofMap::element_nodes`]: tied nodes replaced by their
/// masters, fixed nodes left out) in compressed form, element e's being
/// `nodes[start[e]..start[e + 1]]`, and the node → element incidence over these lists (the
/// elements coupling node n are `incident[node_start[n]..node_start[n + 1]]`, ascending).
pub(super) struct Coupling {
    pub start: Vec<usize>,
    pub nodes: Vec<usize>,
    pub node_start: Vec<usize>,
    pub incident: Vec<usize>,
}

impl Coupling {
    pub(super) fn new(mesh: &Mesh, dofs: &DofMap) -> Self {
        let nn = mesh.nodes.len();
        let mut start = Vec::with_capacity(mesh.elements.len() + 1);
        start.push(0);
        let mut nodes = Vec::with_capacity(NODES * mesh.elements.len());
        let mut list = Vec::with_capacity(NODES);
        for conn in &mesh.elements {
            dofs.element_nodes(conn, &mut list);
            nodes.extend_from_slice(&list);
            start.push(nodes.len());
        }
        let mut node_start = vec![0usize; nn + 1];
        for &n in &nodes {
            node_start[n + 1] += 1;
        }
        for i in 0..nn {
            node_start[i + 1] += node_start[i];
        }
        let mut fill = node_start.clone();
        let mut incident = vec![0usize; nodes.len()];
        for e in 0..mesh.elements.len() {
            for &n in &nodes[start[e]..start[e + 1]] {
                incident[fill[n]] = e;
                fill[n] += 1;
            }
        }
        Self { start, nodes, node_start, incident }
    }

    /// The nodes element `e` couples.
    pub(super) fn element(&self, e: usize) -> &[usize] {
        &self.nodes[self.start[e]..self.start[e + 1]]
    }

    /// The elements coupling node `n`.
    pub(super) fn elements_of(&self, n: usize) -> &[usize] {
        &self.incident[self.node_start[n]..self.node_start[n + 1]]
    }
}

/// Column pointers and sorted row indices of the lower triangle of K_ff.
fn lower_pattern(mesh: &Mesh, dofs: &DofMap) -> (Vec<usize>, Vec<usize>) {
    let nn = mesh.nodes.len();
    let coupling = Coupling::new(mesh, dofs);
    let mut col_ptr = Vec::with_capacity(dofs.free_count() + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    let mut mark = vec![usize::MAX; nn];
    let mut neigh: Vec<usize> = Vec::new();
    for c in 0..nn {
        neigh.clear();
        for &e in coupling.elements_of(c) {
            for &r in coupling.element(e) {
                if r >= c && mark[r] != c {
                    mark[r] = c;
                    neigh.push(r);
                }
            }
        }
        neigh.sort_unstable();
        for b in 0..3 {
            let jc = dofs.free_of[3 * c + b];
            if jc == FIXED {
                continue;
            }
            for &r in &neigh {
                for q in 0..3 {
                    let ir = dofs.free_of[3 * r + q];
                    if ir != FIXED && ir >= jc {
                        row_idx.push(ir);
                    }
                }
            }
            col_ptr.push(row_idx.len());
        }
    }
    (col_ptr, row_idx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// A distorted 2 × 2 × 1 block of steel-like elements and its nodes at x = 0.
    fn distorted_block() -> (Mesh, Material, Vec<usize>) {
        let mesh = Mesh::structured_block([2, 2, 1], |u, v, w| {
            [u + 0.1 * v * v, v + 0.05 * u * w, 0.5 * w + 0.1 * u * v]
        })
        .expect("block");
        let fixed = mesh.nodes_where(|x| x[0] < 1e-12);
        (mesh, Material { e: 200e9, nu: 0.3 }, fixed)
    }

    /// The pattern-based assembly equals a plain triplet assembly of the element matrices.
    #[test]
    fn matches_triplet_assembly() {
        let (mesh, material, fixed) = distorted_block();
        let dofs = DofMap::new(mesh.nodes.len(), &fixed).expect("dofs");
        let k = assemble_lower(&mesh, &material, &dofs).expect("assemble");
        let n = dofs.free_count();
        let mut triplets = Vec::new();
        let mut ke = [[0.0; DOFS]; DOFS];
        for (e, conn) in mesh.elements.iter().enumerate() {
            let coords = mesh.element_coords(e).expect("coords");
            element::stiffness(&coords, &material, &mut ke).expect("element");
            for (a, &na) in conn.iter().enumerate() {
                for (b, &nb) in conn.iter().enumerate() {
                    for i in 0..3 {
                        for j in 0..3 {
                            if let (Some(r), Some(c)) =
                                (dofs.free_index(3 * na + i), dofs.free_index(3 * nb + j))
                                && r >= c
                            {
                                triplets.push(Triplet::new(r, c, ke[3 * a + i][3 * b + j]));
                            }
                        }
                    }
                }
            }
        }
        let reference =
            SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets).expect("triplets");
        let dense_a = k.to_dense();
        let dense_b = reference.to_dense();
        let scale = dense_b.norm_max();
        assert!((&dense_a - &dense_b).norm_max() <= 1e-14 * scale);
        // Free numbering skips exactly the fixed nodes' DOFs.
        assert_eq!(n, 3 * (mesh.nodes.len() - fixed.len()));
        assert_eq!(dofs.free_index(3 * fixed[0]), None);
        assert!(DofMap::new(3, &[3]).is_err());
    }

    /// With tied nodes the assembled K_ff equals Tᵀ K T (dense), T mapping the unknowns to all
    /// DOFs (identity on untied free DOFs, the weights on tied ones, zero on fixed ones); and
    /// the map rejects a tie of a master, a node tied twice, and a tie out of range.
    #[test]
    fn tied_assembly_is_the_transformed_matrix() {
        let (mesh, material, fixed) = distorted_block();
        let nn = mesh.nodes.len();
        // Tie two free nodes to others (one master fixed), as a hanging node would be.
        let free: Vec<usize> = (0..nn).filter(|n| !fixed.contains(n)).collect();
        let ties = vec![
            Tie {
                node: free[3],
                masters: vec![(free[0], 0.375), (free[5], 0.75), (free[7], -0.125)],
            },
            Tie { node: free[9], masters: vec![(free[1], 0.5), (fixed[0], 0.5)] },
        ];
        let dofs = DofMap::with_ties(nn, &fixed, &ties).expect("dofs");
        assert_eq!(dofs.free_count(), 3 * (free.len() - 2));
        let k = assemble_lower(&mesh, &material, &dofs).expect("assemble");
        let all = DofMap::new(nn, &[]).expect("dofs");
        let kfull = assemble_lower(&mesh, &material, &all).expect("assemble").to_dense();
        let nd = 3 * nn;
        let kf =
            faer::Mat::<f64>::from_fn(
                nd,
                nd,
                |i, j| {
                    if i >= j { kfull[(i, j)] } else { kfull[(j, i)] }
                },
            );
        let nf = dofs.free_count();
        let mut t = faer::Mat::<f64>::zeros(nd, nf);
        for g in 0..nd {
            if let Some(f) = dofs.free_index(g) {
                t[(g, f)] = 1.0;
            } else if let Some(masters) = dofs.tie(g / 3) {
                for &(m, w) in masters {
                    if let Some(f) = dofs.free_index(3 * m + g % 3) {
                        t[(g, f)] += w;
                    }
                }
            }
        }
        let reference = t.transpose() * &kf * &t;
        let got = k.to_dense();
        let scale = reference.norm_max();
        for j in 0..nf {
            for i in j..nf {
                assert!((got[(i, j)] - reference[(i, j)]).abs() <= 1e-13 * scale, "({i}, {j})");
            }
        }
        let bad = |ties: &[Tie]| DofMap::with_ties(nn, &fixed, ties).is_err();
        assert!(bad(&[ties[0].clone(), Tie { node: free[0], masters: vec![(free[2], 1.0)] }]));
        assert!(bad(&[ties[0].clone(), ties[0].clone()]));
        assert!(bad(&[Tie { node: nn, masters: vec![] }]));
        assert!(bad(&[Tie { node: free[2], masters: vec![(free[2], 1.0)] }]));
        assert!(bad(&[Tie { node: free[2], masters: vec![(free[4], f64::NAN)] }]));
    }
}
