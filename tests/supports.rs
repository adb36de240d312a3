//! Elastic supports of the gear bodies (`helical_gear_mesh::mesh::supports`): the JSON and its
//! checks, and the static equilibrium with the bodies displaced against oracles derived in each
//! test.

use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{
    BodyPose, EquilibriumSettings, Mesh, MeshOptions, Supports, equilibrium, supported_equilibrium,
};

fn mesh() -> Mesh {
    Mesh::new(&GearPair::paper_table1(), MeshOptions { slices: 60, ..MeshOptions::default() })
        .unwrap()
}

fn support(radial: f64, axial: f64, tilt: f64) -> String {
    format!(
        r#"{{"mass_kg": 2.0, "j_transverse_kgm2": 1e-3, "stiffness": {{"radial_n_per_m": {radial:e},
        "axial_n_per_m": {axial:e}, "tilt_nm_per_rad": {tilt:e}}}}}"#
    )
}

/// Supports a million times stiffer than the tooth pair (c' ≈ 14 N/(mm·µm) over b = 15 mm is
/// k_m ≈ 2.1·10⁸ N/m; against a tilt about y the helix turns the axial shift r_w·θ at the
/// pitch point into TE, a stiffness k_m·(r_w·tan β_b)² ≈ 7·10⁴ N·m/rad) move the bodies by
/// picometres: the static TE is the rigid-bearing one to 2e-6 (each support adds F_t/k, about
/// 1e-6 of TE = F_t/k_m), in a few iterations.
#[test]
fn stiff_supports_give_the_rigid_equilibrium() {
    let mut m = mesh();
    let s = support(2.1e14, 2.1e14, 7e10);
    let supports = Supports::from_json(&format!(r#"{{"pinion": {s}, "gear": {s}}}"#)).unwrap();
    let set = EquilibriumSettings::default();
    for phi_p in [0.0, 0.03, 0.07] {
        let rigid = equilibrium(&mut m, phi_p, 100.0, 30e-6, &set).unwrap();
        let e = supported_equilibrium(&mut m, phi_p, 100.0, 30e-6, &supports, &set).unwrap();
        let d = e.equilibrium.te / rigid.te - 1.0;
        assert!(d.abs() < 2e-6, "{} {}: {d:e}", e.equilibrium.te, rigid.te);
        eprintln!("φp = {phi_p}: TE / rigid TE − 1 = {d:.2e}");
        assert!(e.iterations <= 4, "{} iterations", e.iterations);
    }
}

/// Radial supports k_p, k_g (axial and tilt held stiff): each body moves by its mesh force over
/// k, along the line of action by F_t/k (F_t the transverse normal force: the force on either
/// body in its plane). The flanks open by F_t·(1/k_p + 1/k_g), which the TE must make up to
/// carry the same torque: ΔTE = F_t·(1/k_p + 1/k_g), to first order (1 %). A pure translation
/// keeps the load distribution, so the torque per TE beyond the onset does not change.
#[test]
fn radial_compliance_adds_the_force_over_the_stiffness_to_the_static_te() {
    let mut m = mesh();
    let (k_p, k_g) = (6e8, 9e8);
    let supports = Supports::from_json(&format!(
        r#"{{"pinion": {}, "gear": {}}}"#,
        support(k_p, 1e14, 1e12),
        support(k_g, 1e14, 1e12)
    ))
    .unwrap();
    let set = EquilibriumSettings::default();
    for phi_p in [0.01, 0.05] {
        let rigid = equilibrium(&mut m, phi_p, 100.0, 30e-6, &set).unwrap();
        let e = supported_equilibrium(&mut m, phi_p, 100.0, 30e-6, &supports, &set).unwrap();
        let f = rigid.outputs.force_p;
        let f_t = f[0].hypot(f[1]);
        let want = f_t * (1.0 / k_p + 1.0 / k_g);
        let got = e.equilibrium.te - rigid.te;
        assert!(
            (got / want - 1.0).abs() < 0.01,
            "ΔTE {got:e} against F_t·(1/k_p + 1/k_g) = {want:e}"
        );
        // Each body moved by its force over its stiffness.
        let fg = e.equilibrium.outputs.force_g;
        assert!((e.equilibrium.pose_g.u_x - fg[0] / k_g).abs() <= 1e-9 * fg[0].abs() / k_g);
        assert!(
            (e.equilibrium.pose_p.u_y * k_p / e.equilibrium.outputs.force_p[1] - 1.0).abs() < 1e-9
        );
        eprintln!(
            "φp = {phi_p}: ΔTE = {:.3} µm, F_t·Σ1/k = {:.3} µm, {} iterations",
            got * 1e6,
            want * 1e6,
            e.iterations
        );
    }
}

/// With a coupled 5 × 5 stiffness (translation and tilt coupled, as a gear overhung on its
/// shaft), the equilibrium balances the support's reaction against the mesh's force and
/// moments at the displaced state: R + W = 0 to the iteration's tolerance.
#[test]
fn the_supports_balance_the_mesh_wrench() {
    let mut m = mesh();
    let k = r#"[[4e8, 0, 0, 0, 3e6], [0, 4e8, 0, -3e6, 0], [0, 0, 2e8, 0, 0],
                [0, -3e6, 0, 5e5, 0], [3e6, 0, 0, 0, 5e5]]"#;
    let json = format!(
        r#"{{"gear": {{"mass_kg": 5.0, "j_transverse_kgm2": 0.01, "stiffness_matrix": {k}}},
            "pinion": {}}}"#,
        support(5e8, 3e8, 8e5)
    );
    let supports = Supports::from_json(&json).unwrap();
    let e = supported_equilibrium(
        &mut m,
        0.02,
        100.0,
        30e-6,
        &supports,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let o = &e.equilibrium.outputs;
    for (sup, pose, w) in [
        (
            supports.pinion.unwrap(),
            e.equilibrium.pose_p,
            [o.force_p[0], o.force_p[1], o.force_p[2], o.moment_p[0], o.moment_p[1]],
        ),
        (
            supports.gear.unwrap(),
            e.equilibrium.pose_g,
            [o.force_g[0], o.force_g[1], o.force_g[2], o.moment_g[0], o.moment_g[1]],
        ),
    ] {
        let r = sup.reaction(&pose, &BodyPose::default());
        let scale = w.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..5 {
            assert!((r[i] + w[i]).abs() <= 1e-8 * scale, "component {i}: R {} + W {}", r[i], w[i]);
        }
    }
    assert!(
        e.equilibrium.pose_g.th_x != 0.0 && e.equilibrium.pose_g.th_y != 0.0,
        "{:?}",
        e.equilibrium.pose_g
    );
    eprintln!("gear pose {:?}, {} iterations", e.equilibrium.pose_g, e.iterations);
}

