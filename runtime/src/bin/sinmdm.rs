//! The `sinmdm` command line; see `sinmdm --help`.

fn main() -> std::process::ExitCode {
    sinmdm::cli::main()
}
