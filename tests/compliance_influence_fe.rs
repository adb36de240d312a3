//! The fast FE influence run ([`FeMethod::Fast`]: one axial layer of element stiffnesses, AMD
//! on the node graph, selected solves) against the reference ([`FeMethod::Reference`]: every
//! element integrated, AMD on the DOF graph, whole solves) on the coarse meshes of both
//! Table 1 gears: the same discretised problem, so α*, the surface matrix and the root-stress
//! data agree to rounding (≤ 1e-9 of each block's largest value). Also: the layer-congruent
//! assembly equals the plain one, and the selected solve equals the whole solve on its rows
//! (fixed nodes included).

use faer::Mat;
use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::compliance::fe::gear_mesh::{GearMesh, GearMeshDensity};
use helical_gear_mesh::compliance::fe::{DofMap, FeModel, Material, ModelOptions, assembly, dof};
use helical_gear_mesh::compliance::influence_fe::{DEFAULT_DEPTH_MN, FeMethod, fe_influence_with};
use helical_gear_mesh::params::GearPair;

/// Largest |a − b| over the largest |b|.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

#[test]
fn fast_method_reproduces_the_reference_for_both_table1_gears() {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).expect("geometry");
    let h = DEFAULT_DEPTH_MN * p.normal_module_m;
    // Conforming, and with axial coarsening (tied nodes: the reference solves whole blocks).
    let coarsened = GearMeshDensity { coarse_layers: Some(1), ..GearMeshDensity::coarse() };
    for (d, g) in [(GearMeshDensity::coarse(), &geo.pinion), (GearMeshDensity::coarse(), &geo.gear)]
        .into_iter()
        .chain([(coarsened, &geo.pinion), (coarsened, &geo.gear)])
    {
        let fast = fe_influence_with(g, &p, &d, h, FeMethod::Fast, false).expect("fast");
        let reference =
            fe_influence_with(g, &p, &d, h, FeMethod::Reference, false).expect("reference");
        assert_eq!(fast.stats.dofs, reference.stats.dofs);
        assert_eq!(fast.stats.solved_cases, reference.stats.solved_cases);
        let (a, b) = (&fast.grid, &reference.grid);
        assert_eq!((&a.profile, &a.zeta, &a.teeth), (&b.profile, &b.zeta, &b.teeth));
        for (t, (x, y)) in a.alpha.iter().zip(&b.alpha).enumerate() {
            let r = rel_diff(x, y);
            eprintln!("z = {}, α* block of tooth {}: relative difference {r:.2e}", g.z, b.teeth[t]);
            assert!(r <= 1e-9, "z = {}: α* block {t} differs by {r:e}", g.z);
        }
        let r = rel_diff(&fast.surface, &reference.surface);
        assert!(r <= 1e-9, "z = {}: surface matrix differs by {r:e}", g.z);
        // Root stress: stored as integer multiples of a quantum (1e-4 of the largest value), so
        // a difference of 1e-9 can move a value across a rounding boundary by one unit at most.
        let (s, q) = (&fast.root_stress, &reference.root_stress);
        let rq = (s.quantum_pa_per_n - q.quantum_pa_per_n).abs() / q.quantum_pa_per_n;
        assert!(rq <= 1e-9, "z = {}: stress quantum differs by {rq:e}", g.z);
        assert_eq!(s.sigma.len(), q.sigma.len());
        let (mut total, mut moved) = (0usize, 0usize);
        for (x, y) in s.sigma.iter().zip(&q.sigma) {
            assert_eq!(x.len(), y.len());
            for (u, v) in x.iter().zip(y) {
                assert!((u - v).abs() <= 1, "z = {}: root stress {u} against {v}", g.z);
                total += 1;
                moved += usize::from(u != v);
            }
        }
        assert!(moved * 1000 <= total, "z = {}: {moved} of {total} stress units moved", g.z);
        assert_eq!(
            (&s.tangent_angle_deg, &s.levels_zeta, &s.load_zeta),
            (&q.tangent_angle_deg, &q.levels_zeta, &q.load_zeta)
        );
    }
}

