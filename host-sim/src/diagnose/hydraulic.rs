//! The hydraulic parity relation: the port pressure predicted from the logged shaft angle
//! (the volume the pump displaced), piston position and low-side pressure, over short
//! windows each re-started from the measured pressure (multiple shooting), so a small
//! volume or displacement error cannot integrate into a drift. On a moving piston the same
//! balance is read for the position instead ([`stroke`]).
//!
//! The high-pressure node (port A, its line and chamber A) with the pulsation absorber on
//! it, eq. 9–11 and 22–26 of the paper as the plant model writes them:
//!
//! ```text
//!   (V_h + A·x)/β · dp/dt = D/2π·s(θ)·ω − G_pp·(p − p_low) − (G − G_pp)·(p − p_c) − A·dx/dt − q
//!   I·dq/dt = p − p_gas(v) − R·q,        dv/dt = q        (absorber inlet and gas)
//!   p_meas = g·p_s + o,                 τ·dp_s/dt = p − p_s   (transducer)
//! ```
//!
//! with V_h the high-side volume at mid-stroke (chamber and line), G the total leakage from
//! the high side (eq. 9–10): G_pp of it from port to port (the pump's internal leakage and
//! the cylinder's cross-piston leakage) towards the low side's pressure p_low, the rest
//! (the pump's external leakage and any extra) to the case at the fill pressure p_c — a
//! low side pressurised by a reversing pump on a blocked cylinder feeds the port through
//! the first path only; the case's pressure is the fill's, which the logged low side
//! measures while it sits there. G_pp is a share of G while G stays within its tolerance
//! band ([`LEAKAGE_BAND`]) and that share of the band's top beyond it: an extra leakage
//! drains to the case, as the catalogue's does. The share is the rig file's unless the
//! log's low side departs from the fill, which alone tells the two paths apart. s(θ) the
//! pump's displacement factor (eq. 20, the plant's [`Pump`]), p_gas the polytropic gas law
//! of the plant's [`GasCharge`] (no flow into an empty absorber below its precharge).
//!
//! Each log interval is cut into substeps of at most [`MAX_SUBSTEP_S`], each solved with
//! the backward Euler rule linearised about the gas state, closed form, the absorber's
//! poppet opening and closing located inside the substep ([`node`]): the oil's
//! compliance against the inlet resistance is a time constant of tens of microseconds,
//! which an explicit rule could only follow with microsecond steps. The transducer is
//! stepped exactly for the pressure moving linearly over the substep
//! ([`crate::diagnose::intervals`]), so its reading trails a ramp by the ramp's rate
//! times τ, not by half a substep less.
//!
//! Window starts (multiple shooting): the transducer's state and the pressure's slope from a
//! straight line through the window's first [`START_S`] of measured rows; the true pressure
//! the one whose prediction fits the window best in least squares (the window is nearly
//! linear in it: two runs give the sensitivity); the absorber in equilibrium with it and
//! filling at the slope.

use crate::diagnose::facts::{rows_spanning, LogFacts, LowSide};
use crate::diagnose::intervals::{Interval, Intervals};
use plant_model::accumulator::{GasCharge, ATMOSPHERE_PA};
use plant_model::pump::Pump;
use plant_model::Rig;
use std::f64::consts::PI;
use std::ops::Range;

mod node;
mod stroke;

/// Longest integration substep. [s]
pub const MAX_SUBSTEP_S: f64 = 0.5e-3;

/// Share by which a log interval may exceed a whole number of [`MAX_SUBSTEP_S`] and still
/// be cut into that number of substeps. A logged time column's intervals differ in their
/// last bits (a 1 kHz log's 1 ms read back as 1.000000000001 ms on about every other row):
/// counted from those bits, such a row took three substeps and its neighbour two, so the
/// work and the integration error alternated with the rounding of the time stamps. [1]
pub const SUBSTEP_SLACK: f64 = 1e-6;

/// Span of the measured rows a window's starting pressure and slope are fitted to (ten
/// rows of a 1 kHz log): a span in time, so a faster log's noise does not tilt the slope
/// that starts the transducer and the absorber's inlet. [s]
pub const START_S: f64 = 10e-3;

