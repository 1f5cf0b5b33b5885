//! The `liemesh` command-line tool; see `liemesh --help`.

fn main() -> std::process::ExitCode {
    liemesh::cli::main()
}
