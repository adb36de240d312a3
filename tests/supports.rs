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

/// Each support's reaction at the equilibrium's pose balances the mesh's force and moments on
/// its body, R + W = 0, to 1e-8 of the wrench.
fn assert_balanced(supports: &Supports, e: &helical_gear_mesh::mesh::Equilibrium) {
    let o = &e.outputs;
    for (sup, pose, w) in [
        (
            supports.pinion.unwrap(),
            e.pose_p,
            [o.force_p[0], o.force_p[1], o.force_p[2], o.moment_p[0], o.moment_p[1]],
        ),
        (
            supports.gear.unwrap(),
            e.pose_g,
            [o.force_g[0], o.force_g[1], o.force_g[2], o.moment_g[0], o.moment_g[1]],
        ),
    ] {
        let r = sup.reaction(&pose, &BodyPose::default());
        let scale = w.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..5 {
            assert!((r[i] + w[i]).abs() <= 1e-8 * scale, "component {i}: R {} + W {}", r[i], w[i]);
        }
    }
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
    assert_balanced(&supports, &e.equilibrium);
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
    // The shaft form needs the pair's face width (the gear centre at b/2).
    let shaft = r#"{"gear": {"mass_kg": 5, "j_transverse_kgm2": 1e-2, "shaft":
        {"bending_stiffness_nm2": 1e4, "bearings": [{"z_m": -0.02, "radial_n_per_m": 1e9,
        "axial_n_per_m": 1e8}, {"z_m": 0.035, "radial_n_per_m": 1e9}]}}}"#;
    let e = err(shaft);
    assert!(e.contains("supports.gear.shaft") && e.contains("from_json_for"), "{e}");
    assert!(Supports::from_json_for(shaft, 0.015).unwrap().gear.unwrap().shaft.is_some());
    let bad = shaft.replace("\"radial_n_per_m\": 1e9}", "\"radial_n_per_m\": -1}");
    let e = Supports::from_json_for(&bad, 0.015).unwrap_err().to_string();
    assert!(e.contains("supports.gear.shaft.bearings[1].radial_n_per_m"), "{e}");
    let one = r#"{"gear": {"mass_kg": 5, "j_transverse_kgm2": 1e-2, "shaft":
        {"bending_stiffness_nm2": 1e4, "bearings": [{"z_m": 0.0, "radial_n_per_m": 1e9,
        "axial_n_per_m": 1e8}]}}}"#;
    let e = Supports::from_json_for(one, 0.015).unwrap_err().to_string();
    assert!(e.contains("supports.gear.shaft.bearings") && e.contains("2 … 4"), "{e}");
    let e = err(r#"{"gear": {"mass_kg": 0, "j_transverse_kgm2": 1e-3, "stiffness": {}}}"#);
    assert!(e.contains("supports.gear.mass_kg"), "{e}");
}

