//! The `eha` binary: parses the command line and runs the subcommand (see [`host_sim::cli`]).

fn main() -> std::process::ExitCode {
    host_sim::cli::main()
}
