//! Checks of a whole-gear FE mesh, shared by `tests/compliance_gear_fe.rs` (which asserts them)
//! and the measurement program `app/examples/measure.rs` (which tabulates them for the three
//! mesh densities in `docs/bench/fe.md`).

use helical_gear_mesh::compliance::fe::element::{self, GAUSS3_POINTS, GAUSS3_WEIGHTS};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMesh;

/// Volume of the mesh (m³) and the smallest Jacobian determinant at the 27 Gauss points.
pub fn volume_and_min_jacobian(gm: &GearMesh) -> (f64, f64) {
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
