//! The encoder's rounding in the diagnosis's angle-locked lines, end to end.
//!
//! A current-sensor offset ripples the shaft's speed at the electrical order. Read through
//! a 10 000-count encoder at 500 Hz, that ripple spreads the angle's rounding error into a
//! comb of whole orders (`host_sim::diagnose::count_lines`), and the torque balance's
//! J·(k·ω̄)² turns its microradians at the pump's order into a torque line no effect made.
//! The generator's draw 4500019 (outside the suite's seeds) is such a log: a stroke with a
//! 0.62 A offset and nothing else hidden. Logged again by the same closed loop with a
//! 2¹⁸-count encoder, the same log has no line at the pump's order (checked when the count
//! floor was added); with the rounding's lines counted as the line's noise, the diagnosis
//! names the offset alone.

use host_sim::diagnose::diagnose;
use plant_model::Rig;
use tests::blind::draw;

#[test]
fn an_offsets_speed_ripple_read_in_counts_is_not_the_pumps_ripple() {
    let (d, _) = draw(4_500_019).expect("draw");
    assert_eq!(d.truth.label(), "current_sensor_offset");
    assert_eq!(d.truth.test, "stroke");
    assert_eq!(d.log_rate_hz, 500.0);
    let mut log = d.log(&d.truth_rig(), Some(d.noise_seed)).expect("log");
    d.structure.drop_columns(&mut log);
    let found = diagnose(&log, &Rig::nominal()).expect("diagnosis");
    assert_eq!(
        found.extended.effects,
        ["current_sensor_offset"],
        "causes: {:?}",
        found
            .causes
            .iter()
            .map(|c| (&c.effect, c.score, &c.evidence))
            .collect::<Vec<_>>()
    );
}
