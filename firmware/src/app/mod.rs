//! The STM32G474RE application: the control core ([`firmware::Controller`]) wired to the
//! peripherals of the NUCLEO-G474RE.
//!
//! - [`board`]: every pin, peripheral instance and clock (the one module to change for
//!   another board), the power stage with the hardware over-current trip, and the break
//!   latches; it calls nothing above it.
//! - [`control`]: the current-loop interrupt (highest priority, not a task) and the state
//!   it shares with the tasks; [`bridge`] and [`sensors`] are its drivers over the
//!   board's register blocks. This module joins them: it binds the interrupt vector
//!   (`ADC1_2`) to [`control`] and hands the board's peripherals to the drivers.
//! - [`safe_state`]: the bridge off on a panic, a HardFault, an NMI (a flash ECC error), a
//!   core lockup, a debug halt or a stall.
//! - [`param_flash`]: the parameter table at the end of flash bank 2.
//! - Tasks on the thread-mode executor: [`can_link`] (commands and replies over FDCAN1),
//!   [`telemetry`] (defmt over RTT), [`supervision`] (independent watchdog, LED, load,
//!   stack high-water mark).
//!
//! Start-up: configuration validated (on error the bridge stays off and the error is
//! logged), peripherals brought up with the bridge disabled, the stored parameter table
//! applied over the defaults ([`firmware::param_store::boot`]: a corrupt, other-version
//! or inconsistent record gives the defaults and latches fault 16 — a copy with a double
//! word torn by a power loss during a save raises an ECC error whose NMI the board
//! handles, and is refused like a corrupt one, [`param_flash`]; a flash without the
//! dual-bank layout gives the defaults and fault 18), the stored torque feed-forward table
//! loaded (a wrong size, version, CRC or amplitude refuses it alone: fault 21, the drive
//! runs uncompensated), a watchdog reset of the previous run
//! latched as fault 11, the drive installed, the interrupt enabled, the tasks spawned. The
//! drive starts in Disabled and measures its current offsets; a CAN `SetMode` command
//! starts it once the offsets are measured and (for Speed and Pressure) the encoder index
//! has been seen or Calibrating has aligned the rotor. `docs/bring-up.md` is the bench
//! procedure.

mod board;
mod bridge;
mod can_link;
mod control;
mod param_flash;
mod safe_state;
mod sensors;
mod supervision;
mod telemetry;

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::interrupt;
use embassy_time::Timer;
use firmware::can_protocol::NodeId;
use firmware::compensation::CompensationError;
use firmware::param_store::{boot, BootOutcome, TABLE_LEN};
use firmware::{Config, Controller};

use bridge::Bridge;
use param_flash::Store;
use safe_state::{ecc_errors, last_ecc_error};
use sensors::Sensors;

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    #[cfg(not(feature = "bring-up"))]
    let config = Config::nominal();
    #[cfg(feature = "bring-up")]
    let config = Config::bring_up();
    if let Err(e) = config.validate() {
        defmt::error!(
            "configuration refused: {} {}; the bridge stays off",
            e.field,
            e.problem
        );
        loop {
            Timer::after_secs(1).await;
        }
    }
    // `validate` has checked the PWM rate; whole hertz are what the timer can do.
    let pwm_hz = config.rates.pwm_hz as u32;
    let node = match NodeId::new(board::CAN_NODE) {
        Ok(n) => n,
        Err(_) => {
            defmt::error!("CAN node number {} out of range", board::CAN_NODE);
            loop {
                Timer::after_secs(1).await;
            }
        }
    };

    enable_cycle_counter();
    let b = board::init(pwm_hz, &config, node);
    let t = b.timing;
    defmt::info!(
        "power stage: TIM1 at {=u32} Hz, ARR {=u16} ({=f32} Hz PWM), dead time {=u32} ns, break filter {=u32} ns, over-current trip at {=f32} A (DAC3 code {=u16})",
        t.timer_hz,
        t.arr,
        t.pwm_hz,
        t.dead_time_ns,
        t.break_filter_ns,
        config.limits.hardware_over_current_a,
        t.trip_code
    );
    // Built from the constant nominal configuration, then given the stored table: the
    // constructor folds at compile time, the table goes through the live-parameter path.
    // The live table covers gains, limits and commissioning results, never the rates or
    // the encoder resolution the board was just set up with.
    let mut controller = Controller::new(&config);
    let store = load_parameters(b.flash, &mut controller);
    if b.watchdog_reset {
        defmt::error!(
            "the previous run ended in a watchdog reset (stalled loop, panic or HardFault): fault 11"
        );
        controller.report_watchdog_reset();
    }
    let decimation = controller.telemetry_decimation();
    control::install(controller, Bridge::new(b.power), Sensors::new(b.sensors));
    board::enable_current_loop_interrupt();
    defmt::info!(
        "EHA drive up: PWM {} Hz, CAN node {} at {} bit/s, telemetry every {} periods",
        pwm_hz,
        node.get(),
        board::CAN_BITRATE,
        decimation
    );

    let (link, sender) = can_link::start(b.can);
    spawner.spawn(unwrap_spawn(can_link::receive(link, node, store)));
    spawner.spawn(unwrap_spawn(can_link::transmit(sender, node)));
    spawner.spawn(unwrap_spawn(telemetry::run()));
    spawner.spawn(unwrap_spawn(supervision::run(b.watchdog, b.led, pwm_hz)));
}

