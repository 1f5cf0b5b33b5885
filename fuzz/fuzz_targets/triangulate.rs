#![no_main]
//! Samples from a short run or synthetic, edited with NaN, infinities, duplicates, collinear
//! points, huge/tiny values and inconsistent curves (a `liemesh_fuzz::TriangulateInput`)
//! → `liemesh::triangulate::triangulate`; it must give a valid mesh or a typed error.
//!
//! The decoding and the checks are `liemesh_fuzz::triangulate` (`fuzz/src/lib.rs`), shared with the corpus replay
//! in `tests/fuzz_corpus.rs`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(violation) = liemesh_fuzz::triangulate(data) {
        panic!("{violation}");
    }
});
