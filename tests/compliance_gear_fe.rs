//! Integration tests of the whole-gear FE mesh and its flank influence data.

use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::compliance::fe::element::{self, GAUSS3_POINTS, GAUSS3_WEIGHTS};
use helical_gear_mesh::compliance::fe::gear_mesh::{GearMesh, GearMeshDensity};
use helical_gear_mesh::geometry::inertia::polygon_area;
use helical_gear_mesh::params::GearPair;

/// Volume of the mesh (m³) and the smallest Jacobian determinant at the 27 Gauss points.
fn volume_and_min_jacobian(gm: &GearMesh) -> (f64, f64) {
    let mut vol = 0.0;
    let mut min_det = f64::INFINITY;
    for e in 0..gm.mesh.elements.len() {
        let c = gm.mesh.element_coords(e).expect("element");
        for (k, &z) in GAUSS3_POINTS.iter().enumerate() {
            for (j, &y) in GAUSS3_POINTS.iter().enumerate() {
                for (i, &x) in GAUSS3_POINTS.iter().enumerate() {
                    let det = match element::gradients(&c, [x, y, z]) {
                        Ok((_, det)) => det,
                        Err(err) => err.det,
                    };
                    min_det = min_det.min(det);
                    vol += GAUSS3_WEIGHTS[i] * GAUSS3_WEIGHTS[j] * GAUSS3_WEIGHTS[k] * det;
                }
            }
        }
    }
    (vol, min_det)
}

#[test]
fn mesh_volume_jacobians_and_flank_nodes() {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).expect("geometry");
    for g in [&geo.pinion, &geo.gear] {
        let gm = GearMesh::build(g, &p, &GearMeshDensity::coarse()).expect("mesh");
        let (vol, min_det) = volume_and_min_jacobian(&gm);
        let r_bore = 0.5 * p.bore_diameter_m;
        let exact = p.face_width_m
            * (polygon_area(&g.outline(400)) - std::f64::consts::PI * r_bore * r_bore);
        eprintln!(
            "z = {}: {} nodes, {} DOFs, {} elements, volume {vol:.6e} vs {exact:.6e} (rel {:.2e}), min det {min_det:.3e}",
            g.z,
            gm.mesh.nodes.len(),
            3 * gm.mesh.nodes.len(),
            gm.mesh.elements.len(),
            (vol - exact) / exact
        );
        assert!(min_det > 0.0);
        assert!(((vol - exact) / exact).abs() < 1e-3);
    }
}

#[test]
#[ignore]
fn mesh_sizes() {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).expect("geometry");
    for (name, d) in [
        ("coarse", GearMeshDensity::coarse()),
        ("default", GearMeshDensity::default()),
        ("refined", GearMeshDensity::refined()),
    ] {
        for g in [&geo.pinion, &geo.gear] {
            let gm = GearMesh::build(g, &p, &d).expect("mesh");
            let (vol, min_det) = volume_and_min_jacobian(&gm);
            let exact = p.face_width_m
                * (polygon_area(&g.outline(400))
                    - std::f64::consts::PI * (0.5 * p.bore_diameter_m).powi(2));
            eprintln!(
                "{name} z = {}: {} quads, {} DOFs, {} elements, vol rel {:.2e}, min det {min_det:.2e}, web {:?}",
                g.z,
                gm.quads,
                3 * gm.mesh.nodes.len(),
                gm.mesh.elements.len(),
                (vol - exact) / exact,
                gm.web_radii
            );
        }
    }
}
