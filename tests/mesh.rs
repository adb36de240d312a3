//! Tests of the mesh model façade (`mesh`): load distribution over all contact lines, torques,
//! static equilibrium, load onset, slice convergence, robustness and the table fidelity.
//! The FE compliance is computed once per test binary on the coarse mesh.

mod common;

use std::sync::{Arc, OnceLock};

use helical_gear_mesh::compliance::data::{BodySupport, ComplianceData};
use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::compliance::influence_fe::DEFAULT_DEPTH_MN;
use helical_gear_mesh::dynamics::mesh_stiffness;
use helical_gear_mesh::geometry::Member;
use helical_gear_mesh::mesh::{
    ComplianceModel, EquilibriumSettings, Fidelity, GearCompliance, Mesh, MeshError, MeshOptions,
    MeshState, compute_compliance, equilibrium, static_curve, tip_contact_threshold_curve,
};
use helical_gear_mesh::{DriveLine, GearPair};

use common::{state_at_rest as state, table1_pitch as pitch};

fn coarse() -> &'static (GearCompliance, GearCompliance) {
    static C: OnceLock<(GearCompliance, GearCompliance)> = OnceLock::new();
    C.get_or_init(|| {
        compute_compliance(
            &GearPair::paper_table1(),
            &GearMeshDensity::coarse(),
            ComplianceModel::Interpolated,
        )
        .expect("coarse FE compliance")
    })
}

fn model(options: MeshOptions) -> Mesh {
    let (p, g) = coarse().clone();
    Mesh::with_compliance(&GearPair::paper_table1(), options, p, g).expect("model")
}

/// With a Winkler (constant, local) compliance k per flank and no Hertz term every loaded
/// slice deflects by (k_p + k_g)·q, so q = Δ·cos θ/(k_p + k_g) on every slice; a pair whose
/// contacts all lie in the plane of action has uniform q, and M_F,p = Σ q·g_p·m_n·Δζ.
#[test]
fn uniform_compliance_oracle() {
    let (kp, kg) = (4e-11, 6e-11);
    let options = MeshOptions { local_contact: false, detail: true, ..MeshOptions::default() };
    let pair = GearPair::paper_table1();
    let w = |k| GearCompliance::Winkler { compliance: k, depth_h: 6e-4 };
    let mut m = Mesh::with_compliance(&pair, options, w(kp), w(kg)).expect("model");
    let geo = m.geometry().clone();
    let ct = geo.base_helix_angle.cos();
    let dz = pair.normal_module_m * geo.b0() / m.slices_per_line() as f64;
    let te = 10e-6;
    let mut checked = 0;
    for k in 0..40 {
        let phi = pitch() * k as f64 / 40.0;
        let o = m.evaluate(&state(&m, phi, te)).expect("evaluate");
        let mut mp = 0.0;
        for s in m.slices() {
            let q = s.overlap_m * ct / (kp + kg);
            assert!((s.q_n_per_m - q).abs() <= 1e-9 * q, "q {} vs {q}", s.q_n_per_m);
            if s.kind == "involute/involute" {
                assert!((s.overlap_m - te).abs() < 1e-12);
            }
        }
        if m.slices().iter().all(|s| s.kind == "involute/involute") {
            for s in m.slices() {
                mp += s.q_n_per_m * geo.pinion.rb * dz;
            }
            assert!((o.m_f_p - mp).abs() <= 1e-9 * mp, "{} vs {mp}", o.m_f_p);
            let ratio = o.m_f_g / o.m_f_p;
            assert!((ratio - geo.gear.rb / geo.pinion.rb).abs() < 1e-12);
            checked += 1;
        }
    }
    assert!(checked >= 5, "only {checked} phases with all contacts in the plane of action");
}