/// The current-loop interrupt: ADC1 and ADC2 share this vector; only ADC1's
/// end-of-injected-sequence interrupt is enabled ([`board::enable_current_loop_interrupt`]).
#[interrupt]
fn ADC1_2() {
    control::on_current_sample_interrupt();
}

/// Opens the parameter store and applies its table to `controller`; latches fault 16 for
/// an unusable table and fault 18 when the flash has no store. Returns the store for the
/// save command.
fn load_parameters(
    flash: Option<embassy_stm32::flash::Flash<'static, embassy_stm32::flash::Blocking>>,
    controller: &mut Controller,
) -> Option<Store> {
    let Some(mut store) = flash.and_then(|f| param_flash::open(f).ok()) else {
        defmt::error!(
            "parameters: flash option bit DBANK is cleared (single bank): no parameter store, defaults loaded (fault 18); set DBANK, see docs/bring-up.md"
        );
        controller.report_parameter_flash_layout();
        return None;
    };
    let ecc_before = ecc_errors();
    match boot(&mut store, |v| controller.load_parameters(v).is_ok()) {
        BootOutcome::Stored { sequence } => {
            defmt::info!("parameters: stored table {} loaded", sequence);
            let read = |at: usize, buf: &mut [u8]| store.read_table(at, buf);
            match controller.load_compensation_record(TABLE_LEN, read) {
                Ok(()) => defmt::info!(
                    "torque feed-forward: table loaded (amplitude bound {=f32} A)",
                    controller.compensation().amplitude_bound()
                ),
                Err(e) => {
                    match e {
                        CompensationError::Amplitude {
                            amplitude_a,
                            limit_a,
                        } => defmt::error!(
                            "torque feed-forward: amplitude {=f32} A above compensation.max_current_a {=f32} A",
                            amplitude_a,
                            limit_a
                        ),
                        CompensationError::Record(r) => {
                            defmt::error!("torque feed-forward: stored table refused, {=str}", r.kind())
                        }
                    }
                    defmt::error!("torque feed-forward: running uncompensated (fault 21)");
                    controller.report_compensation_invalid();
                }
            }
        }
        BootOutcome::Defaults => defmt::info!("parameters: none stored, defaults"),
        BootOutcome::DefaultsAfterInvalid(_) => {
            defmt::error!("parameters: stored table unusable, defaults loaded (fault 16)");
            controller.report_parameter_store_invalid();
        }
    }
    let ecc = ecc_errors().wrapping_sub(ecc_before);
    if ecc != 0 {
        defmt::error!(
            "parameters: {=u32} uncorrectable flash ECC errors reading the stored pages (a save cut by a power loss), the copy concerned refused; FLASH_ECCR {=u32:#x}",
            ecc,
            last_ecc_error()
        );
    }
    Some(store)
}

/// Each task is spawned once, so its pool of one is always free: a failure here is a
/// build error in disguise and stops start-up loudly (before the bridge is ever enabled).
fn unwrap_spawn<S>(
    token: Result<embassy_executor::SpawnToken<S>, embassy_executor::SpawnError>,
) -> embassy_executor::SpawnToken<S> {
    match token {
        Ok(t) => t,
        Err(_) => defmt::panic!("task spawned twice"),
    }
}

/// The current loop measures its own duration in CPU cycles.
fn enable_cycle_counter() {
    // SAFETY: called once at start-up, before anything else uses DCB/DWT; embassy does not
    // take the core peripherals.
    let mut cp = unsafe { cortex_m::Peripherals::steal() };
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();
}
