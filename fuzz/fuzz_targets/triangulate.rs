#![no_main]
//! Samples from a short run or synthetic, edited with NaN, infinities, duplicates, collinear
//! points, huge/tiny values and inconsistent curves (a `liemesh::fuzz_checks::TriangulateInput`)
//! → `liemesh::triangulate::triangulate`; it must give a valid mesh or a typed error.
//!
//! The decoding and the checks are `liemesh::fuzz_checks::triangulate`, shared with the corpus replay
//! in `tests/fuzz_corpus.rs`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(violation) = liemesh::fuzz_checks::triangulate(data) {
        panic!("{violation}");
    }
});
