//! Integration tests of the 3D finite-element core (hex20 elements, assembly, Cholesky solver).
//!
//! Each test checks a physical or mathematical property: the patch test (exact linear fields
//! and constant stress on distorted elements), a cantilever against Timoshenko beam theory with
//! mesh convergence, Maxwell–Betti reciprocity of the influence matrix, rigid-body modes of the
//! element stiffness, and the error paths (inverted elements, missing constraints, bad loads).

mod common;

use faer::Mat;
use helical_gear_mesh::compliance::fe::{FeError, FeModel, Material, Mesh, dof, element};

use common::Lcg;

const STEEL: Material = Material { e: 206e9, nu: 0.3 };

/// Puts every mid-edge node at the midpoint of its two corners (straight edges).
fn straighten_edges(mesh: &mut Mesh) {
    for e in 0..mesh.elements.len() {
        let conn = mesh.elements[e];
        for (k, pair) in element::EDGES.iter().enumerate() {
            let (a, b) = (mesh.nodes[conn[pair[0]]], mesh.nodes[conn[pair[1]]]);
            mesh.nodes[conn[8 + k]] =
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])];
        }
    }
}

/// Element nodal displacements gathered from a global displacement column.
fn element_displacements(mesh: &Mesh, e: usize, u: &[f64]) -> [[f64; 3]; 20] {
    let mut ue = [[0.0; 3]; 20];
    for (a, &n) in mesh.elements[e].iter().enumerate() {
        for i in 0..3 {
            ue[a][i] = u[dof(n, i)];
        }
    }
    ue
}

/// Patch test: a 3×3×3 patch of distorted hex20 elements filling the unit cube. Corner nodes
/// are moved randomly by up to ±0.1 (interior nodes in all directions, boundary nodes within
/// their boundary plane), mid-edge nodes sit at edge midpoints. A linear displacement field
/// u = u₀ + A·x is imposed on all boundary nodes; the interior nodes must reproduce it and the
/// stress must be the constant D·ε(A) everywhere.
#[test]
fn patch_test_reproduces_linear_field_and_constant_stress() {
    let n = 3;
    let mut mesh = Mesh::structured_block([n, n, n], |u, v, w| [u, v, w]).expect("block");
    let on_boundary = |c: f64| c.abs() < 1e-12 || (c - 1.0).abs() < 1e-12;
    let mut rng = Lcg(12345);
    let h = 1.0 / n as f64;
    // Corner nodes are the nodes whose coordinates are all multiples of h.
    for x in mesh.nodes.iter_mut() {
        let is_corner = x.iter().all(|&c| ((c / h).round() * h - c).abs() < 1e-12);
        if is_corner {
            for c in x.iter_mut() {
                if !on_boundary(*c) {
                    *c += 0.3 * h * rng.signed();
                }
            }
        }
    }
    straighten_edges(&mut mesh);
    // The patch really is distorted: some interior node is off the regular grid.
    let off_grid = mesh
        .nodes
        .iter()
        .filter(|x| x.iter().any(|&c| ((c / (0.5 * h)).round() * 0.5 * h - c).abs() > 1e-3))
        .count();
    assert!(off_grid > 20, "only {off_grid} nodes moved");

    let u0 = [1.0e-4, -2.0e-4, 0.5e-4];
    let a = [[1.0e-3, 0.4e-3, -0.2e-3], [-0.3e-3, 0.7e-3, 0.5e-3], [0.6e-3, -0.1e-3, -0.9e-3]];
    let linear = |x: &[f64; 3]| -> [f64; 3] {
        let mut u = u0;
        for i in 0..3 {
            for j in 0..3 {
                u[i] += a[i][j] * x[j];
            }
        }
        u
    };
    let mut u_lin = vec![0.0; 3 * mesh.nodes.len()];
    for (k, x) in mesh.nodes.iter().enumerate() {
        u_lin[3 * k..3 * k + 3].copy_from_slice(&linear(x));
    }
    // Residual r = K·u_lin, element by element.
    let mut r = vec![0.0; u_lin.len()];
    let mut ke = [[0.0; 60]; 60];
    for (e, conn) in mesh.elements.iter().enumerate() {
        let coords = mesh.element_coords(e).expect("coords");
        element::stiffness(&coords, &STEEL, &mut ke).expect("element");
        for (p, row) in ke.iter().enumerate() {
            let gp = dof(conn[p / 3], p % 3);
            for (q, &kpq) in row.iter().enumerate() {
                r[gp] += kpq * u_lin[dof(conn[q / 3], q % 3)];
            }
        }
    }
    // Interior displacements with the boundary held at u_lin: u = u_lin + d, K_ii d = −r_i.
    let boundary = mesh.nodes_where(|x| x.iter().any(|&c| on_boundary(c)));
    let interior_count = mesh.nodes.len() - boundary.len();
    assert!(interior_count >= 8 + 36, "patch has {interior_count} interior nodes");
    let model = FeModel::new(mesh.clone(), STEEL, &boundary).expect("model");
    let minus_r: Vec<f64> = r.iter().map(|v| -v).collect();
    let d = model.solve(&minus_r).expect("solve");
    let u_max = u_lin.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d_max = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let disp_err = d_max / u_max;
    let u: Vec<f64> = u_lin.iter().zip(&d).map(|(a, b)| a + b).collect();

    // Exact stress of the linear field.
    let (lambda, mu) = STEEL.lame();
    let tr = a[0][0] + a[1][1] + a[2][2];
    let exact = [
        lambda * tr + 2.0 * mu * a[0][0],
        lambda * tr + 2.0 * mu * a[1][1],
        lambda * tr + 2.0 * mu * a[2][2],
        mu * (a[0][1] + a[1][0]),
        mu * (a[1][2] + a[2][1]),
        mu * (a[2][0] + a[0][2]),
    ];
    let s_max = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut stress_err = 0.0f64;
    for e in 0..mesh.elements.len() {
        let coords = mesh.element_coords(e).expect("coords");
        let ue = element_displacements(&mesh, e, &u);
        let points = element::NODE_NATURAL.iter().copied().chain([[0.3, -0.5, 0.7], [0.0; 3]]);
        for xi in points {
            let s = element::stress(&coords, &ue, &STEEL, xi).expect("stress");
            for k in 0..6 {
                stress_err = stress_err.max((s[k] - exact[k]).abs() / s_max);
            }
        }
    }
    eprintln!("patch test: displacement error {disp_err:.2e}, stress error {stress_err:.2e}");
    assert!(disp_err < 1e-10, "displacement error {disp_err:e}");
    assert!(stress_err < 1e-10, "stress error {stress_err:e}");
}

