//! Hex20 meshes: container, structured mapped blocks, merging of blocks, node and face queries.
//!
//! A [`Mesh`] holds node coordinates in m and hex20 connectivity in the node order of
//! [`super::element`] (corners 0–7, then mid-edge nodes 8–19).
//!
//! A *structured block* is the image of the unit cube (u, v, w) ∈ [0, 1]³ under a mapping
//! x = f(u, v, w), divided into nu × nv × nw elements at equal parameter steps. Every hex20 node
//! — corners and mid-edge nodes alike — is placed by evaluating f at its parameter values, so
//! mid-edge nodes lie on the curved image of the edge and curved geometry is followed to second
//! order. Grading is done inside f. The mapping must preserve orientation
//! (det ∂f/∂(u, v, w) > 0); an inverted block yields elements with a negative Jacobian, which
//! the model rejects.
//!
//! Blocks are glued by [`Mesh::merge`]: nodes closer than a tolerance (relative to the size of
//! the whole model) become one node. Two blocks join conformingly when their common face is the
//! same surface with the same subdivision, so that corners *and* mid-edge nodes coincide.
//! Coincidence is found with a uniform spatial hash of cell size equal to the tolerance, in
//! expected O(n) time.

use std::collections::HashMap;

use super::element::{self, FACES, NODE_NATURAL, NODES};
use super::error::FeError;

/// A hex20 finite-element mesh.
///
/// `nodes[k]` are the coordinates (x, y, z) of node k in m; `elements[e]` lists the 20 node
/// indices of element e in the order of [`super::element`]. The fields are public; use
/// [`Mesh::validate`] (called by [`super::FeModel::new`]) after editing them by hand.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Node coordinates, m.
    pub nodes: Vec<[f64; 3]>,
    /// Element connectivity, 20 node indices per element.
    pub elements: Vec<[usize; NODES]>,
}

/// One face of one element: `local` is the face number 0–5 of [`super::element::FACES`]
/// (0: ζ = −1, 1: ζ = +1, 2: η = −1, 3: ξ = +1, 4: η = +1, 5: ξ = −1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Face {
    /// Element index.
    pub element: usize,
    /// Local face number, 0–5.
    pub local: usize,
}

