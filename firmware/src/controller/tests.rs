//! Façade tests: start-up (the board's power-up measurements and the encoder's reference),
//! each fault's latch/disable/clear cycle, command refusals, calibration. Sensor values are
//! built from the nominal scaling written out here; the tests are in [`faults`],
//! [`startup`] and [`robustness`].

use super::*;
use crate::config::Config;
use crate::io::Measurements;
use crate::supervisor::{Mode, Readiness};

const A_PER_LSB: f32 = 100.0 / 4096.0;
const PA_PER_LSB: f32 = 25e6 / 52428.8;

fn pressure_counts(p: f32) -> u16 {
    (6554.0 + p / PA_PER_LSB + 0.5) as u16
}

/// A healthy drive at rest: 0 A, 280 V, 3 MPa, encoder at `count`.
fn healthy(count: u32) -> Measurements {
    Measurements {
        adc_phase_current: [2048; 3],
        adc_dc_link: 2800,
        adc_pressure: pressure_counts(3e6),
        encoder_count: count,
        encoder_index: false,
        encoder_index_count: 0,
    }
}

/// An index pulse captured at counter `count`, the counter still there.
fn index_at(count: u32) -> Measurements {
    Measurements {
        encoder_index: true,
        encoder_index_count: count,
        ..healthy(count)
    }
}

/// Power samples of the nominal configuration's offset measurement (0.05 s at 20 kHz).
const BOOT_CALLS: usize = 1000;
/// Periods of the nominal bootstrap precharge (0.5 ms at 20 kHz).
const PRECHARGE_CALLS: usize = 10;

/// A board's power-up: the offset measurement at rest with the bridge off, then the shaft
/// turned past the encoder index (captured at counter 0).
fn boot(c: &mut Controller) {
    for _ in 0..BOOT_CALLS {
        c.on_current_sample(&healthy(0));
    }
    c.on_current_sample(&index_at(0));
    assert_eq!(c.readiness(), Readiness::READY);
}

fn running(mode: Mode) -> Controller {
    let mut c = Controller::new(&Config::nominal());
    boot(&mut c);
    c.command(Command::SetMode(mode)).unwrap();
    let out = c.on_current_sample(&healthy(0));
    assert!(
        out.pwm_enabled,
        "{mode:?} should start after the power-up checks"
    );
    assert_eq!(c.mode(), mode);
    c
}

/// xorshift32: a deterministic stream of arbitrary inputs without a dependency.
fn next(state: &mut u32) -> u32 {
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    *state
}

mod faults;
mod robustness;
mod startup;
