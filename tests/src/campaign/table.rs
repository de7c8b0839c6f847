//! The campaign's table: fault class × outcome counts, the worst detection times, the
//! worst overshoots, and what the drive did with what it could not see.

use super::catalogue::Class;
use super::run::{Outcome, Verdict};
use std::fmt::Write as _;

/// Per-class sums.
#[derive(Default)]
struct Row {
    n: usize,
    verdicts: [usize; 6],
    violations: usize,
    worst_detect_s: Option<f64>,
    worst_visible_s: Option<f64>,
    peak_current_a: f64,
    over_current_s: f64,
    peak_pressure_pa: f64,
    blind_pressure_error_pa: f64,
    blind_speed_error_rad_s: f64,
    clear_refused: usize,
    clear_tried: usize,
}

fn verdict_index(v: Verdict) -> usize {
    match v {
        Verdict::Detected => 0,
        Verdict::Late => 1,
        Verdict::Missed => 2,
        Verdict::WrongCode => 3,
        Verdict::RodeThrough => 4,
        Verdict::Unpredicted => 5,
    }
}

fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

fn ms(x: Option<f64>) -> String {
    x.map_or("-".into(), |s| format!("{:.2}", s * 1e3))
}

/// The table of `outcomes` from the campaign of `seed`.
pub fn table(seed: u64, outcomes: &[Outcome]) -> String {
    let mut rows: Vec<(Class, Row)> = Class::ALL.iter().map(|c| (*c, Row::default())).collect();
    let mut total = Row::default();
    for o in outcomes {
        let Some((_, r)) = rows.iter_mut().find(|(c, _)| *c == o.class) else {
            continue;
        };
        for r in [r, &mut total] {
            r.n += 1;
            r.verdicts[verdict_index(o.verdict)] += 1;
            r.violations += usize::from(!o.invariants_held());
            if o.verdict != Verdict::RodeThrough {
                r.worst_detect_s = max_opt(r.worst_detect_s, o.detect_s);
            }
            r.worst_visible_s = max_opt(r.worst_visible_s, o.from_visible_s);
            r.peak_current_a = r.peak_current_a.max(o.peak_current_a);
            r.over_current_s = r.over_current_s.max(o.over_current_s);
            r.peak_pressure_pa = r.peak_pressure_pa.max(o.peak_pressure_pa);
            if o.verdict == Verdict::RodeThrough {
                r.blind_pressure_error_pa = r.blind_pressure_error_pa.max(o.pressure_error_pa);
                r.blind_speed_error_rad_s = r.blind_speed_error_rad_s.max(o.speed_error_rad_s);
            }
            if let Some(refused) = o.clear_refused {
                r.clear_tried += 1;
                r.clear_refused += usize::from(refused);
            }
        }
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fault campaign, seed {seed}: {} injections\n\
         det = latched a right code in time; late/miss/wrong = failures; blind = no rule fired \
         and nothing latched (what the drive did: largest pressure and speed error while it \
         acted); unpr = latched with no rule fired; viol = an invariant broken (PWM after \
         latch, over-current > 1 PWM period, pressure above the relief setting, NaN, no \
         restart after repair, a reject sent for another node's frame); detect = injection to latch, vis = first rule to latch; \
         I>lim = longest run of a bridge current above the 45 A trip; clear = refused/tried \
         with the cause present\n",
        outcomes.len()
    );
    let _ = writeln!(
        s,
        "| class | n | det | late | miss | wrong | blind | unpr | viol | detect ms | vis ms | peak I A | I>lim µs | peak p MPa | blind Δp MPa | blind Δω rad/s | clear |"
    );
    let _ = writeln!(
        s,
        "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
    );
    let line = |s: &mut String, name: &str, r: &Row| {
        let v = r.verdicts;
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.2} | {} | {} | {}/{} |",
            r.n,
            v[0],
            v[1],
            v[2],
            v[3],
            v[4],
            v[5],
            r.violations,
            ms(r.worst_detect_s),
            ms(r.worst_visible_s),
            r.peak_current_a,
            r.over_current_s * 1e6,
            r.peak_pressure_pa / 1e6,
            if v[4] > 0 {
                format!("{:.3}", r.blind_pressure_error_pa / 1e6)
            } else {
                "-".into()
            },
            if v[4] > 0 {
                format!("{:.2}", r.blind_speed_error_rad_s)
            } else {
                "-".into()
            },
            r.clear_refused,
            r.clear_tried
        );
    };
    for (c, r) in &rows {
        if r.n > 0 {
            line(&mut s, c.name(), r);
        }
    }
    line(&mut s, "**all**", &total);
    let failures: Vec<&Outcome> = outcomes.iter().filter(|o| !o.passed()).collect();
    if !failures.is_empty() {
        let _ = writeln!(s, "\nfailures ({}):", failures.len());
        for o in failures.iter().take(40) {
            let _ = writeln!(s, "{}", describe(o));
        }
    }
    let unpredicted: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.verdict == Verdict::Unpredicted)
        .collect();
    if !unpredicted.is_empty() {
        let _ = writeln!(s, "\nunpredicted trips ({}):", unpredicted.len());
        for o in unpredicted.iter().take(40) {
            let _ = writeln!(s, "{}", describe(o));
        }
    }
    s
}

/// One line about one injection.
pub fn describe(o: &Outcome) -> String {
    format!(
        "#{} {} [{}] in {} at {:.4} s: {:?}, rule {:?}, latched {:?} after {} ms; peak I {:.1} A, I>lim {:.1} µs, peak p {:.2} MPa (limit {:.2}); against the twin Δp {:.3} MPa, Δω {:.1} rad/s; PWM after latch {}, NaN {}, rejects to other nodes {}, recovered {} {}",
        o.index,
        o.class.name(),
        o.description,
        o.scenario.name(),
        o.t_inject_s,
        o.verdict,
        o.rule,
        o.latched.map(|f| f.code()),
        ms(o.detect_s),
        o.peak_current_a,
        o.over_current_s * 1e6,
        o.peak_pressure_pa / 1e6,
        o.pressure_limit_pa / 1e6,
        o.pressure_error_pa / 1e6,
        o.speed_error_rad_s,
        o.pwm_after_latch,
        o.nan,
        o.foreign_replies,
        o.recovered,
        o.recovery_note
    )
}
