//! `liemesh batch` over the preset invariant files: one mesh and one report per input, and
//! the same bytes whatever the number of threads.

// Needs the `liemesh` executable: feature `cli`.
#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};
use std::process::Command;

fn run_batch(out: &Path, threads: &str) {
    let status = Command::new(env!("CARGO_BIN_EXE_liemesh"))
        .args(["batch", "examples/presets", "--quiet", "-o"])
        .arg(out)
        .env("RAYON_NUM_THREADS", threads)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .expect("liemesh runs");
    assert!(status.success(), "liemesh batch failed: {status}");
}

fn outputs(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn batch_meshes_every_preset_file_deterministically() {
    let tmp = std::env::temp_dir().join(format!("liemesh-batch-{}", std::process::id()));
    let (one, many) = (tmp.join("one"), tmp.join("many"));
    let _ = std::fs::remove_dir_all(&tmp);
    run_batch(&one, "1");
    run_batch(&many, "2");
    let files = outputs(&one);
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for k in 1..=6 {
        for ext in ["ply", "json"] {
            assert!(names.contains(&format!("fig{k}.{ext}")), "{names:?}");
        }
    }
    assert_eq!(files.len(), 12, "{names:?}");
    for f in &files {
        let other = many.join(f.file_name().unwrap());
        assert_eq!(
            std::fs::read(f).unwrap(),
            std::fs::read(&other).unwrap(),
            "{} differs between 1 and 2 threads",
            f.display()
        );
    }
    // Each report describes its mesh.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(one.join("fig3.json")).unwrap()).unwrap();
    assert_eq!(report["closed"], serde_json::Value::Bool(true));
    assert!(report["triangles"].as_u64().unwrap() > 1000);
    // The mesh equals what `liemesh mesh --invariant` writes for the same file.
    let single = tmp.join("fig3-single.ply");
    let status = Command::new(env!("CARGO_BIN_EXE_liemesh"))
        .args([
            "mesh",
            "--quiet",
            "--invariant",
            "examples/presets/fig3.toml",
            "-o",
        ])
        .arg(&single)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(
        std::fs::read(&single).unwrap(),
        std::fs::read(one.join("fig3.ply")).unwrap()
    );
    let _ = std::fs::remove_dir_all(&tmp);
}
