//! Tooth-root stress: the stress recovery of the FE model against a closed form, the stress
//! influence of the gears (linear in the load, zero at zero load, largest on the loaded tooth)
//! and the root stress of the mesh model (full and table fidelity).

mod common;

use faer::Mat;
use helical_gear_mesh::compliance::fe::stress::{StressPoint, locate_near_surface};
use helical_gear_mesh::compliance::fe::{FeModel, Material, Mesh as FeMesh, dof};

const STEEL: Material = Material { e: 206e9, nu: 0.3 };

/// Relative error of the bending stress at the top surface of a cantilever of hex20 elements
/// (`n` elements along, `m` across each side) against σ = M·c/I, taken as the largest over
/// points between 30 % and 70 % of the length.
fn cantilever_bending_error(n: usize, m: usize) -> f64 {
    let (l, h, w, p) = (0.2, 0.02, 0.02, 1000.0);
    let mesh = FeMesh::structured_block([n, m, m], |u, v, s| [l * u, w * v, h * s]).expect("mesh");
    let fixed = mesh.nodes_where(|x| x[0] < 1e-12);
    let end = mesh.boundary_faces_where(|x| (x[0] - l).abs() < 1e-12);
    let mut f = Mat::<f64>::zeros(3 * mesh.nodes.len(), 1);
    // Uniform shear traction over the end face, resultant P in −z.
    for face in end {
        for (node, fv) in mesh.face_loads(face, |_, _| [0.0, 0.0, -p / (w * h)]).expect("face") {
            for d in 0..3 {
                f[(dof(node, d), 0)] += fv[d];
            }
        }
    }
    let model = FeModel::new(mesh, STEEL, &fixed).expect("model");
    let u = model.solve_block(f.as_ref()).expect("solve");
    let i = w * h.powi(3) / 12.0;
    let mut worst = 0.0f64;
    for k in 3..=7 {
        let x = l * k as f64 / 10.0;
        // Top surface (tension side for a load in −z: M = −P·(L − x) about y, σxx = P(L−x)c/I).
        let point = [x, 0.37 * w, h];
        let (e, xi) = locate_near_surface(model.mesh(), point, 1e-6).expect("on the surface");
        let sp = StressPoint::new(model.mesh(), &STEEL, e, xi).expect("stencil");
        let s = sp.stress(|node, d| u[(dof(node, d), 0)]);
        let exact = p * (l - x) * (h / 2.0) / i;
        worst = worst.max((s[0] - exact).abs() / exact);
    }
    worst
}

/// The stress recovery at a free surface reproduces the bending stress M·c/I of a cantilever
/// under an end load (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., § 21: for the
/// end-loaded cantilever σxx = −P(L − x)z/I is exact away from the ends, also in 3D with
/// Poisson's ratio, § 127), within 2 % on a coarse mesh and 0.5 % on a refined one, the error
/// shrinking under refinement.
#[test]
fn surface_stress_matches_cantilever_bending_closed_form() {
    let coarse = cantilever_bending_error(10, 1);
    let fine = cantilever_bending_error(20, 2);
    eprintln!(
        "cantilever bending stress error: {coarse:.3e} (10 × 1 × 1), {fine:.3e} (20 × 2 × 2)"
    );
    assert!(coarse < 0.02, "coarse error {coarse:.3e}");
    assert!(fine < 0.005, "fine error {fine:.3e}");
    assert!(fine < coarse, "refinement: {fine:.3e} vs {coarse:.3e}");
}

use helical_gear_mesh::compliance::fe::gear_mesh::GearMeshDensity;
use helical_gear_mesh::compliance::influence_fe::{DEFAULT_DEPTH_MN, FeInfluence, fe_influence};
use helical_gear_mesh::compliance::root_stress::RootStressGrid;
use helical_gear_mesh::params::GearPair;
use std::sync::OnceLock;

/// Coarse FE influence data of the Table 1 pinion (computed once per test binary).
fn coarse_pinion() -> &'static FeInfluence {
    static DATA: OnceLock<FeInfluence> = OnceLock::new();
    DATA.get_or_init(|| {
        let p = GearPair::paper_table1();
        let geo = common::table1_geometry();
        fe_influence(
            &geo.pinion,
            &p,
            &GearMeshDensity::coarse(),
            DEFAULT_DEPTH_MN * p.normal_module_m,
            false,
        )
        .expect("FE")
    })
}

/// A load vector on the flank grid: `force` N at the grid point nearest to the middle of the
/// profile and of the face.
fn mid_load(g: &RootStressGrid, force: f64) -> Vec<f64> {
    let (nr, nc) = (g.load_profile.len(), g.load_zeta.len());
    let mut f = vec![0.0; nr * nc];
    f[(nr / 2) * nc + nc / 2] = force;
    f
}

