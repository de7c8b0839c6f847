//! `eha watch` without hardware: the PIL's recorded defmt telemetry (`tests/data`) fed to
//! the binary as `probe-rs run` would, on a pipe and as a file being written.
//!
//! - Under tmux (a real terminal): the screen is captured and must show the mode and the
//!   latched fault by the firmware's names, the counts, the pulsation and the traces; `q`
//!   quits with the log written.
//! - Without a terminal: the counts on standard error, the log's values against the
//!   recording's text (split here, not by the project's parser), a last line without its
//!   line break kept, a followed file finished by Ctrl-C with nothing lost or left behind.
//!
//! tmux is required (`cargo xtask test` installs it): a missing tmux fails the test.

mod common;

use common::{s, scratch};
use firmware::{FaultCode, Mode};
use std::fs;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const RECORDING: &str = include_str!("data/pil-telemetry.log");

/// The recording's telemetry lines.
fn telemetry() -> Vec<&'static str> {
    RECORDING.lines().filter(|l| l.contains("EHA1 ")).collect()
}

/// The text of `key`'s value in a telemetry line, split by hand.
fn text_of<'a>(line: &'a str, key: &str) -> &'a str {
    let start = line.find(&format!(" {key}=")).unwrap() + key.len() + 2;
    let rest = &line[start..];
    &rest[..rest.find(' ').unwrap_or(rest.len())]
}

/// A field the line format sends as `f64` (time) or an integer code.
fn field(line: &str, key: &str) -> f64 {
    text_of(line, key).parse().unwrap()
}

/// A field the line format sends as `f32`, widened as the bench log holds it.
fn field32(line: &str, key: &str) -> f64 {
    f64::from(text_of(line, key).parse::<f32>().unwrap())
}

/// The recording with a boot message first, a garbled telemetry line in the middle and
/// the last `faulted` frames latching fault 9.
fn session_text(faulted: usize) -> String {
    let lines = telemetry();
    let mut text = String::from("INFO  EHA drive up (node 1)\n");
    for (k, l) in lines.iter().enumerate() {
        if k == 400 {
            text.push_str("INFO  EHA1 t_s=0.2 p_ref_pa=garbled\n");
        }
        let l = if k + faulted >= lines.len() {
            l.replace(" fault=0 ", " fault=9 ")
        } else {
            l.to_string()
        };
        text.push_str(&l);
        text.push('\n');
    }
    text
}

fn tmux(socket: &str, args: &[&str]) -> std::process::Output {
    Command::new("tmux")
        .arg("-L")
        .arg(socket)
        .args(args)
        .output()
        .expect("tmux is installed (cargo xtask test installs it)")
}

