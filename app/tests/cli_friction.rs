//! End-to-end tests of the mesh friction on the command line: `--friction FILE|none` on
//! `static`, `simulate` and `sweep`, `static --omega-p`, the loss and efficiency keys of the
//! JSON output, and errors that name the flag, the file and the bad key.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_helical-gear")).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh directory for one test's files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hg-cli-friction-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    file.to_str().unwrap().to_string()
}

/// `static --json` on the default pair (fewer points and slices than the default, for time).
fn static_json(extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["static", "--json", "--points-per-pitch", "8", "--slices", "100"];
    args.extend_from_slice(extra);
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{args:?}: {stderr}");
    serde_json::from_str(&stdout).expect("one JSON object")
}

/// The JSON without the wall times (the only numbers that differ between equal runs).
fn without_timings(mut v: serde_json::Value) -> serde_json::Value {
    let o = v.as_object_mut().unwrap();
    o.remove("seconds");
    o.remove("model_build_s");
    v
}

#[test]
fn static_with_constant_friction_reports_loss_efficiency_and_h_v() {
    let dir = temp_dir("static");
    let file = write(&dir, "constant.json", r#"{"model": "constant", "mu": 0.05}"#);
    let v = static_json(&["--friction", &file, "--omega-p", "300"]);
    let eta = v["mesh_efficiency_mean"].as_f64().unwrap();
    let loss = v["mesh_loss_mean_w"].as_f64().unwrap();
    let h_v = v["loss_factor_h_v"].as_f64().unwrap();
    assert!(eta > 0.99 && eta < 1.0, "mesh_efficiency_mean = {eta}");
    assert!(loss > 0.0, "mesh_loss_mean_w = {loss}");
    assert!((0.1..=0.15).contains(&h_v), "loss_factor_h_v = {h_v}");
    assert_eq!(v["mu_mean"].as_f64(), Some(0.05));
    assert_eq!(v["omega_p_rad_s"].as_f64(), Some(300.0));
    // The summary is the mean of the points, and 1 − loss/(M·ω_p).
    let points = v["points"].as_array().unwrap();
    let mean =
        points.iter().map(|p| p["p_loss_w"].as_f64().unwrap()).sum::<f64>() / points.len() as f64;
    assert!((mean - loss).abs() <= 1e-9 * loss, "{mean} against {loss}");
    assert!((eta - (1.0 - loss / (100.0 * 300.0))).abs() < 1e-12);
    for p in points {
        let l = p["p_loss_w"].as_f64().unwrap();
        let (qp, qg) = (p["q_p_w"].as_f64().unwrap(), p["q_g_w"].as_f64().unwrap());
        assert!(l > 0.0 && ((qp + qg) - l).abs() <= 1e-9 * l, "{p}");
        let e = p["eta_mesh"].as_f64().unwrap();
        assert!(e > 0.99 && e < 1.0, "{p}");
        assert!(p["m_r_p_nm"].as_f64().unwrap() != 0.0 && p["m_r_g_nm"].is_number());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn static_friction_none_is_the_default_and_standstill_has_no_loss() {
    let dir = temp_dir("none");
    let plain = static_json(&[]);
    // Every existing number unchanged; friction off: no loss, efficiency 1, μ null, H_V given.
    assert_eq!(
        without_timings(static_json(&["--friction", "none"])),
        without_timings(plain.clone())
    );
    let none_file = write(&dir, "none.json", r#"{"model": "none"}"#);
    assert_eq!(
        without_timings(static_json(&["--friction", &none_file])),
        without_timings(plain.clone())
    );
    assert_eq!(plain["mesh_loss_mean_w"].as_f64(), Some(0.0));
    assert_eq!(plain["mesh_efficiency_mean"].as_f64(), Some(1.0));
    assert!(plain["mu_mean"].is_null());
    assert!(plain["loss_factor_h_v"].as_f64().is_some_and(|h| h > 0.1 && h < 0.15));

    // At standstill nothing slides: no loss with friction on.
    let file = write(&dir, "constant.json", r#"{"model": "constant", "mu": 0.05}"#);
    let rest = static_json(&["--friction", &file, "--omega-p", "0"]);
    assert_eq!(rest["mesh_loss_mean_w"].as_f64(), Some(0.0));
    assert_eq!(rest["mesh_efficiency_mean"].as_f64(), Some(1.0));
    for p in rest["points"].as_array().unwrap() {
        assert_eq!(p["p_loss_w"].as_f64(), Some(0.0), "{p}");
        assert_eq!(p["m_r_p_nm"].as_f64(), Some(0.0), "{p}");
    }
    // ... and the standstill states are the frictionless ones.
    assert_eq!(rest["ste_um"], plain["ste_um"]);

    // The ISO/TR 14179-2 model by its documented name: a μ of a few hundredths.
    let iso = write(&dir, "iso.json", r#"{"model": "iso_tr_14179_2"}"#);
    let v = static_json(&["--friction", &iso]);
    let mu = v["mu_mean"].as_f64().unwrap();
    assert!(mu > 0.01 && mu < 0.2, "mu_mean = {mu}");
    assert!(v["mesh_loss_mean_w"].as_f64().unwrap() > 0.0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_friction_and_speed_fail_naming_the_flag_file_and_key() {
    let dir = temp_dir("bad");
    let big_mu = write(&dir, "big_mu.json", r#"{"model": "constant", "mu": 2}"#);
    let unknown = write(&dir, "unknown.json", r#"{"model": "constant", "mu_max": 0.1}"#);
    for cmd in [
        &["static"][..],
        &["simulate", "--omega-p", "300", "--t-end", "1e-3"][..],
        &["sweep", "--from", "300", "--to", "300", "--points", "1"][..],
    ] {
        let mut args = cmd.to_vec();
        args.extend(["--friction", &big_mu]);
        let (ok, stdout, stderr) = run(&args);
        assert!(!ok && stdout.is_empty(), "{args:?}");
        for part in ["--friction", "big_mu.json", "friction.mu"] {
            assert!(stderr.contains(part), "{args:?}: {stderr}");
        }
        let mut args = cmd.to_vec();
        args.extend(["--friction", &unknown]);
        let (ok, _, stderr) = run(&args);
        assert!(!ok, "{args:?}");
        for part in ["--friction", "unknown.json", "mu_max"] {
            assert!(stderr.contains(part), "{args:?}: {stderr}");
        }
    }
    // spectrum: with --dynamic, refused before the table is built; without, refused as
    // meaningless (the static spectrum is at standstill).
    let args = ["spectrum", "--dynamic", "--speed", "300", "--friction", &big_mu];
    let (ok, _, stderr) = run(&args);
    assert!(!ok && stderr.contains("friction.mu") && stderr.contains("big_mu.json"), "{stderr}");
    let constant = write(&dir, "constant.json", r#"{"model": "constant", "mu": 0.05}"#);
    let (ok, _, stderr) = run(&["spectrum", "--friction", &constant]);
    assert!(!ok && stderr.contains("--friction") && stderr.contains("--dynamic"), "{stderr}");
    let missing = dir.join("missing.json");
    let (ok, _, stderr) = run(&["static", "--friction", missing.to_str().unwrap()]);
    assert!(!ok && stderr.contains("--friction") && stderr.contains("no such file"), "{stderr}");
    for bad in ["NaN", "inf", "2e5"] {
        let (ok, _, stderr) = run(&["static", "--omega-p", bad]);
        assert!(!ok && stderr.contains("--omega-p"), "{bad}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn simulate_trajectory_carries_the_friction_outputs() {
    let dir = temp_dir("simulate");
    let file = write(&dir, "constant.json", r#"{"model": "constant", "mu": 0.05}"#);
    let args = ["simulate", "--omega-p", "300", "--t-end", "5e-4", "--json", "--friction", &file];
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    let columns: Vec<&str> =
        v["columns"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
    for c in ["m_r_p_nm", "m_r_g_nm", "p_loss_w", "eta_mesh", "q_p_w", "q_g_w"] {
        assert!(columns.contains(&c), "missing column {c}: {columns:?}");
    }
    let loss = v["p_loss_w"].as_array().expect("the p_loss_w samples");
    assert!(loss.iter().all(|x| x.as_f64().unwrap() > 0.0), "{loss:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_reports_the_mean_mesh_efficiency_per_speed() {
    let dir = temp_dir("sweep");
    let file = write(&dir, "constant.json", r#"{"model": "constant", "mu": 0.05}"#);
    let args = [
        "sweep",
        "--from",
        "300",
        "--to",
        "300",
        "--points",
        "1",
        "--refine-runs",
        "0",
        "--json",
        "--friction",
        &file,
    ];
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    let eta = v["mesh_efficiency_mean"].as_array().unwrap();
    assert_eq!(eta.len(), 1);
    let eta = eta[0].as_f64().unwrap();
    // The steady cycle's efficiency is close to the quasi-static one at the same speed.
    let s = static_json(&["--friction", &file, "--omega-p", "300"]);
    let eta_static = s["mesh_efficiency_mean"].as_f64().unwrap();
    assert!(eta > 0.99 && eta < 1.0, "mesh_efficiency_mean = {eta}");
    assert!((eta - eta_static).abs() < 1e-3, "{eta} against the static {eta_static}");
    std::fs::remove_dir_all(&dir).ok();
}
