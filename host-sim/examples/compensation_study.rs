//! The torque feed-forward's closed-loop study of `docs/compensation.md`: prints its tables
//! (markdown). `cargo run --release -p host-sim --example compensation_study [LEVEL …]`
//! (levels in × the nominal rig's effects; default 1 and 3).

use host_sim::compensate::study::{markdown, rows_for};
use plant_model::Rig;

fn main() {
    let levels: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let levels = if levels.is_empty() {
        vec![1.0, 3.0]
    } else {
        levels
    };
    let rig = Rig::nominal();
    let mut rows = Vec::new();
    for level in levels {
        match rows_for(&rig, level) {
            Ok(r) => rows.extend(r),
            Err(e) => {
                eprintln!("study at {level}×: {e}");
                std::process::exit(1);
            }
        }
    }
    print!("{}", markdown(&rows));
}
