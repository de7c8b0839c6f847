//! What the exponential integrator carries from step to step: the rates at the present
//! state, their divided differences over the last two steps and the quadratic extrapolation
//! they give (Newton's divided differences on the actual step lengths), the hydraulic block's
//! matrix functions with what they were built for, the winding's constants and the gases'
//! polytropic series.

use super::blocks::Phi;
use super::gas::GasSeries;
use super::rates::Rates;

/// What the integrator carries from step to step.
#[derive(Clone, Debug, Default)]
pub(in crate::plant) struct History {
    /// The rates at the present state, with the bridge enable and the hydraulic block they
    /// were taken for (every change of the state outside a step resets them).
    pub(super) now: Option<Now>,
    /// The divided difference of the rates over the last step and its length; `None`: the
    /// next step restarts.
    pub(super) last: Option<(Rates, f64)>,
    /// The same over the step before.
    pub(super) before: Option<(Rates, f64)>,
    /// The hydraulic block's matrix functions.
    pub(super) block: Option<HydroBlock>,
    /// The winding's constants.
    pub(super) winding: WindingConsts,
    /// The polytropic series' coefficients of the absorber's and the fill accumulator's gas.
    pub(super) gas: [GasSeries; 2],
}

/// The winding's constants, computed once.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct WindingConsts {
    /// 1/L_d, 1/L_q. [1/H]
    pub(super) inv_l: [f64; 2],
    /// L_q/L_d, −L_d/L_q. [1]
    pub(super) coupling: [f64; 2],
    /// −R/L_d, −R/L_q. [1/s]
    pub(super) decay: [f64; 2],
    /// The fastest the series sees from resistance, with the dead time's band:
    /// (R + r_band)·max(1/L). [1/s]
    pub(super) nu_r: f64,
    /// max(L_q/L_d, L_d/L_q). [1]
    pub(super) nu_w: f64,
}

#[derive(Clone, Copy, Debug)]
pub(super) struct Now {
    pub(super) rates: Rates,
    pub(super) enabled: bool,
    pub(super) key: BlockKey,
}

/// What the hydraulic block is built for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct BlockKey {
    /// β/V_1 and β/V_2. [Pa/m³]
    pub(super) k: [f64; 2],
    /// The absorber's poppet open.
    pub(super) open: bool,
    /// The piston free to move (not blocked, not stuck): the 4×4 block, else the 2×2.
    pub(super) free: bool,
}

/// The hydraulic block's matrix functions.
// Held once, in the history; boxing the larger variant would need an allocator, which this
// `no_std` crate does without.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub(super) enum BlockPhi {
    /// (p_A, q).
    Two(Phi<2>),
    /// (p_A, q, p_B, v).
    Four(Phi<4>),
}

#[derive(Clone, Copy, Debug)]
pub(super) struct HydroBlock {
    pub(super) key: BlockKey,
    /// Its step. [s]
    pub(super) tau: f64,
    pub(super) phi: BlockPhi,
}

impl History {
    /// A history for a plant with `motor` driven by `inverter` and gases of `gas_exponents`
    /// (the absorber's, the fill accumulator's), empty.
    pub(in crate::plant) fn new(
        motor: &crate::motor::Motor,
        inverter: &crate::inverter::Inverter,
        gas_exponents: [f64; 2],
    ) -> Self {
        let inv_l = [1.0 / motor.l_d_h, 1.0 / motor.l_q_h];
        let coupling = [motor.l_q_h / motor.l_d_h, -motor.l_d_h / motor.l_q_h];
        let band = if inverter.has_dead_time() {
            inverter.dead_time_parts(&[0.0; 3]).1
        } else {
            0.0
        };
        History {
            winding: WindingConsts {
                inv_l,
                coupling,
                decay: [-motor.r_s_ohm * inv_l[0], -motor.r_s_ohm * inv_l[1]],
                nu_r: (motor.r_s_ohm + band) * inv_l[0].max(inv_l[1]),
                nu_w: coupling[0].max(-coupling[1]),
            },
            gas: gas_exponents.map(GasSeries::new),
            ..History::default()
        }
    }

    /// Forgets the rates and their slope (the state changed from outside).
    pub(in crate::plant) fn reset(&mut self) {
        self.now = None;
        self.last = None;
        self.before = None;
    }

    /// The extrapolation's coefficients from the history, if there is any.
    pub(super) fn poly(&self) -> Option<Poly> {
        let (d1, h1) = self.last?;
        Some(match self.before {
            // g(t) = g_0 + d1·t + dd·t·(t + h1), dd the second divided difference.
            Some((d0, h0)) => {
                let inv = 1.0 / (h1 + h0);
                let dd = d1.map2(&d0, |a, b| (a - b) * inv);
                Poly {
                    g1: d1.map2(&dd, |a, b| a + b * h1),
                    g2: dd,
                }
            }
            None => Poly {
                g1: d1,
                g2: Rates::default(),
            },
        })
    }

    /// Takes a step of `tau` from rates `g0` to `g1` into the history.
    pub(super) fn push(&mut self, g0: &Rates, g1: &Rates, tau: f64) {
        self.before = self.last;
        let inv = 1.0 / tau;
        self.last = Some((g1.map2(g0, |a, b| (a - b) * inv), tau));
    }
}

/// The linear and quadratic coefficients of the rates' extrapolation over a segment.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Poly {
    pub(super) g1: Rates,
    pub(super) g2: Rates,
}

/// The quadratic g(0) + g_1·t + g_2·t² through rates `g0`, `ga`, `gb` at 0, τ/2 and τ.
pub(super) fn quadratic(g0: &Rates, ga: &Rates, gb: &Rates, tau: f64) -> Poly {
    let d1 = ga.map2(g0, |a, b| (a - b) / (0.5 * tau));
    let d2 = gb.map2(ga, |a, b| (a - b) / (0.5 * tau));
    let g2 = d2.map2(&d1, |a, b| (a - b) / tau);
    Poly {
        g1: d1.map2(&g2, |a, b| a - b * 0.5 * tau),
        g2,
    }
}