/// Force balance in the plane of action and static equilibrium to 1e-9.
#[test]
fn force_balance_and_static_equilibrium() {
    let mut m = model(MeshOptions { detail: true, ..MeshOptions::default() });
    let geo = m.geometry().clone();
    let ratio = geo.gear.rb / geo.pinion.rb;
    for k in 0..10 {
        let phi = pitch() * k as f64 / 10.0;
        let eq = equilibrium(&mut m, phi, 100.0, 2e-5, &EquilibriumSettings::default())
            .expect("equilibrium");
        assert!((eq.outputs.m_f_p - 100.0).abs() <= 1e-9 * 100.0, "M_F,p = {}", eq.outputs.m_f_p);
        let o = m
            .evaluate(&MeshState {
                phi_p: phi,
                phi_g: eq.phi_g,
                w_p: 0.0,
                w_g: 0.0,
                ..Default::default()
            })
            .unwrap();
        if m.slices().iter().filter(|s| s.q_n_per_m > 0.0).all(|s| s.kind == "involute/involute") {
            assert!((o.m_f_g / o.m_f_p - ratio).abs() < 1e-12);
        } else {
            // Off-plane contacts have other moment arms: the balance holds to their share.
            assert!((o.m_f_g / o.m_f_p - ratio).abs() < 0.02 * ratio);
        }
        assert!(eq.te > 0.0 && eq.te < 1e-4);
    }
}

/// Exact zero when nothing overlaps (inside the backlash), and back-flank torques reverse.
#[test]
fn separation_and_back_flanks() {
    let mut m = model(MeshOptions::default());
    let jt = m.geometry().backlash_te;
    for te in [-1e-9, -0.5 * jt, -jt + 1e-9] {
        let o = m.evaluate(&state(&m, 0.01, te)).unwrap();
        assert!(o.separated && o.m_f_p == 0.0 && o.m_f_g == 0.0 && o.f_n == 0.0);
    }
    let o = m.evaluate(&state(&m, 0.01, -jt - 10e-6)).unwrap();
    assert!(o.back_contact && !o.separated);
    assert!(o.m_f_p < 0.0 && o.m_f_g < 0.0, "{o:?}");
}

/// Maximum change of M_F,p between consecutive phases of a scan over one pitch at fixed TE.
fn max_step(m: &mut Mesh, te: f64, steps: usize) -> f64 {
    let mut prev: Option<f64> = None;
    let mut worst: f64 = 0.0;
    for k in 0..=steps {
        let phi = -0.5 * pitch() + pitch() * k as f64 / steps as f64;
        let o = m.evaluate(&state(m, phi, te)).unwrap();
        if let Some(p) = prev {
            worst = worst.max((o.m_f_p - p).abs());
        }
        prev = Some(o.m_f_p);
    }
    worst
}

/// Load onset: at fixed TE, M_F is continuous in φp across the entry and exit of a pair: the
/// largest change between neighbouring phases shrinks in proportion to the phase step (no
/// jumps), for coarse and fine slicing, and finer slicing does not make it larger.
#[test]
fn load_onset_is_continuous() {
    let te = 30e-6;
    let mut results = Vec::new();
    for slices in [100, 400] {
        let mut m = model(MeshOptions { slices, ..MeshOptions::default() });
        let coarse = max_step(&mut m, te, 200);
        let fine = max_step(&mut m, te, 800);
        results.push((slices, coarse, fine));
        assert!(fine < 0.35 * coarse, "slices {slices}: max step {coarse} → {fine} N·m");
    }
    eprintln!("max |ΔM_F,p| (slices, 200 steps, 800 steps): {results:?}");
    assert!(results[1].1 <= 1.1 * results[0].1);
}

/// Slice convergence: the maximum STE changes by less than 0.5 % from 200 to 400 slices.
#[test]
fn slice_convergence_of_ste() {
    let mut ste = Vec::new();
    for slices in [200, 400] {
        let mut m = model(MeshOptions { slices, ..MeshOptions::default() });
        let c = static_curve(&mut m, 100.0, 0.0, pitch(), 20, 1).expect("static");
        ste.push(c.max());
    }
    let rel = (ste[1] - ste[0]).abs() / ste[1];
    eprintln!("STE max 200 / 400 slices: {:.4} / {:.4} µm ({rel:.2e})", ste[0] * 1e6, ste[1] * 1e6);
    assert!(rel < 5e-3, "STE max {ste:?}, change {rel}");
}

