//! Tests of `params`: Table 1 default, JSON round trip, and one test per validation rule that
//! checks the error names the parameter; a fuzz test that no input panics.

use helical_gear_mesh::{DriveLine, GearPair, PairGeometry};

/// Validates `p` and returns the error text, asserting that it names `key`.
fn rejects(p: &GearPair, key: &str) -> String {
    let Err(err) = PairGeometry::new(p) else { panic!("parameters must be rejected") };
    let text = err.to_string();
    assert_eq!(err.name, key, "error names the wrong parameter: {text}");
    assert!(text.contains(key) && text.contains("allowed"), "{text}");
    text
}

fn t1() -> GearPair {
    GearPair::paper_table1()
}

#[test]
fn table1_is_valid_and_round_trips_through_json() {
    let p = t1();
    p.validate().unwrap();
    let text = serde_json::to_string(&p).unwrap();
    assert_eq!(GearPair::from_json(&text).unwrap(), p);
    // Profile shifts default to zero when omitted.
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v.as_object_mut().unwrap().remove("profile_shift_p");
    assert_eq!(GearPair::from_json(&v.to_string()).unwrap().profile_shift_p, 0.0);
    // Unknown keys are an error that names them.
    v.as_object_mut().unwrap().insert("helix_angle_deg".into(), 10.into());
    let e = GearPair::from_json(&v.to_string()).unwrap_err();
    assert!(e.contains("helix_angle_deg"), "{e}");
}

#[test]
fn teeth_below_the_undercut_limit() {
    let mut p = t1();
    p.z_p = 12;
    let text = rejects(&p, "z_p");
    assert!(text.contains("undercut"), "{text}");
    // A positive shift removes the undercut.
    p.profile_shift_p = 0.5;
    p.profile_shift_g = -0.5;
    PairGeometry::new(&p).unwrap();
    let mut p = t1();
    p.z_g = 0;
    rejects(&p, "z_g");
}

#[test]
fn helix_angle_and_plain_ranges() {
    let mut p = t1();
    p.helix_angle_rad = 45f64.to_radians();
    rejects(&p, "helix_angle_rad");
    p.helix_angle_rad = -0.1;
    rejects(&p, "helix_angle_rad");
    let mut p = t1();
    p.face_width_m = 0.0;
    rejects(&p, "face_width_m");
    let mut p = t1();
    p.normal_module_m = -3e-3;
    rejects(&p, "normal_module_m");
    let mut p = t1();
    p.normal_module_m = f64::NAN;
    rejects(&p, "normal_module_m");
    let mut p = t1();
    p.pressure_angle_rad = f64::INFINITY;
    rejects(&p, "pressure_angle_rad");
    let mut p = t1();
    p.normal_backlash_mn = -0.01;
    rejects(&p, "normal_backlash_mn");
    let mut p = t1();
    p.d_mesh_n_s_per_m = -1.0;
    rejects(&p, "d_mesh_n_s_per_m");
    let d = DriveLine { j1_kgm2: 0.0, ..DriveLine::paper_table1() };
    let err = d.check().expect_err("J1 = 0");
    assert_eq!(err.name, "drive.j1_kgm2", "{err}");
    assert!(err.to_string().contains("allowed"), "{err}");
    let mut p = t1();
    p.dedendum_mn = 0.9;
    rejects(&p, "dedendum_mn");
}

#[test]
fn materials() {
    for nu in [0.0, 0.5, -0.2, f64::NAN] {
        let mut p = t1();
        p.material_p.poisson_ratio = nu;
        rejects(&p, "material_p.poisson_ratio");
    }
    let mut p = t1();
    p.material_g.youngs_modulus_pa = 0.0;
    rejects(&p, "material_g.youngs_modulus_pa");
    let mut p = t1();
    p.material_g.density_kg_m3 = -7850.0;
    rejects(&p, "material_g.density_kg_m3");
}

#[test]
fn relief_deeper_or_higher_than_the_tooth_allows() {
    let mut p = t1();
    p.z_p = 18;
    p.profile_shift_p = 0.6;
    p.tip_relief_depth_mn = 0.19;
    p.tip_relief_height_mn = 1.0;
    let text = rejects(&p, "tip_relief_depth_mn");
    assert!(text.contains("pointed"), "{text}");
    let mut p = t1();
    p.tip_relief_height_mn = 2.2;
    let text = rejects(&p, "tip_relief_height_mn");
    assert!(text.contains("form circle"), "{text}");
    let mut p = t1();
    p.tip_relief_depth_mn = 0.25;
    rejects(&p, "tip_relief_depth_mn");
}

