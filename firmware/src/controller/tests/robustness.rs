//! Robustness: arbitrary inputs and commands never panic and keep the outputs sane; an
//! unvalidated configuration does not panic.

use super::*;
use crate::config::Config;
use crate::io::Measurements;
use crate::supervisor::Mode;

#[test]
fn arbitrary_inputs_and_commands_never_panic_and_keep_the_outputs_sane() {
    // The ISR contract: infallible for any peripheral reading and any command sequence;
    // duties finite in [0, 1]; the bridge on only in an active mode without a latched fault.
    for (cfg_no, cfg) in [Config::nominal(), Config::nominal().with_pwm_hz(100e3)]
        .iter()
        .enumerate()
    {
        let mut c = Controller::new(cfg);
        // Powered up as on the board: offsets measured at rest, then the index passes.
        let rest = Measurements {
            adc_phase_current: [2048; 3],
            adc_dc_link: 2800,
            adc_pressure: pressure_counts(5e6),
            ..Measurements::default()
        };
        for _ in 0..2000 {
            c.on_current_sample(&rest);
        }
        c.on_current_sample(&Measurements {
            encoder_index: true,
            ..rest
        });
        let mut rng = 0x9e37_79b9u32 ^ cfg_no as u32;
        let mut count = 0u32;
        let (mut on, mut trips) = (0u32, 0u32);
        for k in 0..200_000u32 {
            let r = next(&mut rng);
            // Mostly plausible readings (so the drive runs for a while between faults),
            // sometimes anything at all.
            let wild = r % 2048 == 0;
            count = if wild {
                next(&mut rng)
            } else {
                (count + (r >> 8) % 7) % 10_000
            };
            let around = |rng: &mut u32, centre: u16, spread: u32| -> u16 {
                if wild {
                    next(rng) as u16
                } else {
                    let x = next(rng) % (2 * spread + 1);
                    (centre as u32 + x).saturating_sub(spread) as u16
                }
            };
            // Plausible phase currents sum to zero, as a star's do; wild ones anything.
            let (a, b) = (around(&mut rng, 2048, 200), around(&mut rng, 2048, 200));
            let c_phase = if wild {
                next(&mut rng) as u16
            } else {
                (3 * 2048u32).saturating_sub(a as u32 + b as u32) as u16
            };
            let m = Measurements {
                adc_phase_current: [a, b, c_phase],
                adc_dc_link: around(&mut rng, 2800, 100),
                adc_pressure: around(&mut rng, pressure_counts(5e6), 2000),
                encoder_count: count,
                encoder_index: count < 7 && r % 2 == 0,
                encoder_index_count: 0,
            };
            let out = c.on_current_sample(&m);
            for d in out.duties {
                assert!(
                    d.is_finite() && (0.0..=1.0).contains(&d),
                    "call {k}: duty {d}"
                );
            }
            if out.pwm_enabled {
                assert!(c.mode().is_active() && c.fault().is_none(), "call {k}");
                on += 1;
            }
            if c.fault().is_some() && c.telemetry().mode == Mode::Disabled {
                trips += 1;
            }
            let t = c.telemetry();
            assert!(t.t_s.is_finite() && t.iq_a.is_finite() && t.uq_v.is_finite());
            if k % 97 == 0 {
                let x = next(&mut rng);
                let f = f32::from_bits(next(&mut rng));
                let cmd = match x % 6 {
                    0 => Command::SetMode(Mode::from_code((x >> 8) as u8 % 4).unwrap()),
                    1 => Command::SetPressure { pa: f },
                    2 => Command::SetPressure {
                        pa: (x >> 8) as f32,
                    },
                    3 => Command::SetSpeed { rad_s: f },
                    4 => Command::ClearFaults,
                    _ => Command::Heartbeat,
                };
                let _ = c.command(cmd);
            } else if k % 7 == 0 {
                let _ = c.command(Command::Heartbeat);
            }
        }
        // The sweep is only worth something if it ran the loops and tripped faults.
        assert!(
            on > 10_000 && trips > 1_000,
            "bridge on {on} calls, faulted {trips}"
        );
    }
}

#[test]
fn an_unvalidated_configuration_does_not_panic() {
    // `new` is documented for validated configurations, but a wrong one must still not
    // take the MCU down from inside the ISR.
    let mut bad = Config::nominal();
    bad.rates.pwm_hz = 0.0;
    bad.rates.speed_loop_hz = f32::NAN;
    bad.rates.pressure_loop_hz = -1.0;
    bad.sensors.encoder_counts_per_rev = 0;
    bad.sensors.current_a_per_lsb = f32::INFINITY;
    bad.current.voltage_limit_v = f32::NAN;
    bad.speed.iq_limit_a = -3.0;
    bad.hydraulics.bulk_modulus_pa = 0.0;
    bad.limits.command_timeout_s = f32::NAN;
    let mut c = Controller::new(&bad);
    let _ = c.command(Command::SetMode(Mode::Pressure));
    for k in 0..2000u32 {
        let out = c.on_current_sample(&healthy(k * 3));
        for d in out.duties {
            assert!((0.0..=1.0).contains(&d), "call {k}: duty {d}");
        }
        let _ = c.telemetry();
    }
}
