//! The 20-node serendipity hexahedron (hex20), isoparametric and quadratic.
//!
//! # Node ordering (the Abaqus C3D20 / VTK quadratic-hexahedron convention)
//!
//! Natural coordinates ξ = (ξ, η, ζ) ∈ [−1, 1]³. Corners 0–7, bottom face (ζ = −1)
//! counter-clockwise seen from +ζ, then the top face (ζ = +1):
//!
//! ```text
//!  0 (−1,−1,−1)   1 (+1,−1,−1)   2 (+1,+1,−1)   3 (−1,+1,−1)
//!  4 (−1,−1,+1)   5 (+1,−1,+1)   6 (+1,+1,+1)   7 (−1,+1,+1)
//! ```
//!
//! then the 12 mid-edge nodes: 8–11 on the bottom edges 0–1, 1–2, 2–3, 3–0; 12–15 on the top
//! edges 4–5, 5–6, 6–7, 7–4; 16–19 on the vertical edges 0–4, 1–5, 2–6, 3–7 (see [`EDGES`]).
//! A correctly ordered element maps this right-handed frame to a right-handed one, so
//! det(∂x/∂ξ) > 0 throughout.
//!
//! # Shape functions
//!
//! With ξₐ the natural coordinates of node a:
//! - corner: Nₐ = ⅛ (1 + ξₐξ)(1 + ηₐη)(1 + ζₐζ)(ξₐξ + ηₐη + ζₐζ − 2);
//! - mid-edge with ξₐ = 0: Nₐ = ¼ (1 − ξ²)(1 + ηₐη)(1 + ζₐζ), and likewise for η, ζ.
//!
//! # Element stiffness
//!
//! Element DOFs are node-major, 3a + i for node a and direction i ∈ {x, y, z}. For isotropic
//! elasticity (Lamé λ, μ) the 3×3 block coupling nodes a and b is
//!
//! Kₐᵦ\[i\]\[j\] = ∫ ( λ gₐᵢ gᵦⱼ + μ gₐⱼ gᵦᵢ + μ δᵢⱼ gₐ·gᵦ ) dV,  gₐ = ∇Nₐ (physical gradient),
//!
//! which equals ∫ Bᵀ D B dV. It is integrated with the full 3×3×3 Gauss–Legendre rule
//! (points 0, ±√(3/5), weights 8/9, 5/9), which leaves exactly the six rigid-body modes as the
//! null space of an undistorted element. The Jacobian determinant is checked at all 27 points;
//! a non-positive or non-finite value is an error, never a NaN result.
//!
//! # Faces
//!
//! Faces are numbered as in Abaqus: 0: ζ = −1, 1: ζ = +1, 2: η = −1, 3: ξ = +1, 4: η = +1,
//! 5: ξ = −1. [`FACES`] lists each face's four corners (counter-clockwise seen from outside)
//! followed by its four mid-edge nodes. Surface integrals use the hex20 shape functions
//! restricted to the face (the nodes off the face vanish there) and a 3×3 Gauss rule.
//!
//! Stresses are in Voigt order [σxx, σyy, σzz, τxy, τyz, τzx], Pa.

use super::error::JacobianError;
use super::material::Material;

/// Number of nodes of a hex20 element.
pub const NODES: usize = 20;
/// Number of DOFs of a hex20 element (three displacement components per node).
pub const DOFS: usize = 60;

/// Natural coordinates (ξ, η, ζ) of the 20 nodes, in element node order.
pub const NODE_NATURAL: [[f64; 3]; NODES] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// The 12 edges as pairs of corner nodes; edge k carries mid-edge node 8 + k.
pub const EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [4, 5],
    [5, 6],
    [6, 7],
    [7, 4],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// The six faces: four corners counter-clockwise seen from outside the element, then the four
/// mid-edge nodes (the node between corners k and k+1 at position 4 + k).
pub const FACES: [[usize; 8]; 6] = [
    [0, 3, 2, 1, 11, 10, 9, 8],
    [4, 5, 6, 7, 12, 13, 14, 15],
    [0, 1, 5, 4, 8, 17, 12, 16],
    [1, 2, 6, 5, 9, 18, 13, 17],
    [2, 3, 7, 6, 10, 19, 14, 18],
    [3, 0, 4, 7, 11, 16, 15, 19],
];

