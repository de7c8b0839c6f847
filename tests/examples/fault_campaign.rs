//! The closed-loop fault campaign: `cargo run --release -p tests --example fault_campaign --
//! [SEED] [PER_CLASS] [BASES_PER_SCENARIO]` (defaults 18, 37, 12: 1036 injections) prints
//! the table (docs/fault-campaign.md records it) and exits 1 when an injection failed.
//! `CAMPAIGN_CASE=K` runs case K alone (as it runs in the whole campaign);
//! `CAMPAIGN_VERBOSE=1` adds one line per injection on stderr.

use rayon::prelude::*;
use std::time::Instant;
use tests::campaign::{plan, run_base, table, Outcome};

fn main() {
    let arg = |k: usize, d: u64| {
        std::env::args()
            .nth(k)
            .map(|s| {
                s.parse()
                    .unwrap_or_else(|_| panic!("argument {k}: a whole number"))
            })
            .unwrap_or(d)
    };
    let (seed, per_class, bases) = (arg(1, 18), arg(2, 37) as usize, arg(3, 12) as usize);
    let p = plan(seed, per_class, bases);
    // One case alone (its own draws make it run as in the whole campaign).
    let only: Option<usize> = std::env::var("CAMPAIGN_CASE")
        .ok()
        .map(|v| v.parse().expect("CAMPAIGN_CASE: a case index"));
    let start = Instant::now();
    let mut outcomes: Vec<Outcome> = (0..p.bases.len())
        .into_par_iter()
        .flat_map_iter(|b| {
            let mut v = Vec::new();
            run_base(&p, b, only, |o| v.push(o));
            v
        })
        .collect();
    outcomes.sort_by_key(|o| o.index);
    print!("{}", table(seed, &outcomes));
    if std::env::var_os("CAMPAIGN_VERBOSE").is_some() {
        for o in &outcomes {
            eprintln!("{}", tests::campaign::describe(o));
        }
    }
    eprintln!(
        "{} injections in {:.1} s",
        outcomes.len(),
        start.elapsed().as_secs_f64()
    );
    if outcomes.iter().any(|o| !o.passed()) {
        std::process::exit(1);
    }
}