/// Depth and width of the square cantilever section, m, and the tip load, N.
const BEAM_H: f64 = 0.1;
const BEAM_P: f64 = 1000.0;

/// Tip deflection (m) of a clamped square beam of length `l` (section `BEAM_H` × `BEAM_H`)
/// under a uniform shear traction of resultant `BEAM_P` in z on the end face x = l, on an
/// nx × nh × nh mesh glued from `blocks` blocks along x. All nodes of the root face x = 0 are
/// fixed. The deflection is the work-conjugate average Σ fᵢ·uᵢ / P, which for a uniform
/// traction is the area average of u_z over the end face.
fn cantilever(l: f64, material: Material, nx: usize, nh: usize, blocks: usize) -> (f64, FeModel) {
    let parts: Vec<Mesh> = (0..blocks)
        .map(|b| {
            let x0 = l * b as f64 / blocks as f64;
            Mesh::structured_block([nx / blocks, nh, nh], |u, v, w| {
                [x0 + l / blocks as f64 * u, BEAM_H * v, BEAM_H * w]
            })
            .expect("block")
        })
        .collect();
    let mesh = Mesh::merge(&parts, 1e-9).expect("merge");
    let tol = 1e-9 * l;
    let clamped = mesh.nodes_where(|x| x[0] < tol);
    let end = mesh.boundary_faces_where(|x| x[0] > l - tol);
    assert_eq!(end.len(), nh * nh);
    let mut f = Mat::<f64>::zeros(3 * mesh.nodes.len(), 1);
    let traction = BEAM_P / (BEAM_H * BEAM_H);
    for &face in &end {
        for (node, force) in mesh.face_loads(face, |_, _| [0.0, 0.0, traction]).expect("load") {
            for i in 0..3 {
                f[(dof(node, i), 0)] += force[i];
            }
        }
    }
    let total: f64 = (0..f.nrows()).map(|i| f[(i, 0)]).sum();
    assert!((total - BEAM_P).abs() < 1e-9 * BEAM_P);
    let model = FeModel::new(mesh, material, &clamped).expect("model");
    let u = model.solve_block(f.as_ref()).expect("solve");
    let work: f64 = (0..f.nrows()).map(|i| f[(i, 0)] * u[(i, 0)]).sum();
    (work / BEAM_P, model)
}

