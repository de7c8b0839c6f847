//! The winding step of the exponential integrator: the currents over a step by the series
//! of [`super::blocks`], with the torque, its moment, the input power and the copper loss
//! integrated by Simpson's rule along them, the step cut where the series would converge
//! slowly and where a phase current crosses the edge of the dead time's band (eq. 2, 5, 17–19;
//! the dead time as in [`crate::inverter`]).

use super::super::actuator::Plant;
use super::super::integrator::{EVENT_REFINEMENTS, EVENT_TOLERANCE};
use super::super::state::{ix, AngleTerms, Vector};
use super::blocks::{mv, M2};
use super::history::Poly;
use super::rates::Rates;
use super::series::{winding_series, winding_series_fixed, Winding, WindingPoints, WindingStart};
use crate::inverter::{dq_to_abc, pole_to_dq};
use crate::motor::{MagnetFlux, Phasor};

/// √3.
const SQRT3: f64 = 1.732_050_807_568_877_2;

/// Sub-intervals of the winding series are cut so that ν·τ stays at or below this.
const WINDING_SPAN: f64 = 0.5;

/// Most sub-intervals of the winding series in one segment (a rig far beyond any motor).
const MAX_WINDING_PIECES: f64 = 1e6;

/// Most pieces the dead time's band crossings cut from one segment.
const MAX_BAND_CUTS: u32 = 12;

/// The bridge as the winding step sees it.
#[derive(Clone, Copy, Debug)]
struct Bridge {
    /// The pole voltages without dead time, d_x·U_dc. [V]
    ideal: [f64; 3],
    /// Whether the dead time is modelled.
    dead: bool,
    /// The dead time's current band. [A]
    band: f64,
}

