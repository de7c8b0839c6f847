//! The gains a tuning reads and proposes: the proportional and integral gain of one PI
//! loop, the speed loop's (Table 1) or the pressure loop's schedule at one setpoint.

/// Proportional and integral gain of a PI. Speed: [A/(rad/s)], [A/rad]; pressure:
/// [(rad/s)/Pa], [(rad/s)/(Pa·s)].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// Proportional gain. [A/(rad/s)] or [(rad/s)/Pa]
    pub kp: f64,
    /// Integral gain. [A/rad] or [(rad/s)/(Pa·s)]
    pub ki: f64,
}
