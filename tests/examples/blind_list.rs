//! Lists what the blind generator draws for a range of seeds, without simulating them: the
//! hidden effect, the scenario, the columns dropped and the truth (a tool to pick held-out
//! draws of one kind: `cargo run --release -p tests --example blind_list -- FROM TO`, then
//! `blind_log` to write the chosen ones).

use tests::blind::draw;

fn main() {
    let usage = "usage: blind_list FROM TO (seeds FROM..TO)";
    let mut args = std::env::args().skip(1);
    let mut seed = || -> u64 {
        args.next().and_then(|a| a.parse().ok()).unwrap_or_else(|| {
            eprintln!("{usage}");
            std::process::exit(2)
        })
    };
    let (from, to) = (seed(), seed());
    for seed in from..to {
        let d = draw(seed);
        println!(
            "{seed} {} {} dropped={:?} {:?} {:?}",
            d.truth.effect_name,
            d.truth.scenario,
            d.structure.dropped,
            d.truth.parameters,
            d.structure.controller
        );
    }
}