/// No NaN and no panic over a dense grid of (phase, TE) from −2× backlash to 5× nominal STE;
/// non-finite inputs are typed errors.
#[test]
fn dense_grid_is_finite() {
    let mut m = model(MeshOptions::default());
    let jt = m.geometry().backlash_te;
    let te_nom = 31e-6;
    let (lo, hi) = (-2.0 * jt, 5.0 * te_nom);
    for i in 0..25 {
        let phi = pitch() * i as f64 / 25.0;
        for k in 0..=40 {
            let te = lo + (hi - lo) * k as f64 / 40.0;
            let mut s = state(&m, phi, te);
            s.w_p = 300.0;
            s.w_g = -300.0 * 30.0 / 47.0 + 0.1;
            let o = m.evaluate(&s).expect("evaluate");
            for v in [o.m_f_p, o.m_f_g, o.m_d_p, o.m_d_g, o.f_n, o.contact_length, o.p_max] {
                assert!(v.is_finite(), "{o:?} at phase {phi}, TE {te}");
            }
            assert_eq!(o.separated, o.n_pairs == 0);
            if te > 0.0 {
                assert!(o.m_f_p >= 0.0);
            }
        }
    }
    let bad = MeshState { phi_p: f64::NAN, ..MeshState::default() };
    assert!(matches!(m.evaluate(&bad), Err(MeshError::NonFinite { name: "phi_p", .. })));
    let bad = MeshState { w_g: f64::INFINITY, ..MeshState::default() };
    let e = m.evaluate(&bad).unwrap_err();
    assert!(e.to_string().contains("w_g"), "{e}");
}

/// Very large angles: the phase reduction keeps the result periodic in the pinion pitch.
#[test]
fn periodic_in_the_pitch() {
    let mut m = model(MeshOptions::default());
    let a = m.evaluate(&state(&m, 0.013, 25e-6)).unwrap();
    let b = m.evaluate(&state(&m, 0.013 + 7.0 * pitch(), 25e-6)).unwrap();
    assert!((a.m_f_p - b.m_f_p).abs() < 1e-9 * a.m_f_p.abs(), "{} vs {}", a.m_f_p, b.m_f_p);
}

/// `MeshTorques::torques` (the right-hand side's evaluation) gives every output the table of
/// outputs marks `torques` (M_F, M_D, TE, the contact length, the friction torques and loss)
/// bit for bit as `mesh` does, across the table's range (driving flanks, backlash, back
/// flanks) and outside it (the full model, complete), with and without friction; and so does
/// `torques_into` written over the record of the previous state's complete evaluation.
#[test]
fn torques_only_evaluation_matches_the_complete_one() {
    use helical_gear_mesh::mesh::Friction;
    for friction in [Friction::none(), Friction::constant(0.05)] {
        torques_only_matches(friction);
    }
}