/// Tip deflections of beam theory for [`cantilever`]: (Timoshenko, Euler–Bernoulli), m.
///
/// Timoshenko: δ = PL³/(3EI) + PL/(κGA) with Cowper's shear coefficient for a rectangle,
/// κ = 10(1 + ν)/(12 + 11ν) (= 5/6 at ν = 0, 0.850 at ν = 0.3). Euler–Bernoulli: PL³/(3EI).
fn beam_theory(l: f64, material: Material) -> (f64, f64) {
    let nu = material.nu;
    let i = BEAM_H.powi(4) / 12.0;
    let area = BEAM_H * BEAM_H;
    let kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
    let bending = BEAM_P * l.powi(3) / (3.0 * material.e * i);
    (bending + BEAM_P * l / (kappa * material.shear_modulus() * area), bending)
}

/// Runs [`cantilever`] on several meshes and returns the relative errors against Timoshenko.
fn cantilever_errors(l: f64, material: Material, meshes: &[(usize, usize)]) -> Vec<f64> {
    let (timoshenko, _) = beam_theory(l, material);
    let mut errors = Vec::new();
    for &(nx, nh) in meshes {
        let t0 = std::time::Instant::now();
        let (delta, model) = cantilever(l, material, nx, nh, 1);
        let err = (delta - timoshenko) / timoshenko;
        let s = model.stats();
        eprintln!(
            "cantilever L/h = {}, nu = {}, {nx}×{nh}×{nh}: {} free DOFs, delta = {delta:.6e} m, \
             Timoshenko {timoshenko:.6e} m, error {:+.4} %, factorisation {:.1} ms, total {:.1} ms",
            l / BEAM_H,
            material.nu,
            s.free_dofs,
            100.0 * err,
            1e3 * s.factorisation_s(),
            1e3 * t0.elapsed().as_secs_f64()
        );
        errors.push(err);
    }
    errors
}

/// Cantilever, L/h = 10, square section, fully clamped root, uniform shear traction at the tip,
/// against Timoshenko theory with κ = 5/6.
///
/// ν = 0 here because the only clamp effect we measured is Poisson's: a fully fixed root face
/// cannot contract laterally, which stiffens the root region. With ν = 0.3 the limit of mesh
/// refinement at L/h = 10 lies 0.72 % below Timoshenko (80×6×6 mesh), about 0.37 % at L/h = 20
/// and 0.19 % at L/h = 40 — it falls as h/L, a local root effect — whereas with ν = 0 the
/// limit agrees with Timoshenko to 0.001 %, so the clamped solid reproduces beam theory
/// including its shear term. Measured errors (FE − Timoshenko)/Timoshenko at ν = 0:
/// 5×1×1: −0.383 %, 10×1×1: −0.122 %, 10×2×2: −0.031 %, 20×2×2: −0.008 %, 20×4×4: −0.002 %.
/// The shear term is 0.60 % of δ, so Euler–Bernoulli would fail the 0.5 % bound on the finer
/// meshes: the test sees the shear deformation. Steel is covered by
/// [`steel_cantilever_within_half_percent_of_timoshenko`].
#[test]
fn cantilever_matches_timoshenko_and_converges() {
    let material = Material { e: 206e9, nu: 0.0 };
    let l = 10.0 * BEAM_H;
    let errors = cantilever_errors(l, material, &[(5, 1), (10, 1), (10, 2), (20, 2)]);
    for w in errors.windows(2) {
        assert!(w[1].abs() < w[0].abs(), "error does not decrease with refinement: {errors:?}");
    }
    assert!(errors.iter().all(|&e| e < 0.0), "displacement FE must be stiff: {errors:?}");
    // Moderate mesh (10×2×2) well within 0.5 %; finest within 0.05 %.
    assert!(errors[2].abs() < 5e-3, "moderate mesh error {:e}", errors[2]);
    assert!(errors[3].abs() < 5e-4, "finest mesh error {:e}", errors[3]);
    // The shear term is resolved: Euler–Bernoulli is more than 0.5 % off the finest result.
    let (t, eb) = beam_theory(l, material);
    let fine = t * (1.0 + errors[3]);
    assert!((fine - eb) / eb > 5e-3, "shear deflection not seen: {}", (fine - eb) / eb);
}

