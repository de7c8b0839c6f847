//! Writes the blind suite's log of each seed given on the command line into a directory and
//! prints what was hidden (and, for a piston ripple, the most a model of it could gain on
//! the log: `tests::blind::line_fit_bound`): a tool to inspect one seed with `eha diagnose`
//! (`cargo run --release -p tests --example blind_log -- DIR SEED…`).

use std::path::PathBuf;
use tests::blind::{draw, generate, line_fit_bound};

fn main() {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().expect("usage: blind_log DIR SEED…"));
    std::fs::create_dir_all(&dir).expect("create the directory");
    for seed in args {
        let seed: u64 = seed.parse().expect("a seed is an unsigned integer");
        let (path, truth) = generate(seed, &dir).expect("generate the log");
        let target = dir.join(format!("seed-{seed}.csv"));
        std::fs::rename(&path, &target).expect("rename the log");
        let bound = match line_fit_bound(&draw(seed)).expect("the ripple's bound") {
            Some(b) => format!(" (a ripple model gains at most {b:.1} points)"),
            None => String::new(),
        };
        println!(
            "{seed}: {} {:?} {} {}{bound}",
            truth.effect_name,
            truth.parameters,
            truth.scenario,
            target.display()
        );
    }
}