#[test]
fn tip_rounding_that_does_not_fit() {
    let mut p = t1();
    p.tip_relief_height_mn = 0.1;
    p.tip_rounding_radius_mn = 0.4;
    let text = rejects(&p, "tip_rounding_radius_mn");
    assert!(text.contains("tangent to the relief"), "{text}");
    let mut p = t1();
    p.z_p = 18;
    p.profile_shift_p = 0.8;
    p.tip_rounding_radius_mn = 0.5;
    let text = rejects(&p, "tip_rounding_radius_mn");
    assert!(text.contains("pointed"), "{text}");
    let mut p = t1();
    p.tip_rounding_radius_mn = -0.01;
    rejects(&p, "tip_rounding_radius_mn");
}

#[test]
fn tip_land_vanishing() {
    let mut p = t1();
    p.z_p = 18;
    p.profile_shift_p = 1.0;
    p.addendum_mn = 1.2;
    let text = rejects(&p, "addendum_mn");
    assert!(text.contains("pointed") || text.contains("interference"), "{text}");
}

#[test]
fn contact_ratio_below_one() {
    let mut p = t1();
    p.helix_angle_rad = 0.0;
    p.addendum_mn = 0.5;
    p.dedendum_mn = 0.8;
    p.tip_relief_depth_mn = 0.0;
    p.rack_fillet_radius_mn = 0.2;
    let text = rejects(&p, "face_width_m");
    assert!(text.contains("ε_α"), "{text}");
}

#[test]
fn bore_and_fillet_that_do_not_fit() {
    let mut p = t1();
    p.bore_diameter_m = 0.08;
    rejects(&p, "bore_diameter_m");
    let mut p = t1();
    p.rack_fillet_radius_mn = 0.6;
    rejects(&p, "rack_fillet_radius_mn");
}

#[test]
fn no_input_panics() {
    // Random, partly absurd parameter sets: validation answers Ok or a ParamError, never panics.
    let mut state = 0x1234_5678_9abc_def0u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let specials = [f64::NAN, f64::INFINITY, -f64::INFINITY, 0.0, -1.0, 1e300, -1e-300];
    let mut ok = 0;
    for i in 0..3000 {
        let mut p = t1();
        let mut pick = |base: f64, spread: f64| {
            let r = next();
            if r < 0.01 {
                specials[(next() * specials.len() as f64) as usize % specials.len()]
            } else {
                base * (1.0 + spread * (2.0 * next() - 1.0))
            }
        };
        p.z_p = (pick(30.0, 0.9)).clamp(0.0, 1e6) as u32;
        p.z_g = (pick(47.0, 0.9)).clamp(0.0, 1e6) as u32;
        p.normal_module_m = pick(3e-3, 0.9);
        p.pressure_angle_rad = pick(0.35, 0.5);
        p.helix_angle_rad = pick(0.3, 1.2);
        p.face_width_m = pick(0.015, 0.9);
        p.profile_shift_p = pick(0.3, 3.0);
        p.profile_shift_g = pick(-0.3, 3.0);
        p.addendum_mn = pick(1.0, 0.5);
        p.dedendum_mn = pick(1.25, 0.5);
        p.rack_fillet_radius_mn = pick(0.3, 1.0);
        p.tip_relief_depth_mn = pick(0.02, 1.5);
        p.tip_relief_height_mn = pick(0.5, 1.0);
        p.tip_rounding_radius_mn = pick(0.05, 2.0);
        p.normal_backlash_mn = pick(0.07, 1.5);
        p.bore_diameter_m = pick(0.015, 1.0);
        if i % 7 == 0 {
            p.material_g.poisson_ratio = pick(0.3, 1.0);
        }
        if PairGeometry::new(&p).is_ok() {
            ok += 1;
        }
    }
    assert!(ok > 100, "only {ok} valid sets: the fuzz covers too little of the valid range");
}