impl Plant {
    /// The winding currents over `tau` from `x0` with the bridge's `duties` held and the
    /// shaft's acceleration `shaft`, and Simpson's integrals of the torque, its moment
    /// ∫(τ − t)·T dt, the input power and the copper loss. The step is cut into pieces where
    /// the series would converge slowly (ν·δ ≤ ½) and where a phase current crosses the edge
    /// of the dead time's band (located by regula falsi on the series), so each piece holds
    /// one linear law of the dead time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn winding_step(
        &self,
        x0: &Vector,
        at: &AngleTerms,
        g0: &Rates,
        poly: &Poly,
        duties: &[f64; 3],
        shaft: &Shaft,
        tau: f64,
    ) -> WindingOut {
        let p = self.motor.pole_pairs;
        let wc = &self.exp.winding;
        let ideal = self.inverter.pole_voltages_ideal(duties);
        let dead = self.inverter.has_dead_time();
        let speed = libm::fabs(p * x0[ix::OMEGA]) + libm::fabs(shaft.alpha_e) * tau;
        if !dead && (wc.nu_r + speed * wc.nu_w) * tau <= WINDING_SPAN {
            return self.winding_step_plain(x0, at, g0, poly, &ideal, shaft, tau);
        }
        let bridge = Bridge {
            ideal,
            dead,
            band: self.inverter.band(),
        };
        let mut out = WindingOut::default();
        let mut i = [x0[ix::ID], x0[ix::IQ]];
        let (mut omega_e, mut alpha_e) = (p * x0[ix::OMEGA], shaft.alpha_e);
        let (mut t0, mut turned) = (0.0, 0.0);
        out.omega_e_mid = omega_e;
        let mut first = None;
        // Band crossings cut at most this many pieces from a step (a current hovering at
        // the band's edge takes the rest whole).
        let mut cuts = MAX_BAND_CUTS;
        while t0 < tau {
            let e = at.rot_e * Phasor::small(turned);
            let (u, rg, inside) = self.dead_time_law(&bridge, e, i);
            if first.is_none() {
                first = Some(self.winding_point(&at.flux, turned, i, u, &rg, 0.0));
            }
            let (accel_load, emf) = forcing_from(shaft, g0, poly, t0);
            let start = WindingStart {
                i,
                u,
                omega_e,
                alpha_e,
                accel_gain: shaft.gain,
                accel_load,
                emf,
            };
            let w = self.piece_matrix(&rg, omega_e);
            // The band's resistance turns with the rotor only while a phase is inside it.
            let turning = inside.iter().any(|k| *k);
            let left = tau - t0;
            let mut delta = self.piece_length(omega_e, alpha_e, t0, tau);
            let mut pts = piece_series(&w, &start, turning, delta);
            if bridge.dead && cuts > 0 {
                let cut = band_cut(&w, &start, turning, bridge.band, e, &inside, &pts, delta);
                if let Some(fr) = cut {
                    delta *= fr;
                    pts = piece_series(&w, &start, turning, delta);
                    cuts -= 1;
                }
            }
            let Some(f0) = first else { break };
            let (mid, end) = self.piece_ends(&at.flux, turned, &pts, &rg);
            add_simpson(&mut out, f0, mid, end, delta, tau, t0);
            // The speed at the step's middle, from the piece holding it.
            let t1 = if delta >= left { tau } else { t0 + delta };
            if t0 <= 0.5 * tau && 0.5 * tau <= t1 {
                let frac = (0.5 * tau - t0) / delta;
                out.omega_e_mid = pts.omega_e_mid + (frac - 0.5) * (pts.omega_e - omega_e);
            }
            i = pts.i[1];
            omega_e = pts.omega_e;
            alpha_e = pts.alpha_e;
            turned += pts.turned[1];
            // The end's values open the next piece (recomputed there with its own law).
            first = None;
            t0 = t1;
        }
        out.i = i;
        out
    }

    /// Torque, input power and copper loss with currents `i`, voltage `u` and the band's
    /// resistance r·G `rg` (turned by `within` since it was taken), the rotor turned by `dth`
    /// (electrical) since the step's start: T_e = 1.5·p_n·[ψ_df·i_q − ψ_qf·i_d + i_d·ψ_df' +
    /// i_q·ψ_qf' + (L_d − L_q)·i_d·i_q] (eq. 5 with the harmonics of eq. 17–19, as in
    /// [`crate::motor`]), P = 1.5·(u − r·G·i)·i, P_cu = 1.5·R_s·|i|².
    #[inline(always)]
    fn winding_point(
        &self,
        f: &MagnetFlux,
        dth: f64,
        i: [f64; 2],
        u: [f64; 2],
        rg: &(M2, M2),
        within: f64,
    ) -> (f64, f64, f64) {
        let m = &self.motor;
        let p = m.pole_pairs;
        let dl = m.l_d_h - m.l_q_h;
        // The flux along the angle to second order (its harmonics turn up to ≈ 0.1 rad
        // per step at the nominal rig's top speed).
        let psi_d = f.d_wb + dth * (f.d_slope_wb + 0.5 * dth * f.d_curvature_wb);
        let psi_q = f.q_wb + dth * (f.q_slope_wb + 0.5 * dth * f.q_curvature_wb);
        let slope_d = f.d_slope_wb + dth * f.d_curvature_wb;
        let slope_q = f.q_slope_wb + dth * f.q_curvature_wb;
        let torque = 1.5
            * p
            * (psi_d * i[1] - psi_q * i[0] + i[0] * slope_d + i[1] * slope_q + dl * i[0] * i[1]);
        let v0 = mv(&rg.0, i);
        let v1 = mv(&rg.1, i);
        let v = [v0[0] + within * v1[0], v0[1] + within * v1[1]];
        let power = 1.5 * ((u[0] - v[0]) * i[0] + (u[1] - v[1]) * i[1]);
        let copper = 1.5 * m.r_s_ohm * (i[0] * i[0] + i[1] * i[1]);
        (torque, power, copper)
    }

    /// The dead time at a piece's start (rotor phasor `e`, currents `i`): the voltage in the
    /// rotor frame with the out-of-band drops, the band's resistance r·G and its derivative
    /// in the angle r·G' (G = ⅔·Σ c_k·c_kᵀ over the phases inside it, c_k phase k's row of
    /// d-q → abc, c_k' = (c_k,q, −c_k,d)) and which side of the band each phase is on.
    #[inline(always)]
    fn dead_time_law(
        &self,
        bridge: &Bridge,
        e: Phasor,
        i: [f64; 2],
    ) -> ([f64; 2], (M2, M2), [bool; 3]) {
        let i_abc = dq_to_abc(i[0], i[1], e.sin, e.cos);
        let mut poles = bridge.ideal;
        let mut rg = ([[0.0; 2]; 2], [[0.0; 2]; 2]);
        let mut inside = [false; 3];
        if bridge.dead {
            let (drop, slope) = self.inverter.dead_time_parts(&i_abc);
            let rows = phase_rows(e);
            for k in 0..3 {
                poles[k] -= drop[k];
                inside[k] = libm::fabs(i_abc[k]) < bridge.band;
                if inside[k] {
                    add_band_phase(&mut rg, rows[k], slope);
                }
            }
        }
        let (ud, uq) = pole_to_dq(&poles, e.sin, e.cos);
        ([ud, uq], rg, inside)
    }

    /// A piece's current equation (eq. 2 at the piece's start): a = −(R_s·I + r·G)/L with
    /// the speed coupling ω_e·(L_q/L_d, −L_d/L_q) off the diagonal, and its rate of change
    /// a1 = −r·G'·ω_e/L as the band's resistance turns with the rotor.
    #[inline(always)]
    fn piece_matrix(&self, rg: &(M2, M2), omega_e: f64) -> Winding {
        let m = &self.motor;
        let wc = &self.exp.winding;
        let (inv_l, coupling) = (wc.inv_l, wc.coupling);
        Winding {
            a: [
                [
                    -m.r_s_ohm * inv_l[0] - inv_l[0] * rg.0[0][0],
                    omega_e * coupling[0] - inv_l[0] * rg.0[0][1],
                ],
                [
                    omega_e * coupling[1] - inv_l[1] * rg.0[1][0],
                    -m.r_s_ohm * inv_l[1] - inv_l[1] * rg.0[1][1],
                ],
            ],
            a1: [
                [
                    -inv_l[0] * rg.1[0][0] * omega_e,
                    -inv_l[0] * rg.1[0][1] * omega_e,
                ],
                [
                    -inv_l[1] * rg.1[1][0] * omega_e,
                    -inv_l[1] * rg.1[1][1] * omega_e,
                ],
            ],
            coupling,
            inv_l,
        }
    }

    /// The length of the piece from `t0`: the rest of the step, at most ½/ν at the speed
    /// bound |ω_e| + |α_e|·(τ − t0) (so ν·δ ≤ ½), at least τ/[`MAX_WINDING_PIECES`].
    #[inline(always)]
    fn piece_length(&self, omega_e: f64, alpha_e: f64, t0: f64, tau: f64) -> f64 {
        let wc = &self.exp.winding;
        let speed = libm::fabs(omega_e) + libm::fabs(alpha_e) * (tau - t0);
        let nu = wc.nu_r + speed * wc.nu_w;
        let left = tau - t0;
        left.min(WINDING_SPAN / nu.max(1e-300))
            .max(tau / MAX_WINDING_PIECES)
    }

    /// Torque, input power and copper loss ([`Plant::winding_point`]) at the middle and the
    /// end of a piece from the series' points `pts`, the rotor turned by `turned` before it.
    #[inline(always)]
    fn piece_ends(
        &self,
        f: &MagnetFlux,
        turned: f64,
        pts: &WindingPoints,
        rg: &(M2, M2),
    ) -> ((f64, f64, f64), (f64, f64, f64)) {
        let mid = self.winding_point(
            f,
            turned + pts.turned[0],
            pts.i[0],
            pts.u[0],
            rg,
            pts.turned[0],
        );
        let end = self.winding_point(
            f,
            turned + pts.turned[1],
            pts.i[1],
            pts.u[1],
            rg,
            pts.turned[1],
        );
        (mid, end)
    }
}

