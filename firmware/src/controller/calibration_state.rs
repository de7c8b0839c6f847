//! Where the Calibrating sequence is (offsets, alignment, commissioning) and the running
//! mean of the phase-current ADC results the offsets come from.

/// A running mean of the three phase-current ADC results.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct OffsetAverage {
    n: u32,
    sums: [u32; 3],
}

impl OffsetAverage {
    /// Nothing summed yet.
    pub(super) const START: OffsetAverage = OffsetAverage { n: 0, sums: [0; 3] };

    /// Adds one sample; after `calls` samples returns their mean [counts] and starts again.
    pub(super) fn add(&mut self, adc: [u16; 3], calls: u32) -> Option<[f32; 3]> {
        for (s, a) in self.sums.iter_mut().zip(adc) {
            *s = s.saturating_add(u32::from(a));
        }
        self.n += 1;
        if self.n < calls {
            return None;
        }
        let n = self.n as f32;
        let mean = self.sums.map(|s| s as f32 / n);
        *self = OffsetAverage::START;
        Some(mean)
    }
}

/// Where the Calibrating sequence is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Calibration {
    /// Measuring the current offsets, bridge off.
    Offsets(OffsetAverage),
    /// Aligning the rotor, `n` periods so far.
    Align { n: u32 },
    /// Running the commissioning sequence ([`crate::commissioning`]).
    Commission,
}

impl Calibration {
    /// The start of the sequence.
    pub(super) const START: Calibration = Calibration::Offsets(OffsetAverage::START);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_comes_after_the_given_number_of_samples_and_restarts() {
        let mut a = OffsetAverage::START;
        assert_eq!(a.add([2000, 2050, 2100], 3), None);
        assert_eq!(a.add([2002, 2050, 2100], 3), None);
        assert_eq!(a.add([2004, 2050, 2103], 3), Some([2002.0, 2050.0, 2101.0]));
        assert_eq!(a, OffsetAverage::START);
    }
}