/// A unit load on tooth 0 puts its own fillet in tension, more than the neighbours' fillets,
/// and in the range of a cantilever estimate (Pa per N); zero load gives zero stress.
#[test]
fn load_on_tooth_zero_stresses_its_own_fillet_most() {
    let g = &coarse_pinion().root_stress;
    let t0 = g.teeth.iter().position(|&t| t == 0).expect("tooth 0");
    let f = mid_load(g, 1.0);
    let own = g.max_principal(t0, &f);
    eprintln!(
        "tangent angles {:?} deg; σ1 per N: own {own:.4e} Pa, neighbours {:?}",
        g.tangent_angle_deg,
        g.teeth.iter().enumerate().map(|(t, _)| g.max_principal(t, &f)).collect::<Vec<_>>()
    );
    assert!(own > 0.0);
    for (t, &o) in g.teeth.iter().enumerate() {
        if o != 0 {
            assert!(g.max_principal(t, &f) < 0.5 * own, "tooth {o}");
        }
    }
    let zero = vec![0.0; g.loads()];
    assert_eq!(g.max_principal(t0, &zero), 0.0);
}

/// The stress influence is linear in the load: scaling a load distribution scales the stress
/// tensor (every component, hence the principal stress), and superposition holds.
#[test]
fn root_stress_is_linear_in_the_load() {
    let g = &coarse_pinion().root_stress;
    let t0 = g.teeth.iter().position(|&t| t == 0).expect("tooth 0");
    let n = g.loads();
    let mut rng = common::Lcg(7);
    let a: Vec<f64> = (0..n).map(|_| 100.0 * rng.uniform()).collect();
    let b: Vec<f64> = (0..n).map(|_| 50.0 * rng.uniform()).collect();
    let (sa, sb) = (g.stress(t0, &a), g.stress(t0, &b));
    let scaled: Vec<f64> = a.iter().map(|v| 3.0 * v).collect();
    let sum: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x + y).collect();
    let (s3, ss) = (g.stress(t0, &scaled), g.stress(t0, &sum));
    let scale = sa.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    for i in 0..sa.len() {
        assert!((s3[i] - 3.0 * sa[i]).abs() <= 1e-12 * scale, "scaling, component {i}");
        assert!((ss[i] - sa[i] - sb[i]).abs() <= 1e-12 * scale, "superposition, component {i}");
    }
    let p = g.max_principal(t0, &a);
    assert!(common::rel_diff(g.max_principal(t0, &scaled), 3.0 * p) < 1e-12);
}

/// The embedded Table 1 root-stress resource agrees with a fresh FE computation at its
/// density, the default without axial coarsening (to two quanta of the stored integers).
#[test]
fn embedded_root_stress_matches_a_fresh_computation() {
    use helical_gear_mesh::compliance::data::{ComplianceData, RootStressData};
    use helical_gear_mesh::geometry::Member;
    let p = GearPair::paper_table1();
    let embedded = RootStressData::embedded_table1().expect("resource parses");
    let fresh = ComplianceData::compute(
        &p,
        &GearMeshDensity::conforming(),
        DEFAULT_DEPTH_MN * p.normal_module_m,
        false,
    )
    .expect("FE");
    let fresh = fresh.root_stress().expect("root stress computed");
    assert_eq!(embedded.key, fresh.key);
    assert_eq!(embedded.density, fresh.density);
    for m in [Member::Pinion, Member::Gear] {
        let (e, f) = (embedded.member(m), fresh.member(m));
        assert_eq!(e.tangent_angle_deg.len(), f.tangent_angle_deg.len());
        assert!(common::rel_diff(e.quantum_pa_per_n, f.quantum_pa_per_n) < 1e-6);
        let worst = e
            .sigma
            .iter()
            .flatten()
            .zip(f.sigma.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .max()
            .unwrap_or(0);
        assert!(worst <= 2, "{m:?}: embedded and fresh differ by {worst} quanta");
    }
    // Table 1's compliance data carry the embedded root stress.
    let data = ComplianceData::embedded_table1().expect("embedded");
    assert_eq!(data.root_stress().map(|s| s.as_ref()), Some(embedded.as_ref()));
}

use helical_gear_mesh::mesh::model::MeshModel;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions};

/// The Table 1 model at full fidelity (embedded FE data, 40 slices).
fn table1_model() -> MeshModel {
    MeshModel::new(&GearPair::paper_table1(), common::coarse_options(Fidelity::Full))
        .expect("model")
}