fn torques_only_matches(friction: helical_gear_mesh::mesh::Friction) {
    use helical_gear_mesh::mesh::MeshTorques;
    use helical_gear_mesh::mesh::outputs::MESH_OUTPUT_FIELDS;
    let names: Vec<_> = MESH_OUTPUT_FIELDS.iter().filter(|f| f.torques).map(|f| f.name).collect();
    assert_eq!(
        names,
        ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "contact_length", "M_R_p", "M_R_g", "P_loss"]
    );
    let mut table =
        model(MeshOptions { fidelity: Fidelity::Table, friction, ..MeshOptions::default() });
    let (lo, hi) = table.table().expect("table").te_range();
    let mut partial = 0;
    // A complete record at a loaded state (with friction torques and a loss when the model
    // has friction).
    let mut s0 = state(&table, 0.2, 0.5 * hi);
    (s0.w_p, s0.w_g) = (300.0, -190.0);
    let mut stale = table.mesh(&s0).unwrap();
    assert!(stale.m_f_p > 0.0);
    for i in 0..60 {
        let phi = 0.37 * i as f64;
        let te = lo * 1.2 + (hi * 1.2 - lo * 1.2) * (i as f64 / 59.0);
        let mut s = state(&table, phi, te);
        s.w_p = 300.0;
        s.w_g = -190.0;
        let a = table.mesh(&s).unwrap();
        let (b, complete) = table.torques(&s).unwrap();
        // In place over a record that holds another state's complete outputs (as a right-hand
        // side's cache does): the same torques outputs and flag.
        let mut c = stale;
        assert_eq!(table.torques_into(&s, &mut c).unwrap(), complete);
        for f in MESH_OUTPUT_FIELDS.iter().filter(|f| f.torques) {
            let (x, y) = (f.real(&a).expect("a Real"), f.real(&b).expect("a Real"));
            assert_eq!(x.to_bits(), y.to_bits(), "{} at TE {te:e}: {x:e} vs {y:e}", f.name);
            let z = f.real(&c).expect("a Real");
            assert_eq!(
                x.to_bits(),
                z.to_bits(),
                "{} in place at TE {te:e}: {x:e} vs {z:e}",
                f.name
            );
        }
        if complete {
            assert_eq!(a, c);
        }
        stale = a;
        if complete {
            assert_eq!(a, b);
        } else {
            partial += 1;
        }
    }
    assert!(partial > 20, "the table's torque-only path ran at {partial} points");
}

/// The back-flank axis is sampled at its first need, and the same whenever that is: a table
/// whose first back-flank state comes from an evaluation gives, bit for bit, the outputs of a
/// table whose back flanks were sampled up front (through `te_range`), at back-flank states
/// and at driving-flank ones before and after; and the back-flank outputs agree with the full
/// model (the table's error).
#[test]
fn back_flanks_are_sampled_on_demand_and_the_same_whenever() {
    let o = MeshOptions {
        fidelity: Fidelity::Table,
        table_phase_points: 16,
        table_te_points: 12,
        ..MeshOptions::default()
    };
    let mut lazy = model(o);
    let mut eager = model(o);
    let mut full = model(MeshOptions::default());
    let t = lazy.table().expect("table");
    assert!(!t.back_flanks_sampled(), "the build sampled the back flanks");
    assert!(t.back_build_seconds().is_none());
    let (lo, _) = eager.table().expect("table").te_range();
    assert!(eager.table().expect("table").back_flanks_sampled());
    // Driving flanks first: the back flanks stay unsampled.
    let drive = state(&lazy, 0.11, 20e-6);
    let a = lazy.evaluate(&drive).unwrap();
    assert_eq!(a, eager.evaluate(&drive).unwrap());
    assert!(!lazy.table().expect("table").back_flanks_sampled());
    // A back-flank state 40 % of the way along the back axis.
    let jt = lazy.geometry().backlash_te;
    let back_te = -jt + 0.4 * (lo + jt);
    let back = state(&lazy, 0.23, back_te);
    let b = lazy.evaluate(&back).unwrap();
    assert!(lazy.table().expect("table").back_flanks_sampled());
    let e = eager.evaluate(&back).unwrap();
    assert_eq!(b, e);
    assert!(b.back_contact && b.m_f_p < 0.0, "{b:?}");
    let f = full.evaluate(&back).unwrap();
    let err = (b.m_f_p - f.m_f_p).abs() / f.m_f_p.abs();
    assert!(err < 5e-3, "back-flank M_F,p {} against the full model {}: {err:e}", b.m_f_p, f.m_f_p);
    assert_eq!(lazy.evaluate(&drive).unwrap(), a);
    assert_eq!(lazy.table().unwrap().te_range(), eager.table().unwrap().te_range());
    assert_eq!(lazy.table().unwrap().truncations(), eager.table().unwrap().truncations());
}

