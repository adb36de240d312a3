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

/// `simulate --supports`: both bodies move on the guide's example supports, coupled to Eqs.
/// 1–4. The JSON carries the poses and support forces per output time, the coupled modes and
/// the support-force statistics; the mean support force balances the mean mesh force on each
/// body (their mean accelerations are small over whole mesh periods) within 2 %, the pinion is
/// held towards the gear (R_p_x > 0), the gear away from it. The text output names the
/// modes; `--dt` and DOPRI5 are refused with the reason.
#[test]
fn simulate_with_supports_reports_poses_and_support_forces() {
    let dir = std::env::temp_dir().join(format!("hg-cli-supports-sim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("supports.json");
    std::fs::write(&file, EXAMPLE).unwrap();
    let f = file.to_str().unwrap();
    let base = ["simulate", "--omega-p", "300", "--t-end", "2.2e-3"];
    let mut args = base.to_vec();
    args.extend(["--supports", f, "--json"]);
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let s = &v["supports"];
    assert_eq!(s["window_mesh_periods"].as_u64(), Some(3));
    assert!(s["modes_hz"].as_array().unwrap().len() >= 12, "{}", s["modes_hz"]);
    let forces = s["support_forces"].as_object().unwrap();
    assert_eq!(forces.len(), 10);
    for r in forces.values() {
        assert_eq!(r["orders"].as_array().unwrap().len(), 3);
    }
    let n = v["time_s"].as_array().unwrap().len();
    let col = |name: &str| -> Vec<f64> {
        let c = v["bodies"][name].as_array().unwrap_or_else(|| panic!("{name}"));
        assert_eq!(c.len(), n);
        c.iter().map(|x| x.as_f64().unwrap()).collect()
    };
    for name in ["u_p_x", "th_g_y", "v_g_z", "om_p_x", "R_p_x", "R_g_my"] {
        col(name);
    }
    let names: Vec<&str> =
        v["columns"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
    assert_eq!(names.last(), Some(&"R_g_my"));
    // The window: the last 3·128 samples.
    let window = 3 * 128;
    let mean = |x: &[f64]| x[x.len() - window..].iter().sum::<f64>() / window as f64;
    let fpx: Vec<f64> =
        v["force_p_x_n"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    let (r_p, f_p) = (forces["R_p_x"]["reaction_mean_n"].as_f64().unwrap(), mean(&fpx));
    assert!((mean(&col("R_p_x")) - r_p).abs() < 1e-9 * r_p.abs());
    assert!(r_p > 0.0 && forces["R_g_x"]["reaction_mean_n"].as_f64().unwrap() < 0.0);
    assert!((r_p + f_p).abs() < 0.02 * f_p.abs(), "R {r_p} F {f_p}");

    let mut text = base.to_vec();
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    text.extend(["--supports", f]);
    let mut with_out = text.clone();
    with_out.extend(["--out", o]);
    let (ok, stdout, stderr) = run(&with_out);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("linearised coupled modes") && stdout.contains("R_g_my"), "{stdout}");
    // The spectrum: a header and one row per mesh order, and its figure.
    let csv = std::fs::read_to_string(out.join("support_spectrum.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3, "{csv}");
    assert!(csv.starts_with("order,frequency_hz,R_p_x,R_p_y,R_p_z,R_g_x,R_g_y,R_g_z"), "{csv}");
    assert!(std::fs::metadata(out.join("support_spectrum.png")).unwrap().len() > 1000);

    for (extra, why) in
        [(&["--dt", "1e-5"][..], "leave --dt out"), (&["--method", "dopri5"][..], "RK4 only")]
    {
        let mut a = text.clone();
        a.extend_from_slice(extra);
        let (ok, _, stderr) = run(&a);
        assert!(!ok && stderr.contains(why), "{extra:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `sweep --supports`: the same speeds with both bodies on their supports (table fidelity with
/// its pose sensitivities). The JSON's `supports` block holds per speed TE_max/STE_max, the
/// steady flags and the support-force statistics, the coupled modes and the speeds where the
/// first mesh order meets them; `--out` writes the curve beside the rigid one. Around the mode
/// at 1.89 kHz (mesh order 1 at 395.8 rad/s) the response on the supports peaks; on rigid
/// bearings the speeds lie between the resonances. `--out` without `--supports` is refused.
#[test]
fn sweep_with_supports_reports_the_supported_curve() {
    let dir = std::env::temp_dir().join(format!("hg-cli-supports-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("supports.json");
    std::fs::write(&file, EXAMPLE).unwrap();
    let out = dir.join("out");
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());
    let args =
        ["sweep", "--from", "380", "--to", "400", "--points", "5", "--json", "--supports", f];
    let mut a = args.to_vec();
    a.extend(["--out", o]);
    let (ok, stdout, stderr) = run(&a);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let s = &v["supports"];
    let ratio: Vec<f64> =
        s["te_max_over_ste_max"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert_eq!(ratio.len(), 5);
    assert!(s["steady"].as_array().unwrap().iter().all(|x| x.as_bool() == Some(true)));
    let modes: Vec<f64> =
        s["mode_speeds_rad_s"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert!(modes.iter().any(|w| (w - 395.8).abs() < 1.0), "{modes:?}");
    assert_eq!(s["support_forces"]["R_p_y"]["reaction_mean_n"].as_array().unwrap().len(), 5);
    // The peak lies inside the range (near 392.5 rad/s), not at its ends.
    let top = ratio.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(top > ratio[0] && top > ratio[4], "{ratio:?}");
    let csv = std::fs::read_to_string(out.join("sweep_supports.csv")).unwrap();
    assert_eq!(csv.lines().count(), 6, "{csv}");
    assert!(std::fs::metadata(out.join("sweep_supports.png")).unwrap().len() > 1000);
    let (ok, _, stderr) =
        run(&["sweep", "--from", "380", "--to", "400", "--points", "5", "--out", o]);
    assert!(!ok && stderr.contains("--supports"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The guide's example supports (the file its figures were made with).
const EXAMPLE: &str = include_str!("../../docs/gear-bodies/supports.json");
