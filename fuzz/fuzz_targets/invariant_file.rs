#![no_main]
//! Bytes → the invariant-file parser, the PLY reader and the OBJ reader; what they accept
//! must be valid and round-trip through the writers, what they reject must be explained.
//!
//! The decoding and the checks are `liemesh_fuzz::invariant_file` (`fuzz/src/lib.rs`), shared with the corpus replay
//! in `tests/fuzz_corpus.rs`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(violation) = liemesh_fuzz::invariant_file(data) {
        panic!("{violation}");
    }
});
