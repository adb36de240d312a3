//! Errors of the finite-element core.
//!
//! Every variant names the offending item (element, node, DOF or argument) so that a user can
//! find it in the mesh. Node and element numbers are 0-based indices into [`super::Mesh`].

use std::fmt;

/// A non-positive (or non-finite) Jacobian determinant found inside one element.
///
/// Returned by the element-level routines of [`super::element`], which do not know the element's
/// number; [`JacobianError::in_element`] attaches it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobianError {
    /// det(∂x/∂ξ) at the offending point, m³ (volume per unit natural volume); for a face
    /// integral, the surface Jacobian |∂x/∂s × ∂x/∂t| in m².
    pub det: f64,
    /// Natural coordinates (ξ, η, ζ) of the point where it was found.
    pub xi: [f64; 3],
}

impl JacobianError {
    /// The same error, attributed to element `element`.
    pub fn in_element(self, element: usize) -> FeError {
        FeError::NonPositiveJacobian { element, det: self.det, xi: self.xi }
    }
}

impl fmt::Display for JacobianError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "non-positive Jacobian determinant {:e} at natural coordinates ({}, {}, {})",
            self.det, self.xi[0], self.xi[1], self.xi[2]
        )
    }
}

impl std::error::Error for JacobianError {}

/// Everything that can go wrong while building, assembling, factorising or solving an FE model.
#[derive(Debug, Clone, PartialEq)]
pub enum FeError {
    /// Material constants outside E > 0, −1 < ν < 0.5.
    InvalidMaterial {
        /// Young's modulus given, Pa.
        e: f64,
        /// Poisson's ratio given.
        nu: f64,
    },
    /// The mesh has no nodes or no elements.
    EmptyMesh,
    /// A node coordinate is NaN or infinite.
    NonFiniteNode {
        /// Node index.
        node: usize,
    },
    /// An element refers to a node index ≥ the number of nodes.
    NodeOutOfRange {
        /// Element index.
        element: usize,
        /// The invalid node index.
        node: usize,
        /// Number of nodes in the mesh.
        nodes: usize,
    },
    /// An element uses the same node twice (e.g. after merging nodes closer than the tolerance).
    DegenerateElement {
        /// Element index.
        element: usize,
        /// The repeated node index.
        node: usize,
    },
    /// A node belongs to no element, so its displacement is undetermined.
    OrphanNode {
        /// Node index.
        node: usize,
    },
    /// det(∂x/∂ξ) ≤ 0 (or not finite) at an integration point: the element is inverted or
    /// too distorted (e.g. a left-handed node ordering or a misplaced mid-edge node).
    NonPositiveJacobian {
        /// Element index.
        element: usize,
        /// The determinant found, m³ (m² for a face).
        det: f64,
        /// Natural coordinates (ξ, η, ζ) of the integration point.
        xi: [f64; 3],
    },
    /// A fixed node index ≥ the number of nodes.
    FixedNodeOutOfRange {
        /// The invalid node index.
        node: usize,
        /// Number of nodes in the mesh.
        nodes: usize,
    },
    /// A connected part of the mesh is not held against rigid-body motion: its fixed nodes
    /// are fewer than three or all on one straight line.
    Underconstrained {
        /// One node of the part (the lowest index).
        example_node: usize,
        /// Number of nodes in the part.
        part_nodes: usize,
        /// Number of fixed nodes in the part.
        fixed_nodes: usize,
    },
    /// The reduced stiffness matrix is not numerically positive definite (a mechanism the
    /// constraint check did not catch, or extreme ill-conditioning).
    NotPositiveDefinite {
        /// Index of the failed pivot in the factorisation's (fill-reducing) ordering.
        pivot: usize,
    },
    /// A load block with the wrong number of rows.
    LoadShape {
        /// Rows given.
        rows: usize,
        /// Rows expected (3 × number of nodes).
        expected: usize,
    },
    /// A load entry is NaN or infinite.
    NonFiniteLoad {
        /// Row (global DOF) of the entry.
        row: usize,
        /// Column (load case) of the entry.
        col: usize,
    },
    /// An invalid argument to a mesh-building routine, described in words.
    InvalidInput(String),
    /// A failure inside the sparse linear-algebra library (e.g. out of memory).
    Solver(String),
}

impl fmt::Display for FeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidMaterial { e, nu } => write!(
                f,
                "invalid FE material E = {e} Pa, nu = {nu}: allowed E > 0 and -1 < nu < 0.5"
            ),
            Self::EmptyMesh => write!(f, "FE mesh has no nodes or no elements"),
            Self::NonFiniteNode { node } => write!(f, "FE node {node} has a non-finite coordinate"),
            Self::NodeOutOfRange { element, node, nodes } => write!(
                f,
                "FE element {element} refers to node {node}, but the mesh has {nodes} nodes"
            ),
            Self::DegenerateElement { element, node } => {
                write!(f, "FE element {element} uses node {node} more than once")
            }
            Self::OrphanNode { node } => write!(f, "FE node {node} belongs to no element"),
            Self::NonPositiveJacobian { element, det, xi } => write!(
                f,
                "FE element {element} is inverted or too distorted: Jacobian determinant {det:e} \
                 at natural coordinates ({}, {}, {})",
                xi[0], xi[1], xi[2]
            ),
            Self::FixedNodeOutOfRange { node, nodes } => {
                write!(f, "fixed node {node} does not exist (the mesh has {nodes} nodes)")
            }
            Self::Underconstrained { example_node, part_nodes, fixed_nodes } => write!(
                f,
                "the mesh part containing node {example_node} ({part_nodes} nodes) can move as a \
                 rigid body: it has {fixed_nodes} fixed nodes, and needs at least three not on \
                 one line"
            ),
            Self::NotPositiveDefinite { pivot } => write!(
                f,
                "FE stiffness matrix is not positive definite (Cholesky pivot {pivot} failed): \
                 check constraints and element quality"
            ),
            Self::LoadShape { rows, expected } => {
                write!(f, "FE load block has {rows} rows, expected {expected} (3 per node)")
            }
            Self::NonFiniteLoad { row, col } => {
                write!(f, "FE load entry (DOF {row}, case {col}) is not finite")
            }
            Self::InvalidInput(s) => write!(f, "FE input: {s}"),
            Self::Solver(s) => write!(f, "FE sparse solver: {s}"),
        }
    }
}

impl std::error::Error for FeError {}