/// For each face: (index of the natural coordinate held fixed, its value ±1).
const FACE_AXIS: [(usize, f64); 6] =
    [(2, -1.0), (2, 1.0), (1, -1.0), (0, 1.0), (1, 1.0), (0, -1.0)];

/// 3-point Gauss–Legendre abscissae on [−1, 1].
pub const GAUSS3_POINTS: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
/// 3-point Gauss–Legendre weights (5/9, 8/9, 5/9).
pub const GAUSS3_WEIGHTS: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];

/// Shape functions N₀…N₁₉ at natural coordinates `xi`.
pub fn shape(xi: [f64; 3]) -> [f64; NODES] {
    let mut n = [0.0; NODES];
    for (a, na) in n.iter_mut().enumerate() {
        let c = NODE_NATURAL[a];
        if a < 8 {
            let p = [1.0 + c[0] * xi[0], 1.0 + c[1] * xi[1], 1.0 + c[2] * xi[2]];
            let s = c[0] * xi[0] + c[1] * xi[1] + c[2] * xi[2] - 2.0;
            *na = 0.125 * p[0] * p[1] * p[2] * s;
        } else {
            let mut v = 0.25;
            for k in 0..3 {
                v *= if c[k] == 0.0 { 1.0 - xi[k] * xi[k] } else { 1.0 + c[k] * xi[k] };
            }
            *na = v;
        }
    }
    n
}

/// Derivatives ∂Nₐ/∂ξⱼ at natural coordinates `xi`; entry `[a][j]`.
pub fn shape_derivatives(xi: [f64; 3]) -> [[f64; 3]; NODES] {
    let mut d = [[0.0; 3]; NODES];
    for (a, da) in d.iter_mut().enumerate() {
        let c = NODE_NATURAL[a];
        if a < 8 {
            let p = [1.0 + c[0] * xi[0], 1.0 + c[1] * xi[1], 1.0 + c[2] * xi[2]];
            let s = c[0] * xi[0] + c[1] * xi[1] + c[2] * xi[2] - 2.0;
            for j in 0..3 {
                let others = p[(j + 1) % 3] * p[(j + 2) % 3];
                // ∂/∂ξⱼ [pⱼ · others · s] = cⱼ · others · (s + pⱼ)
                da[j] = 0.125 * c[j] * others * (s + p[j]);
            }
        } else {
            // One natural coordinate m of a mid-edge node is 0.
            let f = |k: usize| if c[k] == 0.0 { 1.0 - xi[k] * xi[k] } else { 1.0 + c[k] * xi[k] };
            let df = |k: usize| if c[k] == 0.0 { -2.0 * xi[k] } else { c[k] };
            for (j, daj) in da.iter_mut().enumerate() {
                *daj = 0.25 * df(j) * f((j + 1) % 3) * f((j + 2) % 3);
            }
        }
    }
    d
}

/// Physical shape-function gradients and Jacobian determinant at one point.
///
/// Returns (gₐ = ∇Nₐ in 1/m, det ∂x/∂ξ in m³), or the error if det ≤ 0 or not finite.
pub fn gradients(
    coords: &[[f64; 3]; NODES],
    xi: [f64; 3],
) -> Result<([[f64; 3]; NODES], f64), JacobianError> {
    let dn = shape_derivatives(xi);
    // J[i][j] = ∂xᵢ/∂ξⱼ
    let mut jac = [[0.0; 3]; 3];
    for (x, d) in coords.iter().zip(dn.iter()) {
        for i in 0..3 {
            for j in 0..3 {
                jac[i][j] += x[i] * d[j];
            }
        }
    }
    let cof = [
        [
            jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1],
            jac[1][2] * jac[2][0] - jac[1][0] * jac[2][2],
            jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0],
        ],
        [
            jac[0][2] * jac[2][1] - jac[0][1] * jac[2][2],
            jac[0][0] * jac[2][2] - jac[0][2] * jac[2][0],
            jac[0][1] * jac[2][0] - jac[0][0] * jac[2][1],
        ],
        [
            jac[0][1] * jac[1][2] - jac[0][2] * jac[1][1],
            jac[0][2] * jac[1][0] - jac[0][0] * jac[1][2],
            jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0],
        ],
    ];
    let det = jac[0][0] * cof[0][0] + jac[0][1] * cof[0][1] + jac[0][2] * cof[0][2];
    if !(det.is_finite() && det > 0.0) {
        return Err(JacobianError { det, xi });
    }
    // (J⁻¹)[j][i] = cof[i][j] / det, and gᵢ = Σⱼ ∂N/∂ξⱼ (J⁻¹)[j][i].
    let inv_det = 1.0 / det;
    let mut g = [[0.0; 3]; NODES];
    for (ga, d) in g.iter_mut().zip(dn.iter()) {
        for i in 0..3 {
            ga[i] = (d[0] * cof[i][0] + d[1] * cof[i][1] + d[2] * cof[i][2]) * inv_det;
        }
    }
    Ok((g, det))
}