/// The shaft's load acceleration and the back-EMF's extrapolation E(t) = E_0 + E_1·t +
/// E_2·t² re-centred on a piece starting at `t0`: (L_1 + 2·t0·L_2, L_2) and
/// (E(t0), E_1 + 2·t0·E_2, E_2).
#[inline(always)]
fn forcing_from(shaft: &Shaft, g0: &Rates, poly: &Poly, t0: f64) -> ([f64; 2], [[f64; 2]; 3]) {
    let (g1, g2) = (&poly.g1, &poly.g2);
    (
        [shaft.load[0] + 2.0 * t0 * shaft.load[1], shaft.load[1]],
        [
            [
                g0.emf[0] + t0 * (g1.emf[0] + t0 * g2.emf[0]),
                g0.emf[1] + t0 * (g1.emf[1] + t0 * g2.emf[1]),
            ],
            [
                g1.emf[0] + 2.0 * t0 * g2.emf[0],
                g1.emf[1] + 2.0 * t0 * g2.emf[1],
            ],
            g2.emf,
        ],
    )
}

/// Adds phase k, inside the dead time's band with the band's resistance `slope` r, to r·G
/// and r·G': ⅔·r·c·cᵀ and ⅔·r·(c'·cᵀ + c·c'ᵀ), c = `row`, c' = (c_q, −c_d).
#[inline(always)]
fn add_band_phase(rg: &mut (M2, M2), row: [f64; 2], slope: f64) {
    let (c, d) = (row, [row[1], -row[0]]);
    let g = slope * 2.0 / 3.0;
    for r in 0..2 {
        for col in 0..2 {
            rg.0[r][col] += g * c[r] * c[col];
            rg.1[r][col] += g * (d[r] * c[col] + c[r] * d[col]);
        }
    }
}

