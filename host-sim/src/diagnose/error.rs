//! Why a log could not be diagnosed: the bench-log contract's errors and the rig file's.

/// Why a log could not be diagnosed.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// The log breaks the bench-log contract.
    #[error(transparent)]
    Log(#[from] crate::bench_log::BenchLogError),
    /// The rig file is invalid.
    #[error("cannot diagnose on this rig: {0}")]
    Rig(#[from] plant_model::RigError),
}
