//! `liemesh paper -o DIR` writes six meshes, six pictures and the Table 3 comparison.

// Needs the `liemesh` executable: feature `cli`.
#![cfg(feature = "cli")]

use std::process::Command;

#[test]
fn paper_writes_six_meshes_six_pictures_and_a_six_row_table() {
    let dir = std::env::temp_dir().join(format!("liemesh-paper-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_liemesh"))
        .args(["paper", "-o"])
        .arg(&dir)
        .output()
        .expect("runs liemesh");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for n in 1..=6 {
        for ext in ["ply", "png"] {
            let f = dir.join(format!("fig{n}.{ext}"));
            let len = std::fs::metadata(&f).map(|m| m.len()).unwrap_or(0);
            assert!(len > 0, "{} missing or empty", f.display());
        }
    }
    let rows: Vec<&str> = stdout.lines().filter(|l| l.starts_with("fig")).collect();
    assert_eq!(rows.len(), 6, "{stdout}");
    for (n, row) in rows.iter().enumerate() {
        assert!(row.starts_with(&format!("fig{}", n + 1)), "{row}");
    }
    let md = std::fs::read_to_string(dir.join("table.md")).unwrap();
    assert_eq!(md.lines().filter(|l| l.starts_with("| fig")).count(), 6);
    let _ = std::fs::remove_dir_all(&dir);
}