/// Table fidelity sampled at the full model's slices (`table_slices` = `slices` = 200):
/// relative torque error against `full` at random points ≤ 0.5 % where the torque exceeds 1 %
/// of nominal, the damping torque (from the interpolated loaded extent) within 2 %, fallback
/// outside the range, exact zero inside the backlash. The default sample slices (100) are
/// held against the converged model in `tests/table_slices.rs`; there the damping torque
/// carries the extent's coarser steps (a slice of 25 per contact line instead of 50).
#[test]
fn table_matches_full() {
    let mut full = model(MeshOptions::default());
    let o = MeshOptions { fidelity: Fidelity::Table, table_slices: 200, ..MeshOptions::default() };
    let mut table = model(o);
    let t = table.table().expect("table");
    let (lo, hi) = t.te_range();
    eprintln!(
        "table build {:.2} s, self-check max rel err {:.2e} on {} cells, TE range [{lo:.3e}, {hi:.3e}] m",
        t.build_seconds(),
        t.max_rel_err(),
        t.checked_points()
    );
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for _ in 0..400 {
        let phi = 10.0 * uniform();
        let te = lo + (hi - lo) * uniform();
        let mut s = state(&full, phi, te);
        s.w_p = 200.0;
        s.w_g = -120.0;
        let a = full.evaluate(&s).unwrap();
        let b = table.evaluate(&s).unwrap();
        assert!((a.m_d_p - b.m_d_p).abs() <= 0.02 * a.m_d_p.abs() + 1e-9 || a.n_pairs != b.n_pairs);
        if a.m_f_p.abs() > 1.0 {
            worst = worst.max((a.m_f_p - b.m_f_p).abs() / a.m_f_p.abs());
            n += 1;
        } else {
            assert!((a.m_f_p - b.m_f_p).abs() < 0.05, "{} vs {}", a.m_f_p, b.m_f_p);
        }
    }
    eprintln!("table vs full: max rel err {worst:.2e} over {n} points");
    assert!(worst <= 5e-3, "max relative error {worst}");
    // Outside the range: the full model (same up to the warm start's rounding).
    let s = state(&full, 0.02, 1.5 * hi);
    let (a, b) = (full.evaluate(&s).unwrap(), table.evaluate(&s).unwrap());
    assert!((a.m_f_p - b.m_f_p).abs() < 1e-9 * a.m_f_p && a.n_pairs == b.n_pairs);
}

/// The ζ-precomputed compliance kernel (`SliceInfluence`) and the general interpolation give
/// the same mesh outputs to rounding, on driving and back flanks (the back flanks use the
/// mirrored slice index), and the kernel is on by default for interpolated compliance.
#[test]
fn slice_kernel_matches_general_interpolation() {
    let mut fast = model(MeshOptions::default());
    let mut slow = fast.clone();
    assert!(fast.use_slice_kernel(true));
    assert!(!slow.use_slice_kernel(false));
    let jt = fast.geometry().backlash_te;
    for k in 0..12 {
        let phi_p = k as f64 * pitch() / 12.0;
        for te in [10e-6, 40e-6, -jt - 15e-6] {
            let s = state(&fast, phi_p, te);
            let (a, b) = (fast.evaluate(&s).unwrap(), slow.evaluate(&s).unwrap());
            for (x, y) in [(a.m_f_p, b.m_f_p), (a.m_f_g, b.m_f_g), (a.f_n, b.f_n)] {
                assert!((x - y).abs() <= 1e-10 * y.abs().max(1e-9), "{x} vs {y} at {phi_p}, {te}");
            }
            assert_eq!((a.n_pairs, a.back_contact), (b.n_pairs, b.back_contact));
        }
    }
}

