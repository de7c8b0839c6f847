//! How far a least-squares fit is driven: the optimiser's iterations per parameter (its
//! patience) and the relative reduction of the objective and of the step below which it
//! stops (its tolerance).
//!
//! The diagnosis fits in two kinds. Most fits only screen: calibrations and released fits
//! whose objectives are compared by the likelihood-ratio decision, against χ² thresholds
//! of 15–18 noise units on objectives of 10⁴–10⁵. Those stop at [`Effort::SCREENING`]. The
//! fits whose parameters are used — the baseline and the extended model the report predicts
//! with, a feed-forward learned from a log — are driven further, from where the screening
//! left them.
//!
//! The hydraulic relation's tolerance bands leave flat curved valleys (transducer gain
//! against displacement and volume) along which the optimiser creeps by hundredths of a
//! noise unit per iteration long after the decision is settled; how many iterations a
//! fit spends there varies several-fold with the last bits of the arithmetic, and with it
//! the diagnosis's time (`docs/diagnosis.md`, Speed).

/// The optimiser's patience and tolerance, and how it takes its Jacobians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effort {
    /// Iterations per free parameter in each search. [1]
    pub patience: usize,
    /// Relative reduction of the objective (and of the step) below which a search stops. [1]
    pub tolerance: f64,
    /// Whether the Jacobian may be carried between iterations by Broyden's update
    /// ([`crate::diagnose::secant`]) instead of differenced at each: for fits whose
    /// objectives only are compared, not their parameters reported.
    pub secant: bool,
}

impl Effort {
    /// The decision's fits: three hundred-thousandths of an objective of 10⁴–10⁵ noise
    /// units is 0.3–3 units, below the χ² thresholds the decision compares differences
    /// with; ten iterations per parameter bound the creep along the valleys, whose short
    /// steps take the Jacobian by Broyden's update between differencings.
    pub const SCREENING: Effort = Effort {
        patience: 10,
        tolerance: 3e-5,
        secant: true,
    };

    /// The fits the report predicts with, polished from the screening's end: a
    /// hundred-thousandth, 0.1–1 noise unit.
    pub const REPORTED: Effort = Effort {
        patience: 10,
        tolerance: 1e-5,
        secant: false,
    };

    /// The effort a fit stopped at this one is driven on to where its result decides or is
    /// reported: the reported effort after the screening, `None` for the others.
    pub fn refined(self) -> Option<Effort> {
        (self == Effort::SCREENING).then_some(Effort::REPORTED)
    }

    /// A fit whose parameters are used beyond the report (a feed-forward learned from
    /// them): the creep along the valleys followed to its end.
    pub const THOROUGH: Effort = Effort {
        patience: 25,
        tolerance: 1e-5,
        secant: false,
    };
}
