//! Stress recovery at a point of the hex20 displacement field, in particular at a free surface.
//!
//! # Method
//! Inside element e with nodal coordinates xₐ and nodal displacements uₐ (a = 0 … 19) the
//! displacement is u(ξ) = Σₐ Nₐ(ξ)·uₐ. At the natural coordinates ξ of the point (found by the
//! inverse isoparametric map, [`super::element::natural_coordinates`]) the displacement gradient
//! is H = Σₐ uₐ ⊗ ∇Nₐ(ξ) with the physical shape-function gradients ∇Nₐ = J⁻ᵀ ∂Nₐ/∂ξ, the small
//! strain ε = ½(H + Hᵀ), and Hooke's law for the isotropic material (Lamé λ, μ) gives
//!
//! σ = λ·tr(ε)·I + 2μ·ε   (Pa, Voigt order [σxx, σyy, σzz, τxy, τyz, τzx], tension positive).
//!
//! # Why at the point itself, not extrapolated from Gauss points
//! The quantity wanted is the stress *at* the surface of the tooth-root fillet, where it is
//! largest. The strain of a quadratic (hex20) element is evaluated directly at the surface point
//! from the shape-function derivatives there: this is the element's own field, it needs no
//! choice of extrapolation polynomial, and at a point of the surface it is exactly as accurate
//! as the interpolated displacement field allows (the Gauss points lie inside the element, at
//! ±√(3/5) of the half-width from the centre, so extrapolating from them to the surface
//! reproduces the same quadratic field at best). A [`StressPoint`] keeps the element's node
//! numbers and the gradients ∇Nₐ at the point, so the stress of any number of load cases costs
//! 60 multiply-adds each and is linear in the displacements, hence in the loads.
//!
//! # Points on a curved surface
//! A point of the exact (curved) surface lies within the quadratic approximation error of the
//! element face, i.e. possibly a little outside every element. [`locate_near_surface`] accepts
//! the element whose natural coordinates exceed the unit cube least (up to a tolerance) and
//! clamps them to [−1, 1]³: the point is projected onto the discretised surface.
//!
//! The check against a closed form (bending stress M·c/I of a cantilever of hex20 elements,
//! Timoshenko & Goodier, *Theory of Elasticity*, 3rd ed., §§ 21 and 127) is
//! `tests/root_stress.rs`.

use super::element::{self, NODES};
use super::error::JacobianError;
use super::material::Material;
use super::mesh::{ElementBox, Mesh};

/// The stress stencil of one point in one element: the element's nodes and the physical
/// shape-function gradients ∇Nₐ (1/m) at the point, with the material's Lamé constants (Pa).
#[derive(Debug, Clone, PartialEq)]
pub struct StressPoint {
    /// Element index.
    pub element: usize,
    /// Natural coordinates of the point in the element (within [−1, 1]³).
    pub xi: [f64; 3],
    /// Global node numbers of the element (its DOFs are 3·node + direction).
    pub nodes: [usize; NODES],
    /// ∇Nₐ at the point, 1/m.
    pub gradients: [[f64; 3]; NODES],
    lambda: f64,
    mu: f64,
}

impl StressPoint {
    /// The stencil of the point at natural coordinates `xi` of element `element` of `mesh`
    /// with `material`. Errors: an element that does not exist (reported with det = NaN) or a
    /// non-positive Jacobian at the point.
    pub fn new(
        mesh: &Mesh,
        material: &Material,
        element: usize,
        xi: [f64; 3],
    ) -> Result<Self, JacobianError> {
        let (Some(coords), Some(&nodes)) =
            (mesh.element_coords(element), mesh.elements.get(element))
        else {
            return Err(JacobianError { det: f64::NAN, xi });
        };
        let (gradients, _) = element::gradients(&coords, xi)?;
        let (lambda, mu) = material.lame();
        Ok(Self { element, xi, nodes, gradients, lambda, mu })
    }

    /// Stress (Pa, Voigt order [σxx, σyy, σzz, τxy, τyz, τzx]) of the displacement field whose
    /// component d at node n is `u(n, d)` (m).
    pub fn stress(&self, mut u: impl FnMut(usize, usize) -> f64) -> [f64; 6] {
        let mut h = [[0.0; 3]; 3];
        for (&node, g) in self.nodes.iter().zip(self.gradients.iter()) {
            for (i, hi) in h.iter_mut().enumerate() {
                let ui = u(node, i);
                for j in 0..3 {
                    hi[j] += ui * g[j];
                }
            }
        }
        let (lambda, mu) = (self.lambda, self.mu);
        let tr = h[0][0] + h[1][1] + h[2][2];
        [
            lambda * tr + 2.0 * mu * h[0][0],
            lambda * tr + 2.0 * mu * h[1][1],
            lambda * tr + 2.0 * mu * h[2][2],
            mu * (h[0][1] + h[1][0]),
            mu * (h[1][2] + h[2][1]),
            mu * (h[2][0] + h[0][2]),
        ]
    }
}

/// The normal stress t·σ·s (Pa) of a Voigt stress vector between unit vectors `t` and `s`.
pub fn project(sigma: &[f64; 6], t: [f64; 3], s: [f64; 3]) -> f64 {
    let m = [
        [sigma[0], sigma[3], sigma[5]],
        [sigma[3], sigma[1], sigma[4]],
        [sigma[5], sigma[4], sigma[2]],
    ];
    let mut v = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            v += t[i] * m[i][j] * s[j];
        }
    }
    v
}

/// The element of `mesh` containing the point `x` (m) up to `tol` in natural coordinates, and
/// the natural coordinates clamped to [−1, 1]³ (see the module docs); `None` when no element's
/// natural coordinates are within 1 + `tol` in every direction.
///
/// Candidates are the elements whose node bounding box, widened by 2 % of its size, contains
/// `x`; among them the one whose coordinates exceed the unit cube least is taken.
pub fn locate_near_surface(mesh: &Mesh, x: [f64; 3], tol: f64) -> Option<(usize, [f64; 3])> {
    locate_near_surface_with(mesh, &mesh.element_boxes(), x, tol)
}

/// [`locate_near_surface`] with the element boxes of [`Mesh::element_boxes`] computed once
/// (same candidates, same result). `None` also when `boxes` does not match the element count.
pub fn locate_near_surface_with(
    mesh: &Mesh,
    boxes: &[ElementBox],
    x: [f64; 3],
    tol: f64,
) -> Option<(usize, [f64; 3])> {
    if boxes.len() != mesh.elements.len() {
        return None;
    }
    let mut best: Option<(f64, usize, [f64; 3])> = None;
    for (e, b) in boxes.iter().enumerate() {
        if !b.contains_widened(x) {
            continue;
        }
        let c = mesh.element_coords(e)?;
        if let Some(xi) = element::natural_coordinates(&c, x) {
            let excess = xi.iter().map(|v| v.abs() - 1.0).fold(0.0f64, f64::max);
            if excess <= tol && best.is_none_or(|b| excess < b.0) {
                best = Some((excess, e, xi));
            }
        }
    }
    best.map(|(_, e, xi)| (e, xi.map(|v| v.clamp(-1.0, 1.0))))
}
