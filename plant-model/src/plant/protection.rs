//! The bridge's protection state the plant carries: the hardware over-current break (its
//! threshold and latch) and the watch on the bridge currents a fault campaign asserts on
//! (what [`super::faulted`] arms, trips and reads).

/// The hardware break and the current watch.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Protection {
    /// Break threshold on any leg current's magnitude. [A]
    pub(super) break_threshold_a: Option<f64>,
    /// Gates held off by the break.
    pub(super) latched: bool,
    /// A break happened since the last `Plant::take_break_event`.
    pub(super) event: bool,
    /// The watch's limit. [A]
    pub(super) watch_limit_a: Option<f64>,
    /// Largest leg current since the last `Plant::take_current_watch`. [A]
    pub(super) peak_a: f64,
    /// Time any leg current spent above the watch's limit since then. [s]
    pub(super) time_above_s: f64,
}

/// What the current watch saw since it was last read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CurrentWatch {
    /// Largest magnitude of any bridge leg's current. [A]
    pub peak_a: f64,
    /// Time any leg's current magnitude spent above the watch's limit. [s]
    pub time_above_s: f64,
}
