//! The value tables (`VAL_`) from the firmware's enumerations: modes, fault codes,
//! functions, reject reasons, step-test loops and parameter ids by name; and the
//! parameter value signals `SetParameter` and `Parameter` share, multiplexed by the id,
//! in each parameter's unit and bounds from `firmware::parameters`.

use super::signal::{ascii, shortest, signal, Kind, Mux, Signal};
use firmware::can_protocol::{Function, RejectReason};
use firmware::parameters::ParamId;
use firmware::step_test::StepLoop;
use firmware::{FaultCode, Mode};

/// "BelowMinimum" → "below minimum".
pub fn words(debug_name: &str) -> String {
    let mut out = String::new();
    for (k, c) in debug_name.chars().enumerate() {
        if c.is_uppercase() && k > 0 {
            out.push(' ');
        }
        out.extend(c.to_lowercase());
    }
    out
}

/// Mode codes and names.
pub fn mode_choices() -> Vec<(i64, String)> {
    Mode::ALL
        .iter()
        .map(|m| (i64::from(m.code()), m.name().to_string()))
        .collect()
}

/// Fault codes and what they mean (0: none).
pub fn fault_choices() -> Vec<(i64, String)> {
    let mut v = vec![(0, "none".to_string())];
    v.extend(
        FaultCode::ALL
            .iter()
            .map(|f| (i64::from(f.code()), ascii(f.description()))),
    );
    v
}

/// Function codes and the commands' names.
pub fn function_choices() -> Vec<(i64, String)> {
    Function::ALL
        .iter()
        .map(|f| (i64::from(f.code()), format!("{f:?}")))
        .collect()
}

pub(super) fn reason_choices() -> Vec<(i64, String)> {
    RejectReason::ALL
        .iter()
        .map(|r| (i64::from(r.code()), words(&format!("{r:?}"))))
        .collect()
}

pub(super) fn loop_choices() -> Vec<(i64, String)> {
    StepLoop::ALL
        .iter()
        .map(|l| (i64::from(l.code()), words(&format!("{l:?}"))))
        .collect()
}

pub(super) fn parameter_choices() -> Vec<(i64, String)> {
    ParamId::ALL
        .iter()
        .map(|p| (i64::from(p.code()), p.name().to_string()))
        .collect()
}

/// The signal name of a parameter's value (`speed.kp` → `speed_kp`).
pub fn parameter_signal(p: ParamId) -> String {
    p.name().replace('.', "_")
}

/// One value signal per parameter, multiplexed by the id at byte 0, the value at byte 1.
pub(super) fn parameter_values() -> Vec<Signal> {
    let mut v = vec![signal("ParameterId", 0, 8, Kind::Unsigned)
        .mux(Mux::Switch)
        .choices(parameter_choices())
        .about("parameter id (firmware::parameters)")];
    v.extend(ParamId::ALL.iter().map(|p| {
        signal(&parameter_signal(*p), 1, 32, Kind::Float)
            .unit(p.unit())
            .range(shortest(p.min()), shortest(p.max()))
            .mux(Mux::Case(p.code()))
            .about(&format!("{} [{}]", p.name(), p.unit()))
    }));
    v
}
