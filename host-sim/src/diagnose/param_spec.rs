//! A fitted parameter's search coordinate: the dimensionless u the least squares search
//! (the logarithm of the value's ratio to its nominal for positive quantities, a scaled
//! difference for signed ones), its hard bounds and tolerance band, its Gaussian prior, and
//! MINUIT's sine transform u = c + h·sin(v) that keeps the search within the bounds.

/// Offset of the optimiser's coordinates from the sine transform's: MINPACK sizes its first
/// trust region from the norm of the starting point, which at the centre of every range
/// would be zero and freeze the search. [rad]
const V_OFFSET: f64 = 2.0;

/// How a parameter's search coordinate maps to its value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scale {
    /// value = nominal·exp(u): positive quantities spanning decades.
    Log,
    /// value = nominal + unit·u: signed quantities.
    Linear {
        /// Value change per search unit. [unit]
        unit: f64,
    },
}

/// One fitted parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSpec {
    /// Name (for reports).
    pub name: &'static str,
    /// Value at u = 0. [unit]
    pub nominal: f64,
    /// Coordinate map.
    pub scale: Scale,
    /// Hard bounds on u.
    pub u_bounds: (f64, f64),
    /// Gaussian prior on u as (mean, standard deviation), or none (flat within bounds).
    pub prior: Option<(f64, f64)>,
    /// The tolerance band on u the bounds were narrowed to ([`ParamSpec::with_band`]), if
    /// any: the parameter's released fit is judged against it.
    pub band: Option<(f64, f64)>,
    /// Start of the search in u.
    pub start: f64,
}

impl ParamSpec {
    /// The value at coordinate `u`. [unit]
    pub fn value(&self, u: f64) -> f64 {
        match self.scale {
            Scale::Log => self.nominal * u.exp(),
            Scale::Linear { unit } => self.nominal + unit * u,
        }
    }

    /// The coordinate of `value`.
    pub fn coordinate(&self, value: f64) -> f64 {
        match self.scale {
            Scale::Log => (value / self.nominal).ln(),
            Scale::Linear { unit } => (value - self.nominal) / unit,
        }
    }

    /// A positive parameter searched in logarithm, within `[lo, hi]` times nominal.
    pub fn log(name: &'static str, nominal: f64, lo: f64, hi: f64) -> ParamSpec {
        ParamSpec {
            name,
            nominal,
            scale: Scale::Log,
            u_bounds: (lo.ln(), hi.ln()),
            prior: None,
            band: None,
            start: 0.0,
        }
    }

    /// A signed parameter searched linearly in units of `unit`, within `[lo, hi]` (values).
    pub fn linear(name: &'static str, nominal: f64, unit: f64, lo: f64, hi: f64) -> ParamSpec {
        ParamSpec {
            name,
            nominal,
            scale: Scale::Linear { unit },
            u_bounds: ((lo - nominal) / unit, (hi - nominal) / unit),
            prior: None,
            band: None,
            start: 0.0,
        }
    }

    /// Held within a tolerance band `[lo, hi]` (values): the bounds narrowed to it, flat
    /// within (every tolerance combination equally likely a priori), the start inside it.
    pub fn with_band(mut self, lo: f64, hi: f64) -> ParamSpec {
        let (a, b) = (self.coordinate(lo), self.coordinate(hi));
        let (a, b) = (a.min(b), a.max(b));
        let (lo_u, hi_u) = self.u_bounds;
        self.u_bounds = (a.max(lo_u), b.min(hi_u).max(a.max(lo_u)));
        self.band = Some((a, b));
        self.start = self.start.clamp(self.u_bounds.0, self.u_bounds.1);
        self
    }

    /// With a Gaussian prior on u of mean `mean` and standard deviation `sd`.
    pub fn with_prior(mut self, mean: f64, sd: f64) -> ParamSpec {
        self.prior = Some((mean, sd.max(1e-12)));
        self
    }

    /// Starting at `value`.
    pub fn starting_at(mut self, value: f64) -> ParamSpec {
        self.start = self.coordinate(value);
        self
    }

    fn centre(&self) -> (f64, f64) {
        let (lo, hi) = self.u_bounds;
        (0.5 * (lo + hi), 0.5 * (hi - lo))
    }

    pub(crate) fn u_of_v(&self, v: f64) -> f64 {
        let (c, h) = self.centre();
        c + h * (v - V_OFFSET).sin()
    }

    pub(crate) fn v_of_u(&self, u: f64) -> f64 {
        let (c, h) = self.centre();
        if h <= 0.0 {
            return V_OFFSET;
        }
        ((u - c) / h).clamp(-1.0, 1.0).asin() + V_OFFSET
    }
}