/// The hydraulic model's parameters (SI).
#[derive(Clone, Debug)]
pub struct HydraulicParams {
    /// Pump displacement D. [m³/rev]
    pub displacement_m3_per_rev: f64,
    /// High-side oil volume at mid-stroke, V_h (chamber A and line). [m³]
    pub high_side_volume_m3: f64,
    /// Effective bulk modulus β. [Pa]
    pub bulk_modulus_pa: f64,
    /// Piston area A. [m²]
    pub area_m2: f64,
    /// Absorber gas charge, `None` without an absorber.
    pub absorber: Option<GasCharge>,
    /// Absorber inlet inertance I. [kg/m⁴]
    pub inlet_inertance_kg_m4: f64,
    /// Absorber inlet resistance R. [Pa·s/m³]
    pub inlet_resistance_pa_s_m3: f64,
    /// Total leakage conductance from the high side, G. [(m³/s)/Pa]
    pub leakage_m3_s_pa: f64,
    /// The port-to-port part's share of G within the band. [1]
    pub port_to_port_share: f64,
    /// The top of G's tolerance band, beyond which the port-to-port part stays put.
    /// [(m³/s)/Pa]
    pub leakage_top_m3_s_pa: f64,
    /// Transducer gain g. [1]
    pub sensor_gain: f64,
    /// Transducer offset o. [Pa]
    pub sensor_offset_pa: f64,
    /// Transducer time constant τ. [s]
    pub sensor_lag_s: f64,
    /// Pump pistons z and peak-to-peak flow ripple over mean flow (0: ideal flow).
    pub ripple: (u32, f64),
}

impl HydraulicParams {
    /// The rig file's values.
    pub fn nominal(rig: &Rig) -> HydraulicParams {
        let a = &rig.absorber;
        let port_to_port =
            rig.pump.internal_leakage_m3_s_pa + rig.cylinder.internal_leakage_m3_s_pa;
        let leakage = nominal_leakage(rig);
        HydraulicParams {
            displacement_m3_per_rev: rig.pump.displacement_m3_per_rev,
            high_side_volume_m3: rig.cylinder.chamber_a_volume_m3,
            bulk_modulus_pa: rig.oil.bulk_modulus_pa,
            area_m2: rig.cylinder.area_m2,
            absorber: a.enabled.then_some(GasCharge {
                shell_volume_m3: a.shell_volume_m3,
                precharge_pa: a.precharge_pa,
                exponent: a.polytropic_exponent,
            }),
            inlet_inertance_kg_m4: a.inlet_inertance_kg_m4,
            inlet_resistance_pa_s_m3: a.inlet_resistance_pa_s_m3,
            leakage_m3_s_pa: leakage,
            port_to_port_share: if leakage > 0.0 {
                port_to_port / leakage
            } else {
                0.0
            },
            leakage_top_m3_s_pa: leakage * LEAKAGE_BAND.1,
            sensor_gain: 1.0,
            sensor_offset_pa: rig.sensors.pressure.offset_pa,
            sensor_lag_s: rig.sensors.pressure.lag_time_constant_s,
            ripple: (
                rig.pump.pistons,
                if rig.pump.piston_ripple {
                    if rig.pump.ripple_amplitude_ratio > 0.0 {
                        rig.pump.ripple_amplitude_ratio
                    } else {
                        plant_model::pump::kinematic_ripple_ratio(rig.pump.pistons)
                    }
                } else {
                    0.0
                },
            ),
        }
    }
}

/// Tolerance band of the total leakage as fractions of the rig file's. [1]
pub const LEAKAGE_BAND: (f64, f64) = (0.8, 1.2);

/// The rig file's total leakage from the high side of a blocked cylinder: the pump's
/// internal and external leakage and the cylinder's cross-piston leakage. [(m³/s)/Pa]
pub fn nominal_leakage(rig: &Rig) -> f64 {
    rig.pump.internal_leakage_m3_s_pa
        + rig.pump.external_leakage_m3_s_pa
        + rig.pump.extra_leakage_m3_s_pa
        + rig.cylinder.internal_leakage_m3_s_pa
}

