//! The table with the gear bodies displaced (`mesh::table::PoseTable`) against the full model,
//! over the poses that stiff, medium and soft supports produce on Table 1 at 100 N·m: at each
//! point of the supported static curve (8 phases over a pitch), at the static TE and at 0.8 and
//! 1.2 times it (a dynamic swing of the load) with the static poses. The errors are stated in
//! the module docs of `mesh::table::pose` and the guide.

use helical_gear_mesh::GearPair;
use helical_gear_mesh::mesh::{
    BodyPose, EquilibriumSettings, Fidelity, Mesh, MeshOptions, MeshState, MeshTorques, Supports,
    TABLE_POSE_BOUND_MN, supported_static_curve,
};

fn supports(scale: f64) -> Supports {
    let body = |m: f64, j: f64, r: f64, a: f64, t: f64| {
        format!(
            r#"{{"mass_kg": {m}, "j_transverse_kgm2": {j}, "stiffness": {{"radial_n_per_m": {:e},
            "axial_n_per_m": {:e}, "tilt_nm_per_rad": {:e}}}}}"#,
            r * scale,
            a * scale,
            t * scale
        )
    };
    Supports::from_json(&format!(
        r#"{{"pinion": {}, "gear": {}}}"#,
        body(2.0, 1e-3, 6e8, 3e8, 8e5),
        body(5.0, 1e-2, 9e8, 3e8, 2e6)
    ))
    .unwrap()
}

/// Largest errors (M_F,p over the nominal torque, force over |F|, tilting moments over |F|·b)
/// of `table` against `full` over the supported static curve on `supports`, and the same for
/// the table ignoring the pose; with the largest relative translation.
fn errors(full: &mut Mesh, table: &mut Mesh, supports: &Supports) -> ([f64; 3], [f64; 3], f64) {
    let pitch = 2.0 * std::f64::consts::PI / 30.0;
    let set = EquilibriumSettings::default();
    let curve = supported_static_curve(full, 100.0, 0.0, pitch, 8, 1, supports, &set).unwrap();
    let (gp, gg) = full.base_radii();
    let b = GearPair::paper_table1().face_width_m;
    let (mut e, mut ignored, mut u_max) = ([0.0f64; 3], [0.0f64; 3], 0.0f64);
    for p in &curve.points {
        let rel =
            [p.pose_g.u_x - p.pose_p.u_x, p.pose_g.u_y - p.pose_p.u_y, p.pose_g.u_z - p.pose_p.u_z];
        u_max = rel.iter().fold(u_max, |m, v| m.max(v.abs()));
        for f in [0.8, 1.0, 1.2] {
            let te = p.te * f;
            let s = MeshState {
                phi_p: p.phi_p,
                phi_g: (te - p.phi_p * gp) / gg,
                pose_p: p.pose_p,
                pose_g: p.pose_g,
                ..Default::default()
            };
            let a = full.mesh(&s).unwrap();
            let fmag = a.force_p.iter().map(|x| x * x).sum::<f64>().sqrt();
            let rigid = MeshState { pose_p: BodyPose::default(), pose_g: BodyPose::default(), ..s };
            for (err, o) in
                [(&mut e, table.mesh(&s).unwrap()), (&mut ignored, table.mesh(&rigid).unwrap())]
            {
                err[0] = err[0].max((a.m_f_p - o.m_f_p).abs() / 100.0);
                for k in 0..3 {
                    err[1] = err[1].max((a.force_p[k] - o.force_p[k]).abs() / fmag);
                }
                for k in 0..2 {
                    let d = (a.moment_p[k] - o.moment_p[k])
                        .abs()
                        .max((a.moment_g[k] - o.moment_g[k]).abs());
                    err[2] = err[2].max(d / (fmag * b));
                }
            }
        }
    }
    (e, ignored, u_max)
}

