//! The loaded extent resolved within the slices (`mesh::model::extent`): the damping torque
//! and the contact length converge at second order in the slice width, and they are
//! continuous in the state.

mod common;

use helical_gear_mesh::DriveLine;
use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{Mesh, MeshOptions, MeshState};

#[test]
fn the_damping_torque_converges_at_second_order_in_the_slice_width() {
    let pair = GearPair::paper_table1();
    let base = MeshOptions::default().sized_for(&DriveLine::paper_table1());
    let mut reference = Mesh::new(&pair, MeshOptions { slices: 1600, ..base }).unwrap();
    // 16 phases over a pitch at TE = 16, 32 and 48 µm, with a TE rate.
    let states = common::benchmark_states(reference.geometry(), 16);
    let r: Vec<_> = states.iter().map(|s| reference.evaluate(s).unwrap()).collect();
    let mut errors = Vec::new();
    for slices in [100, 200, 400] {
        let mut mesh = Mesh::new(&pair, MeshOptions { slices, ..base }).unwrap();
        let (mut md, mut cl) = (0.0f64, 0.0f64);
        for (s, r) in states.iter().zip(&r) {
            let o = mesh.evaluate(s).unwrap();
            md = md.max(((o.m_d_p - r.m_d_p) / r.m_d_p).abs());
            cl = cl.max(((o.contact_length - r.contact_length) / r.contact_length).abs());
        }
        // M_D is the extent times a factor of the state: the same relative error.
        assert!((md - cl).abs() <= 1e-9, "{slices} slices: M_D {md:.3e}, length {cl:.3e}");
        errors.push(md);
    }
    // Measured 8.2e-4, 2.0e-4 and 4.8e-5 on the benchmark's 192 states; counted in whole
    // slices 1.27e-2, 7.3e-3 and 4.1e-3 (first order).
    assert!(errors[0] <= 1.5e-3, "100 slices: {:.3e}", errors[0]);
    for w in errors.windows(2) {
        assert!(w[1] <= w[0] / 3.0, "halving the slice width: {:.3e} → {:.3e}", w[0], w[1]);
    }
}

#[test]
fn the_contact_length_jumps_only_where_a_loaded_run_reaches_the_face() {
    let pair = GearPair::paper_table1();
    let base = MeshOptions::default().sized_for(&DriveLine::paper_table1());
    let mut mesh = Mesh::new(&pair, MeshOptions { slices: 100, ..base }).unwrap();
    let geo = mesh.geometry().clone();
    let pitch = common::table1_pitch();
    // A slice's line length w = b/(n_line·cos β_b).
    let slice_length =
        pair.face_width_m / (mesh.slices_per_line() as f64 * geo.base_helix_angle.cos());
    let mut length = |phi_p: f64, te: f64| {
        let s = MeshState { phi_p, phi_g: geo.phi_g_for_te(phi_p, te), ..Default::default() };
        mesh.evaluate(&s).unwrap().contact_length
    };
    // TE from 1 to 60 µm in steps of 0.05 µm at four phases; a step that changes the length
    // by more than a tenth of a slice is bisected 30 times (to 5e-17 m of TE): what is left
    // is a jump. Counted in whole slices, the length jumps by a slice's line length wherever
    // a slice enters; resolved, it jumps only where a newly loaded slice at the face end of a
    // line adds the half slice to the face at once (`mesh::model::extent`).
    for phase in [0.1, 0.3, 0.45, 0.8] {
        let phi_p = phase * pitch;
        let mut jumps = 0;
        let mut last = length(phi_p, 1e-6);
        for k in 1..=1180 {
            let (a, b) = (1e-6 + (k - 1) as f64 * 0.05e-6, 1e-6 + k as f64 * 0.05e-6);
            let lb = length(phi_p, b);
            if (lb - last).abs() > 0.1 * slice_length {
                let (mut lo, mut hi) = (a, b);
                let (mut l_lo, mut l_hi) = (last, lb);
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    let l_mid = length(phi_p, mid);
                    if (l_mid - l_lo).abs() >= (l_hi - l_mid).abs() {
                        (hi, l_hi) = (mid, l_mid);
                    } else {
                        (lo, l_lo) = (mid, l_mid);
                    }
                }
                let jump = (l_hi - l_lo).abs();
                if jump > 0.01 * slice_length {
                    jumps += 1;
                    assert!(
                        jump <= 0.51 * slice_length,
                        "phase {phase}, TE {:.4} µm: the length jumps by {jump:.3e} m (a slice: \
                         {slice_length:.3e} m)",
                        lo * 1e6
                    );
                }
            }
            last = lb;
        }
        assert!(jumps <= 2, "phase {phase}: {jumps} jumps");
    }
}
