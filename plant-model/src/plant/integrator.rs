//! The choice of integration scheme ([`Integrator`]: the exponential scheme of
//! [`super::exponential`] or classical RK4 of [`super::rk4`]) and the limits both share when
//! they locate switching events inside a step by regula falsi.

/// Events handled inside one step before the rest of it is taken plainly.
pub(super) const MAX_EVENTS_PER_STEP: usize = 6;
/// Most refinements of an event's time.
pub(super) const EVENT_REFINEMENTS: usize = 30;
/// Event time located to this fraction of a step (50 ps at 50 µs).
pub(super) const EVENT_TOLERANCE: f64 = 1e-6;

/// The integration scheme of [`super::Plant::advance`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Integrator {
    /// The default ([`super::exponential`] module): the winding currents and the port-A node
    /// with the absorber's inlet solved exactly over each step, the rest by second-order
    /// exponential Adams–Bashforth, one model evaluation per step.
    #[default]
    Exponential,
    /// Classical fourth-order Runge–Kutta over the whole state ([`super::rk4`] module),
    /// `substeps` equal steps per step of the rig (1: the plant's integrator before the
    /// exponential scheme; 4: the accuracy reference at a quarter of the step).
    Rk4 {
        /// Steps per step of the rig (1 to 64).
        substeps: u32,
    },
}

/// Most RK4 substeps per step of the rig.
pub(super) const MAX_SUBSTEPS: u32 = 64;

impl Integrator {
    /// The names [`Integrator::from_name`] takes, with what each is.
    pub const NAMES: [(&'static str, &'static str); 3] = [
        (
            "exponential",
            "exact linear blocks + exponential Adams–Bashforth 2, the default",
        ),
        ("rk4", "classical Runge–Kutta at the step of the rig"),
        (
            "rk4-quarter",
            "classical Runge–Kutta at a quarter of it, the accuracy reference",
        ),
    ];

    /// By name (one of [`Integrator::NAMES`]).
    pub fn from_name(name: &str) -> Option<Integrator> {
        match name {
            "exponential" => Some(Integrator::Exponential),
            "rk4" => Some(Integrator::Rk4 { substeps: 1 }),
            "rk4-quarter" => Some(Integrator::Rk4 { substeps: 4 }),
            _ => None,
        }
    }

    /// Its name: one of [`Integrator::NAMES`], or `rk4/N` for other substeps.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Exponential => "exponential",
            Integrator::Rk4 { substeps: 1 } => "rk4",
            Integrator::Rk4 { substeps: 4 } => "rk4-quarter",
            Integrator::Rk4 { .. } => "rk4/N",
        }
    }
}