/// The winding series over `d` from a piece's `start`, with the matrix turning with the
/// rotor while a phase is inside the band (`turning`), held otherwise.
#[inline(always)]
fn piece_series(w: &Winding, start: &WindingStart, turning: bool, d: f64) -> WindingPoints {
    if turning {
        winding_series(w, start, d)
    } else {
        winding_series_fixed(w, start, d)
    }
}

/// How far the phases are from changing side of the band at rotor phasor `e` and currents
/// `i`, (|i_k| − band)/band, its sign turned for those `inside` it: positive until one does.
#[inline(always)]
fn band_margins(band: f64, e: Phasor, i: [f64; 2], inside: &[bool; 3]) -> [f64; 3] {
    let i_abc = dq_to_abc(i[0], i[1], e.sin, e.cos);
    let mut m = [0.0; 3];
    for k in 0..3 {
        let d = (libm::fabs(i_abc[k]) - band) / band;
        m[k] = if inside[k] { -d } else { d };
    }
    m
}

/// The smallest of the margins `m` of the `watched` phases (+∞ when none is).
#[inline(always)]
fn watched_margin(m: [f64; 3], watched: &[bool; 3]) -> f64 {
    (0..3)
        .filter(|k| watched[*k])
        .map(|k| m[k])
        .fold(f64::INFINITY, f64::min)
}

