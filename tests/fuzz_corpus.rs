//! Replays the committed fuzz corpora (`fuzz/corpus/<target>/*`) on stable Rust.
//!
//! Each file goes through the very function its cargo-fuzz target calls
//! (`liemesh_fuzz::{mesher, triangulate, invariant_file}`, from `fuzz/src/lib.rs`, which the
//! test suite includes as the module `fuzz_checks`), so the bytes are decoded the same way and the
//! same output invariants are checked; a panic counts as a failure too.
//! Every failing file is listed with its violation. See `fuzz/README.md`.

// The fuzz targets' checks (see `tests/suite.rs`).
use crate::fuzz_checks::{Target, TARGETS};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read the corpus {}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

fn replay(name: &str, target: Target, min_files: usize) {
    let files = corpus(name);
    assert!(
        files.len() >= min_files,
        "the {name} corpus has {} files, expected at least {min_files}",
        files.len()
    );
    let mut failures = Vec::new();
    for path in &files {
        let data = std::fs::read(path).unwrap();
        let outcome = catch_unwind(AssertUnwindSafe(|| target(&data)));
        let file = path.file_name().unwrap().to_string_lossy();
        match outcome {
            Ok(Ok(())) => {}
            Ok(Err(violation)) => failures.push(format!("{file}: {violation}")),
            Err(panic) => {
                let msg = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                failures.push(format!("{file}: panicked: {msg}"));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} {name} corpus files fail:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

fn target(name: &str) -> Target {
    TARGETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .unwrap()
}

#[test]
fn mesher_corpus_replays_clean() {
    replay("mesher", target("mesher"), 20);
}

#[test]
fn triangulate_corpus_replays_clean() {
    replay("triangulate", target("triangulate"), 20);
}

#[test]
fn invariant_file_corpus_replays_clean() {
    replay("invariant_file", target("invariant_file"), 20);
}

#[test]
fn every_target_has_a_corpus_and_a_fuzz_binary() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let manifest = std::fs::read_to_string(fuzz.join("Cargo.toml")).unwrap();
    for (name, _) in TARGETS {
        assert!(
            fuzz.join("corpus").join(name).is_dir(),
            "no corpus for {name}"
        );
        let source = fuzz.join("fuzz_targets").join(format!("{name}.rs"));
        let text = std::fs::read_to_string(&source).unwrap();
        assert!(
            text.contains(&format!("liemesh_fuzz::{name}(data)")),
            "{} does not call liemesh_fuzz::{name}",
            source.display()
        );
        assert!(manifest.contains(&format!("name = \"{name}\"")));
    }
}
