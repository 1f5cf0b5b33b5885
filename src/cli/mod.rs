//! The `liemesh` command line (kept in the library so it can be tested).
