//! The bench log's number text: the shortest decimal that parses back to the same f64, in
//! the layout of Rust's own float formatting — positional (`{}`) for magnitudes in
//! [1e-5, 1e16) and zero, exponent notation (`{:e}`) beyond, where positional would spell
//! out dozens of zeros.
//!
//! The digits come from the `zmij` crate (Schubfach with a fast path: the shortest
//! round-trip digits, the nearest of them when several are as short — the digits Rust's
//! formatter chooses too), at a fraction of the cost of `core::fmt`'s Grisu/Dragon path and
//! about half of Ryū's. Its layout is Rust's but for a whole number's trailing `.0` (`100.0`
//! where Rust writes `100`) and a positive exponent's sign (`1e+16` where Rust writes
//! `1e16`): the same positional range (the decimal point between 4 places before the first
//! digit and 16 after it), the same exponent notation otherwise (`1e-7`, `1.234e33`). So the
//! text is zmij's with that suffix and that sign dropped, byte for byte what
//! `write!(s, "{v}")` or `write!(s, "{v:e}")` gives (checked against them in the tests
//! below), except where two shortest decimals may be equally near, which Rust's own
//! formatting spells.

/// Appends the text of `v` to `out`.
pub fn push(out: &mut String, v: f64) {
    let mut buf = zmij::Buffer::new();
    match spell(&mut buf, v) {
        Some([head, tail]) => {
            out.push_str(head);
            out.push_str(tail);
        }
        None => push_std(out, v),
    }
}

/// Appends the text of `v` to the bytes `out`.
pub fn push_bytes(out: &mut Vec<u8>, v: f64) {
    let mut buf = zmij::Buffer::new();
    match spell(&mut buf, v) {
        Some([head, tail]) => {
            out.extend_from_slice(head.as_bytes());
            out.extend_from_slice(tail.as_bytes());
        }
        None => {
            let mut s = String::new();
            push_std(&mut s, v);
            out.extend_from_slice(s.as_bytes());
        }
    }
}

/// Rust's own formatting of `v` in the log's layout (the reference, and the path of the
/// possible ties, NaN and the infinities, which never reach a checked log).
fn push_std(out: &mut String, v: f64) {
    use std::fmt::Write as _;
    let a = v.abs();
    let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

/// The text of `v` from zmij in `buf`, in two pieces to be written one after the other (the
/// second empty but for a positive exponent, whose sign falls between them), or `None` where
/// Rust's own formatting must spell it (not finite, or possibly a tie).
#[inline]
fn spell(buf: &mut zmij::Buffer, v: f64) -> Option<[&str; 2]> {
    if !v.is_finite() {
        return None;
    }
    let text = buf.format_finite(v);
    let text = text.strip_suffix(".0").unwrap_or(text);
    if maybe_tie(v, text.as_bytes()) {
        return None;
    }
    // Only magnitudes from 1e16 on are written with a positive exponent.
    if v.abs() >= 1e16 {
        if let Some(k) = text.find("e+") {
            return Some([&text[..=k], &text[k + 2..]]);
        }
    }
    Some([text, ""])
}

/// Whether zmij's `text` for `v` may be one of two equally near shortest decimals (which of
/// the two a formatter takes is its own rule: zmij's and Rust's need not agree). Equally
/// near n-digit decimals are neighbours (any between them would be nearer) and `v` is their
/// midpoint: its exact decimal expansion has n + 1 significant digits. The exact value
/// m·2^e (m odd) is an integer for e ≥ 0, never such a midpoint; for e < 0 it has −e
/// fractional digits, so point − e significant ones (value = 0.d₁d₂… × 10^point). So a tie
/// needs e < 0 and point − e = n + 1 ≤ 18. The decimal point's place is bounded from the
/// binary exponent first (10^(point − 1) ≤ |v| < 2^(E + 1)), which rules out nearly every
/// value before the text is read.
fn maybe_tie(v: f64, text: &[u8]) -> bool {
    let bits = v.to_bits();
    let raw_exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (m, e) = if raw_exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), raw_exp - 1075)
    };
    if m == 0 {
        return false;
    }
    let e = e + m.trailing_zeros() as i32;
    if e >= 0 {
        return false;
    }
    // |v| ≥ 2^E with E = raw_exp − 1023 (normal numbers): point ≥ ⌊E·log₁₀2⌋ + 1.
    if raw_exp != 0 {
        let lowest = (f64::from(raw_exp - 1023) * std::f64::consts::LOG10_2).floor() as i32 + 1;
        if lowest - e > 18 {
            return false;
        }
    }
    let (n, point) = digits_and_point(text);
    point - e == n + 1
}