/// Steel (ν = 0.3): at L/h = 40 the root's Poisson stiffening (≈ 0.19 %, see
/// [`cantilever_matches_timoshenko_and_converges`]) leaves room for the 0.5 % bound. Measured:
/// 40×1×1: −0.487 %, 80×1×1: −0.319 %, 80×2×2: −0.260 %, 160×2×2: −0.216 %.
#[test]
fn steel_cantilever_within_half_percent_of_timoshenko() {
    let l = 40.0 * BEAM_H;
    let errors = cantilever_errors(l, STEEL, &[(40, 1), (80, 1), (80, 2), (160, 2)]);
    for w in errors.windows(2) {
        assert!(w[1].abs() < w[0].abs(), "error does not decrease with refinement: {errors:?}");
    }
    assert!(errors.iter().all(|&e| e < 0.0 && e.abs() < 5e-3), "{errors:?}");
}

/// Gluing the beam from two blocks gives the same tip deflection as one block.
#[test]
fn merged_blocks_give_the_same_answer_as_one_block() {
    let l = 10.0 * BEAM_H;
    let (one, m1) = cantilever(l, STEEL, 8, 2, 1);
    let (two, m2) = cantilever(l, STEEL, 8, 2, 2);
    assert_eq!(m1.stats().nodes, m2.stats().nodes);
    assert!((one - two).abs() < 1e-10 * one, "{one} vs {two}");
}

/// Maxwell–Betti: on a curved, twisted block clamped at one end, the displacement at load point
/// i in direction dᵢ due to a unit load at point j in direction dⱼ equals the converse.
#[test]
fn influence_matrix_is_symmetric() {
    let mesh = Mesh::structured_block([4, 2, 2], |u, v, w| {
        let th = 0.6 * u; // bent in the x–y plane and twisted about the bar axis
        let (y, z) = (0.03 * (v - 0.5), 0.02 * (w - 0.5));
        let tw = 0.4 * u;
        let (y, z) = (y * tw.cos() - z * tw.sin(), y * tw.sin() + z * tw.cos());
        let r = 0.2 + y;
        [r * th.sin(), r * th.cos() - 0.2, z]
    })
    .expect("block");
    let clamped = mesh.nodes_where(|x| x[0].abs() < 1e-12);
    assert!(!clamped.is_empty());
    // Six load points spread over the unclamped nodes, each with its own direction.
    let free: Vec<usize> = (0..mesh.nodes.len()).filter(|p| !clamped.contains(p)).collect();
    let m = free.len();
    let points: Vec<(usize, usize)> =
        [(m - 1, 2), (m / 2, 0), (m / 3, 1), (2 * m / 3, 2), (7, 0), (m / 4 + 5, 1)]
            .into_iter()
            .map(|(i, d)| (free[i], d))
            .collect();
    let model = FeModel::new(mesh, STEEL, &clamped).expect("model");
    let mut f = Mat::<f64>::zeros(model.dofs(), points.len());
    for (j, &(p, d)) in points.iter().enumerate() {
        f[(dof(p, d), j)] = 1.0;
    }
    let u = model.solve_block(f.as_ref()).expect("solve");
    let k = points.len();
    let c = |i: usize, j: usize| u[(dof(points[i].0, points[i].1), j)];
    let c_max = (0..k)
        .flat_map(|i| (0..k).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(c(i, j).abs()));
    let mut asym = 0.0f64;
    for i in 0..k {
        assert!(c(i, i) > 0.0, "diagonal compliance must be positive");
        for j in 0..i {
            asym = asym.max((c(i, j) - c(j, i)).abs() / c_max);
        }
    }
    eprintln!("reciprocity: {k}×{k} influence matrix, max |C - Cᵀ| / max |C| = {asym:.2e}");
    assert!(asym < 1e-10, "asymmetry {asym:e}");
    let s = model.stats();
    assert_eq!(s.solved_cases, k);
    assert!(s.solve_s >= 0.0 && s.assembly_s > 0.0 && s.numeric_s > 0.0);
}

