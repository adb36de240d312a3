//! End-to-end tests of the `helical-gear` binary: the JSON contract of `geometry` and `contact`
//! and clear errors for bad input.

use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_helical-gear")).args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn geometry_json_has_the_contract_keys_and_table1_values() {
    let (ok, stdout, _) = run(&["geometry", "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    for key in [
        "eps_alpha",
        "eps_beta",
        "base_radius_p_m",
        "base_radius_g_m",
        "tip_radius_p_m",
        "tip_radius_g_m",
        "center_distance_m",
        "j_p_kgm2",
        "j_g_kgm2",
    ] {
        assert!(v[key].as_f64().is_some_and(f64::is_finite), "missing {key}");
    }
    assert!((v["eps_alpha"].as_f64().unwrap() - 1.663).abs() < 0.005);
    assert!((v["base_radius_p_m"].as_f64().unwrap() - 42.861e-3).abs() < 5e-6);
    assert!(v["assumptions"].as_array().is_some_and(|a| !a.is_empty()));
}

#[test]
fn contact_json_lists_slices() {
    let (ok, stdout, _) = run(&["contact", "--phi-p", "0.01", "--te", "20e-6", "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let slices = v["slices"].as_array().unwrap();
    assert!(!slices.is_empty());
    for s in slices {
        for key in ["zeta", "pair", "kind", "overlap_m", "rho_p_m", "rho_g_m", "arm_p_m", "arm_g_m"]
        {
            assert!(!s[key].is_null(), "missing {key}");
        }
        if s["kind"] == "involute/involute" {
            assert!((s["overlap_m"].as_f64().unwrap() - 20e-6).abs() < 1e-12);
        }
    }
}

#[test]
fn bad_parameters_give_a_clear_error() {
    let dir = std::env::temp_dir().join(format!("hg-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("p.json");
    let (_, template, _) = run(&["params"]);
    std::fs::write(&file, template.replace("\"z_p\": 30", "\"z_p\": 12")).unwrap();
    let (ok, stdout, stderr) = run(&["geometry", "--json", "--params", file.to_str().unwrap()]);
    assert!(!ok && stdout.is_empty());
    assert!(stderr.contains("z_p") && stderr.contains("undercut"), "{stderr}");
    let (ok, _, stderr) =
        run(&["geometry", "--params", dir.join("missing.json").to_str().unwrap()]);
    assert!(!ok && stderr.contains("cannot read"), "{stderr}");
    let (ok, _, stderr) = run(&["contact", "--phi-p", "NaN", "--te", "0"]);
    assert!(!ok && stderr.contains("finite"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}
