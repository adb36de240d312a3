//! End-to-end tests of the `helical-gear` binary with flank modifications: the contract keys of
//! `static` (Winkler flags, K_Hβ) and `harris`.

use helical_gear_mesh::GearPair;

fn cli(args: &[&str]) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_helical-gear"))
        .args(args)
        .output()
        .expect("run helical-gear");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

/// The contract keys of `static` (Winkler flags, K_Hβ) and `harris` (docs/modifications.md).
#[test]
fn cli_static_and_harris_keys() {
    let dir = std::env::temp_dir().join(format!("hg_mods_cli_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut p = GearPair::paper_table1();
    p.modifications.mesh_misalignment_m = 10e-6;
    let params = dir.join("p.json");
    std::fs::write(&params, serde_json::to_string(&p).unwrap()).unwrap();
    let w = [
        "--compliance",
        "winkler",
        "--winkler-c-prime",
        "14",
        "--no-local-contact",
        "--slices",
        "40",
    ];
    let mut args = vec!["static", "--json", "--points-per-pitch", "4", "--params"];
    args.push(params.to_str().unwrap());
    args.extend(w);
    let s = cli(&args);
    for key in ["k_h_beta_max", "k_h_beta_iso", "k_h_beta_cycle"] {
        assert!(s[key].as_f64().unwrap() > 1.0, "{key}: {s}");
    }
    let record: helical_gear_mesh::results::StaticRunRecord =
        serde_json::from_value(s.clone()).expect("static --json is the StaticRunRecord");
    assert_eq!(record.points.len(), record.curve.ste_um.len());
    assert_eq!(record.slices, 40);
    let pt = &s["points"][0];
    for key in ["k_h_beta", "line_load_max_n_per_mm", "line_load_mean_n_per_mm"] {
        assert!(pt[key].as_f64().unwrap() > 0.0, "{key}: {pt}");
    }
    let variants = dir.join("v.json");
    std::fs::write(
        &variants,
        r#"[{"name": "none"}, {"name": "crowned", "modifications": {"pinion": {"lead_crowning_m": 5e-6}}}]"#,
    )
    .unwrap();
    let mut args = vec!["harris", "--json", "--torque-from", "50", "--to", "100", "--points", "2"];
    args.extend(["--points-per-pitch", "4", "--variants", variants.to_str().unwrap()]);
    args.extend(w);
    let h = cli(&args);
    assert_eq!(h["torques_nm"], serde_json::json!([50.0, 100.0]));
    let record: helical_gear_mesh::results::HarrisRecord =
        serde_json::from_value(h.clone()).expect("harris --json is the HarrisRecord");
    assert_eq!(record.variants.len(), 2);
    assert_eq!(h["variants"][1]["name"], "crowned");
    assert_eq!(h["variants"][0]["ste_peak_to_peak_um"].as_array().unwrap().len(), 2);
    std::fs::remove_dir_all(&dir).ok();
}