/// The table's errors with poses stay at the level of its own error on rigid bearings
/// (2.0·10⁻⁴ of M_F,p): for supports 10 times stiffer than the guide's example, the example,
/// and 3 times softer (relative translations up to 0.6, 6.1 and 18.3 µm), M_F,p within 10⁻³ of
/// the nominal torque, the force within 10⁻³ of |F| and the tilting moments within 10⁻³ of
/// |F|·b (measured at most 3.2·10⁻⁴, 2.9·10⁻⁴ and 4.2·10⁻⁴, for the soft supports).
/// Ignoring the pose would be wrong by 2.6–80 % of the torque. A pose beyond the table's bound is
/// refused naming the relative component.
#[test]
fn the_table_with_poses_follows_the_full_model() {
    let pair = GearPair::paper_table1();
    let mut full = Mesh::new(&pair, MeshOptions::default()).unwrap();
    let mut table =
        Mesh::new(&pair, MeshOptions { fidelity: Fidelity::Table, ..MeshOptions::default() })
            .unwrap();
    // The first posed state builds the sensitivities; preparing afterwards changes nothing,
    // and a copy of the model shares them.
    let posed = MeshState {
        phi_p: 0.01,
        phi_g: -0.0060851,
        pose_g: BodyPose { u_x: 1e-6, ..Default::default() },
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let first = table.mesh(&posed).unwrap();
    eprintln!(
        "first posed evaluation (builds the sensitivities): {:.2} s",
        t0.elapsed().as_secs_f64()
    );
    table.prepare_poses().unwrap();
    assert_eq!(table.mesh(&posed).unwrap(), first);
    let copy = table.clone();
    let sensitivities = |m: &Mesh| match m {
        Mesh::Table(t) => t.table().pose_table().unwrap().clone(),
        Mesh::Full(_) => unreachable!("a table"),
    };
    assert!(std::sync::Arc::ptr_eq(&sensitivities(&table), &sensitivities(&copy)));
    assert_eq!(copy.clone().mesh(&posed).unwrap(), first);
    for (name, scale) in [("stiff", 10.0), ("example", 1.0), ("soft", 1.0 / 3.0)] {
        let (e, ignored, u) = errors(&mut full, &mut table, &supports(scale));
        eprintln!(
            "{name:8} supports (relative translation up to {:.1} µm): table with poses: M_F,p \
             {:.2e} of the torque, force {:.2e} of |F|, moments {:.2e} of |F|·b; ignoring the \
             pose: {:.2e}, {:.2e}, {:.2e}",
            u * 1e6,
            e[0],
            e[1],
            e[2],
            ignored[0],
            ignored[1],
            ignored[2]
        );
        assert!(e[0] < 1e-3 && e[1] < 1e-3 && e[2] < 1e-3, "{name}: {e:?}");
        assert!(ignored[0] > 0.02, "{name}: the pose matters ({ignored:?})");
    }
    let mn = pair.normal_module_m;
    let beyond = MeshState {
        pose_g: BodyPose { u_y: 1.01 * TABLE_POSE_BOUND_MN * mn, ..Default::default() },
        ..posed
    };
    let err = table.mesh(&beyond).unwrap_err().to_string();
    assert!(err.contains("U_y") && err.contains("fidelity full"), "{err}");
    assert!(full.mesh(&beyond).is_ok());
}

/// The back flanks' pose sensitivities are sampled at the first posed back-flank state, not by
/// the build (nor does the build sample the table's back flanks), and the same whenever: a
/// table whose first posed state is on the back flanks gives, bit for bit, the outputs of one
/// that reached the back flanks after the driving ones; the posed back-flank state agrees with
/// the full model.
#[test]
fn back_flank_pose_sensitivities_are_sampled_on_demand_and_the_same_whenever() {
    let pair = GearPair::paper_table1();
    let opts = MeshOptions {
        slices: 100,
        table_phase_points: 32,
        table_te_points: 24,
        ..MeshOptions::default()
    };
    let mut full = Mesh::new(&pair, opts).unwrap();
    let table = || Mesh::new(&pair, MeshOptions { fidelity: Fidelity::Table, ..opts }).unwrap();
    let (mut lazy, mut eager) = (table(), table());
    let geo = full.geometry().clone();
    let jt = geo.backlash_te;
    let pose_g = BodyPose { u_x: 2e-6, u_y: -3e-6, th_y: 2e-5, ..Default::default() };
    let at = |phi_p: f64, te: f64| MeshState {
        phi_p,
        phi_g: geo.phi_g_for_te(phi_p, te),
        pose_g,
        ..Default::default()
    };
    let (drive, back) = (at(0.03, 20e-6), at(0.11, -jt - 30e-6));
    let sampled = |m: &Mesh| m.table().unwrap().back_flanks_sampled();

    lazy.prepare_poses().unwrap();
    assert!(!sampled(&lazy), "the pose build sampled the back flanks");
    let d = lazy.mesh(&drive).unwrap();
    assert!(!sampled(&lazy));
    let b = lazy.mesh(&back).unwrap();
    assert!(sampled(&lazy) && b.back_contact && b.m_f_p < 0.0, "{b:?}");
    assert_eq!(lazy.mesh(&drive).unwrap(), d);

    assert_eq!(eager.mesh(&back).unwrap(), b);
    assert_eq!(eager.mesh(&drive).unwrap(), d);

    // Over a pitch and three back-flank loads (light to heavy): within 2·10⁻³ of M_F,p
    // (measured at most 3.6·10⁻⁴ on this 32 × 24 table), where ignoring the pose would be off
    // by more than 5 %.
    let (mut worst, mut ignored) = (0.0f64, f64::INFINITY);
    for phi_p in [0.05, 0.11, 0.137, 0.2, 0.31] {
        for te in [-jt - 10e-6, -jt - 30e-6, -jt - 45e-6] {
            let s = at(phi_p, te);
            let rigid = MeshState { pose_g: BodyPose::default(), ..s };
            let (t, f) = (lazy.mesh(&s).unwrap(), full.mesh(&s).unwrap());
            assert!(t.back_contact && f.back_contact, "{t:?}");
            worst = worst.max((t.m_f_p - f.m_f_p).abs() / f.m_f_p.abs());
            ignored =
                ignored.min((full.mesh(&rigid).unwrap().m_f_p - f.m_f_p).abs() / f.m_f_p.abs());
        }
    }
    eprintln!(
        "posed back-flank states: M_F,p within {worst:e} of the full model (the pose moves it by at least {ignored:e})"
    );
    assert!(worst < 2e-3 && ignored > 0.05, "{worst:e}, {ignored:e}");
}
