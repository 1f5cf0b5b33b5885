//! Reading and writing: mesh files, reports, invariant files, pictures.

pub mod report;