/// Coordinates of a single curved, skewed hex20 element (valid, positive Jacobian).
fn curved_element() -> [[f64; 3]; 20] {
    let mut c = [[0.0; 3]; 20];
    for (ca, xi) in c.iter_mut().zip(element::NODE_NATURAL.iter()) {
        let (x, y, z) = (xi[0], xi[1], xi[2]);
        *ca = [
            0.01 * (1.0 + x) + 0.002 * y * z + 0.001 * y * y,
            0.008 * (1.0 + y) + 0.001 * x,
            0.012 * (1.0 + z) + 0.0015 * x * x + 0.001 * x * y,
        ];
    }
    c
}

/// The element stiffness annihilates the six rigid-body modes, and its null space is exactly
/// six-dimensional (full integration: no spurious zero-energy modes).
#[test]
fn element_stiffness_has_exactly_six_rigid_body_modes() {
    let coords = curved_element();
    let mut ke = [[0.0; 60]; 60];
    element::stiffness(&coords, &STEEL, &mut ke).expect("element");
    let k_max = ke.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for (r, row) in ke.iter().enumerate() {
        for (c, &v) in row.iter().enumerate() {
            assert_eq!(v, ke[c][r], "not symmetric at ({r}, {c})");
        }
    }
    // Three translations and three infinitesimal rotations u = ω × x.
    let mut worst = 0.0f64;
    for m in 0..6 {
        let mut v = [0.0; 60];
        for (a, x) in coords.iter().enumerate() {
            let u = match m {
                0..=2 => {
                    let mut t = [0.0; 3];
                    t[m] = 1.0;
                    t
                }
                _ => {
                    let mut w = [0.0; 3];
                    w[m - 3] = 1.0 / 0.01; // unit displacement at the element size
                    [
                        w[1] * x[2] - w[2] * x[1],
                        w[2] * x[0] - w[0] * x[2],
                        w[0] * x[1] - w[1] * x[0],
                    ]
                }
            };
            v[3 * a..3 * a + 3].copy_from_slice(&u);
        }
        let v_max = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for row in &ke {
            let kv: f64 = row.iter().zip(&v).map(|(a, b)| a * b).sum();
            worst = worst.max(kv.abs() / (k_max * v_max));
        }
    }
    assert!(worst < 1e-12, "K·(rigid mode) = {worst:e} relative");
    let k = nalgebra::DMatrix::from_fn(60, 60, |r, c| ke[r][c]);
    let mut eig: Vec<f64> = k.symmetric_eigen().eigenvalues.iter().copied().collect();
    eig.sort_by(f64::total_cmp);
    let lmax = eig[59];
    eprintln!(
        "element eigenvalues / max: 6th {:.1e}, 7th {:.2e}",
        eig[5].abs() / lmax,
        eig[6] / lmax
    );
    assert!(eig[..6].iter().all(|l| l.abs() < 1e-10 * lmax), "{:?}", &eig[..7]);
    assert!(eig[6] > 1e-4 * lmax, "spurious zero-energy mode: {:e}", eig[6] / lmax);
}

