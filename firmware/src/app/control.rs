//! The current-loop interrupt and the state it shares with the tasks.
//!
//! One ADC end-of-sequence interrupt per PWM period, at the highest priority: sample →
//! [`Controller::on_current_sample`] (current loop every call; speed and pressure loops at
//! their divided rates inside the façade) → duties to the bridge. The controller, the
//! bridge and the sensors live in one critical-section mutex: the interrupt borrows them
//! for its whole body, the tasks only for a command or a telemetry copy (microseconds), so
//! the interrupt's jitter is bounded by the longest of those.
//!
//! Overrun: if ADC1 has already finished the next period's sequence when the body ends,
//! the loop missed a sample; the controller latches its watchdog fault and the bridge is
//! turned off at once. Liveness for the independent watchdog is the interrupt counter
//! [`isr_count`], read by the supervision task. A hardware break (gate-driver fault line,
//! phase comparator, system break, or a break forced by [`super::safe_state`]) latches
//! fault 17; its sources, latched by the board even when they have gone again
//! ([`break_sources`]), are kept for the supervision task's log
//! ([`last_break_sources`]).
//!
//! Telemetry is captured here, every `telemetry_decimation` periods exactly: the frame
//! goes into a queue of [`TELEMETRY_QUEUE`] frames without waiting (dropped and counted
//! when it is full, [`telemetry_dropped`]) and the telemetry task logs it; nothing on the
//! way can block this interrupt.

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::DWT;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::CriticalSectionMutex;
use embassy_sync::channel::Channel;
use firmware::{Controller, TelemetryFrame};

use super::board::breaks::{break_sources, clear_break_latches};
use super::board::regs::CURRENT_ADC_REGS;
use super::bridge::{Bridge, BridgeEvent};
use super::safe_state;
use super::sensors::Sensors;

/// Frames the telemetry queue holds: 1.6 ms at full rate (20 kHz), more than the
/// telemetry task's longest wait behind the other tasks.
pub const TELEMETRY_QUEUE: usize = 32;

/// What the control interrupt owns.
pub struct Drive {
    /// The control core.
    pub controller: Controller,
    bridge: Bridge,
    sensors: Sensors,
    /// Periods until the next telemetry frame.
    telemetry_countdown: u32,
    /// Non-maskable interrupts counted when the last break was seen.
    nmis_seen: u32,
}

/// The drive once installed. An explicit zero tag for "empty" (not `Option`, whose `None`
/// would take a niche value inside the controller): the static is then all zero and lives
/// in `.bss`, instead of an 8 KiB initial image in flash.
#[repr(u8)]
enum Slot {
    Empty = 0,
    Installed(Drive) = 1,
}

impl Slot {
    fn as_mut(&mut self) -> Option<&mut Drive> {
        match self {
            Slot::Empty => None,
            Slot::Installed(d) => Some(d),
        }
    }
}

static DRIVE: CriticalSectionMutex<RefCell<Slot>> =
    CriticalSectionMutex::new(RefCell::new(Slot::Empty));
static ISR_COUNT: AtomicU32 = AtomicU32::new(0);
static ISR_MAX_CYCLES: AtomicU32 = AtomicU32::new(0);
static OVERRUNS: AtomicU32 = AtomicU32::new(0);
static BREAKS: AtomicU32 = AtomicU32::new(0);
static BREAK_SOURCES: AtomicU32 = AtomicU32::new(0);
static TELEMETRY_DROPPED: AtomicU32 = AtomicU32::new(0);
static TELEMETRY: Channel<CriticalSectionRawMutex, TelemetryFrame, TELEMETRY_QUEUE> =
    Channel::new();

/// Installs the drive; the interrupt does nothing before this.
pub fn install(controller: Controller, bridge: Bridge, sensors: Sensors) {
    // Assigned in place, not `replace`d: no second 7.6 KiB value (the old slot) passes over
    // the stack at boot.
    DRIVE.lock(|d| {
        *d.borrow_mut() = Slot::Installed(Drive {
            controller,
            bridge,
            sensors,
            telemetry_countdown: 1,
            nmis_seen: safe_state::nmis(),
        })
    });
}

