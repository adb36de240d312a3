//! The table's sample slices (`MeshOptions::table_slices`, `mesh::table` "Sample slices"): the
//! table samples the full model at min(`slices`, `table_slices`) slices, the full model outside
//! the table keeps `slices`, and the default (100) leaves the table's error against the
//! converged model (800 slices) where sampling at 200 slices puts it.

mod common;

use helical_gear_mesh::DriveLine;
use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshError, MeshOptions, MeshState};

/// Largest relative errors of (M_F,p, M_D,p) of `mesh` against `reference` over `states`.
fn max_rel_err(mesh: &mut Mesh, reference: &[(f64, f64)], states: &[MeshState]) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for (s, (f, d)) in states.iter().zip(reference) {
        let o = mesh.evaluate(s).unwrap();
        worst.0 = worst.0.max(((o.m_f_p - f) / f).abs());
        worst.1 = worst.1.max(((o.m_d_p - d) / d).abs());
    }
    worst
}

#[test]
fn the_default_sample_slices_keep_the_tables_error_against_800_slices() {
    let pair = GearPair::paper_table1();
    let base = MeshOptions::default().sized_for(&DriveLine::paper_table1());
    assert_eq!(base.table_slices, 100);
    let mut reference = Mesh::new(&pair, MeshOptions { slices: 800, ..base }).unwrap();
    // The benchmark's 192 states, with a TE rate for the damping torque (M_F,p does not depend
    // on the speeds).
    let states = common::benchmark_states(reference.geometry(), 64);
    let r: Vec<(f64, f64)> = states
        .iter()
        .map(|s| {
            let o = reference.evaluate(s).unwrap();
            (o.m_f_p, o.m_d_p)
        })
        .collect();
    let table = MeshOptions { fidelity: Fidelity::Table, ..base };
    let mut at_100 = Mesh::new(&pair, table).unwrap();
    let mut at_200 = Mesh::new(&pair, MeshOptions { table_slices: 200, ..table }).unwrap();
    let (e100, d100) = max_rel_err(&mut at_100, &r, &states);
    let (e200, d200) = max_rel_err(&mut at_200, &r, &states);
    // M_F,p: the default table's error (96 × 24, `mesh::table` "Default size": 1.99e-4 on these
    // states), within a few percent of sampling at the full evaluation's 200 slices (measured
    // 1.99e-4 and 1.93e-4).
    assert!(e100 <= 2.1e-4, "sampled at 100 slices: {e100:.3e}");
    assert!(e100 <= 1.05 * e200, "100 slices {e100:.3e} against 200 slices {e200:.3e}");
    // M_D,p follows the loaded extent, resolved within the slices (second order in the slice
    // width, `tests/mesh_extent.rs`): its table error is the interpolation's, and sampling at
    // 100 slices leaves it where 200 put it (measured 5.46e-3 and 5.63e-3).
    assert!(d100 <= 6e-3, "M_D,p: {d100:.3e} at 100 slices");
    assert!(d100 <= 1.05 * d200, "M_D,p: {d100:.3e} at 100, {d200:.3e} at 200 slices");
}

#[test]
fn the_table_samples_at_the_smaller_of_slices_and_table_slices_and_falls_back_at_slices() {
    let pair = GearPair::paper_table1();
    let small = MeshOptions {
        fidelity: Fidelity::Table,
        table_phase_points: 16,
        table_te_points: 12,
        ..MeshOptions::default()
    };
    let build = |slices, table_slices| {
        Mesh::new(&pair, MeshOptions { slices, table_slices, ..small }).unwrap()
    };
    // slices 200, table_slices 60: the same table as slices 60 (every table value equal bit
    // for bit), but the full model outside the table at its own slices.
    let mut capped = build(200, 60);
    let mut same = build(60, 60);
    // slices 60 under the default table_slices 100: the table samples at 60.
    let mut under = build(60, 100);
    let geo = capped.geometry().clone();
    let pitch = common::table1_pitch();
    let (lo, hi) = capped.table().unwrap().te_range();
    for k in 0..10 {
        let phi_p = (k as f64 + 0.3) / 10.0 * pitch;
        for te in [0.2 * hi, 0.7 * hi] {
            let s = MeshState { phi_p, phi_g: geo.phi_g_for_te(phi_p, te), ..Default::default() };
            let a = capped.evaluate(&s).unwrap();
            assert_eq!(a.m_f_p.to_bits(), same.evaluate(&s).unwrap().m_f_p.to_bits());
            assert_eq!(a.m_f_p.to_bits(), under.evaluate(&s).unwrap().m_f_p.to_bits());
        }
    }
    // Beyond the driving axis: the full model at `slices`.
    let beyond = hi * 1.05;
    assert!(beyond > lo);
    let s = MeshState {
        phi_p: 0.1 * pitch,
        phi_g: geo.phi_g_for_te(0.1 * pitch, beyond),
        ..Default::default()
    };
    let full = |slices| {
        let o = MeshOptions { slices, ..MeshOptions::default() };
        Mesh::new(&pair, o).unwrap().evaluate(&s).unwrap().m_f_p
    };
    assert_eq!(capped.evaluate(&s).unwrap().m_f_p.to_bits(), full(200).to_bits());
    assert_eq!(same.evaluate(&s).unwrap().m_f_p.to_bits(), full(60).to_bits());
}

#[test]
fn table_slices_outside_its_bounds_is_an_error_naming_it() {
    let pair = GearPair::paper_table1();
    for (fidelity, n) in [(Fidelity::Table, 9), (Fidelity::Full, 4001), (Fidelity::Table, 0)] {
        let o = MeshOptions { fidelity, table_slices: n, ..common::coarse_options(fidelity) };
        match Mesh::new(&pair, o) {
            Err(MeshError::Param(e)) => assert!(e.to_string().contains("table_slices"), "{e}"),
            other => panic!("table_slices = {n}: {other:?}"),
        }
    }
}