impl Mesh {
    /// Builds a mesh from nodes (m) and hex20 connectivity, after [`Mesh::validate`].
    pub fn new(nodes: Vec<[f64; 3]>, elements: Vec<[usize; NODES]>) -> Result<Self, FeError> {
        let mesh = Self { nodes, elements };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Checks that the mesh is non-empty, coordinates are finite, node indices are in range,
    /// no element repeats a node and every node belongs to some element.
    ///
    /// Element shape (Jacobian) is checked during assembly, not here.
    pub fn validate(&self) -> Result<(), FeError> {
        if self.nodes.is_empty() || self.elements.is_empty() {
            return Err(FeError::EmptyMesh);
        }
        if let Some(node) = self.nodes.iter().position(|x| !x.iter().all(|c| c.is_finite())) {
            return Err(FeError::NonFiniteNode { node });
        }
        let mut used = vec![false; self.nodes.len()];
        for (element, conn) in self.elements.iter().enumerate() {
            for (k, &node) in conn.iter().enumerate() {
                if node >= self.nodes.len() {
                    return Err(FeError::NodeOutOfRange { element, node, nodes: self.nodes.len() });
                }
                if conn[..k].contains(&node) {
                    return Err(FeError::DegenerateElement { element, node });
                }
                used[node] = true;
            }
        }
        if let Some(node) = used.iter().position(|&u| !u) {
            return Err(FeError::OrphanNode { node });
        }
        Ok(())
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of elements.
    pub fn element_count(&self) -> usize {
        self.elements.len()
    }

    /// Coordinates (m) of the 20 nodes of element `element`, or `None` if it or one of its
    /// nodes does not exist.
    pub fn element_coords(&self, element: usize) -> Option<[[f64; 3]; NODES]> {
        let conn = self.elements.get(element)?;
        let mut c = [[0.0; 3]; NODES];
        for (ca, &n) in c.iter_mut().zip(conn.iter()) {
            *ca = *self.nodes.get(n)?;
        }
        Some(c)
    }

    /// A structured block of nu × nv × nw hex20 elements, the image of the unit cube under
    /// `map(u, v, w) -> [x, y, z]` (m).
    ///
    /// Parameters are sampled at steps 1/(2n) in each direction; corner nodes at even, mid-edge
    /// nodes at odd multiples (face- and body-centre points of the quadratic grid are not hex20
    /// nodes and are not generated). Element (i, j, k) spans u ∈ [i/nu, (i+1)/nu] etc., with
    /// its ξ, η, ζ axes along u, v, w; elements are numbered with i fastest. Errors: a count of
    /// zero, or `map` returning a non-finite coordinate.
    pub fn structured_block(
        counts: [usize; 3],
        mut map: impl FnMut(f64, f64, f64) -> [f64; 3],
    ) -> Result<Self, FeError> {
        let [nu, nv, nw] = counts;
        if nu == 0 || nv == 0 || nw == 0 {
            return Err(FeError::InvalidInput(format!(
                "structured block needs at least one element per direction, got {nu}×{nv}×{nw}"
            )));
        }
        // Quadratic grid (2n + 1 points per direction); a point is a hex20 node when at most
        // one of its three indices is odd.
        let (gu, gv, gw) = (2 * nu + 1, 2 * nv + 1, 2 * nw + 1);
        let grid_len = gu
            .checked_mul(gv)
            .and_then(|p| p.checked_mul(gw))
            .ok_or_else(|| FeError::InvalidInput("structured block too large".into()))?;
        let mut id = vec![usize::MAX; grid_len];
        let mut nodes = Vec::new();
        for k in 0..gw {
            for j in 0..gv {
                for i in 0..gu {
                    if (i % 2) + (j % 2) + (k % 2) > 1 {
                        continue;
                    }
                    let (u, v, w) = (
                        i as f64 / (gu - 1) as f64,
                        j as f64 / (gv - 1) as f64,
                        k as f64 / (gw - 1) as f64,
                    );
                    let x = map(u, v, w);
                    if !x.iter().all(|c| c.is_finite()) {
                        return Err(FeError::InvalidInput(format!(
                            "block mapping gives a non-finite point at (u, v, w) = ({u}, {v}, {w})"
                        )));
                    }
                    id[i + gu * (j + gv * k)] = nodes.len();
                    nodes.push(x);
                }
            }
        }
        let mut elements = Vec::with_capacity(nu * nv * nw);
        for k in 0..nw {
            for j in 0..nv {
                for i in 0..nu {
                    let mut conn = [0usize; NODES];
                    for (c, xi) in conn.iter_mut().zip(NODE_NATURAL.iter()) {
                        // Natural coordinate −1, 0, +1 → grid offset 0, 1, 2.
                        let gi = 2 * i + (xi[0] + 1.0) as usize;
                        let gj = 2 * j + (xi[1] + 1.0) as usize;
                        let gk = 2 * k + (xi[2] + 1.0) as usize;
                        *c = id[gi + gu * (gj + gv * gk)];
                    }
                    elements.push(conn);
                }
            }
        }
        Ok(Self { nodes, elements })
    }

    /// Merges meshes into one, joining nodes closer than `rel_tol` × (diagonal of the bounding
    /// box of all nodes).
    ///
    /// Nodes are numbered in order of first appearance (block by block); elements keep their
    /// order, block by block. Duplicates inside one block are joined as well. `rel_tol` must be
    /// in (0, 0.01]; 1e-9 suits meshes whose coincident nodes come from the same formulas.
    /// Errors: no blocks, a bad tolerance, invalid block meshes, or an element whose own nodes
    /// would be joined ([`FeError::DegenerateElement`], numbered in the merged mesh).
    pub fn merge(blocks: &[Mesh], rel_tol: f64) -> Result<Self, FeError> {
        if !(rel_tol > 0.0 && rel_tol <= 1e-2) {
            return Err(FeError::InvalidInput(format!(
                "merge tolerance {rel_tol} outside (0, 0.01]"
            )));
        }
        for b in blocks {
            b.validate()?;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for x in blocks.iter().flat_map(|b| b.nodes.iter()) {
            for k in 0..3 {
                lo[k] = lo[k].min(x[k]);
                hi[k] = hi[k].max(x[k]);
            }
        }
        let total: usize = blocks.iter().map(|b| b.nodes.len()).sum();
        if total == 0 {
            return Err(FeError::EmptyMesh);
        }
        let diag =
            ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
        let tol = (rel_tol * diag).max(f64::MIN_POSITIVE);
        let tol2 = tol * tol;
        // Spatial hash: cell → first node of a chain; `next` links the chain.
        let mut head: HashMap<[i64; 3], usize> = HashMap::with_capacity(total);
        let mut next: Vec<usize> = Vec::with_capacity(total);
        let mut nodes: Vec<[f64; 3]> = Vec::with_capacity(total);
        let mut elements = Vec::with_capacity(blocks.iter().map(|b| b.elements.len()).sum());
        // `as i64` saturates for huge quotients, which keeps the hash correct (only slower).
        let cell = |x: &[f64; 3]| -> [i64; 3] {
            [
                ((x[0] - lo[0]) / tol).floor() as i64,
                ((x[1] - lo[1]) / tol).floor() as i64,
                ((x[2] - lo[2]) / tol).floor() as i64,
            ]
        };
        for b in blocks {
            let mut local = Vec::with_capacity(b.nodes.len());
            for x in &b.nodes {
                let c = cell(x);
                let mut found = None;
                'search: for dz in -1..=1i64 {
                    for dy in -1..=1i64 {
                        for dx in -1..=1i64 {
                            let key = [
                                c[0].saturating_add(dx),
                                c[1].saturating_add(dy),
                                c[2].saturating_add(dz),
                            ];
                            let mut p = head.get(&key).copied().unwrap_or(usize::MAX);
                            while p != usize::MAX {
                                let y = nodes[p];
                                let d2 = (x[0] - y[0]).powi(2)
                                    + (x[1] - y[1]).powi(2)
                                    + (x[2] - y[2]).powi(2);
                                if d2 <= tol2 {
                                    found = Some(p);
                                    break 'search;
                                }
                                p = next[p];
                            }
                        }
                    }
                }
                let idx = match found {
                    Some(p) => p,
                    None => {
                        let p = nodes.len();
                        nodes.push(*x);
                        next.push(head.insert(c, p).unwrap_or(usize::MAX));
                        p
                    }
                };
                local.push(idx);
            }
            for conn in &b.elements {
                let mut m = [0usize; NODES];
                for (mk, &n) in m.iter_mut().zip(conn.iter()) {
                    *mk = local[n];
                }
                elements.push(m);
            }
        }
        let mesh = Self { nodes, elements };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Indices (ascending) of the nodes whose coordinates (m) satisfy `pred`, e.g. the bore:
    /// `mesh.nodes_where(|x| x[0].hypot(x[1]) < r_bore + tol)`.
    pub fn nodes_where(&self, mut pred: impl FnMut(&[f64; 3]) -> bool) -> Vec<usize> {
        self.nodes.iter().enumerate().filter(|(_, x)| pred(x)).map(|(i, _)| i).collect()
    }

    /// The element containing the point `x` (m) and the natural coordinates of `x` in it, or
    /// `None` if no element contains it.
    ///
    /// Candidates are the elements whose node bounding box contains `x`; for each, the inverse
    /// isoparametric map ([`element::natural_coordinates`]) is solved and the point accepted when
    /// all |ξᵢ| ≤ 1 + 1e-9. Linear in the number of elements (meant for a few hundred queries).
    pub fn locate(&self, x: [f64; 3]) -> Option<(usize, [f64; 3])> {
        for e in 0..self.elements.len() {
            let c = self.element_coords(e)?;
            if !in_widened_box(&c, x) {
                continue;
            }
            if let Some(xi) = element::natural_coordinates(&c, x)
                && xi.iter().all(|v| v.abs() <= 1.0 + 1e-9)
            {
                return Some((e, xi));
            }
        }
        None
    }

    /// The node bounding box of every element, for repeated [`Mesh::locate_with`] queries.
    pub fn element_boxes(&self) -> Vec<ElementBox> {
        self.elements
            .iter()
            .map(|conn| {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for &n in conn {
                    for k in 0..3 {
                        lo[k] = lo[k].min(self.nodes[n][k]);
                        hi[k] = hi[k].max(self.nodes[n][k]);
                    }
                }
                ElementBox { lo, hi }
            })
            .collect()
    }

    /// [`Mesh::locate`] with the element boxes `boxes` of [`Mesh::element_boxes`] computed once:
    /// the same candidates in the same order, so the same result, without recomputing every
    /// element's box per query. `None` also when `boxes` does not match the element count.
    pub fn locate_with(&self, boxes: &[ElementBox], x: [f64; 3]) -> Option<(usize, [f64; 3])> {
        if boxes.len() != self.elements.len() {
            return None;
        }
        for (e, b) in boxes.iter().enumerate() {
            if !b.contains_widened(x) {
                continue;
            }
            let c = self.element_coords(e)?;
            if let Some(xi) = element::natural_coordinates(&c, x)
                && xi.iter().all(|v| v.abs() <= 1.0 + 1e-9)
            {
                return Some((e, xi));
            }
        }
        None
    }

    /// The global node indices of a face: four corners counter-clockwise seen from outside,
    /// then four mid-edge nodes ([`super::element::FACES`] order). `None` for a face that does
    /// not exist.
    pub fn face_nodes(&self, face: Face) -> Option<[usize; 8]> {
        let conn = self.elements.get(face.element)?;
        let local = FACES.get(face.local)?;
        let mut out = [0usize; 8];
        for (o, &a) in out.iter_mut().zip(local.iter()) {
            *o = conn[a];
        }
        Some(out)
    }

    /// All element faces on the boundary of the mesh (faces not shared by two elements), in
    /// order of element then local face.
    ///
    /// Faces are matched by their four corner nodes, so blocks must have been merged first.
    pub fn boundary_faces(&self) -> Vec<Face> {
        let key = |conn: &[usize; NODES], f: usize| -> [usize; 4] {
            let mut k =
                [conn[FACES[f][0]], conn[FACES[f][1]], conn[FACES[f][2]], conn[FACES[f][3]]];
            k.sort_unstable();
            k
        };
        let mut count: HashMap<[usize; 4], u32> = HashMap::with_capacity(3 * self.elements.len());
        for conn in &self.elements {
            for f in 0..6 {
                *count.entry(key(conn, f)).or_insert(0) += 1;
            }
        }
        let mut out = Vec::new();
        for (element, conn) in self.elements.iter().enumerate() {
            for local in 0..6 {
                if count.get(&key(conn, local)) == Some(&1) {
                    out.push(Face { element, local });
                }
            }
        }
        out
    }

    /// The boundary faces all eight of whose nodes satisfy `pred`, e.g. the end face of a beam:
    /// `mesh.boundary_faces_where(|x| (x[0] - l).abs() < tol)`.
    pub fn boundary_faces_where(&self, mut pred: impl FnMut(&[f64; 3]) -> bool) -> Vec<Face> {
        self.boundary_faces()
            .into_iter()
            .filter(|&f| {
                self.face_nodes(f)
                    .is_some_and(|ns| ns.iter().all(|&n| self.nodes.get(n).is_some_and(&mut pred)))
            })
            .collect()
    }

    /// Consistent nodal forces (N) of a surface traction on one face: returns the eight face
    /// nodes (global indices, [`Mesh::face_nodes`] order) with their force vectors.
    ///
    /// `traction(x, n)` is the traction in Pa at point `x` (m) with unit outward normal `n`; see
    /// [`super::element::face_forces`]. Errors: a face that does not exist, or a degenerate face.
    pub fn face_loads(
        &self,
        face: Face,
        traction: impl FnMut([f64; 3], [f64; 3]) -> [f64; 3],
    ) -> Result<[(usize, [f64; 3]); 8], FeError> {
        let nodes = self.face_nodes(face).ok_or_else(|| {
            FeError::InvalidInput(format!(
                "face {} of element {} does not exist",
                face.local, face.element
            ))
        })?;
        let coords = self.element_coords(face.element).ok_or_else(|| {
            FeError::InvalidInput(format!("element {} refers to missing nodes", face.element))
        })?;
        let f = element::face_forces(&coords, face.local, traction)
            .map_err(|e| e.in_element(face.element))?;
        let mut out = [(0usize, [0.0; 3]); 8];
        for (o, (&n, fk)) in out.iter_mut().zip(nodes.iter().zip(f.iter())) {
            *o = (n, *fk);
        }
        Ok(out)
    }
}

/// True when `x` lies in the bounding box of the element nodes `c`, widened on every side by
/// 2 % of the sum of its edge lengths (the candidate test before the inverse isoparametric map).
/// The node bounding box of one element (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementBox {
    /// Smallest node coordinates, m.
    pub lo: [f64; 3],
    /// Largest node coordinates, m.
    pub hi: [f64; 3],
}

impl ElementBox {
    /// Whether `x` (m) lies in the box widened by 2 % of the sum of its edge lengths on every
    /// side (the candidate test of [`Mesh::locate`]).
    pub fn contains_widened(&self, x: [f64; 3]) -> bool {
        let (lo, hi) = (self.lo, self.hi);
        let margin = 0.02 * ((hi[0] - lo[0]) + (hi[1] - lo[1]) + (hi[2] - lo[2]));
        (0..3).all(|k| x[k] >= lo[k] - margin && x[k] <= hi[k] + margin)
    }
}

pub(crate) fn in_widened_box(c: &[[f64; 3]], x: [f64; 3]) -> bool {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in c {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let margin = 0.02 * ((hi[0] - lo[0]) + (hi[1] - lo[1]) + (hi[2] - lo[2]));
    (0..3).all(|k| x[k] >= lo[k] - margin && x[k] <= hi[k] + margin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_counts_and_boundary() {
        let m = Mesh::structured_block([3, 2, 4], |u, v, w| [3.0 * u, 2.0 * v, 4.0 * w])
            .expect("block");
        // Nodes of a hex20 grid: corners + mid-edge nodes along the three directions.
        let (a, b, c) = (3usize, 2usize, 4usize);
        let corners = (a + 1) * (b + 1) * (c + 1);
        let mids = a * (b + 1) * (c + 1) + (a + 1) * b * (c + 1) + (a + 1) * (b + 1) * c;
        assert_eq!(m.node_count(), corners + mids);
        assert_eq!(m.element_count(), a * b * c);
        assert_eq!(m.boundary_faces().len(), 2 * (a * b + b * c + c * a));
        assert!(m.validate().is_ok());
        // Mid-edge node of element 0 between corners 0 and 1 lies half-way.
        let e0 = m.elements[0];
        assert_eq!(m.nodes[e0[8]], [0.5, 0.0, 0.0]);
        assert_eq!(m.boundary_faces_where(|x| x[2] > 4.0 - 1e-12).len(), a * b);
        assert!(Mesh::structured_block([0, 1, 1], |u, v, w| [u, v, w]).is_err());
        assert!(Mesh::structured_block([1, 1, 1], |u, _, _| [u / 0.0, 0.0, 0.0]).is_err());
    }

    #[test]
    fn merging_two_blocks_equals_one_block() {
        let whole = Mesh::structured_block([4, 2, 2], |u, v, w| [2.0 * u, v, w]).expect("block");
        let left = Mesh::structured_block([2, 2, 2], |u, v, w| [u, v, w]).expect("block");
        let right = Mesh::structured_block([2, 2, 2], |u, v, w| [1.0 + u, v, w]).expect("block");
        let merged = Mesh::merge(&[left, right], 1e-9).expect("merge");
        assert_eq!(merged.node_count(), whole.node_count());
        assert_eq!(merged.element_count(), whole.element_count());
        assert_eq!(merged.boundary_faces().len(), whole.boundary_faces().len());
        assert!(Mesh::merge(&[], 1e-9).is_err());
        assert!(Mesh::merge(&[whole], 0.5).is_err());
    }

    #[test]
    fn merging_quarter_rings_closes_the_ring() {
        // Four curved quarter-ring blocks: the last face meets the first one.
        let (ri, ro, t) = (0.5, 1.0, 0.2);
        let (nr, nt, nz) = (2usize, 3usize, 1usize);
        let blocks: Vec<Mesh> = (0..4)
            .map(|q| {
                Mesh::structured_block([nr, nt, nz], |u, v, w| {
                    let r = ri + (ro - ri) * u;
                    let th = std::f64::consts::FRAC_PI_2 * (q as f64 + v);
                    [r * th.cos(), r * th.sin(), t * w]
                })
                .expect("block")
            })
            .collect();
        let ring = Mesh::merge(&blocks, 1e-9).expect("merge");
        let per_block = blocks[0].node_count();
        // Each of the four shared faces carries (2nr+1)(nz+1) + (nr+1)nz nodes.
        let shared = (2 * nr + 1) * (nz + 1) + (nr + 1) * nz;
        assert_eq!(ring.node_count(), 4 * per_block - 4 * shared);
        let outer = ring.nodes_where(|x| x[0].hypot(x[1]) > ro - 1e-9);
        assert_eq!(outer.len(), 2 * 4 * nt * (nz + 1) + 4 * nt * nz);
        // Boundary: inner + outer cylinders and both ends; no internal faces left.
        assert_eq!(ring.boundary_faces().len(), 2 * 4 * nt * nz + 2 * 4 * nt * nr);
    }

    #[test]
    fn validation_errors() {
        let mut m = Mesh::structured_block([1, 1, 1], |u, v, w| [u, v, w]).expect("block");
        assert_eq!(Mesh::new(vec![], vec![]), Err(FeError::EmptyMesh));
        m.elements[0][3] = 99;
        assert!(matches!(m.validate(), Err(FeError::NodeOutOfRange { element: 0, node: 99, .. })));
        m.elements[0][3] = m.elements[0][2];
        assert!(matches!(m.validate(), Err(FeError::DegenerateElement { element: 0, .. })));
    }
}