/// Runs `f` on the controller inside a critical section (keep `f` short: the current
/// loop waits for it). `None` before [`install`].
pub fn with_controller<R>(f: impl FnOnce(&mut Controller) -> R) -> Option<R> {
    DRIVE.lock(|d| {
        d.try_borrow_mut()
            .ok()
            .and_then(|mut d| d.as_mut().map(|d| f(&mut d.controller)))
    })
}

/// Number of completed control interrupts (wraps).
pub fn isr_count() -> u32 {
    ISR_COUNT.load(Ordering::Relaxed)
}

/// Longest control-interrupt body so far. [CPU cycles]
pub fn isr_max_cycles() -> u32 {
    ISR_MAX_CYCLES.load(Ordering::Relaxed)
}

/// Overruns seen so far.
pub fn overruns() -> u32 {
    OVERRUNS.load(Ordering::Relaxed)
}

/// Hardware breaks seen so far.
pub fn breaks() -> u32 {
    BREAKS.load(Ordering::Relaxed)
}

/// The break sources active when the last break was seen ([`break_sources`]).
pub fn last_break_sources() -> u8 {
    BREAK_SOURCES.load(Ordering::Relaxed) as u8
}

/// Telemetry frames dropped because the queue was full (wraps).
pub fn telemetry_dropped() -> u32 {
    TELEMETRY_DROPPED.load(Ordering::Relaxed)
}

/// The next telemetry frame, when the interrupt has queued one.
pub async fn next_telemetry_frame() -> TelemetryFrame {
    TELEMETRY.receive().await
}

/// The interrupt body (called from the vector the application binds, `ADC1_2`).
pub fn on_current_sample_interrupt() {
    let start = DWT::cycle_count();
    DRIVE.lock(|d| {
        if let Ok(mut d) = d.try_borrow_mut() {
            if let Some(d) = d.as_mut() {
                d.step();
            }
        }
    });
    let cycles = DWT::cycle_count().wrapping_sub(start);
    ISR_MAX_CYCLES.fetch_max(cycles, Ordering::Relaxed);
    ISR_COUNT.fetch_add(1, Ordering::Relaxed);
}

impl Drive {
    fn step(&mut self) {
        let m = self.sensors.sample();
        let out = self.controller.on_current_sample(&m);
        let was_on = self.bridge.enabled();
        if self.bridge.apply(&out) == BridgeEvent::Break {
            // The hardware has already cut the bridge; the controller latches it, so
            // restarting takes the operator's clear.
            let system = self.bridge.take_system_break();
            let nmis = safe_state::nmis();
            let nmi = nmis != self.nmis_seen;
            self.nmis_seen = nmis;
            let sources = break_sources(system, nmi);
            clear_break_latches();
            BREAK_SOURCES.store(u32::from(sources), Ordering::Relaxed);
            BREAKS.fetch_add(1, Ordering::Relaxed);
            self.controller.report_hardware_break();
        } else if !was_on && self.bridge.enabled() {
            // A fresh enable: what the latches caught meanwhile (a comparator pulse shorter
            // than the break filter) belongs to no break.
            clear_break_latches();
        }
        self.telemetry_countdown = self.telemetry_countdown.saturating_sub(1);
        if self.telemetry_countdown == 0 {
            self.telemetry_countdown = self.controller.telemetry_decimation();
            if TELEMETRY.try_send(self.controller.telemetry()).is_err() {
                TELEMETRY_DROPPED.fetch_add(1, Ordering::Relaxed);
            }
        }
        if CURRENT_ADC_REGS.isr().read().jeos() {
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
            self.controller.report_overrun();
            self.bridge.disable();
        }
    }
}