/// Natural coordinates ξ of the physical point `x` (m) in the element with nodal coordinates
/// `coords` (inverse isoparametric map, Newton's method from the element centre).
///
/// Returns `None` if the iteration does not converge (to 1e-12 in ξ) or meets a singular
/// Jacobian; the result may lie outside [−1, 1]³ when `x` is outside the element, so callers
/// test containment themselves.
pub fn natural_coordinates(coords: &[[f64; 3]; NODES], x: [f64; 3]) -> Option<[f64; 3]> {
    let mut xi = [0.0; 3];
    for _ in 0..60 {
        let n = shape(xi);
        let dn = shape_derivatives(xi);
        let mut r = [-x[0], -x[1], -x[2]];
        let mut j = [[0.0; 3]; 3];
        for a in 0..NODES {
            for i in 0..3 {
                r[i] += n[a] * coords[a][i];
                for k in 0..3 {
                    j[i][k] += coords[a][i] * dn[a][k];
                }
            }
        }
        let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
            - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
            + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        // Cramer's rule for J δ = r.
        let solve_col = |col: usize| {
            let mut m = j;
            for i in 0..3 {
                m[i][col] = r[i];
            }
            (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
                / det
        };
        let delta = [solve_col(0), solve_col(1), solve_col(2)];
        let mut step = 0.0f64;
        for k in 0..3 {
            xi[k] = (xi[k] - delta[k]).clamp(-3.0, 3.0);
            step = step.max(delta[k].abs());
        }
        if !step.is_finite() {
            return None;
        }
        if step < 1e-12 {
            return Some(xi);
        }
    }
    None
}

/// Element stiffness matrix of a hex20 element, N/m, written into `ke` (60×60, symmetric,
/// DOF order 3a + i).
///
/// `coords` are the nodal coordinates in m in the order of the module documentation. Uses the
/// full 3×3×3 Gauss rule and no heap allocation. On error `ke` holds partial sums.
pub fn stiffness(
    coords: &[[f64; 3]; NODES],
    material: &Material,
    ke: &mut [[f64; DOFS]; DOFS],
) -> Result<(), JacobianError> {
    let (lambda, mu) = material.lame();
    for row in ke.iter_mut() {
        row.fill(0.0);
    }
    for (k, &z) in GAUSS3_POINTS.iter().enumerate() {
        for (j, &y) in GAUSS3_POINTS.iter().enumerate() {
            for (i, &x) in GAUSS3_POINTS.iter().enumerate() {
                let (g, det) = gradients(coords, [x, y, z])?;
                let w = GAUSS3_WEIGHTS[i] * GAUSS3_WEIGHTS[j] * GAUSS3_WEIGHTS[k] * det;
                let (lw, mw) = (lambda * w, mu * w);
                for a in 0..NODES {
                    let ga = g[a];
                    for b in a..NODES {
                        let gb = g[b];
                        let dot = mw * (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]);
                        for p in 0..3 {
                            let row = &mut ke[3 * a + p];
                            for q in 0..3 {
                                row[3 * b + q] += lw * ga[p] * gb[q] + mw * ga[q] * gb[p];
                            }
                            row[3 * b + p] += dot;
                        }
                    }
                }
            }
        }
    }
    // Mirror the upper triangle to the lower one (K_ba = K_abᵀ), so that Kₑ is exactly
    // symmetric also inside the diagonal blocks, where rounding differs between (p, q) and (q, p).
    for r in 1..DOFS {
        let (upper, lower) = ke.split_at_mut(r);
        for (c, v) in lower[0].iter_mut().enumerate().take(r) {
            *v = upper[c][r];
        }
    }
    Ok(())
}