/// The shaft form (`mesh::shaft`) against beam theory. A shaft 10⁶ times stiffer than its
/// bearings gives the rigid-shaft stiffness k_uu = Σk_i, k_uθ = Σk_i·d_i, k_θθ = Σk_i·d_i²
/// (d_i = z_i − z_c); bearings 10⁶ times stiffer than the shaft, with the gear midway between
/// two at span L, give the simply supported beam, k_uu = 48·EI/L³ (deflection F·L³/(48·EI)) and
/// k_θθ = 12·EI/L (slope M·L/(12·EI)), uncoupled; both to 1e-5. In the y–z plane the coupling
/// changes sign (w′ = −θ_x). At any pose, the bearings' forces on the shaft balance the
/// support's force and moment on the body to 1e-9.
#[test]
fn the_shaft_form_is_beam_theory() {
    use helical_gear_mesh::mesh::shaft::ShaftSupport;
    let zc = 0.0075;
    // Stiff shaft, overhung gear: bearings at −20 mm and +35 mm from the end face.
    let b = [(-0.02, 3e8, 1e8), (0.035, 5e8, 0.0)];
    let s = ShaftSupport::new("s", 1e11, &b, zc).unwrap();
    let k = s.stiffness();
    let d: Vec<f64> = b.iter().map(|x| x.0 - zc).collect();
    let kuu: f64 = b.iter().map(|x| x.1).sum();
    let kut: f64 = b.iter().zip(&d).map(|(x, d)| x.1 * d).sum();
    let ktt: f64 = b.iter().zip(&d).map(|(x, d)| x.1 * d * d).sum();
    let rel = |a: f64, e: f64| ((a - e) / e).abs();
    assert!(rel(k[0][0], kuu) < 1e-5 && rel(k[1][1], kuu) < 1e-5, "{k:?}");
    assert!(rel(k[0][4], kut) < 1e-5 && rel(k[1][3], -kut) < 1e-5, "{k:?} {kut}");
    assert!(rel(k[4][4], ktt) < 1e-5 && rel(k[3][3], ktt) < 1e-5, "{k:?} {ktt}");
    assert_eq!(k[2][2], 1e8);
    // Stiff bearings, gear midway: the simply supported beam.
    let (ei, l) = (2e4, 0.1);
    let s = ShaftSupport::new("s", ei, &[(zc - l / 2.0, 1e15, 1e8), (zc + l / 2.0, 1e15, 0.0)], zc)
        .unwrap();
    let k = s.stiffness();
    assert!(rel(k[0][0], 48.0 * ei / l.powi(3)) < 1e-5, "{}", k[0][0]);
    assert!(rel(k[4][4], 12.0 * ei / l) < 1e-5, "{}", k[4][4]);
    assert!(k[0][4].abs() < 1e-5 * (k[0][0] * k[4][4]).sqrt());
    // Balance of the bearing forces against the support's force and moment on the body.
    let s =
        ShaftSupport::new("s", 3e4, &[(-0.02, 3e8, 1e8), (0.035, 5e8, 0.0), (0.06, 2e8, 0.0)], zc)
            .unwrap();
    let k = s.stiffness();
    let p = BodyPose { u_x: 3e-6, u_y: -2e-6, u_z: 1e-6, th_x: 4e-5, th_y: -7e-5 };
    let v = p.values();
    let r: Vec<f64> = (0..5).map(|i| -(0..5).map(|j| k[i][j] * v[j]).sum::<f64>()).collect();
    let (mut f, mut m) = ([0.0; 3], [0.0; 2]);
    for (bf, bearing) in s.bearing_forces(&p).zip(s.bearings()) {
        let d = bearing.z_m - zc;
        for c in 0..3 {
            f[c] += bf[c];
        }
        m[0] += -d * bf[1];
        m[1] += d * bf[0];
    }
    let scale = r[..3].iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for c in 0..3 {
        assert!((f[c] - r[c]).abs() < 1e-9 * scale, "force {c}: {} against {}", f[c], r[c]);
    }
    let mscale = r[3].abs().max(r[4].abs());
    assert!(
        (m[0] - r[3]).abs() < 1e-9 * mscale && (m[1] - r[4]).abs() < 1e-9 * mscale,
        "{m:?} {r:?}"
    );
}

/// Supports softer against tilt than the mesh (10³ N·m/rad against the mesh's ≈ 7·10⁴) and a
/// gear support of 10⁶ N/m, under 1 N·m: the plain fixed point overshoots (each iterate's
/// tilt answers the last one's moment, which grows with the tilt faster than the support), and
/// the solve turns to Newton's method (module docs): it settles, and the reactions balance the
/// mesh's force and moments at the displaced state to 1e-8 of the wrench.
#[test]
fn soft_supports_settle_by_newton_and_balance_the_mesh() {
    let mut m = mesh();
    let json =
        format!(r#"{{"pinion": {}, "gear": {}}}"#, support(6e8, 3e8, 1e3), support(1e6, 3e8, 2e6));
    let supports = Supports::from_json(&json).unwrap();
    let e =
        supported_equilibrium(&mut m, 0.0, 1.0, 1e-6, &supports, &EquilibriumSettings::default())
            .unwrap();
    eprintln!(
        "{} iterations; pinion tilt {:.3e} {:.3e} rad, gear u_x {:.3e} m",
        e.iterations,
        e.equilibrium.pose_p.th_x,
        e.equilibrium.pose_p.th_y,
        e.equilibrium.pose_g.u_x
    );

    assert_balanced(&supports, &e.equilibrium);
}
