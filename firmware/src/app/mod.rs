//! The STM32G474RE application: the control core ([`firmware::Controller`]) wired to the
//! peripherals of the NUCLEO-G474RE.
//!
//! - [`board`]: every pin, peripheral instance and clock (the one module to change for
//!   another board), and the interrupt vector of the current loop.
//! - [`control`]: the current-loop interrupt (highest priority, not a task) and the state
//!   it shares with the tasks; [`bridge`] and [`sensors`] are its drivers.
//! - [`param_flash`]: the parameter table in the last two flash pages.
//! - Tasks on the thread-mode executor: [`can_link`] (commands and replies over FDCAN1),
//!   [`telemetry`] (defmt over RTT), [`supervision`] (independent watchdog, LED, load).
//!
//! Start-up: configuration validated (on error the bridge stays off and the error is
//! logged), peripherals brought up with the bridge disabled, the stored parameter table
//! applied over the defaults ([`firmware::param_store::boot`]: a corrupt,
//! other-version or inconsistent record gives the defaults and latches fault 16), the
//! drive installed, the interrupt enabled, the tasks spawned. The drive starts in Disabled; a CAN `SetMode`
//! command starts it.

mod board;
mod bridge;
mod can_link;
mod control;
mod param_flash;
mod sensors;
mod supervision;
mod telemetry;

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_time::Timer;
use firmware::can_protocol::NodeId;
use firmware::param_store::{boot, BootOutcome};
use firmware::{Config, Controller};
use panic_probe as _;

use bridge::Bridge;
use sensors::Sensors;

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let config = Config::nominal();
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
    let b = board::init(pwm_hz, config.sensors.encoder_counts_per_rev);
    // The live table covers gains, limits and commissioning results, never the rates or
    // the encoder resolution the board was just set up with.
    let mut store = match param_flash::open(b.flash) {
        Ok(s) => s,
        Err(_) => defmt::panic!("parameter pages do not fit the flash layout"),
    };
    // Built from the constant nominal configuration, then given the stored table: the
    // constructor folds at compile time, the table goes through the live-parameter path.
    let mut controller = Controller::new(&config);
    let outcome = boot(&mut store, |v| controller.load_parameters(v).is_ok());
    match outcome {
        BootOutcome::Stored { sequence } => {
            defmt::info!("parameters: stored table {} loaded", sequence)
        }
        BootOutcome::Defaults => defmt::info!("parameters: none stored, defaults"),
        BootOutcome::DefaultsAfterInvalid(_) => {
            defmt::error!("parameters: stored table unusable, defaults loaded (fault 16)");
            controller.report_parameter_store_invalid();
        }
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

    let (tx, rx) = can_link::split(b.can.into_normal_mode());
    spawner.spawn(unwrap_spawn(can_link::receive(rx, node, store)));
    spawner.spawn(unwrap_spawn(can_link::transmit(tx, node)));
    spawner.spawn(unwrap_spawn(telemetry::run(pwm_hz)));
    spawner.spawn(unwrap_spawn(supervision::run(b.watchdog, b.led, pwm_hz)));
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
