//! End-to-end tests of the elastic supports on the command line: `static --supports FILE`
//! reports each point's body poses and the static TE with the bodies displaced; bad files are
//! errors naming the flag, the file and the key.

use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_helical-gear")).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn static_json(extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["static", "--json", "--points-per-pitch", "4", "--slices", "60"];
    args.extend_from_slice(extra);
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{args:?}: {stderr}");
    serde_json::from_str(&stdout).expect("one JSON object")
}

/// Radial supports of 6e8 and 9e8 N/m (axial and tilt held stiff) raise every point's static
/// TE by about F_t·(1/k_p + 1/k_g) ≈ 6.5 µm on Table 1 at 100 N·m (`tests/supports.rs` checks
/// the oracle to 1 %); each point reports both poses, and the gear moved away from the pinion
/// (u_g_x > 0) and the pinion away from the gear (u_p_x < 0). Without `--supports` no pose key
/// is written.
#[test]
fn static_with_supports_reports_the_poses_and_the_displaced_te() {
    let dir = std::env::temp_dir().join(format!("hg-cli-supports-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let body = |k: f64| {
        format!(
            r#"{{"mass_kg": 2, "j_transverse_kgm2": 1e-3, "stiffness": {{"radial_n_per_m": {k:e},
            "axial_n_per_m": 1e14, "tilt_nm_per_rad": 1e12}}}}"#
        )
    };
    let file = dir.join("supports.json");
    std::fs::write(&file, format!(r#"{{"pinion": {}, "gear": {}}}"#, body(6e8), body(9e8)))
        .unwrap();
    let rigid = static_json(&[]);
    let soft = static_json(&["--supports", file.to_str().unwrap()]);
    let (rp, sp) = (rigid["points"].as_array().unwrap(), soft["points"].as_array().unwrap());
    assert_eq!(rp.len(), sp.len());
    for (r, s) in rp.iter().zip(sp) {
        assert!(r.get("pose_g").is_none());
        let d = s["ste_um"].as_f64().unwrap() - r["ste_um"].as_f64().unwrap();
        assert!((6.3..6.7).contains(&d), "ΔSTE {d} µm");
        let (pp, pg) = (s["pose_p"].as_array().unwrap(), s["pose_g"].as_array().unwrap());
        assert_eq!((pp.len(), pg.len()), (5, 5));
        assert!(pg[0].as_f64().unwrap() > 0.0 && pp[0].as_f64().unwrap() < 0.0, "{pp:?} {pg:?}");
    }
    // A bad key is named with the flag and the file.
    let bad = dir.join("bad.json");
    std::fs::write(&bad, format!(r#"{{"gear": {}}}"#, body(-1.0))).unwrap();
    let (ok, _, stderr) = run(&["static", "--supports", bad.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        stderr.contains("--supports") && stderr.contains("supports.gear.stiffness.radial_n_per_m"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