/// Where a phase current changes side of the band within the piece of `delta` whose series
/// ends at `pts`: the fraction of the piece just past the crossing, by regula falsi on the
/// series ([`past_crossing`]), or `None` if no watched phase crosses before the piece's
/// end. A phase that starts the piece on the band's edge has just crossed it and is not
/// watched.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn band_cut(
    w: &Winding,
    start: &WindingStart,
    turning: bool,
    band: f64,
    e: Phasor,
    inside: &[bool; 3],
    pts: &WindingPoints,
    delta: f64,
) -> Option<f64> {
    let start_m = band_margins(band, e, start.i, inside);
    let watched = start_m.map(|m| m > 0.0);
    let end = e * Phasor::small(pts.turned[1]);
    let m1 = watched_margin(band_margins(band, end, pts.i[1], inside), &watched);
    let m0 = watched_margin(start_m, &watched);
    if m1 <= 0.0 {
        // A phase changes side within the piece: cut it just past the crossing.
        let hi = past_crossing(m0, m1, |fr| {
            let trial = piece_series(w, start, turning, fr * delta);
            let turned_e = e * Phasor::small(trial.turned[1]);
            watched_margin(band_margins(band, turned_e, trial.i[1], inside), &watched)
        });
        if hi < 1.0 {
            return Some(hi);
        }
    }
    None
}

/// Regula falsi (Illinois) for the zero of `margin` over the piece's fraction in [0, 1],
/// from `m0` > 0 at 0 and `m1` ≤ 0 at 1: the bracket's end past the zero, after at most
/// [`EVENT_REFINEMENTS`] trials or once the bracket is within [`EVENT_TOLERANCE`].
#[inline(always)]
fn past_crossing(m0: f64, m1: f64, margin: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = ((0.0, m0), (1.0, m1));
    let mut kept = 0i8;
    let mut fr = m0 / (m0 - m1);
    for _ in 0..EVENT_REFINEMENTS {
        if hi.0 - lo.0 <= EVENT_TOLERANCE {
            break;
        }
        let v = margin(fr);
        if v > 0.0 {
            lo = (fr, v);
            kept = if kept > 0 { kept + 1 } else { 1 };
            if kept > 1 {
                hi.1 *= 0.5;
            }
        } else {
            hi = (fr, v);
            kept = if kept < 0 { kept - 1 } else { -1 };
            if kept < -1 {
                lo.1 *= 0.5;
            }
        }
        fr = lo.0 + (hi.0 - lo.0) * lo.1 / (lo.1 - hi.1);
    }
    hi.0
}

/// Adds a piece's Simpson integrals to `out`: over the piece [t0, t0 + δ] of the step τ,
/// δ/6·(f_0 + 4·f_mid + f_end) of the torque, the input power and the copper loss
/// (`f0`, `mid`, `end`), and of the torque's moment (τ − t)·T_e.
#[inline(always)]
fn add_simpson(
    out: &mut WindingOut,
    f0: (f64, f64, f64),
    mid: (f64, f64, f64),
    end: (f64, f64, f64),
    delta: f64,
    tau: f64,
    t0: f64,
) {
    let k = delta / 6.0;
    out.torque += k * (f0.0 + 4.0 * mid.0 + end.0);
    out.torque_moment += k
        * ((tau - t0) * f0.0 + 4.0 * (tau - t0 - 0.5 * delta) * mid.0 + (tau - t0 - delta) * end.0);
    out.e_in += k * (f0.1 + 4.0 * mid.1 + end.1);
    out.e_cu += k * (f0.2 + 4.0 * mid.2 + end.2);
}