/// The coarse pre-solve of a cold start only chooses where the load solver starts: cold
/// evaluations with it agree with cold evaluations from q = 0 to the solver's tolerance
/// (1e-10 relative) on both flank sides, light to heavy load, at 200 and 400 slices, and they
/// need fewer factorisations.
#[test]
fn coarse_cold_start_gives_the_solution_of_the_cold_solve() {
    for slices in [200, 400] {
        let mut coarse_start = model(MeshOptions { slices, ..MeshOptions::default() });
        let mut from_zero = coarse_start.clone();
        from_zero.use_coarse_start(false);
        let jt = coarse_start.geometry().backlash_te;
        for k in 0..10 {
            let phi_p = (k as f64 + 0.3) * pitch() / 10.0;
            for te in [5e-6, 30e-6, 60e-6, -jt - 15e-6] {
                let s = state(&coarse_start, phi_p, te);
                coarse_start.forget_warm_start();
                from_zero.forget_warm_start();
                let (a, b) = (coarse_start.evaluate(&s).unwrap(), from_zero.evaluate(&s).unwrap());
                for (x, y) in [(a.m_f_p, b.m_f_p), (a.m_f_g, b.m_f_g), (a.f_n, b.f_n)] {
                    assert!(
                        (x - y).abs() <= 1e-10 * y.abs().max(1e-9),
                        "{slices} slices: {x} vs {y} at {phi_p}, {te}"
                    );
                }
                assert_eq!((a.n_pairs, a.back_contact), (b.n_pairs, b.back_contact));
            }
        }
        let (with, without) = (coarse_start.stats(), from_zero.stats());
        assert_eq!(with.solves, without.solves);
        assert!(
            with.factorizations < without.factorizations,
            "{slices} slices: {with:?} against {without:?}"
        );
    }
}

/// The load solver's work counters: a warm-started trajectory needs few factorisations per
/// solve (held factors serve simplified-Newton steps), and every solve is counted.
#[test]
fn solve_counters() {
    let mut m = model(MeshOptions::default());
    for k in 0..50 {
        let phi_p = k as f64 * pitch() / 50.0;
        m.evaluate(&state(&m, phi_p, 30e-6)).unwrap();
    }
    let st = m.stats();
    eprintln!("{st:?}");
    assert_eq!(st.solves, 50);
    assert!(st.factorizations >= 1 && st.iterations >= st.solves);
    assert!(st.slices > 0 && st.evaluations > st.iterations);
    m.reset_stats();
    assert_eq!(m.stats().solves, 0);
}

/// Compliance referred to the rim (each body fixed just inside its rim,
/// `ComplianceData::compute_rim_fixed`) against the bore-fixed default on the coarse mesh: the
/// bodies between bore and rim are removed, so the mesh is stiffer (higher linearised mesh
/// stiffness, lower static TE) and the provenance says so.
#[test]
fn rim_fixed_compliance_gives_a_stiffer_mesh() {
    let pair = GearPair::paper_table1();
    let h = DEFAULT_DEPTH_MN * pair.normal_module_m;
    let data = ComplianceData::compute_rim_fixed(&pair, &GearMeshDensity::coarse(), h, false)
        .expect("rim-fixed FE");
    let BodySupport::Rim { diameter_p_m, diameter_g_m } = data.provenance.support else {
        panic!("provenance: {:?}", data.provenance.support);
    };
    let geo = helical_gear_mesh::PairGeometry::new(&pair).expect("geometry");
    assert!(diameter_p_m > pair.bore_diameter_m && diameter_p_m < 2.0 * geo.pinion.rf);
    assert!(diameter_g_m > diameter_p_m && diameter_g_m < 2.0 * geo.gear.rf);
    let interp = |m: Member| {
        GearCompliance::Interpolated(Arc::new(data.interpolated(m).expect("interpolated")))
    };
    let options = MeshOptions { slices: 100, ..MeshOptions::default() };
    let mut rim =
        Mesh::with_compliance(&pair, options, interp(Member::Pinion), interp(Member::Gear))
            .expect("rim model");
    let mut bore = model(options);
    let torque = DriveLine::paper_table1().torque_nm;
    let k_rim = mesh_stiffness(&mut rim, 0.0, torque).expect("k rim");
    let k_bore = mesh_stiffness(&mut bore, 0.0, torque).expect("k bore");
    let ste_rim = static_curve(&mut rim, torque, 0.0, pitch(), 8, 1).expect("STE rim").max();
    let ste_bore = static_curve(&mut bore, torque, 0.0, pitch(), 8, 1).expect("STE bore").max();
    eprintln!(
        "coarse: k {:.1} → {:.1} N/µm, STE max {:.2} → {:.2} µm (bore → rim fixed)",
        k_bore * 1e-6,
        k_rim * 1e-6,
        ste_bore * 1e6,
        ste_rim * 1e6
    );
    assert!(k_rim > 2.0 * k_bore, "k {k_rim} vs {k_bore}");
    assert!(ste_rim < 0.5 * ste_bore, "STE {ste_rim} vs {ste_bore}");
}