/// An inverted or badly distorted element is reported by number, without panic or NaN.
#[test]
fn negative_jacobian_is_an_error_naming_the_element() {
    // Two elements along x; the second is made invalid in two ways.
    let good =
        Mesh::structured_block([2, 1, 1], |u, v, w| [0.2 * u, 0.1 * v, 0.1 * w]).expect("block");
    let fixed = good.nodes_where(|x| x[0] < 1e-12);

    // (a) A mid-edge node moved past the far corner of its edge: folds the element there.
    let mut bent = good.clone();
    let conn = bent.elements[1];
    let (a, b) = (bent.nodes[conn[0]], bent.nodes[conn[1]]);
    bent.nodes[conn[8]] = [b[0] + 0.5 * (b[0] - a[0]), a[1], a[2]];
    // (b) Top and bottom swapped: a mirrored (left-handed) element.
    let mut mirrored = good.clone();
    let c = mirrored.elements[1];
    let mut m = c;
    for k in 0..4 {
        m.swap(k, k + 4); // corners: bottom ↔ top
        m.swap(8 + k, 12 + k); // mid-edge nodes: bottom ↔ top
    }
    mirrored.elements[1] = m;

    for mesh in [bent, mirrored] {
        let err = FeModel::new(mesh.clone(), STEEL, &fixed).expect_err("invalid element");
        match err {
            FeError::NonPositiveJacobian { element, det, .. } => {
                assert_eq!(element, 1);
                assert!(det <= 0.0 || !det.is_finite());
            }
            other => panic!("unexpected error {other}"),
        }
        assert!(err.to_string().contains("element 1"), "{err}");
        let coords = mesh.element_coords(1).expect("coords");
        let mut ke = [[0.0; 60]; 60];
        assert!(element::stiffness(&coords, &STEEL, &mut ke).is_err());
    }
    assert!(FeModel::new(good, STEEL, &fixed).is_ok());
}

/// Missing constraints, bad fixed nodes and bad loads are typed errors.
#[test]
fn constraint_and_load_errors() {
    let mesh =
        Mesh::structured_block([2, 1, 1], |u, v, w| [0.2 * u, 0.1 * v, 0.1 * w]).expect("block");
    // Nodes along one edge only (collinear): rotation about that edge is free.
    let edge = mesh.nodes_where(|x| x[0] < 1e-12 && x[1] < 1e-12);
    assert!(edge.len() >= 3);
    assert!(matches!(
        FeModel::new(mesh.clone(), STEEL, &edge),
        Err(FeError::Underconstrained { fixed_nodes: 3, .. })
    ));
    assert!(matches!(
        FeModel::new(mesh.clone(), STEEL, &[]),
        Err(FeError::Underconstrained { fixed_nodes: 0, .. })
    ));
    assert!(matches!(
        FeModel::new(mesh.clone(), STEEL, &[10_000]),
        Err(FeError::FixedNodeOutOfRange { node: 10_000, .. })
    ));
    assert!(matches!(
        FeModel::new(mesh.clone(), Material { e: 1e9, nu: 0.5 }, &edge),
        Err(FeError::InvalidMaterial { .. })
    ));
    // A second, free-floating block: the merged mesh has an unconstrained part.
    let other =
        Mesh::structured_block([1, 1, 1], |u, v, w| [1.0 + 0.1 * u, 0.1 * v, 0.1 * w]).expect("b");
    let two = Mesh::merge(&[mesh.clone(), other], 1e-9).expect("merge");
    let root = two.nodes_where(|x| x[0] < 1e-12);
    assert!(matches!(FeModel::new(two, STEEL, &root), Err(FeError::Underconstrained { .. })));

    let fixed = mesh.nodes_where(|x| x[0] < 1e-12);
    let model = FeModel::new(mesh, STEEL, &fixed).expect("model");
    let n = model.dofs();
    assert!(matches!(
        model.solve_block(Mat::<f64>::zeros(n + 1, 1).as_ref()),
        Err(FeError::LoadShape { .. })
    ));
    let mut f = Mat::<f64>::zeros(n, 2);
    f[(5, 1)] = f64::NAN;
    assert!(matches!(
        model.solve_block(f.as_ref()),
        Err(FeError::NonFiniteLoad { row: 5, col: 1 })
    ));
    // Loads on fixed DOFs are ignored and fixed displacements are exactly zero.
    let mut f = Mat::<f64>::zeros(n, 1);
    f[(dof(fixed[0], 0), 0)] = 1e6;
    let u = model.solve_block(f.as_ref()).expect("solve");
    assert!((0..n).all(|i| u[(i, 0)] == 0.0));
    assert!(model.is_fixed(dof(fixed[0], 2)));
}
