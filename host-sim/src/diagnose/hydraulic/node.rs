//! One integration substep of the hydraulic relation's high-pressure node
//! ([`super`], eq. 9–11 and 22–26): the backward Euler rule linearised about the gas
//! state, in closed form, with the absorber's poppet located inside the step. An empty
//! absorber opens where the node's pressure, rising with the poppet shut, reaches the
//! gas's precharge; a filled one closes where its oil runs out. Between those instants the
//! step is solved on each side, so no oil is lent by an absorber that has none: taken
//! at the step's end, a closing leaves the node with the inlet's whole step of outflow
//! while the absorber held less, an excess of oil that the node's small capacitance turns
//! into a lasting pressure error.

use super::{Hydraulics, Interval, State, ATMOSPHERE_PA};
use plant_model::accumulator::GasCharge;

impl Hydraulics {
    /// One substep of `step`'s length with the node's inflow, low-side, case and floor
    /// pressures `flows` and the oil's capacitance `c_oil`; the transducer follows it with
    /// `step`'s factors (the pressure taken as moving linearly).
    #[inline]
    pub(super) fn substep(&self, st: &mut State, step: &Interval, flows: [f64; 4], c_oil: f64) {
        let floor = flows[3];
        let p_start = st.p;
        match &self.params.absorber {
            None => st.p = self.closed(st, step.h, flows, c_oil),
            Some(gas) => self.with_absorber(st, gas, step.h, step.per_h, flows, c_oil),
        }
        // The check valve from the fill feeds the port below the fill level.
        st.p = st.p.max(floor);
        st.s = step.lag.next(st.s, p_start, st.p);
    }

    /// The node's balance over `h` from `st`, diag·p' = rhs − h·q' (q' the absorber's
    /// inflow; with it shut, p' = rhs/diag).
    #[inline]
    fn node(&self, st: &State, h: f64, flows: [f64; 4], c_oil: f64) -> (f64, f64) {
        let [q_in, p_low, p_case, _] = flows;
        let g = self.params.leakage_m3_s_pa;
        let g_pp = self.port_to_port;
        let rhs = c_oil * st.p + h * q_in + h * (g_pp * p_low + (g - g_pp) * p_case);
        (rhs, c_oil + h * g)
    }

    /// The node's pressure after `h` with the absorber shut, from `st`.
    #[inline]
    fn closed(&self, st: &State, h: f64, flows: [f64; 4], c_oil: f64) -> f64 {
        let (rhs, diag) = self.node(st, h, flows, c_oil);
        rhs / diag
    }

    /// The node and the absorber over `h` (`per_h` its reciprocal) from `st`, the poppet's
    /// opening and closing located inside the step: an empty absorber opens where the
    /// shut node's pressure reaches the gas's, a filled one closes where its oil runs out;
    /// the step is solved up to there and on from there.
    #[inline]
    fn with_absorber(
        &self,
        st: &mut State,
        gas: &GasCharge,
        h: f64,
        per_h: f64,
        flows: [f64; 4],
        c_oil: f64,
    ) {
        let (rhs, diag) = self.node(st, h, flows, c_oil);
        let (p_try, q_try, gas_vol) = self.open(st, gas, h, per_h, (rhs, diag));
        if st.v <= 0.0 {
            let p_shut = rhs / diag;
            // The poppet holds an empty absorber shut: no oil leaves it.
            if q_try < 0.0 {
                shut(st, gas);
                st.p = p_shut;
                return;
            }
            let p_open = st.g - ATMOSPHERE_PA;
            if st.p < p_open && p_shut > p_open {
                let before = h * (p_open - st.p) / (p_shut - st.p);
                let after = h - before;
                if after > EVENT_SHARE * h {
                    st.p = self.closed(st, before, flows, c_oil);
                    let balance = self.node(st, after, flows, c_oil);
                    let solved = self.open(st, gas, after, 1.0 / after, balance);
                    take_open(st, gas, after, solved);
                    return;
                }
            }
        } else {
            let v_end = st.v + h * q_try;
            if v_end < 0.0 {
                let before = h * st.v / (st.v - v_end);
                let after = h - before;
                if before > EVENT_SHARE * h && after > EVENT_SHARE * h {
                    let balance = self.node(st, before, flows, c_oil);
                    st.p = self.open(st, gas, before, 1.0 / before, balance).0;
                    shut(st, gas);
                    st.p = self.closed(st, after, flows, c_oil);
                    return;
                }
            }
        }
        take_open(st, gas, h, (p_try, q_try, gas_vol));
    }

    /// The pressure, the inlet flow and the gas volume after `h` (`per_h` its reciprocal)
    /// from `st` with the absorber's inlet open, the node's balance over `h` being
    /// `(rhs, diag)` ([`Self::node`]): backward Euler linearised about the gas.
    #[inline]
    fn open(
        &self,
        st: &State,
        gas: &GasCharge,
        h: f64,
        per_h: f64,
        (rhs, diag): (f64, f64),
    ) -> (f64, f64, f64) {
        let hp = &self.params;
        // The inlet, (I + h·R + h²·k_g)·q' = I·q − h·p_gas + h·p' with the gas's
        // stiffness k_g = n·p_g/V_g, taken times V_g; with the node's
        // diag·p' = rhs − h·q' it gives p' in one division, and q' from the node
        // without another: the divisions a substep waits on are the pressure's alone.
        let gas_vol = (gas.shell_volume_m3 - st.v).max(1e-3 * gas.shell_volume_m3);
        let inlet = hp.inlet_inertance_kg_m4 + h * hp.inlet_resistance_pa_s_m3;
        let den = inlet * gas_vol + h * h * gas.exponent * st.g;
        let drive = (hp.inlet_inertance_kg_m4 * st.q - h * (st.g - ATMOSPHERE_PA)) * gas_vol;
        let p_try = (rhs * den - h * drive) / (diag * den + h * h * gas_vol);
        let q_try = (rhs - diag * p_try) * per_h;
        (p_try, q_try, gas_vol)
    }
}

/// `st` after `h` with the absorber open, from [`Hydraulics::open`]'s pressure, inlet flow
/// and gas volume.
#[inline]
fn take_open(st: &mut State, gas: &GasCharge, h: f64, solved: (f64, f64, f64)) {
    let (p_try, q_try, gas_vol) = solved;
    st.q = q_try;
    let v_new = (st.v + h * q_try).max(0.0);
    st.g = if v_new > 0.0 {
        st.g + gas.exponent * st.g / gas_vol * (v_new - st.v)
    } else {
        gas.precharge_abs_pa()
    };
    st.v = v_new;
    st.p = p_try;
}

/// The absorber shut and empty: no inlet flow, no oil, the gas at its precharge.
#[inline]
fn shut(st: &mut State, gas: &GasCharge) {
    st.q = 0.0;
    st.v = 0.0;
    st.g = gas.precharge_abs_pa();
}

/// Least share of a substep an absorber's opening or closing is located at: an event
/// nearer the substep's end is taken at it. [1]
const EVENT_SHARE: f64 = 1e-6;
