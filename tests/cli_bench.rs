//! `liemesh bench --tiny --json` prints the expected keys with positive numbers, and judges the
//! targets its workloads cover.

// Needs the `liemesh` executable: feature `cli`.
#![cfg(feature = "cli")]

use std::process::Command;

#[test]
fn bench_json_has_keys_and_positive_numbers() {
    let out = Command::new(env!("CARGO_BIN_EXE_liemesh"))
        .args(["bench", "--quick", "--tiny", "--json"])
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let rows = v["rows"].as_array().expect("rows");
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["workload"].as_str().unwrap())
        .collect();
    for name in ["fig1", "fig6"] {
        assert!(names.contains(&name), "{names:?}");
    }
    assert!(names.iter().any(|n| n.starts_with("sphere-")));
    assert!(names.iter().any(|n| n.starts_with("ellipsoid-")));
    for r in rows {
        assert!(r["triangles"].as_u64().unwrap() > 0);
        for key in [
            "sample_ns_per_tri",
            "triangulate_ns_per_tri",
            "validate_ns_per_tri",
            "total_ns_per_tri",
            "spade_ns_per_tri",
            "total_over_spade",
        ] {
            let x = r[key].as_f64().unwrap_or(-1.0);
            assert!(x > 0.0 && x.is_finite(), "{key} = {x} in {r}");
        }
    }
    for r in rows {
        // Validation is one stage of the run: less than the whole.
        let part = r["validate_ns_per_tri"].as_f64().unwrap();
        assert!(part < r["total_ns_per_tri"].as_f64().unwrap(), "{r}");
    }
    let fig6 = v["fig6_sampling_ms"].as_array().expect("fig6_sampling_ms");
    assert!(fig6.len() >= 3);
    for key in ["dual_over_f64", "sphere_scaling", "ellipsoid_scaling"] {
        let x = v["ratios"][key].as_f64().unwrap_or(-1.0);
        assert!(x > 0.0 && x.is_finite(), "{key} = {x}");
    }
    // The fidelity rows say which β band and insertion gap they found (or came closest with).
    let fidelity = v["fidelity"].as_array().expect("fidelity");
    assert_eq!(fidelity.len(), 2);
    for f in fidelity {
        for key in ["beta_deg", "gap"] {
            let pair = f[key].as_array().unwrap_or_else(|| panic!("{key} in {f}"));
            assert_eq!(pair.len(), 2, "{f}");
            assert!(pair.iter().all(|x| x.as_f64().unwrap() > 0.0), "{f}");
        }
        assert!(f["max_error_deg"].as_f64().unwrap() > 0.0, "{f}");
    }
    // Each target the run covers is judged: a limit, a verdict, and a measured value that is
    // a positive number or, for an unreached fidelity limit, null.
    let targets = v["targets"].as_array().expect("targets");
    let names: Vec<&str> = targets
        .iter()
        .map(|t| t["target"].as_str().unwrap())
        .collect();
    assert!(
        names.iter().any(|n| n.starts_with("fig1..fig6")),
        "{names:?}"
    );
    assert!(
        names.iter().any(|n| n.starts_with("Dual<f64>")),
        "{names:?}"
    );
    for t in targets {
        assert!(t["limit"].as_f64().unwrap() > 0.0, "{t}");
        let met = t["met"].as_bool().expect("a verdict");
        match t["measured"].as_f64() {
            Some(x) => {
                assert!(x > 0.0 && x.is_finite(), "{t}");
                assert_eq!(met, x <= t["limit"].as_f64().unwrap(), "{t}");
            }
            None => assert!(t["measured"].is_null() && !met, "{t}"),
        }
    }
}
