//! The process's memory between the stages of a long command: what the allocator has kept
//! of the blocks a stage freed, handed back to the system before the next stage allocates
//! its own (`docs/memory.md`).

/// Returns the memory the allocator holds free, in every arena, to the system: after the
/// diagnosis's fits (their Jacobians and per-evaluation vectors, the windows' runs on the
/// worker threads) and before its whole-log predictions, so that the process's peak is the
/// larger of the two stages rather than their sum. Does nothing where the allocator is
/// not glibc's.
pub fn return_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free pages of the allocator's own arenas; it
    // touches no block in use and is safe to call from any thread.
    unsafe {
        libc::malloc_trim(0);
    }
}