/// Stress σ = D ε (Voigt order [σxx, σyy, σzz, τxy, τyz, τzx], Pa) at natural coordinates
/// `xi` of an element with nodal coordinates `coords` (m) and nodal displacements `u` (m).
pub fn stress(
    coords: &[[f64; 3]; NODES],
    u: &[[f64; 3]; NODES],
    material: &Material,
    xi: [f64; 3],
) -> Result<[f64; 6], JacobianError> {
    let (g, _) = gradients(coords, xi)?;
    // Displacement gradient H[i][j] = ∂uᵢ/∂xⱼ.
    let mut h = [[0.0; 3]; 3];
    for (ua, ga) in u.iter().zip(g.iter()) {
        for i in 0..3 {
            for j in 0..3 {
                h[i][j] += ua[i] * ga[j];
            }
        }
    }
    let (lambda, mu) = material.lame();
    let tr = h[0][0] + h[1][1] + h[2][2];
    Ok([
        lambda * tr + 2.0 * mu * h[0][0],
        lambda * tr + 2.0 * mu * h[1][1],
        lambda * tr + 2.0 * mu * h[2][2],
        mu * (h[0][1] + h[1][0]),
        mu * (h[1][2] + h[2][1]),
        mu * (h[2][0] + h[0][2]),
    ])
}