/// At full fidelity the root stress is reported for both gears under load, zero when the
/// flanks separate, and the torques, TE and F_n are those of the same model without the
/// root-stress data, bit for bit.
#[test]
fn root_stress_at_full_fidelity_leaves_the_other_outputs_unchanged() {
    use helical_gear_mesh::compliance::data::ComplianceData;
    use helical_gear_mesh::mesh::model::{MeshWorkspace, WarmStart};
    let pair = GearPair::paper_table1();
    let with = table1_model();
    assert!(with.has_root_stress());
    // The same compliance without the root-stress data.
    let data = ComplianceData::embedded_table1().expect("embedded");
    let (p, g) = (
        helical_gear_mesh::mesh::model::GearCompliance::Interpolated(std::sync::Arc::new(
            data.interpolated(helical_gear_mesh::geometry::Member::Pinion).expect("p"),
        )),
        helical_gear_mesh::mesh::model::GearCompliance::Interpolated(std::sync::Arc::new(
            data.interpolated(helical_gear_mesh::geometry::Member::Gear).expect("g"),
        )),
    );
    let without = MeshModel::with_compliance(&pair, common::coarse_options(Fidelity::Full), p, g)
        .expect("model");
    assert!(!without.has_root_stress());
    let geo = common::table1_geometry();
    let pitch = common::table1_pitch();
    let (mut w1, mut w2) = (MeshWorkspace::new(&with), MeshWorkspace::new(&without));
    for i in 0..6 {
        let phi_p = pitch * i as f64 / 6.0;
        for te in [-1e-6, 10e-6, 30e-6] {
            let state = helical_gear_mesh::mesh::MeshState {
                phi_p,
                phi_g: geo.phi_g_for_te(phi_p, te),
                w_p: 0.0,
                w_g: 0.0,
                ..Default::default()
            };
            let a = with.evaluate(&state, &mut w1, &mut WarmStart::default()).expect("eval");
            let b = without.evaluate(&state, &mut w2, &mut WarmStart::default()).expect("eval");
            assert_eq!(
                (a.m_f_p, a.m_f_g, a.te, a.f_n, a.p_max, a.n_pairs),
                (b.m_f_p, b.m_f_g, b.te, b.f_n, b.p_max, b.n_pairs)
            );
            assert_eq!((b.root_stress_p, b.root_stress_g), (0.0, 0.0));
            if a.separated {
                assert_eq!((a.root_stress_p, a.root_stress_g), (0.0, 0.0));
            } else {
                assert!(a.root_stress_p > 0.0 && a.root_stress_g > 0.0, "{a:?}");
                assert!(a.root_stress_p.is_finite() && a.root_stress_g.is_finite());
            }
        }
    }
}

/// At the static equilibrium of 100 N·m the root stress is of the order of the nominal
/// bending stress F_t/(b·m_n) times a form factor of 1 … 4, and grows with the torque.
#[test]
fn static_root_stress_is_plausible_and_grows_with_the_torque() {
    use helical_gear_mesh::mesh::statics::{EquilibriumSettings, equilibrium};
    let pair = GearPair::paper_table1();
    let geo = common::table1_geometry();
    let mut mesh = Mesh::new(&pair, common::coarse_options(Fidelity::Full)).expect("mesh");
    let settings = EquilibriumSettings::default();
    let e1 = equilibrium(&mut mesh, 0.0, 100.0, 20e-6, &settings).expect("100 N·m");
    let e2 = equilibrium(&mut mesh, 0.0, 200.0, 40e-6, &settings).expect("200 N·m");
    let ft = 100.0 / geo.pinion.r;
    let nominal = ft / (pair.face_width_m * pair.normal_module_m);
    let (sp, sg) = (e1.outputs.root_stress_p, e1.outputs.root_stress_g);
    eprintln!(
        "100 N·m: σ_F p {:.1} MPa, g {:.1} MPa; nominal F_t/(b·m_n) {:.1} MPa",
        sp / 1e6,
        sg / 1e6,
        nominal / 1e6
    );
    for s in [sp, sg] {
        assert!(s > 1.0 * nominal && s < 4.0 * nominal, "{s:e} vs nominal {nominal:e}");
    }
    assert!(e2.outputs.root_stress_p > 1.5 * sp && e2.outputs.root_stress_g > 1.5 * sg);
    let _ = MeshOptions::default();
}

/// At table fidelity the root stress is interpolated as a secant node value like the torques;
/// it agrees with the full model within the table's accuracy, and the torques stay those of a
/// table without it.
#[test]
fn table_root_stress_agrees_with_the_full_model() {
    let pair = GearPair::paper_table1();
    let mut full = Mesh::new(&pair, common::coarse_options(Fidelity::Full)).expect("full");
    let mut table = Mesh::new(&pair, common::coarse_options(Fidelity::Table)).expect("table");
    let pitch = common::table1_pitch();
    let mut worst = [0.0f64; 3];
    for i in 0..7 {
        let phi_p = pitch * (i as f64 + 0.37) / 7.0;
        for te in [15e-6, 27e-6, 41e-6] {
            let s = common::state_at_rest(&full, phi_p, te);
            let (a, b) = (full.evaluate(&s).expect("full"), table.evaluate(&s).expect("table"));
            worst[0] = worst[0].max(common::rel_diff(b.m_f_p, a.m_f_p));
            worst[1] = worst[1].max(common::rel_diff(b.root_stress_p, a.root_stress_p));
            worst[2] = worst[2].max(common::rel_diff(b.root_stress_g, a.root_stress_g));
        }
    }
    eprintln!(
        "table vs full, largest relative difference: M_F_p {:.2e}, σ_F p {:.2e}, g {:.2e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst[1] < 0.03 && worst[2] < 0.03, "{worst:?}");
}
