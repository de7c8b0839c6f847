//! The process's memory between the stages of a long command: where glibc's allocator
//! takes large blocks from, and what it has kept of the blocks a stage freed, handed back
//! to the system before the next stage allocates its own (`docs/memory.md`).

/// Size from which glibc's allocator maps a block of its own, returned to the system when
/// freed, outside the fits: a whole-log column, once freed, goes back to the system instead
/// of staying in a fragmented heap. [B]
pub const MAPPED_FROM_B: usize = 128 * 1024;

/// The same threshold while the diagnosis fits ([`FitStage`]): above a fit's per-evaluation
/// residual vector (8 B a row over the 22 300 rows a fit reads at most, 10 s at one row per
/// 0.45 ms; twice that once the priors' rows are appended), which the optimiser allocates
/// and frees at every model run: from the heap it is reused, instead of mapped, faulted in
/// page by page and unmapped (with the other cores' address translations flushed) each
/// time. The Jacobians, a few times larger and allocated once an iteration, stay mapped:
/// kept in the heap, their leftovers would add to the fits' peak, which on a short log
/// written tersely is the process's (`docs/memory.md`). [B]
pub const FIT_MAPPED_FROM_B: usize = 1024 * 1024;

/// Fixes glibc's threshold for mapping a block of its own at `bytes`. By default the
/// threshold rises to the largest block freed so far (up to 32 MiB), after which a
/// diagnosis's whole-log columns come from the heap, whose freed space is kept and
/// fragmented: the process then holds a fifth more than it uses. Does nothing where the
/// allocator is not glibc's.
fn map_blocks_from(bytes: usize) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter (under the main arena's lock; a
    // refusal, return 0, leaves the threshold as it was); it touches no block.
    unsafe {
        libc::mallopt(
            libc::M_MMAP_THRESHOLD,
            libc::c_int::try_from(bytes).unwrap_or(libc::c_int::MAX),
        );
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = bytes;
}

/// Large blocks mapped from [`MAPPED_FROM_B`] on: the threshold every command runs with.
pub fn large_blocks_mapped() {
    map_blocks_from(MAPPED_FROM_B);
}

/// The diagnosis's fitting stage: from [`FitStage::begin`] until the value is dropped,
/// blocks up to [`FIT_MAPPED_FROM_B`] come from the heap; when it ends, large blocks are
/// mapped from [`MAPPED_FROM_B`] again and what the fits freed is handed back to the system
/// ([`return_freed_memory`]), so that the next stage's peak is its own. The threshold is
/// the process's: one that diagnoses in-process (a test, an example) keeps
/// [`MAPPED_FROM_B`] afterwards, as `eha` has from its start.
pub struct FitStage(());

impl FitStage {
    /// Starts the stage.
    pub fn begin() -> FitStage {
        map_blocks_from(FIT_MAPPED_FROM_B);
        FitStage(())
    }
}

impl Drop for FitStage {
    fn drop(&mut self) {
        large_blocks_mapped();
        return_freed_memory();
    }
}

/// Returns the memory the allocator holds free, in every arena, to the system: after the
/// diagnosis's fits (their Jacobians and per-evaluation vectors, the windows' runs on the
/// worker threads) and before its whole-log predictions, so that the process's peak is the
/// larger of the two stages rather than their sum. Does nothing where the allocator is
/// not glibc's.
fn return_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free pages of the allocator's own arenas; it
    // touches no block in use and is safe to call from any thread.
    unsafe {
        libc::malloc_trim(0);
    }
}