/// Consistent nodal forces (N) of a surface traction on face `face` (0–5, see [`FACES`]).
///
/// `traction(x, n)` gives the traction vector in Pa at the physical point `x` (m) where the
/// unit outward normal is `n`; e.g. a pressure p is `|_, n| [-p*n[0], -p*n[1], -p*n[2]]`.
/// Entry k of the result is the force on element node `FACES[face][k]`; the forces are
/// fᵢ = ∫ Nᵢ t dA, integrated with a 3×3 Gauss rule. A face of zero area, a non-finite surface
/// Jacobian or `face > 5` is an error (with `det` the surface Jacobian, m², or NaN for a bad
/// face index).
pub fn face_forces(
    coords: &[[f64; 3]; NODES],
    face: usize,
    mut traction: impl FnMut([f64; 3], [f64; 3]) -> [f64; 3],
) -> Result<[[f64; 3]; 8], JacobianError> {
    let Some(&(axis, sign)) = FACE_AXIS.get(face) else {
        return Err(JacobianError { det: f64::NAN, xi: [f64::NAN; 3] });
    };
    // The two free natural coordinates in cyclic order, so that s·(t_a × t_b) points outward.
    let (ia, ib) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut f = [[0.0; 3]; 8];
    for (j, &t) in GAUSS3_POINTS.iter().enumerate() {
        for (i, &s) in GAUSS3_POINTS.iter().enumerate() {
            let mut xi = [0.0; 3];
            xi[axis] = sign;
            xi[ia] = s;
            xi[ib] = t;
            let n = shape(xi);
            let dn = shape_derivatives(xi);
            let mut x = [0.0; 3];
            let mut ta = [0.0; 3];
            let mut tb = [0.0; 3];
            for a in 0..NODES {
                for k in 0..3 {
                    x[k] += n[a] * coords[a][k];
                    ta[k] += dn[a][ia] * coords[a][k];
                    tb[k] += dn[a][ib] * coords[a][k];
                }
            }
            let normal = [
                sign * (ta[1] * tb[2] - ta[2] * tb[1]),
                sign * (ta[2] * tb[0] - ta[0] * tb[2]),
                sign * (ta[0] * tb[1] - ta[1] * tb[0]),
            ];
            let area =
                (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
            if !(area.is_finite() && area > 0.0) {
                return Err(JacobianError { det: area, xi });
            }
            let unit = [normal[0] / area, normal[1] / area, normal[2] / area];
            let tr = traction(x, unit);
            let w = GAUSS3_WEIGHTS[i] * GAUSS3_WEIGHTS[j] * area;
            for (fk, &a) in f.iter_mut().zip(FACES[face].iter()) {
                for c in 0..3 {
                    fk[c] += n[a] * tr[c] * w;
                }
            }
        }
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kronecker_delta_and_partition_of_unity() {
        for (a, &xa) in NODE_NATURAL.iter().enumerate() {
            let n = shape(xa);
            for (b, &nb) in n.iter().enumerate() {
                let expect = if a == b { 1.0 } else { 0.0 };
                assert!((nb - expect).abs() < 1e-15, "N{b}(node {a}) = {nb}");
            }
        }
        let xi = [0.3, -0.7, 0.45];
        let n = shape(xi);
        let d = shape_derivatives(xi);
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        for j in 0..3 {
            assert!(d.iter().map(|r| r[j]).sum::<f64>().abs() < 1e-14);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let xi = [0.21, -0.43, 0.77];
        let d = shape_derivatives(xi);
        let h = 1e-6;
        for j in 0..3 {
            let mut p = xi;
            let mut m = xi;
            p[j] += h;
            m[j] -= h;
            let (np, nm) = (shape(p), shape(m));
            for a in 0..NODES {
                let fd = (np[a] - nm[a]) / (2.0 * h);
                assert!((fd - d[a][j]).abs() < 1e-9, "dN{a}/dxi{j}: {fd} vs {}", d[a][j]);
            }
        }
    }

    #[test]
    fn edges_and_faces_are_consistent_with_natural_coordinates() {
        for (k, e) in EDGES.iter().enumerate() {
            let m = NODE_NATURAL[8 + k];
            for i in 0..3 {
                let mid = 0.5 * (NODE_NATURAL[e[0]][i] + NODE_NATURAL[e[1]][i]);
                assert_eq!(mid, m[i]);
            }
        }
        for (f, nodes) in FACES.iter().enumerate() {
            let (axis, sign) = FACE_AXIS[f];
            for &a in nodes {
                assert_eq!(NODE_NATURAL[a][axis], sign, "face {f} node {a}");
            }
        }
    }

    #[test]
    fn natural_coordinates_invert_the_isoparametric_map() {
        // A distorted, curved element: the unit cube with a quadratic bulge and a shear.
        let mut c = [[0.0; 3]; NODES];
        for (ca, xa) in c.iter_mut().zip(NODE_NATURAL.iter()) {
            let [u, v, w] = *xa;
            *ca = [u + 0.2 * v * v + 0.1 * w, v - 0.1 * u * u, 0.5 * w + 0.1 * u * v];
        }
        let xi = [0.37, -0.81, 0.55];
        let n = shape(xi);
        let mut x = [0.0; 3];
        for (na, ca) in n.iter().zip(c.iter()) {
            for k in 0..3 {
                x[k] += na * ca[k];
            }
        }
        let back = natural_coordinates(&c, x).expect("converges");
        for k in 0..3 {
            assert!((back[k] - xi[k]).abs() < 1e-10, "{back:?} vs {xi:?}");
        }
        // A point far outside maps outside [−1, 1]³ (or fails to converge).
        assert!(natural_coordinates(&c, [5.0, 0.0, 0.0]).is_none_or(|v| v[0] > 1.0));
    }

    #[test]
    fn face_forces_of_uniform_traction_sum_to_total() {
        // Unit cube scaled to 2 × 3 × 4 m; face 3 (ξ = +1) is x = 2, area 12 m².
        let mut c = [[0.0; 3]; NODES];
        for (ca, xa) in c.iter_mut().zip(NODE_NATURAL.iter()) {
            *ca = [1.0 + xa[0], 1.5 * (1.0 + xa[1]), 2.0 * (1.0 + xa[2])];
        }
        let f = face_forces(&c, 3, |_, n| {
            assert!((n[0] - 1.0).abs() < 1e-14);
            [0.0, 0.0, 5.0]
        })
        .expect("valid face");
        let total: f64 = f.iter().map(|v| v[2]).sum();
        assert!((total - 60.0).abs() < 1e-12);
        // Serendipity quad8 under uniform load: corners −1/12, mid-edges +1/3 of the total.
        assert!((f[0][2] + 5.0).abs() < 1e-12 && (f[4][2] - 20.0).abs() < 1e-12);
        assert!(face_forces(&c, 6, |_, _| [0.0; 3]).is_err());
    }
}