/// The number of significant digits of zmij's `text` (finite, non-zero, its whole number's
/// `.0` dropped) and the place of its decimal point (value = 0.d₁d₂… × 10^point).
fn digits_and_point(text: &[u8]) -> (i32, i32) {
    let body = text.strip_prefix(b"-").unwrap_or(text);
    let (mantissa, exp) = match body.iter().position(|b| *b == b'e') {
        Some(k) => {
            let (m, rest) = body.split_at(k);
            let rest = &rest[1..];
            let (neg, digits) = match rest.strip_prefix(b"-") {
                Some(d) => (true, d),
                None => (false, rest.strip_prefix(b"+").unwrap_or(rest)),
            };
            let x = digits
                .iter()
                .fold(0i32, |x, b| 10 * x + i32::from(b - b'0'));
            (m, if neg { -x } else { x })
        }
        None => (body, 0),
    };
    let mut n = 0i32;
    let mut point = 0i32;
    let mut seen_point = false;
    let mut leading = true;
    let mut zeros = 0i32;
    for &b in mantissa {
        if b == b'.' {
            seen_point = true;
            continue;
        }
        if leading && b == b'0' {
            if seen_point {
                point -= 1;
            }
            continue;
        }
        leading = false;
        if !seen_point {
            point += 1;
        }
        if b == b'0' {
            zeros += 1;
        } else {
            n += zeros + 1;
            zeros = 0;
        }
    }
    (n, point + exp)
}

#[cfg(test)]
mod tests {
    use super::push;
    use rand_core::{RngCore, SeedableRng};
    use std::fmt::Write as _;

    /// Rust's own formatting, the layout the log has always had.
    fn std_text(v: f64) -> String {
        let a = v.abs();
        let mut s = String::new();
        let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
            write!(s, "{v}")
        } else {
            write!(s, "{v:e}")
        };
        s
    }

    fn ours(v: f64) -> String {
        let mut s = String::new();
        push(&mut s, v);
        s
    }

    #[test]
    fn text_is_rusts_own_for_chosen_values() {
        for v in [
            5e6,
            0.1,
            1e-13,
            -2.5e20,
            0.0,
            -0.0,
            1.0,
            100.0,
            1e15,
            9.999999999999998e15,
            1e16,
            1e-5,
            9.999999999999999e-6,
            0.000123,
            123.456,
            -7.0,
            1.0 / 3.0,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            4999874.5f32 as f64,
            0.1f32 as f64,
            1e300,
            1e-300,
            5.960464477539063e-8,
            280.1000061035156,
            f64::MIN_POSITIVE / 3.0,
        ] {
            assert_eq!(ours(v), std_text(v), "{v:?}");
        }
    }

    #[test]
    fn text_is_rusts_own_for_short_binary_fractions() {
        // Values with few exact decimal digits (m·2^−k, m small) hold the midpoints of two
        // shortest decimals, where zmij and Rust may choose differently.
        for k in 1..80 {
            for m in [
                1u64,
                3,
                5,
                7,
                11,
                13,
                255,
                1023,
                65535,
                0x1f_ffff,
                0x3f_ffff_ffff,
            ] {
                for s in [1.0, -1.0] {
                    let v = s * m as f64 * 2f64.powi(-k);
                    assert_eq!(ours(v), std_text(v), "{v:?}");
                    let w = v * 1e10;
                    assert_eq!(ours(w), std_text(w), "{w:?}");
                }
            }
        }
    }

    #[test]
    fn text_is_rusts_own_for_random_bits_and_f32_values() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(29);
        for _ in 0..200_000 {
            let v = f64::from_bits(rng.next_u64());
            if v.is_finite() {
                assert_eq!(ours(v), std_text(v), "{v:?} ({:#x})", v.to_bits());
            }
            // The telemetry's values are f32 widened to f64, the common case of a log.
            let w = f32::from_bits(rng.next_u32()) as f64;
            if w.is_finite() {
                assert_eq!(ours(w), std_text(w), "{w:?}");
            }
            // Ordinary magnitudes, where the positional layout is used.
            let m = (rng.next_u64() >> 11) as f64
                * 2f64.powi(-53)
                * 10f64.powi((rng.next_u32() % 30) as i32 - 8);
            assert_eq!(ours(m), std_text(m), "{m:?}");
        }
    }
}
