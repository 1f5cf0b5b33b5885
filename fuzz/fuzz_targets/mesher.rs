#![no_main]
//! Invariant + parameters (a `liemesh_fuzz::MesherInput`) → `liemesh::run`;
//! the run must give a valid mesh or the typed error that fits the input.
//!
//! The decoding and the checks are `liemesh_fuzz::mesher` (`fuzz/src/lib.rs`), shared with the corpus replay
//! in `tests/fuzz_corpus.rs`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(violation) = liemesh_fuzz::mesher(data) {
        panic!("{violation}");
    }
});