/// The static onset of tip contact: just below the threshold no tip rounding carries load, at
/// it one does; it lies above the static TE (no static tip contact for Table 1), and the
/// periodic interpolation of the curve returns the stored values at the stored angles.
#[test]
fn tip_contact_threshold_brackets_the_onset() {
    let mut m = model(MeshOptions { slices: 100, ..MeshOptions::default() });
    let torque = DriveLine::paper_table1().torque_nm;
    let ste = static_curve(&mut m, torque, 0.0, pitch(), 8, 1).expect("STE").max();
    let curve = tip_contact_threshold_curve(&m, 0.0, pitch(), 4, 6.0 * ste, 60).expect("curve");
    let (phi, t) = curve.min().expect("tip contact within 6 × STE max");
    assert!(t > ste, "threshold {t} vs STE max {ste}");
    let tip = |m: &mut Mesh, te: f64| m.evaluate_full(&state(m, phi, te)).unwrap().tip_contact;
    assert!(tip(&mut m, t));
    assert!(!tip(&mut m, t - 5e-9));
    for (p, te) in curve.phi_p.iter().zip(&curve.te) {
        let v = te.unwrap_or(curve.te_max);
        assert!((curve.at(*p) - v).abs() <= 1e-12 * v);
        assert!((curve.at(*p + pitch()) - v).abs() <= 1e-9 * v);
    }
}

/// β = 18.5°, b = 10.7 mm (a design of a study's hypercube) and its coarse FE compliance,
/// computed once per test binary.
fn overload_design() -> &'static (GearPair, GearCompliance, GearCompliance) {
    static C: OnceLock<(GearPair, GearCompliance, GearCompliance)> = OnceLock::new();
    C.get_or_init(|| {
        let pair = GearPair {
            helix_angle_rad: 18.5f64.to_radians(),
            face_width_m: 0.0107,
            ..GearPair::paper_table1()
        };
        let (p, g) =
            compute_compliance(&pair, &GearMeshDensity::coarse(), ComplianceModel::Interpolated)
                .expect("coarse FE compliance");
        (pair, p, g)
    })
}

/// Under heavy overload (up to 4.6× the nominal static TE, the neighbouring pairs' tip
/// roundings in contact) a solve from a cold start gives the loads that continuation along TE
/// gives (each state from its neighbour's loads, 10 µm apart). Without the load solver's
/// continuation retry every cold solve from 1.3× up reported an indefinite compliance.
#[test]
fn cold_solves_under_heavy_overload_follow_the_loaded_path() {
    let (pair, cp, cg) = overload_design().clone();
    let options = MeshOptions { slices: 40, ..MeshOptions::default() };
    let mut path = Mesh::with_compliance(&pair, options, cp, cg).unwrap();
    let mut cold = path.clone();
    for phi in [-0.045637, -0.032725, 0.0] {
        path.forget_warm_start();
        for k in 1..=32 {
            let te = 10e-6 * k as f64;
            let a = path.evaluate(&state(&path, phi, te)).expect("continued along TE");
            cold.forget_warm_start();
            let b = cold.evaluate(&state(&cold, phi, te)).unwrap_or_else(|e| {
                panic!("cold solve at TE {te:e}, phase {phi}: {e}");
            });
            assert!(
                (a.f_n - b.f_n).abs() <= 1e-9 * a.f_n,
                "TE {te:e}, phase {phi}: F_n {} (path) vs {} (cold)",
                a.f_n,
                b.f_n
            );
        }
    }
}