/// The logged signals the hydraulic model reads.
#[derive(Clone, Copy, Debug)]
pub struct HydraulicInputs<'a> {
    /// Time. [s]
    pub t_s: &'a [f64],
    /// Shaft angle, unwrapped. [rad]
    pub theta_rad: &'a [f64],
    /// Low-side pressure. [Pa]
    pub p_low_pa: LowSide<'a>,
    /// The case's pressure p_c the leakage's other path drains to: the fill's, which the
    /// logged low side measures while it sits there ([`LogFacts::low_side_apart`]). [Pa]
    pub case_pa: LowSide<'a>,
    /// Piston position, when it moves. [m]
    pub x_m: Option<&'a [f64]>,
    /// Measured pressure (window starts). [Pa]
    pub p_pa: &'a [f64],
    /// Measured pressure smoothed, when the piston moves ([`LogFacts::p_smooth_pa`]). [Pa]
    pub p_smooth_pa: Option<&'a [f64]>,
    /// Rows a window's start is fitted to ([`START_S`] at the log's sampling).
    pub start_rows: usize,
    /// The fill level the port's check valve holds it above, as the transducer reads it. [Pa]
    pub fill_pa: f64,
    /// The fill level row by row where it moves ([`LogFacts::fill_track_pa`]), in place of
    /// `fill_pa`. [Pa]
    pub fill_track_pa: Option<&'a [f64]>,
}

impl<'a> HydraulicInputs<'a> {
    /// The inputs of `log` with its `facts`.
    pub fn of(log: &'a crate::bench_log::BenchLog, facts: &'a LogFacts) -> HydraulicInputs<'a> {
        HydraulicInputs {
            t_s: &log.t_s,
            theta_rad: &facts.theta_rad,
            p_low_pa: facts.p_low(log),
            case_pa: if facts.low_side_apart {
                LowSide::Level(facts.fill_low_pa)
            } else {
                facts.p_low(log)
            },
            x_m: facts.x_smooth_m.as_deref(),
            p_pa: &log.p_pa,
            p_smooth_pa: facts.p_smooth_pa.as_deref(),
            start_rows: rows_spanning(START_S, facts.period_s, 2),
            // The check valve opens only where the port is the suction side: a moving
            // payload's, or a blocked cylinder's whose pump reverses into a low side it
            // pressurises. Elsewhere a blocked cylinder's port stays above the fill, and
            // there the floor would only bend the windows' start, fitted as if linear.
            fill_pa: if facts.piston_moves || facts.low_side_apart {
                facts.fill_pa
            } else {
                f64::NEG_INFINITY
            },
            fill_track_pa: facts.fill_track_pa.as_deref(),
        }
    }
}

/// State of the high-pressure node.
#[derive(Clone, Copy, Debug)]
struct State {
    /// Port pressure. [Pa]
    p: f64,
    /// Absorber inlet flow. [m³/s]
    q: f64,
    /// Oil in the absorber. [m³]
    v: f64,
    /// Absolute gas pressure in the absorber, integrated in the gas law's rate form
    /// dp_g = n·p_g·dv/V_g (the plant's [`GasCharge::pressure_rate`]; no power per step). [Pa]
    g: f64,
    /// Transducer state. [Pa]
    s: f64,
}

/// Substeps a log interval of `dt` [s] is cut into: the fewest of at most
/// [`MAX_SUBSTEP_S`], give or take [`SUBSTEP_SLACK`].
fn substeps(dt: f64) -> usize {
    ((dt / MAX_SUBSTEP_S * (1.0 - SUBSTEP_SLACK)).ceil() as usize).max(1)
}

/// Intercept at the first row and slope of a straight line through `y` against `t`.
fn line_start(t: &[f64], y: &[f64]) -> (f64, f64) {
    let n = t.len().min(y.len());
    if n < 2 {
        return (y.first().copied().unwrap_or(0.0), 0.0);
    }
    let t0 = t[0];
    let (mut st, mut sy, mut stt, mut sty) = (0.0, 0.0, 0.0, 0.0);
    for k in 0..n {
        let x = t[k] - t0;
        st += x;
        sy += y[k];
        stt += x * x;
        sty += x * y[k];
    }
    let nf = n as f64;
    let den = nf * stt - st * st;
    if den <= 0.0 {
        return (sy / nf, 0.0);
    }
    let slope = (nf * sty - st * sy) / den;
    ((sy - slope * st) / nf, slope)
}

