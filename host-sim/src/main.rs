//! The `eha` binary: parses the command line and runs the subcommand (see [`host_sim::cli`]).

fn main() -> std::process::ExitCode {
    return_large_blocks_when_freed();
    host_sim::cli::main()
}

/// Size from which glibc's allocator maps a block of its own, returned to the system when
/// freed. [B]
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_THRESHOLD_B: libc::c_int = 128 * 1024;

/// Fixes glibc's threshold for mapping a block of its own at [`MMAP_THRESHOLD_B`]. By
/// default the threshold rises to the largest block freed so far (up to 32 MiB), after
/// which a diagnosis's whole-log columns come from the heap, whose freed space is kept
/// and fragmented: the process then holds a fifth more than it uses. Every command's
/// memory is bounded by what it holds live (`docs/memory.md`).
fn return_large_blocks_when_freed() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter; it is called before any thread
    // starts, and a refusal (return 0) leaves the default in place.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD_B);
    }
}
