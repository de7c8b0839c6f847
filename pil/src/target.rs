//! The PIL run on the target: the scenario in closed loop, telemetry out, the loop steps
//! measured beside it, the figures and the exit code.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use crate::firmware_paths;
use crate::icount::{self, Tally};
use crate::stack;
use closed_loop::{by_name, controller_config, ClosedLoop};
use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use firmware::compensation::{Compensation, Table, BINS, CHANNELS};
use firmware::current_loop::CurrentLoop;
use firmware::pressure_loop::PressureLoop;
use firmware::speed_loop::SpeedLoop;
use firmware::svpwm::modulate;
use firmware::transforms::{inverse_park, sin_cos, Dq};
use firmware::Measurements;
use plant_model::Rig;

/// The scenario: the paper's low-speed pressure holding.
const SCENARIO: &str = "pressure-hold";
/// Simulated time. [s]
const DURATION_S: f64 = 0.5;
/// Sensor-noise seed; the host run uses the same (`eha simulate --seed 1`).
const SEED: u64 = 1;
/// Telemetry rate: the rate of the host simulator's bench logs (`eha simulate`), so the two
/// logs have the same instants. [Hz]
const LOG_RATE_HZ: f64 = 2000.0;
/// Every this many periods the closed-loop step's own stack depth is measured.
const STACK_BRACKET_EVERY: u64 = 50;
/// The first this many telemetry frames have their stack depth measured.
const STACK_BRACKET_FRAMES: u32 = 20;

#[entry]
fn main() -> ! {
    let code = match run() {
        Ok(()) => 0,
        Err(()) => 1,
    };
    semihosting::process::exit(code)
}

fn run() -> Result<(), ()> {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        defmt::error!("PIL: core peripherals already taken");
        return Err(());
    };
    icount::start(&mut cp.SYST);
    let per_tick = icount::measured_instructions_per_tick();

    let Some(scenario) = by_name(SCENARIO) else {
        defmt::error!("PIL: no scenario {=str}", SCENARIO);
        return Err(());
    };
    let rig = Rig::nominal();
    let config = controller_config(&rig);
    // The loop and the feed-forward live in static memory, as the firmware's controller
    // does once installed. Building them is the harness's work, not the firmware's (the
    // plant, a ClosedLoop around the controller, the test table): measured alone, and the
    // run's high-water mark counts from after it.
    let (built, compensation, setup_stack) = setup(&rig, &config, scenario);
    stack::restart();
    let cl = match built {
        Ok(cl) => cl,
        Err(e) => {
            defmt::error!("PIL: cannot build the loop: {}", defmt::Display2Format(&e));
            return Err(());
        }
    };
    let period = cl.period_s();
    let every = libm::round(1.0 / LOG_RATE_HZ / period).max(1.0) as u64;
    let steps = libm::ceil(DURATION_S / period) as u64;

    // Separate instances of the controller's loops, fed each period with what the
    // controller saw (the ADC counts, the telemetry's angle, speeds and references): the
    // same code as inside `Controller::on_current_sample`, bracketed alone.
    let mut current = CurrentLoop::new(&config);
    let Some(compensation) = compensation else {
        defmt::error!("PIL: the feed-forward's test table was refused");
        return Err(());
    };
    let mut speed = SpeedLoop::new(&config);
    let mut pressure = PressureLoop::new(&config);
    pressure.reset(scenario.initial_pressure_pa as f32, 0.0);
    pressure.set_target(closed_loop::scenario::HOLD_PRESSURE_PA as f32);
    let pole_pairs = config.motor.pole_pairs as f32;

    let (mut t_empty, mut t_step, mut t_current, mut t_speed, mut t_pressure) = (
        Tally::default(),
        Tally::default(),
        Tally::default(),
        Tally::default(),
        Tally::default(),
    );
    // Two parts of the current-loop step, for what dominates it: the sine/cosine pair of
    // the angle (the sine table) and the space-vector modulator (with its division by U_dc).
    let (mut t_sin_cos, mut t_svpwm) = (Tally::default(), Tally::default());
    let mut rows: u32 = 0;
    let mut step_stack: u32 = 0;
    let mut emit_stack: u32 = 0;
    for k in 0..steps {
        let mut m = Measurements::default();
        let mut step = || {
            t_step.measure(&mut *cl, |cl| {
                cl.step_with(|seen| {
                    m = seen;
                    seen
                })
            })
        };
        // The bracket paints before and scans after the instruction count's own bracket.
        let s = if k % STACK_BRACKET_EVERY == 0 {
            let (s, depth) = stack::depth(step);
            step_stack = step_stack.max(depth);
            s
        } else {
            step()
        };
        if k % every == 0 {
            if rows < STACK_BRACKET_FRAMES {
                let ((), depth) = stack::depth(|| s.telemetry.emit());
                emit_stack = emit_stack.max(depth);
            } else {
                s.telemetry.emit();
            }
            rows += 1;
        }
        let tel = s.telemetry;
        t_empty.measure((), |()| ());
        // The current-loop step as the controller runs it in Speed and Pressure: the
        // torque feed-forward looked up and added to the q reference, then the step.
        t_current.measure((&mut current, compensation), |(c, ff)| {
            let (iq_ff, flux) =
                ff.current(tel.theta_m_rad, tel.speed_rad_s, tel.p_pa, tel.iq_ref_a);
            c.step(
                &m,
                tel.theta_m_rad * pole_pairs,
                Dq {
                    d: 0.0,
                    q: tel.iq_ref_a + iq_ff,
                },
                tel.speed_rad_s * pole_pairs,
                flux,
            )
        });
        let sc = t_sin_cos.measure(tel.theta_m_rad * pole_pairs, sin_cos);
        t_svpwm.measure(
            (
                inverse_park(
                    Dq {
                        d: tel.ud_v,
                        q: tel.uq_v,
                    },
                    sc,
                ),
                tel.udc_v,
            ),
            |(v, u_dc)| modulate(v, u_dc),
        );
        // The speed-loop step as the controller runs it: the reference modulated against
        // the pump's flow ripple, the acceleration current added.
        t_speed.measure((&mut speed, compensation), |(sl, ff)| {
            let (w_ref, i_acc) = ff.flow().modulate(tel.theta_m_rad, tel.speed_ref_rad_s);
            sl.step(w_ref, tel.speed_rad_s) + i_acc
        });
        t_pressure.measure(&mut pressure, |pl| pl.step(tel.p_pa));
    }

    let Some(paths) = firmware_paths::measure(&config, &Table::ZERO) else {
        defmt::error!("PIL: the firmware's boot or save path failed on the RAM flash");
        return Err(());
    };
    let run_stack = stack::whole_run();
    defmt::info!(
        "PIL current_loop_instructions={=f64} speed_loop_instructions={=f64} pressure_loop_instructions={=f64} closed_loop_step_instructions={=f64} sin_cos_instructions={=f64} svpwm_instructions={=f64} bracket_overhead_instructions={=f64} instructions_per_tick_measured={=f64} calls={=u64} simulated_s={=f64} telemetry_rows={=u32} stack_peak_bytes={=u32} stack_size_bytes={=u32} closed_loop_step_stack_bytes={=u32} telemetry_emit_stack_bytes={=u32} boot_stack_bytes={=u32} parameter_save_stack_bytes={=u32} can_serve_stack_bytes={=u32} harness_setup_stack_bytes={=u32}",
        t_current.mean_instructions(&t_empty),
        t_speed.mean_instructions(&t_empty),
        t_pressure.mean_instructions(&t_empty),
        t_step.mean_instructions(&t_empty),
        t_sin_cos.mean_instructions(&t_empty),
        t_svpwm.mean_instructions(&t_empty),
        t_empty.mean_ticks() * icount::INSTRUCTIONS_PER_TICK as f64,
        per_tick,
        t_current.calls(),
        cl.time_s(),
        rows,
        run_stack.peak_bytes,
        run_stack.size_bytes,
        step_stack,
        emit_stack,
        paths.boot,
        paths.save,
        paths.serve,
        setup_stack
    );
    Ok(())
}