/// A prepared model: the parameters with the pump's ripple tables built once.
pub struct Hydraulics {
    params: HydraulicParams,
    pump: Pump,
    /// The leakage's port-to-port part G_pp. [(m³/s)/Pa]
    port_to_port: f64,
}

impl Hydraulics {
    /// Prepares `params` on `rig` (for the pump's geometry).
    pub fn new(params: HydraulicParams, rig: &Rig) -> Hydraulics {
        let mut pp = rig.pump.clone();
        pp.pistons = params.ripple.0.max(1);
        pp.piston_ripple = params.ripple.1 > 0.0;
        pp.ripple_amplitude_ratio = params.ripple.1;
        let g = params.leakage_m3_s_pa;
        Hydraulics {
            pump: Pump::new(&pp),
            port_to_port: params.port_to_port_share * g.min(params.leakage_top_m3_s_pa),
            params,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &HydraulicParams {
        &self.params
    }

    /// Predicts the measured pressure over each of `windows`, written into `out` at the
    /// windows' rows (the other rows untouched).
    pub fn predict(&self, inputs: &HydraulicInputs<'_>, windows: &[Range<usize>], out: &mut [f64]) {
        for w in windows {
            self.predict_window(inputs, w.clone(), &mut out[w.clone()]);
        }
    }

    /// Predicts the measured pressure over the window `rows` into `out`, row `rows.start + i`
    /// at index i.
    pub fn predict_window(&self, x: &HydraulicInputs<'_>, rows: Range<usize>, out: &mut [f64]) {
        let hp = &self.params;
        let head = rows.start..(rows.start + x.start_rows).min(rows.end);
        let (s0, slope) = line_start(&x.t_s[head.clone()], &x.p_pa[head]);
        let gain = hp.sensor_gain.max(1e-6);
        let s_true = (s0 - hp.sensor_offset_pa) / gain;
        let guess = s_true + hp.sensor_lag_s * slope / gain;
        // Multiple shooting: the window's initial pressure is the least-squares one, found
        // from the response to a small change of it (the window is nearly linear in it).
        let n = rows.len();
        let mut a = vec![0.0; n];
        let mut b = vec![0.0; n];
        let delta = 1e3;
        self.simulate_window(
            x,
            rows.clone(),
            [guess, guess + delta],
            s_true,
            slope / gain,
            [&mut a, &mut b],
        );
        let (mut num, mut den) = (0.0, 0.0);
        for k in rows.start + 1..rows.end {
            let i = k - rows.start;
            let g = (b[i] - a[i]) / delta;
            num += g * (x.p_pa[k] - a[i]);
            den += g * g;
        }
        let shift = if den > 0.0 { num / den } else { 0.0 };
        for k in rows.clone() {
            let i = k - rows.start;
            out[i] = a[i] + shift * (b[i] - a[i]) / delta;
        }
    }

    /// The measured pressure over `rows` from each of the true pressures `p0` and
    /// transducer state `s0` at the first row, the pressure rising at `slope` there, into
    /// the matching `out` (row i of the window at index i). The runs share the inputs'
    /// work (pump flow, volume, transducer factor) and step side by side.
    fn simulate_window<const N: usize>(
        &self,
        x: &HydraulicInputs<'_>,
        rows: Range<usize>,
        p0: [f64; N],
        s0: f64,
        slope: f64,
        out: [&mut [f64]; N],
    ) {
        let hp = &self.params;
        let mut st = p0.map(|p0| self.start_state(p0, s0, slope));
        let ripple = hp.ripple.1 > 0.0;
        let gain = hp.sensor_gain;
        let mut out = out;
        for (o, st) in out.iter_mut().zip(&st) {
            o[0] = gain * st.s + hp.sensor_offset_pa;
        }
        let per_rad = hp.displacement_m3_per_rev / (2.0 * PI);
        // The check valve from the fill holds the port at the fill level: the transducer's
        // reading of it in true pressure.
        let floor_at = |k: usize| {
            let fill = x.fill_track_pa.map_or(x.fill_pa, |f| f[k]);
            (fill - hp.sensor_offset_pa) / gain.max(1e-6)
        };
        // Each log interval's substeps and the transducer's factors over them.
        let mut intervals = Intervals::new(hp.sensor_lag_s, substeps);
        for k in rows.start..rows.end.saturating_sub(1) {
            let next = k + 1;
            let dt = x.t_s[next] - x.t_s[k];
            let interval = intervals.at(dt);
            let steps = interval.steps;
            let dtheta = x.theta_rad[next] - x.theta_rad[k];
            let (x0, dx) = match x.x_m {
                Some(xm) => (xm[k], xm[next] - xm[k]),
                None => (0.0, 0.0),
            };
            let (p_low, p_case) = (x.p_low_pa.at(k), x.case_pa.at(k));
            // Flow into the node over a substep: pump minus piston, as a mean [m³/s]; and
            // the oil's capacitance at the piston's position [m³/Pa]. Both are the row's
            // own unless the pump ripples or the piston moves.
            let q_at = |factor: f64| (per_rad * factor * dtheta - hp.area_m2 * dx) / dt;
            let c_at = |f: f64| {
                let volume = hp.high_side_volume_m3 + hp.area_m2 * (x0 + f * dx);
                volume.max(1e-9) / hp.bulk_modulus_pa
            };
            let uniform = !ripple && dx == 0.0;
            let row = (q_at(1.0), c_at(0.0));
            let floor = floor_at(k);
            for j in 0..steps {
                let (q_in, c_oil) = if uniform {
                    row
                } else {
                    let f = (j as f64 + 0.5) / steps as f64;
                    let factor = if ripple {
                        self.pump.displacement_factor(x.theta_rad[k] + f * dtheta)
                    } else {
                        1.0
                    };
                    (q_at(factor), c_at(f))
                };
                for st in st.iter_mut() {
                    self.substep(st, &interval, [q_in, p_low, p_case, floor], c_oil);
                }
            }
            for (o, st) in out.iter_mut().zip(&st) {
                o[next - rows.start] = gain * st.s + hp.sensor_offset_pa;
            }
        }
    }

    /// The node at a window's start: true pressure `p0`, transducer at `s0`, the absorber
    /// in equilibrium with `p0` and filling at the pressure's `slope`.
    fn start_state(&self, p0: f64, s0: f64, slope: f64) -> State {
        let hp = &self.params;
        let (v0, q0) = match &hp.absorber {
            Some(g) => (g.oil_volume_m3(p0), g.capacitance_m3_per_pa(p0) * slope),
            None => (0.0, 0.0),
        };
        let g0 = match &hp.absorber {
            Some(g) if v0 > 0.0 => g.pressure_pa(v0) + ATMOSPHERE_PA,
            Some(g) => g.precharge_abs_pa(),
            None => ATMOSPHERE_PA,
        };
        State {
            p: p0,
            q: q0,
            v: v0,
            g: g0,
            s: s0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model run open-loop from pressure `p0` (transducer settled there, no slope).
    fn open_loop(hp: &HydraulicParams, t: &[f64], th: &[f64], p_low: f64, p0: f64) -> Vec<f64> {
        let n = t.len();
        let pl = vec![p_low; n];
        let p = vec![p0; n];
        let inputs = HydraulicInputs {
            t_s: t,
            theta_rad: th,
            p_low_pa: LowSide::Logged(&pl),
            case_pa: LowSide::Level(0.5e6),
            x_m: None,
            p_pa: &p,
            p_smooth_pa: None,
            start_rows: 10,
            fill_pa: 0.0,
            fill_track_pa: None,
        };
        let mut out = vec![0.0; n];
        Hydraulics::new(hp.clone(), &Rig::nominal()).simulate_window(
            &inputs,
            0..n,
            [p0],
            p0,
            0.0,
            [&mut out],
        );
        out
    }

    #[test]
    fn a_logged_time_column_is_cut_into_the_same_substeps_on_every_row() {
        // Time stamps written to a tenth of a microsecond and read back, at 500 Hz, 1, 2
        // and 10 kHz: their differences scatter in the last bits around 2, 1, 0.5 and
        // 0.1 ms, and every row takes the 4, 2, 1 and 1 substeps of at most 0.5 ms the
        // nominal interval needs.
        for (rate, expected) in [(500.0, 4), (1e3, 2), (2e3, 1), (1e4, 1)] {
            let t: Vec<f64> = (0..20_000)
                .map(|k| format!("{:.7}", k as f64 / rate).parse().unwrap())
                .collect();
            let counts: Vec<usize> = t.windows(2).map(|w| substeps(w[1] - w[0])).collect();
            assert!(
                t.windows(2).any(|w| w[1] - w[0] > 1.0 / rate),
                "{rate} Hz: no interval above the nominal one to try"
            );
            assert!(counts.iter().all(|&c| c == expected), "{rate} Hz");
        }
        // An interval a part in ten thousand over whole substeps takes one more.
        assert_eq!(substeps(1.0001e-3), 3);
        assert_eq!(substeps(1.5e-3), 3);
    }

    #[test]
    fn oil_alone_is_compressed_by_the_displaced_volume_over_its_capacitance() {
        // No absorber, no leakage: Δp = D/2π·Δθ·β/V, exactly (the capacitance is constant).
        let rig = Rig::nominal();
        let mut hp = HydraulicParams::nominal(&rig);
        hp.absorber = None;
        hp.leakage_m3_s_pa = 0.0;
        let n = 500;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t.iter().map(|t| 20.0 * t).collect();
        let out = open_loop(&hp, &t, &th, 0.5e6, 1e6);
        let dv = 1.5e-6 / (2.0 * PI) * th[n - 1];
        let expected = 1e6 + dv * 6.5e8 / 450e-6;
        assert!(
            (out[n - 1] - expected).abs() < 1e-6 * expected,
            "{} vs {expected}",
            out[n - 1]
        );
    }

    #[test]
    fn a_hold_with_the_pump_replacing_the_leakage_stays_put() {
        // The pump turns at ω = 2π·G·(p − p_low)/D: the pressure holds at any absorber state.
        let rig = Rig::nominal();
        let hp = HydraulicParams::nominal(&rig);
        let (p0, pl) = (5e6, 0.5e6);
        let w = 2.0 * PI * hp.leakage_m3_s_pa * (p0 - pl) / hp.displacement_m3_per_rev;
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t.iter().map(|t| w * t).collect();
        let out = open_loop(&hp, &t, &th, pl, p0);
        for y in &out {
            assert!((y - p0).abs() < 10.0, "{y}");
        }
    }

    #[test]
    fn a_pressurised_low_side_feeds_the_port_through_the_port_to_port_path_only() {
        // The nominal rig's leakages (nominal-rig.md): pump internal and cylinder
        // cross-piston 1e-13 (m³/s)/Pa each from port to port, the pump's external 1e-13 to
        // the case at the 0.5 MPa fill. A port held at 2.65 MPa against a low side at
        // 15 MPa gains 2e-13·12.35e6 − 1e-13·2.15e6 = 2.255e-6 m³/s, which a pump turning
        // backwards at ω = −2π·2.255e-6/D takes away: the pressure holds.
        let rig = Rig::nominal();
        let hp = HydraulicParams::nominal(&rig);
        let (p0, pl) = (2.65e6, 15e6);
        let w = -2.0 * PI * 2.255e-6 / rig.pump.displacement_m3_per_rev;
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t.iter().map(|t| w * t).collect();
        let out = open_loop(&hp, &t, &th, pl, p0);
        for y in &out {
            assert!((y - p0).abs() < 10.0, "{y}");
        }
    }

    /// The rig file's model sealed (no leakage), and its absorber's gas charge.
    fn sealed() -> (HydraulicParams, GasCharge) {
        let mut hp = HydraulicParams::nominal(&Rig::nominal());
        hp.leakage_m3_s_pa = 0.0;
        let gas = hp.absorber.expect("the rig file's absorber");
        (hp, gas)
    }

    /// Oil stored in the sealed node between pressures `p0` and `p` by the volume balance:
    /// the oil's compression plus the absorber's gas-law volume (eq. 22). [m³]
    fn stored(hp: &HydraulicParams, gas: &GasCharge, p0: f64, p: f64) -> f64 {
        (p - p0) * hp.high_side_volume_m3 / hp.bulk_modulus_pa + gas.oil_volume_m3(p)
            - gas.oil_volume_m3(p0)
    }

    #[test]
    fn above_precharge_the_absorber_adds_the_gas_law_capacitance() {
        // Quasi-static filling from 4 to ~4.2 MPa: the volume displaced equals the oil
        // compressed plus the absorber's gas-law volume change (eq. 22), to 1 %.
        let (hp, gas) = sealed();
        let n = 3000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        // 2 mL over 3 s.
        let per_rad = 1.5e-6 / (2.0 * PI);
        let w = 2e-6 / 3.0 / per_rad;
        let th: Vec<f64> = t.iter().map(|t| w * t).collect();
        let out = open_loop(&hp, &t, &th, 0.5e6, 4e6);
        let stored = stored(&hp, &gas, 4e6, out[n - 1]);
        let displaced = per_rad * th[n - 1];
        assert!(
            (stored / displaced - 1.0).abs() < 0.01,
            "{stored} vs {displaced}"
        );
    }

    #[test]
    fn an_absorber_drawn_empty_returns_no_more_oil_than_it_held() {
        // The pump draws 14 mL/s from a port at 3.05 MPa, just above the 3 MPa precharge:
        // the absorber gives its oil up (eq. 22), empties near 0.33 s and the oil alone
        // carries the fall from there. By the volume balance, at every row the displaced
        // volume equals the oil's compression plus the absorber's gas-law volume,
        // C_oil·(p − p0) + V_abs(p) − V_abs(p0) = −Q·t, solved for p by bisection. The
        // inlet's resistance holds the pressure R·Q = 420 Pa off that quasi-static curve
        // while the absorber flows and the inertance starts that flow; once shut, the
        // curve is exact.
        let (hp, gas) = sealed();
        let per_rad = hp.displacement_m3_per_rev / (2.0 * PI);
        let q = 1.4e-5;
        let n = 401;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t.iter().map(|t| -q / per_rad * t).collect();
        let p0 = 3.05e6;
        let out = open_loop(&hp, &t, &th, 0.5e6, p0);
        let exact = |t: f64| {
            let (mut lo, mut hi) = (0.0, p0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if stored(&hp, &gas, p0, mid) > -q * t {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            0.5 * (lo + hi)
        };
        let empty = t.iter().position(|&t| exact(t) < gas.precharge_pa).unwrap();
        assert!(
            (300..380).contains(&empty) && out[n - 1] < 2.5e6,
            "the test's premise: emptied at row {empty}, ends at {}",
            out[n - 1]
        );
        for k in 20..n {
            let bound = if k < empty + 5 { 600.0 } else { 100.0 };
            let e = out[k] - exact(t[k]);
            assert!(e.abs() < bound, "t {:.3} s: {:.0} Pa off", t[k], e);
        }
    }

    #[test]
    fn the_transducer_lags_a_ramp_by_its_time_constant() {
        // A pressure ramp of rate r seen through a first-order lag τ trails by r·τ (the
        // substeps' 0.5 ms would take h/2 = 2.5 % off it if the pressure were held over
        // each).
        let rig = Rig::nominal();
        let mut hp = HydraulicParams::nominal(&rig);
        hp.absorber = None;
        hp.leakage_m3_s_pa = 0.0;
        let n = 400;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t.iter().map(|t| 2.0 * t).collect();
        let ideal = open_loop(&hp, &t, &th, 0.5e6, 1e6);
        hp.sensor_lag_s = 0.01;
        let lagged = open_loop(&hp, &t, &th, 0.5e6, 1e6);
        let rate = 1.5e-6 / (2.0 * PI) * 2.0 * 6.5e8 / 450e-6;
        let trail = ideal[n - 1] - lagged[n - 1];
        assert!(
            (trail / (rate * 0.01) - 1.0).abs() < 1e-3,
            "{trail} vs {}",
            rate * 0.01
        );
    }
}
