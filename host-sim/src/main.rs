//! The `eha` binary: parses the command line and runs the subcommand (see [`host_sim::cli`]).

fn main() -> std::process::ExitCode {
    // Every command maps its large blocks, so that what it frees goes back to the system.
    host_sim::memory::large_blocks_mapped();
    host_sim::cli::main()
}
