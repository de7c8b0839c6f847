//! Scores `eha diagnose` on a directory of bench logs with a `truth.json` beside them, in
//! the layout of `shared/data/foreign-logs/` and `foreign-logs-2/` (gunzipped): an entry
//! per log with its `effect` and `parameters`, or for a pair `"effect": "a+b"` and an
//! `effects` list. Each log is diagnosed against the nominal rig; it is right when
//! `extended.effects` names exactly the hidden effects (`none`: an empty list) and each
//! hidden effect's main parameter, as its cause gives it, is within 25 %
//! (`tests::blind::table`). Prints one Markdown row per log, the failures with the causes'
//! evidence, and the count by test, nothing hidden, one effect and pairs; the time is of
//! the diagnosis alone, one run, logs taken one after another.
//!
//! `--drop COLUMN[,COLUMN…]` reads every log without those optional columns, as a bench
//! that did not log them would have written it (`--drop theta_m_rad`: no angle).
//! `--rows first:SHARE` or `--rows last:SHARE` reads only that share of each log's rows:
//! a shorter log of the same test, or one whose recorder started late
//! (`tests::blind::cut`).
//!
//! ```text
//! cargo run --release -p tests --example foreign_table -- DIR [--drop COLUMNS] [--rows first:0.45]
//! ```

use std::path::Path;
use std::process::ExitCode;
use tests::blind::cut::Cut;
use tests::blind::judge::PARAMETER_TOLERANCE;
use tests::blind::table::score_dir;

const USAGE: &str = "usage: foreign_table DIR [--drop COLUMN[,COLUMN…]] \
                     [--rows first:SHARE|last:SHARE] (bench logs and truth.json)";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((dir, options)) = args.split_first() else {
        eprintln!("{USAGE}");
        return ExitCode::from(2);
    };
    let (mut drop, mut cut) = (Vec::new(), None);
    let mut rest = options.iter();
    while let Some(flag) = rest.next() {
        match (flag.as_str(), rest.next()) {
            ("--drop", Some(columns)) => drop.extend(columns.split(',')),
            ("--rows", Some(rows)) => match Cut::parse(rows) {
                Ok(c) => cut = Some(c),
                Err(e) => {
                    eprintln!("foreign_table: --rows {e}");
                    return ExitCode::from(2);
                }
            },
            _ => {
                eprintln!("{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
    match score_dir(Path::new(dir), &drop, cut) {
        Ok(tally) => {
            let (right, n) = tally.total();
            println!("\n{}", tally.markdown());
            println!(
                "{right} of {n} right (exactly the hidden effects, each main parameter \
                 within {:.0} %)",
                100.0 * PARAMETER_TOLERANCE
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("foreign_table: {e}");
            ExitCode::from(2)
        }
    }
}