/// A design whose load problem stops being well posed inside the table's designed TE range:
/// the overload design at twice the torque (the designed range, 4× the nominal static TE,
/// reaches beyond the 4.6–4.7× of the nominal 100 N·m where the solve fails at some phases).
/// The table ends at the last TE node every phase row reached and records the cut; inside it
/// agrees with the full model; beyond it the table model hands the state to the full model,
/// which reports it out of range.
#[test]
fn table_ends_where_the_model_stops_holding() {
    let (pair, cp, cg) = overload_design().clone();
    let torque = 200.0;
    let base = MeshOptions {
        slices: 40,
        table_phase_points: 16,
        table_te_points: 12,
        table_design_torque_nm: torque,
        ..MeshOptions::default()
    };
    let mut full = Mesh::with_compliance(&pair, base, cp.clone(), cg.clone()).unwrap();
    let mut table =
        Mesh::with_compliance(&pair, MeshOptions { fidelity: Fidelity::Table, ..base }, cp, cg)
            .expect("the table builds up to the model's range");
    let t = table.table().expect("table");
    let (_, hi) = t.te_range();
    let cuts = t.truncations().to_vec();
    eprintln!("TE range up to {hi:.3e} m, cuts: {cuts:#?}");
    assert_eq!(cuts.len(), 1, "{cuts:?}");
    let cut = &cuts[0];
    assert_eq!(cut.flanks, "driving");
    assert!(cut.covered_m < cut.designed_m, "{cut:?}");
    assert_eq!(cut.covered_m, hi);
    assert!(cut.cause.contains("outside the model's range"), "{}", cut.cause);

    // The nominal static TE lies inside.
    let mut te_nom: f64 = 0.0;
    for k in 0..8 {
        let phi = pitch() * (k as f64 + 0.5) / 8.0;
        let eq = equilibrium(&mut full, phi, torque, 1e-5, &EquilibriumSettings::default())
            .expect("static equilibrium");
        te_nom = te_nom.max(eq.te);
    }
    eprintln!("nominal static TE {te_nom:.3e} m: covered {:.2}×", hi / te_nom);
    assert!(hi > te_nom);

    // Inside: the table agrees with the full model (from a cold start, as a state is met
    // first) to the error of its coarse 16 × 12 grid.
    for k in 0..24 {
        let phi = 0.173 * k as f64;
        let te = te_nom * 0.5 + (hi * 0.95 - te_nom * 0.5) * (k as f64 / 23.0);
        full.forget_warm_start();
        let a = full.evaluate(&state(&full, phi, te)).expect("inside the model's range");
        let b = table.evaluate(&state(&table, phi, te)).expect("inside the table's range");
        let e = (a.m_f_p - b.m_f_p).abs() / a.m_f_p.abs();
        assert!(e < 0.02, "TE {te:e}: table {} vs full {} N·m", b.m_f_p, a.m_f_p);
    }

    // Beyond: the same answer as the full model (both from a cold start), an out-of-range
    // error among them.
    let mut out = 0;
    for k in 0..16 {
        let phi = pitch() * k as f64 / 16.0;
        let te = cut.designed_m;
        full.forget_warm_start();
        table.forget_warm_start();
        let a = full.evaluate(&state(&full, phi, te));
        let b = table.evaluate(&state(&table, phi, te));
        assert_eq!(a, b, "TE {te:e} at phase {phi}");
        out += matches!(b, Err(MeshError::OutOfRange { .. })) as usize;
    }
    assert!(out > 0, "no state at the designed range was out of range");
}