/// Polls `f` every 100 ms for up to `limit`.
fn wait_for(limit: Duration, mut f: impl FnMut() -> bool) -> bool {
    let start = Instant::now();
    while start.elapsed() < limit {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    false
}

#[test]
fn the_live_view_under_tmux_shows_mode_fault_counts_pulsation_and_traces() {
    let d = scratch("watch", "tmux");
    let input = d.join("probe-rs.txt");
    fs::write(&input, session_text(50)).unwrap();
    let log = d.join("bench.csv");
    let status = d.join("status.txt");
    let socket = format!("eha-watch-test-{}", std::process::id());
    let command = format!(
        "cat '{}' | '{}' watch --out '{}'; echo $? > '{}'",
        s(&input),
        env!("CARGO_BIN_EXE_eha"),
        s(&log),
        s(&status)
    );
    let o = tmux(
        &socket,
        &[
            "new-session",
            "-d",
            "-x",
            "120",
            "-y",
            "40",
            "-s",
            "watch",
            &command,
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut screen = String::new();
    let ended = wait_for(Duration::from_secs(60), || {
        let o = tmux(&socket, &["capture-pane", "-p", "-t", "watch"]);
        screen = String::from_utf8_lossy(&o.stdout).into_owned();
        screen.contains("stream ended") && screen.contains("written")
    });
    let quit = tmux(&socket, &["send-keys", "-t", "watch", "q"]);
    let exited = wait_for(Duration::from_secs(20), || status.exists());
    let _ = tmux(&socket, &["kill-server"]);
    assert!(
        ended,
        "the view never showed the end of the stream:\n{screen}"
    );
    assert!(quit.status.success());
    assert!(exited, "q did not end the view:\n{screen}");
    assert_eq!(fs::read_to_string(&status).unwrap().trim(), "0");

    // The recording's mode code and the injected fault, by the firmware's names.
    let mode = Mode::from_code(field(telemetry()[0], "mode") as u8).unwrap();
    for expected in [
        format!("mode {}", mode.name()),
        format!("fault {}", FaultCode::OverSpeed),
        "frames 1000".to_string(),
        "other lines 1".to_string(),
        "malformed 1 (first: line 402".to_string(),
        "pulsation (last 1 s)".to_string(),
        "kPa p-p".to_string(),
        "= order".to_string(),
        format!("log {}: 1000 rows, written", s(&log)),
        "p_pa".into(),
        "p_ref_pa".into(),
        "speed_rad_s".into(),
        "speed_ref_rad_s".into(),
        "iq_a".into(),
    ] {
        assert!(
            screen.contains(&expected),
            "`{expected}` not on the screen:\n{screen}"
        );
    }
    // Three trace panels, each with its axis labels: the traces have been drawn.
    assert!(screen.matches("[MPa]").count() == 1, "{screen}");
    assert!(screen.matches("[rad/s]").count() == 1, "{screen}");
    assert!(screen.matches("[A]").count() == 1, "{screen}");
    let braille = screen
        .chars()
        .filter(|c| ('\u{2801}'..='\u{28FF}').contains(c))
        .count();
    assert!(braille > 300, "{braille} trace dots:\n{screen}");
    let written = host_sim::bench_log::read(&log).unwrap();
    assert_eq!(written.len(), 1000);
}

/// Runs `eha watch ARGS` with `input` on standard input and no terminal.
fn headless(args: &[&str], input: &[u8]) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_eha"))
        .arg("watch")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Checks that `log` holds the recording's frames, value for value.
fn check_log_values(log: &Path, frames: usize) {
    let written = host_sim::bench_log::read(log).unwrap();
    assert_eq!(written.len(), frames);
    for (k, line) in telemetry().iter().enumerate().take(frames) {
        assert_eq!(written.t_s[k], field(line, "t_s"), "row {k}");
        assert_eq!(written.p_pa[k], field32(line, "p_pa"), "row {k}");
        assert_eq!(
            written.speed_rad_s[k],
            field32(line, "speed_rad_s"),
            "row {k}"
        );
        assert_eq!(written.iq_a[k], field32(line, "iq_a"), "row {k}");
        assert_eq!(written.id_a[k], field32(line, "id_a"), "row {k}");
    }
}

#[test]
fn without_a_terminal_it_counts_the_lines_and_keeps_a_last_line_without_its_break() {
    let d = scratch("watch", "headless");
    let log = d.join("bench.csv");
    let mut text = session_text(0);
    // The stream ends in the middle of a line that is nonetheless a whole frame (the
    // probe was unplugged before the line break), after a line cut short.
    let last = telemetry().pop().unwrap().to_string();
    let cut = &last[..last.len() / 2];
    text = text.replace(&format!("{last}\n"), &format!("{cut}\n{last}"));
    let o = headless(&["--out", s(&log)], text.as_bytes());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(o.stdout.is_empty());
    for expected in [
        "1000 telemetry frames of 1003 lines from standard input",
        "1 other lines skipped",
        "2 malformed; first at line 402: field `p_ref_pa` is not a number",
        "1000 rows written to",
    ] {
        assert!(err.contains(expected), "`{expected}` not in: {err}");
    }
    check_log_values(&log, 1000);
    let written = host_sim::bench_log::read(&log).unwrap();
    assert_eq!(written.meta("malformed_lines"), Some("2"));
    assert_eq!(written.meta("watched_from"), Some("standard input"));
    assert_eq!(entries(&d), ["bench.csv"]);
}

#[test]
fn a_followed_file_is_logged_as_it_grows_and_ctrl_c_finishes_the_log() {
    let d = scratch("watch", "follow");
    let stream = d.join("probe-rs.txt");
    let log = d.join("bench.csv");
    let text = session_text(0);
    let half = text.len() / 2;
    fs::write(&stream, &text[..half]).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_eha"))
        .args(["watch", s(&stream), "--out", s(&log)])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(400));
    // The decoder writes on; the watcher follows the file.
    fs::OpenOptions::new()
        .append(true)
        .open(&stream)
        .unwrap()
        .write_all(&text.as_bytes()[half..])
        .unwrap();
    std::thread::sleep(Duration::from_millis(800));
    assert!(!log.exists(), "the log appears only when finished");
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("1000 rows written to"), "{err}");
    check_log_values(&log, 1000);
    assert_eq!(entries(&d), ["bench.csv", "probe-rs.txt"]);
}

#[test]
fn too_few_frames_write_no_log_and_bad_signals_are_refused() {
    let d = scratch("watch", "few");
    let log = d.join("bench.csv");
    let text: String = telemetry()[..10].iter().map(|l| format!("{l}\n")).collect();
    let o = headless(&["--out", s(&log)], text.as_bytes());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("only 10 telemetry frames"), "{err}");
    assert!(entries(&d).is_empty(), "{:?}", entries(&d));

    let o = headless(&["--signals", "p_pa+pressure"], b"");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("`pressure` is not a telemetry signal"),
        "{err}"
    );
}
