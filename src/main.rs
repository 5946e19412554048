//! The `hbal` command line ([`hbal::cli::main`]: solve, sweep, compare, modes, report and
//! check scene files).

fn main() -> std::process::ExitCode {
    hbal::cli::main()
}