impl Plant {
    /// [`Plant::winding_step`] without dead time, in one piece: the series once, Simpson's
    /// rule on its start, middle and end.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn winding_step_plain(
        &self,
        x0: &Vector,
        at: &AngleTerms,
        g0: &Rates,
        poly: &Poly,
        poles: &[f64; 3],
        shaft: &Shaft,
        tau: f64,
    ) -> WindingOut {
        let m = &self.motor;
        let wc = &self.exp.winding;
        let (g1, g2) = (&poly.g1, &poly.g2);
        let p = m.pole_pairs;
        let f = &at.flux;
        let (ud, uq) = pole_to_dq(poles, at.rot_e.sin, at.rot_e.cos);
        let i0 = [x0[ix::ID], x0[ix::IQ]];
        let omega_e = p * x0[ix::OMEGA];
        let w = Winding {
            a: [
                [wc.decay[0], omega_e * wc.coupling[0]],
                [omega_e * wc.coupling[1], wc.decay[1]],
            ],
            a1: [[0.0; 2]; 2],
            coupling: wc.coupling,
            inv_l: wc.inv_l,
        };
        let start = WindingStart {
            i: i0,
            u: [ud, uq],
            omega_e,
            alpha_e: shaft.alpha_e,
            accel_gain: shaft.gain,
            accel_load: shaft.load,
            emf: [g0.emf, g1.emf, g2.emf],
        };
        let pts = winding_series_fixed(&w, &start, tau);
        let dl = m.l_d_h - m.l_q_h;
        let harmonic = f.d_slope_wb != 0.0 || f.q_slope_wb != 0.0;
        let point = |dth: f64, i: [f64; 2], u: [f64; 2]| {
            let torque = if harmonic {
                let psi_d = f.d_wb + dth * (f.d_slope_wb + 0.5 * dth * f.d_curvature_wb);
                let psi_q = f.q_wb + dth * (f.q_slope_wb + 0.5 * dth * f.q_curvature_wb);
                let slope_d = f.d_slope_wb + dth * f.d_curvature_wb;
                let slope_q = f.q_slope_wb + dth * f.q_curvature_wb;
                psi_d * i[1] - psi_q * i[0] + i[0] * slope_d + i[1] * slope_q + dl * i[0] * i[1]
            } else {
                f.d_wb * i[1] - f.q_wb * i[0] + dl * i[0] * i[1]
            };
            let power = u[0] * i[0] + u[1] * i[1];
            let copper = i[0] * i[0] + i[1] * i[1];
            (torque, power, copper)
        };
        let a = point(0.0, i0, [ud, uq]);
        let b = point(pts.turned[0], pts.i[0], pts.u[0]);
        let c = point(pts.turned[1], pts.i[1], pts.u[1]);
        let k = tau / 6.0;
        let kt = 1.5 * p * k;
        WindingOut {
            i: pts.i[1],
            torque: kt * (a.0 + 4.0 * b.0 + c.0),
            torque_moment: kt * tau * (a.0 + 2.0 * b.0),
            e_in: 1.5 * k * (a.1 + 4.0 * b.1 + c.1),
            e_cu: 1.5 * m.r_s_ohm * k * (a.2 + 4.0 * b.2 + c.2),
            omega_e_mid: pts.omega_e_mid,
        }
    }
}

/// Rows of the d-q → abc transform at the electrical-angle phasor `e`: phase k's current is
/// c_k · (i_d, i_q).
fn phase_rows(e: Phasor) -> [[f64; 2]; 3] {
    let half = 0.5 * SQRT3;
    let (s, c) = (e.sin, e.cos);
    [
        [c, -s],
        [-0.5 * c + half * s, 0.5 * s + half * c],
        [-0.5 * c - half * s, 0.5 * s - half * c],
    ]
}

/// The shaft as the winding series sees it.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Shaft {
    /// Electrical acceleration at the start. [rad/s²]
    pub(super) alpha_e: f64,
    /// Electrical acceleration per ampere of i_d, i_q. [rad/s²/A]
    pub(super) gain: [f64; 2],
    /// The load's electrical acceleration slope and curvature. [rad/s³], [rad/s⁴]
    pub(super) load: [f64; 2],
}

/// What [`Plant::winding_step`] gives.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct WindingOut {
    /// Currents at the end. [A]
    pub(super) i: [f64; 2],
    /// ∫T_e dt [N·m·s] and ∫(τ − t)·T_e dt [N·m·s²].
    pub(super) torque: f64,
    pub(super) torque_moment: f64,
    /// Input energy and copper loss. [J]
    pub(super) e_in: f64,
    pub(super) e_cu: f64,
    /// Electrical speed at the middle of the step. [rad/s]
    pub(super) omega_e_mid: f64,
}
