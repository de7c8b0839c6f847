//! The running estimators of the commissioning steps: allocation-free sums that turn
//! samples into a mean, a circular mean of angles, and the least-squares slope of
//! flux-linkage change against current change (the inductance).

use crate::transforms::sin_cos;

/// Arithmetic mean of a stream of samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mean {
    sum: f32,
    n: u32,
}

impl Mean {
    /// Adds one sample.
    #[inline]
    pub fn add(&mut self, x: f32) {
        self.sum += x;
        self.n += 1;
    }

    /// The mean (0 with no sample).
    pub fn value(&self) -> f32 {
        if self.n == 0 {
            0.0
        } else {
            self.sum / self.n as f32
        }
    }
}

/// Mean direction of angles, from the sum of their unit vectors (wrap-free: 359° and 1°
/// average to 0°, not 180°).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CircularMean {
    sin: f32,
    cos: f32,
}

impl CircularMean {
    /// Adds one angle. [rad]
    pub fn add(&mut self, theta: f32) {
        let sc = sin_cos(theta);
        self.sin += sc.sin;
        self.cos += sc.cos;
    }

    /// Adds the direction of another mean with equal weight.
    pub fn add_direction(&mut self, other: &CircularMean) {
        let r = libm::sqrtf(other.sin * other.sin + other.cos * other.cos);
        if r > 0.0 {
            self.sin += other.sin / r;
            self.cos += other.cos / r;
        }
    }

    /// The mean direction in (−π, π]. [rad]
    pub fn value(&self) -> f32 {
        libm::atan2f(self.sin, self.cos)
    }
}

/// Least-squares slope through the origin of y against x: the inductance L from segments
/// with flux-linkage change y = ∫(u − R·i)dt [V·s] and current change x [A] (eq. 2 at
/// standstill: u = R·i + L·di/dt, integrated over the segment).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SlopeFit {
    sxy: f32,
    sxx: f32,
}

impl SlopeFit {
    /// Adds one segment.
    #[inline]
    pub fn add(&mut self, x: f32, y: f32) {
        self.sxy += x * y;
        self.sxx += x * x;
    }

    /// The slope Σxy/Σx² (0 with no segment).
    pub fn value(&self) -> f32 {
        if self.sxx > 0.0 {
            self.sxy / self.sxx
        } else {
            0.0
        }
    }
}

/// Angle difference `a − b` wrapped into (−π, π]. [rad]
pub fn angle_difference(a: f32, b: f32) -> f32 {
    let sc = sin_cos(a - b);
    libm::atan2f(sc.sin, sc.cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circular_mean_across_the_wrap() {
        let mut m = CircularMean::default();
        // 359° and 1° (in rad): the mean is 0, not π.
        m.add(-0.017_453);
        m.add(0.017_453);
        assert!(m.value().abs() < 1e-3, "{}", m.value());
        let mut a = CircularMean::default();
        a.add(3.1);
        let mut b = CircularMean::default();
        b.add(-3.1);
        a.add_direction(&b);
        // 3.1 and −3.1 rad straddle π: the mean is π.
        assert!((a.value().abs() - core::f32::consts::PI).abs() < 2e-3);
    }

    #[test]
    fn slope_of_exact_segments_is_the_inductance() {
        // ψ = L·Δi with L = 12 mH for Δi = 4, −8, 4 A.
        let mut f = SlopeFit::default();
        for x in [4.0, -8.0, 4.0] {
            f.add(x, 12e-3 * x);
        }
        assert!((f.value() - 12e-3).abs() < 1e-8);
        assert!((angle_difference(0.1, 6.2) - (0.1 + core::f32::consts::TAU - 6.2)).abs() < 2e-3);
    }
}