/// A partial gear-pair JSON takes every missing key from Table 1 (also inside the materials),
/// a partial drive-line JSON from Table 1's drive line, and an unknown key is still an error
/// naming it.
#[test]
fn partial_json_takes_missing_keys_from_table1() {
    let p = GearPair::from_json(r#"{"helix_angle_rad": 0.2}"#).unwrap();
    assert_eq!(p, GearPair { helix_angle_rad: 0.2, ..GearPair::paper_table1() });
    assert_eq!(GearPair::from_json("{}").unwrap(), GearPair::paper_table1());
    let p = GearPair::from_json(r#"{"material_g": {"poisson_ratio": 0.29}}"#).unwrap();
    let mut q = GearPair::paper_table1();
    q.material_g.poisson_ratio = 0.29;
    assert_eq!(p, q);
    let d = DriveLine::from_json(r#"{"torque_nm": 50}"#).unwrap();
    assert_eq!(d, DriveLine { torque_nm: 50.0, ..DriveLine::paper_table1() });
    let e = GearPair::from_json(r#"{"helix_angle": 0.2}"#).unwrap_err();
    assert!(e.contains("unknown field `helix_angle`"), "{e}");
    let e = DriveLine::from_json(r#"{"torque": 1}"#).unwrap_err();
    assert!(e.contains("unknown field `torque`"), "{e}");
}

/// With missing keys filled from Table 1, serde would read an array as a struct of defaults:
/// `[]` where an object belongs is refused, naming the key, in the pair and in the
/// modifications (the FMUs' `modifications` string).
#[test]
fn an_array_where_an_object_belongs_is_refused() {
    use helical_gear_mesh::modifications::Modifications;
    for (json, key) in [
        ("[]", "(the gear pair)"),
        ("[30, 47]", "(the gear pair)"),
        (r#"{"material_p": []}"#, "material_p"),
        (r#"{"modifications": []}"#, "modifications"),
        (r#"{"modifications": {"gear": []}}"#, "modifications.gear"),
        (r#"{"modifications": {"pinion": {"tip_relief": []}}}"#, "modifications.pinion.tip_relief"),
    ] {
        let e = GearPair::from_json(json).expect_err(json);
        assert!(e.contains(key) && e.contains("must be an object"), "{json}: {e}");
    }
    assert!(
        GearPair::from_json(r#"{"modifications": {"pinion": {"deviation_map": null}}}"#).is_ok()
    );
    let e = DriveLine::from_json("[1]").expect_err("[1]");
    assert!(e.contains("(the drive line)") && e.contains("must be an object"), "{e}");
    let e = Modifications::from_json("[]").expect_err("[]");
    assert!(e.contains("modifications") && e.contains("must be an object"), "{e}");
    assert_eq!(Modifications::from_json("{}").unwrap(), Modifications::default());
}

/// The drive line is not part of the gear pair: a pair JSON with a `drive` key (an object, a
/// partial one or anything else) is refused with a message that says where the drive line
/// goes now (CLI `--drive`, Python `drive=`, C `drive_json`), not a bare "unknown field".
#[test]
fn pair_json_with_drive_is_refused_pointing_to_the_drive_line() {
    for json in [r#"{"drive": {"torque_nm": 50}}"#, r#"{"drive": {}}"#, r#"{"drive": [1]}"#] {
        let e = GearPair::from_json(json).expect_err(json);
        assert!(!e.contains("unknown field"), "{json}: {e}");
        for place in ["--drive", "drive=", "drive_json"] {
            assert!(e.contains(place), "{json}: {e} does not name {place}");
        }
    }
}

/// A partial drive-line JSON takes every missing key from Table 1's drive line; `{}` is Table
/// 1's; every value is checked against its bounds by `DriveLine::check`, naming `drive.<key>`.
#[test]
fn partial_drive_json_takes_missing_keys_from_table1() {
    assert_eq!(DriveLine::from_json("{}").unwrap(), DriveLine::paper_table1());
    let d = DriveLine::from_json(r#"{"j2_kgm2": 1.5, "d1_nms_per_rad": 0.1}"#).unwrap();
    let t = DriveLine::paper_table1();
    assert_eq!(d, DriveLine { j2_kgm2: 1.5, d1_nms_per_rad: 0.1, ..t });
    let back = DriveLine::from_json(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_eq!(back, d);
    let d = DriveLine::from_json(r#"{"torque_nm": 2e9}"#).unwrap();
    let e = d.check().expect_err("|M| > 1e9");
    assert_eq!(e.name, "drive.torque_nm", "{e}");
}