#[test]
fn layer_congruent_assembly_equals_the_plain_one() {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).expect("geometry");
    let gm = GearMesh::build(&geo.gear, &p, &GearMeshDensity::coarse()).expect("mesh");
    let material = Material::from(&p.material_g);
    let dofs = DofMap::new(gm.mesh.nodes.len(), &gm.bore_nodes).expect("dofs");
    let congruence = gm.layer_congruence();
    assert_eq!(congruence.len(), gm.mesh.elements.len());
    // Every element above layer 0 is claimed congruent to one of layer 0.
    assert_eq!(congruence.iter().flatten().count(), gm.mesh.elements.len() - gm.quads);
    let plain = assembly::assemble_lower(&gm.mesh, &material, &dofs).expect("plain");
    let turned = assembly::assemble_lower_congruent(&gm.mesh, &material, &dofs, &congruence)
        .expect("turned");
    assert_eq!(plain.symbolic().col_ptr(), turned.symbolic().col_ptr());
    assert_eq!(plain.symbolic().row_idx(), turned.symbolic().row_idx());
    // The nodes of each layer are computed from their own turn, so the turned copy of layer 0
    // differs from them by rounding of the coordinates (~1e-16 of the radius, ~1e-14 of an
    // element), which the Jacobian inverses amplify: a few 1e-12 of the largest entry.
    let r = rel_diff(turned.val(), plain.val());
    assert!(r <= 1e-10, "congruent assembly differs by {r:e}");
    // A wrong claim (the wrong angle) is detected on the coordinates and integrated instead.
    let wrong: Vec<_> = congruence
        .iter()
        .map(|c| c.map(|c| assembly::Congruent { angle: c.angle + 0.1, ..c }))
        .collect();
    let checked =
        assembly::assemble_lower_congruent(&gm.mesh, &material, &dofs, &wrong).expect("checked");
    assert_eq!(checked.val(), plain.val());
}

#[test]
fn selected_solve_equals_the_whole_solve_on_its_rows() {
    selected_solve_case(&GearMeshDensity::coarse());
}

/// As above on a mesh with axial coarsening: the wanted nodes and the loads include tied
/// nodes (their displacements interpolated from their masters, their loads passed to them).
#[test]
fn selected_solve_equals_the_whole_solve_with_tied_nodes() {
    selected_solve_case(&GearMeshDensity { coarse_layers: Some(1), ..GearMeshDensity::coarse() });
}

fn selected_solve_case(density: &GearMeshDensity) {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).expect("geometry");
    let gm = GearMesh::build(&geo.pinion, &p, density).expect("mesh");
    let congruence = gm.layer_congruence();
    let options = ModelOptions { congruent: &congruence, node_ordering: true, ties: &gm.ties };
    let material = Material::from(&p.material_p);
    let model =
        FeModel::with_options(gm.mesh.clone(), material, &gm.bore_nodes, &options).expect("model");
    let flank = gm.flank(0).expect("tooth 0");
    // Three load cases: a flank node, two nodes together, and a load on a fixed node only.
    let node = |k: usize| flank.nodes[k].expect("the loaded tooth has a node at every point");
    let (a, b) = (node(0), node(flank.nodes.len() - 1));
    let fixed = gm.bore_nodes[0];
    let mut cases = vec![
        vec![(dof(a, 0), 1.0), (dof(a, 2), -0.5)],
        vec![(dof(a, 1), 2.0), (dof(b, 0), 1.0), (dof(b, 0), 0.5)],
        vec![(dof(fixed, 1), 3.0)],
    ];
    let mut wanted: Vec<usize> =
        vec![a, b, fixed, gm.flank(-1).expect("tooth -1").nodes[3].expect("a node")];
    if let Some(t) = gm.ties.get(gm.ties.len() / 2) {
        cases.push(vec![(dof(t.node, 0), 1.5), (dof(a, 2), 0.25)]);
        wanted.push(t.node);
        wanted.push(t.masters[0].0);
    }
    let selected = model.solve_at_nodes(&cases, &wanted).expect("selected");
    let mut f = Mat::<f64>::zeros(model.dofs(), cases.len());
    for (c, case) in cases.iter().enumerate() {
        for &(r, v) in case {
            f[(r, c)] += v;
        }
    }
    let whole = model.solve_block(f.as_ref()).expect("whole");
    let scale = (0..model.dofs()).fold(0.0f64, |m, r| m.max(whole[(r, 0)].abs()));
    for (c, _) in cases.iter().enumerate() {
        for (i, &node) in wanted.iter().enumerate() {
            for d in 0..3 {
                let (x, y) = (selected[(3 * i + d, c)], whole[(dof(node, d), c)]);
                assert!((x - y).abs() <= 1e-12 * scale, "case {c}, node {node}: {x} against {y}");
            }
        }
    }
    // Fixed DOFs are exactly zero; the load on a fixed node alone moves nothing.
    for d in 0..3 {
        assert_eq!(selected[(6 + d, 0)], 0.0);
        assert!((0..wanted.len() * 3).all(|r| selected[(r, 2)] == 0.0));
    }
    assert!(model.solve_at_nodes(&cases, &[gm.mesh.nodes.len()]).is_err());
    assert!(model.solve_at_nodes(&[vec![(model.dofs(), 1.0)]], &wanted).is_err());
    assert!(model.solve_at_nodes(&[vec![(dof(a, 0), f64::NAN)]], &wanted).is_err());
}
