//! The steady path of `Mesh::evaluate` does not allocate: after a warm-up over the same
//! kind of states, evaluations along a trajectory make no heap allocation (counted by a global
//! allocator wrapper; this file holds a single test so that no other test allocates meanwhile).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use helical_gear_mesh::GearPair;
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::mesh::{ComplianceModel, Mesh, MeshOptions, MeshState, compute_compliance};

use common::coarse_options;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn steady_evaluations_do_not_allocate() {
    let pair = GearPair::paper_table1();
    let (p, g) =
        compute_compliance(&pair, &GearMeshDensity::coarse(), ComplianceModel::Interpolated)
            .expect("compliance");
    let mut m = Mesh::with_compliance(&pair, MeshOptions::default(), p, g).expect("model");
    let geo = m.geometry().clone();
    let pitch = geo.pinion.angular_pitch();
    let state = |k: usize| {
        let phi_p = 3.0 * pitch * k as f64 / 400.0;
        let te = 30e-6 + 5e-6 * (k as f64 * 0.37).sin();
        MeshState {
            phi_p,
            phi_g: geo.phi_g_for_te(phi_p, te),
            w_p: 300.0,
            w_g: -191.0,
            ..Default::default()
        }
    };
    for k in 0..400 {
        m.evaluate(&state(k)).expect("warm-up");
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let mut sum = 0.0;
    for k in 0..400 {
        sum += m.evaluate(&state(k)).expect("evaluate").m_f_p;
    }
    let count = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert!(sum.is_finite());
    assert_eq!(count, 0, "{count} allocations in 400 steady evaluations");

    // The table with tooth deviations (per-pair values) and its Jacobian: no allocation at all.
    use helical_gear_mesh::mesh::{Fidelity, MeshTorques};
    let mut dev = pair.clone();
    dev.modifications.pinion.pitch_deviations_m = vec![1e-6; dev.z_p as usize];
    dev.modifications.pinion.pitch_deviations_m[3] = -1e-6;
    dev.modifications.gear.runout_m = 4e-6;
    let opts = coarse_options(Fidelity::Table);
    let mut t = Mesh::new(&dev, opts).expect("table with deviations");
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let mut sum = 0.0;
    for k in 0..400 {
        sum += t.evaluate(&state(k * 37)).expect("evaluate").m_f_p;
        sum += t.mesh_jacobian(&state(k * 37)).expect("jacobian").1.d[0][0];
    }
    let count = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert!(sum.is_finite());
    assert_eq!(count, 0, "{count} allocations in 400 table evaluations with deviations");
}
