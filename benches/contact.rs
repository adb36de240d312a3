//! Cost of one full instant-line-of-contact evaluation (all slices, all tooth pairs) for the
//! Table 1 gear pair: `cargo bench --bench contact`.

use helical_gear_mesh::contact::ContactSolver;
use helical_gear_mesh::{GearPair, PairGeometry};

fn main() {
    divan::main();
}

/// Full contact evaluation at `n` axial slices per pair over a sweep of mesh positions.
#[divan::bench(args = [50, 100, 200])]
fn contact_all_pairs(bencher: divan::Bencher, n: usize) {
    let g = PairGeometry::new(&GearPair::paper_table1()).unwrap();
    let s = ContactSolver::new(&g);
    let zetas = s.slice_zetas(n);
    let mut out = Vec::with_capacity(8 * n);
    let mut i = 0u64;
    bencher.bench_local(|| {
        i += 1;
        let phi_p = (i % 97) as f64 * g.pinion.angular_pitch() / 97.0;
        let phi_g = g.phi_g_for_te(phi_p, 30e-6);
        s.contacts(divan::black_box(phi_p), phi_g, &zetas, &mut out);
        out.len()
    });
}

/// Geometry construction (validation, generation, inertias) for Table 1.
#[divan::bench]
fn pair_geometry_new() -> PairGeometry {
    PairGeometry::new(divan::black_box(&GearPair::paper_table1())).unwrap()
}