/// The JSON: the diagonal and the matrix forms; every bad value named.
#[test]
fn the_json_is_read_and_bad_values_are_named() {
    let s = Supports::from_json(&format!(r#"{{"gear": {}}}"#, support(4e8, 2e8, 1e6))).unwrap();
    assert!(s.pinion.is_none());
    let k = s.gear.unwrap().stiffness;
    assert_eq!([k[0][0], k[1][1], k[2][2], k[3][3], k[4][4]], [4e8, 4e8, 2e8, 1e6, 1e6]);
    assert_eq!(k[0][1], 0.0);
    let err = |json: &str| Supports::from_json(json).unwrap_err().to_string();
    let e = err(&format!(r#"{{"wheel": {}}}"#, support(1e8, 1e8, 1e6)));
    assert!(e.contains("supports.wheel"), "{e}");
    let e = err(&format!(r#"{{"gear": {}}}"#, support(-1e8, 1e8, 1e6)));
    assert!(e.contains("supports.gear.stiffness.radial_n_per_m"), "{e}");
    let e = err(r#"{"gear": {"mass_kg": 1, "j_transverse_kgm2": 1e-3}}"#);
    assert!(e.contains("supports.gear.stiffness"), "{e}");
    let e = err(r#"{"pinion": {"mass_kg": 1, "j_transverse_kgm2": 1e-3, "stiffness_matrix":
        [[1e8,5,0,0,0],[0,1e8,0,0,0],[0,0,1e8,0,0],[0,0,0,1e6,0],[0,0,0,0,1e6]]}}"#);
    assert!(e.contains("supports.pinion.stiffness_matrix[1][0]") && e.contains("symmetric"), "{e}");
    // Symmetric but not positive definite.
    let e = err(r#"{"pinion": {"mass_kg": 1, "j_transverse_kgm2": 1e-3, "stiffness_matrix":
        [[1e8,0,0,0,2e8],[0,1e8,0,0,0],[0,0,1e8,0,0],[0,0,0,1e6,0],[2e8,0,0,0,1e6]]}}"#);
    assert!(e.contains("positive definite"), "{e}");
    let e = err(r#"{"gear": {"shaft": {"bending_stiffness_nm2": 1e4, "bearings": []}}}"#);
    assert!(e.contains("supports.gear.shaft") && e.contains("not read yet"), "{e}");
    let e = err(r#"{"gear": {"mass_kg": 0, "j_transverse_kgm2": 1e-3, "stiffness": {}}}"#);
    assert!(e.contains("supports.gear.mass_kg"), "{e}");
}
