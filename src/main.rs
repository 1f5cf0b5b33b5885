//! The `liemesh` command-line tool; see `liemesh --help`.
//!
//! Everything only the command line needs (argument parsing, progress, pictures, benchmarks,
//! batch runs, the paper's reproduction) lives in this binary's modules ([`cli`]), built with
//! the `cli` feature (on by default); the library (`src/lib.rs`) holds the mesher.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
