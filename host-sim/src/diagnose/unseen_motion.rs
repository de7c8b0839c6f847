//! Whether a log without the piston's position shows the piston moving: a volume balance of
//! the high side (eq. 9–11 bounded, not solved) over the oil the pump displaced.

use crate::bench_log::BenchLog;
use crate::diagnose::low_side::LowSide;
use plant_model::Rig;
use std::f64::consts::PI;

/// Whether a log without the piston's position shows it moving: the oil the pump
/// displaced, D/2π·θ, swings over a range more than twice what the high side could take —
/// its oil's compression over the logged pressure range, the whole absorber shell if the
/// pressure rose above its precharge, and twice the rig's leakage — plus a cubic
/// centimetre. A blocked cylinder's pump only replaces leakage and compression; what it
/// sends back and forth (a pressure sine through the absorber, a reversal into a low side
/// that relieves to the fill) returns, where a stroke's pump keeps turning one way. [m³]
pub fn unseen_piston_motion(log: &BenchLog, p_low: LowSide<'_>, rig: &Rig) -> bool {
    let d_per_rad = rig.pump.displacement_m3_per_rev / (2.0 * PI);
    let leakage = rig.pump.internal_leakage_m3_s_pa
        + rig.pump.external_leakage_m3_s_pa
        + rig.cylinder.internal_leakage_m3_s_pa;
    let (mut net, mut low, mut high, mut leaked) = (0.0, 0.0, 0.0, 0.0);
    for k in 1..log.len() {
        let dt = log.t_s[k] - log.t_s[k - 1];
        net += d_per_rad * log.speed_rad_s[k] * dt;
        (low, high) = (f64::min(low, net), f64::max(high, net));
        leaked += 2.0 * leakage * (log.p_pa[k] - p_low.at(k)).abs() * dt;
    }
    let displaced = high - low;
    let (lo, hi) = log
        .p_pa
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(*p), h.max(*p))
        });
    let compression = rig.cylinder.chamber_a_volume_m3 / rig.oil.bulk_modulus_pa * (hi - lo);
    let absorber = if rig.absorber.enabled && hi > rig.absorber.precharge_pa {
        rig.absorber.shell_volume_m3
    } else {
        0.0
    };
    displaced > 2.0 * (compression + absorber + leaked) + 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1 kHz log of `seconds` with the shaft at `speed(t)` and the port at `p(t)`.
    fn log_of(seconds: f64, speed: impl Fn(f64) -> f64, p: impl Fn(f64) -> f64) -> BenchLog {
        let t: Vec<f64> = (0..(seconds * 1e3) as usize)
            .map(|k| k as f64 * 1e-3)
            .collect();
        let n = t.len();
        BenchLog {
            p_pa: t.iter().map(|&t| p(t)).collect(),
            p_ref_pa: vec![0.0; n],
            speed_rad_s: t.iter().map(|&t| speed(t)).collect(),
            iq_a: vec![0.0; n],
            id_a: vec![0.0; n],
            t_s: t,
            ..BenchLog::default()
        }
    }

    #[test]
    fn a_pressure_sine_through_the_absorber_is_not_a_moving_piston() {
        // Thirty 1 Hz cycles of 4.5 ± 1.5 MPa, the pump turning at ω = W·sin(2πt), which
        // displaces D/2π·W/π = 16.7 cm³ into the absorber and back each cycle: 1.0 L back and
        // forth in all, more than the bound of twice the high side's storage (oil
        // 450e-6/650e6·3e6 = 2.1 cm³, the 400 mL shell above the 3 MPa precharge) and twice
        // its leakage (2·3e-13·|p − 0.5 MPa|·30 s = 72 cm³), 949 cm³. The oil returns: the
        // displaced volume's range stays 16.7 cm³.
        let w = 16.7e-6 * PI / (1.5e-6 / (2.0 * PI));
        let log = log_of(
            30.0,
            |t| w * (2.0 * PI * t).sin(),
            |t| 4.5e6 - 1.5e6 * (2.0 * PI * t).cos(),
        );
        assert!(!unseen_piston_motion(
            &log,
            LowSide::Level(0.5e6),
            &Rig::nominal()
        ));
    }

    #[test]
    fn a_stroke_turning_one_way_is_a_moving_piston() {
        // 30 rad/s for 10 s at the fill: 1.5e-6/2π·300 = 71.6 cm³ displaced, where the high
        // side at a constant 0.55 MPa stores nothing and leaks 2·3e-13·0.05e6·10 = 0.3 cm³.
        let log = log_of(10.0, |_| 30.0, |_| 0.55e6);
        assert!(unseen_piston_motion(
            &log,
            LowSide::Level(0.5e6),
            &Rig::nominal()
        ));
    }
}
