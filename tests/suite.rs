//! Every integration test, as one test binary: each file of `tests/` is a module of this one.
//!
//! One binary rather than one per file because each test binary compiles the mesher's generic
//! pipeline again for every scalar and field type it uses (the test profile is optimised, and
//! optimised builds do not share generic code between crates): with one binary per file (21)
//! that was most of a fresh `cargo test --all-features` build (docs/performance.md, "Build
//! time").
//!
//! Run one file's tests by its name as a filter, e.g. `cargo test --test suite classes::`. A
//! new file of `tests/` must be declared below (`autotests = false` in Cargo.toml): the test at
//! the end fails until it is.

// The fuzz targets' checks, the very file the `liemesh-fuzz` crate is built from; several of
// the modules below check outputs with them.
#[allow(dead_code)]
#[path = "../fuzz/src/lib.rs"]
mod fuzz_checks;

mod audit_field;
mod audit_jvp;
mod audit_prediction;
mod audit_scalars;
mod classes;
mod cli;
mod cli_batch;
mod cli_bench;
mod derivatives;
mod engine;
mod errors;
mod fuzz_corpus;
mod paper;
mod preset_files;
mod properties;
mod quality;
mod regressions;
mod snapshots;
mod user_surfaces;
mod validate;

/// Every `.rs` file of `tests/` is a module above: with `autotests = false`, a file left out
/// would compile and run nowhere.
#[test]
fn every_file_of_tests_is_a_module_of_the_suite() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let suite = std::fs::read_to_string(dir.join("suite.rs")).unwrap();
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        let Some(module) = name.strip_suffix(".rs") else {
            continue;
        };
        if module != "suite" && !suite.contains(&format!("\nmod {module};")) {
            missing.push(name);
        }
    }
    assert!(
        missing.is_empty(),
        "tests/suite.rs does not declare {missing:?}"
    );
}