/// The loop and the feed-forward built into static memory, with the stack that took.
/// [bytes]
#[inline(never)]
fn setup(
    rig: &Rig,
    config: &firmware::Config,
    scenario: &closed_loop::Scenario,
) -> (
    Result<&'static mut ClosedLoop, closed_loop::BuildError>,
    Option<&'static Compensation>,
    u32,
) {
    let ((cl, ff), depth) =
        stack::depth(|| (build_loop(rig, config, scenario), feed_forward(config)));
    (cl, ff, depth)
}

static mut LOOP: MaybeUninit<ClosedLoop> = MaybeUninit::uninit();
static mut FEED_FORWARD: MaybeUninit<Compensation> = MaybeUninit::uninit();

/// The closed loop of the scenario, moved into static memory.
#[inline(never)]
fn build_loop(
    rig: &Rig,
    config: &firmware::Config,
    scenario: &closed_loop::Scenario,
) -> Result<&'static mut ClosedLoop, closed_loop::BuildError> {
    let cl = ClosedLoop::new(rig, config, scenario, SEED)?;
    // SAFETY: called once, before any reference to the static exists.
    Ok(unsafe { (*addr_of_mut!(LOOP)).write(cl) })
}

/// [`active_feed_forward`], moved into static memory.
#[inline(never)]
fn feed_forward(config: &firmware::Config) -> Option<&'static Compensation> {
    let c = active_feed_forward(config)?;
    // SAFETY: called once, before any reference to the static exists.
    Some(unsafe { (*addr_of_mut!(FEED_FORWARD)).write(c) })
}

/// An active feed-forward for the measurement: every channel non-zero (a 72/rev line in
/// the constant channel, 18/rev per pressure, 24/rev per current, a few percent of the
/// nominal rig's torques), so the step takes its full path; and the speed modulation
/// against a 9-piston pump's flow ripple, so the speed-loop step does too.
fn active_feed_forward(config: &firmware::Config) -> Option<Compensation> {
    let mut cfg = *config;
    cfg.compensation.enabled = true;
    // The speed modulation of a 9-piston pump's kinematic ripple.
    cfg.compensation.flow_pistons = 9;
    cfg.compensation.flow_ratio = 0.0152;
    let mut raw = [[0i16; CHANNELS]; BINS];
    for (b, r) in raw.iter_mut().enumerate() {
        let th = b as f32 * core::f32::consts::TAU / BINS as f32;
        let line = |k: f32| libm::sinf(k * th) * 20_000.0;
        *r = [line(72.0) as i16, line(18.0) as i16, line(24.0) as i16];
    }
    // 0.05 A, 1.2e-9 A/Pa (6 mA at 5 MPa), 0.02 A/A full scale.
    let table = Table::from_raw([19, 44, 20], &raw)?;
    let mut c = Compensation::new(&cfg);
    c.install(&table, &cfg).ok()?;
    (c.is_active() && c.flow().is_active()).then_some(c)
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    semihosting::process::exit(101)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("PIL panicked: {}", defmt::Display2Format(info));
    semihosting::process::exit(101)
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    defmt::error!("PIL: HardFault");
    semihosting::process::exit(102)
}
