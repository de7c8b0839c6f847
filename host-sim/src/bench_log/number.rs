//! The bench log's number text: the shortest decimal that parses back to the same f64, in
//! the layout of Rust's own float formatting — positional (`{}`) for magnitudes in
//! [1e-5, 1e16) and zero, exponent notation (`{:e}`) beyond, where positional would spell
//! out dozens of zeros.
//!
//! The digits come from the `ryu` crate (Ryū, Adams 2018: the shortest round-trip digits,
//! the nearest of them when several are as short — the digits Rust's formatter chooses too),
//! at a fraction of the cost of `core::fmt`'s Grisu/Dragon path: formatting a log's numbers
//! took a fifth of an `eha simulate` run. The layout is rebuilt here from the digits and
//! their decimal exponent, so a file's text is byte for byte what `write!(s, "{v}")` or
//! `write!(s, "{v:e}")` gives (checked against them in the tests below).

/// Appends the text of `v` to `out`.
pub fn push(out: &mut String, v: f64) {
    let mut buf = Text::default();
    spell(&mut buf, v);
    out.push_str(buf.as_str());
}

/// Appends the text of `v` to the bytes `out`.
pub fn push_bytes(out: &mut Vec<u8>, v: f64) {
    let mut buf = Text::default();
    spell(&mut buf, v);
    out.extend_from_slice(&buf.bytes[..buf.len]);
}

/// A number's text, at most 26 bytes (`-1.2345678901234567e-308`).
struct Text {
    bytes: [u8; 40],
    len: usize,
}

impl Default for Text {
    fn default() -> Self {
        Text {
            bytes: [b'0'; 40],
            len: 0,
        }
    }
}

impl Text {
    fn push(&mut self, b: u8) {
        if self.len < self.bytes.len() {
            self.bytes[self.len] = b;
            self.len += 1;
        }
    }

    fn push_all(&mut self, s: &[u8]) {
        for b in s {
            self.push(*b);
        }
    }

    fn as_str(&self) -> &str {
        // Only ASCII is ever written.
        core::str::from_utf8(&self.bytes[..self.len]).unwrap_or("NaN")
    }
}

/// Spells `v` into `out`.
fn spell(out: &mut Text, v: f64) {
    let a = v.abs();
    let mut ryu_buf = ryu::Buffer::new();
    let decomposed = (v.is_finite() && a != 0.0).then(|| decompose(ryu_buf.format_finite(v)));
    // Two shortest decimals can be equally near a double; Ryū then takes the even one,
    // Rust the upper. Rust's own formatting spells the cases that may be such a tie (and
    // zero, NaN and the infinities, which never reach a checked log).
    let Some((negative, d, point)) = decomposed.filter(|(_, d, point)| !maybe_tie(v, d, *point))
    else {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
            write!(s, "{v}")
        } else {
            write!(s, "{v:e}")
        };
        out.push_all(s.as_bytes());
        return;
    };
    let digits = &d.buf[..d.len];
    if negative {
        out.push(b'-');
    }
    let n = digits.len() as i32;
    if (1e-5..1e16).contains(&a) {
        // Positional, the decimal point `point` digits after the first digit's place.
        if point <= 0 {
            out.push_all(b"0.");
            for _ in 0..-point {
                out.push(b'0');
            }
            out.push_all(digits);
        } else if point < n {
            let (int, frac) = digits.split_at(point as usize);
            out.push_all(int);
            out.push(b'.');
            out.push_all(frac);
        } else {
            out.push_all(digits);
            for _ in 0..point - n {
                out.push(b'0');
            }
        }
    } else {
        let (first, rest) = digits.split_at(1);
        out.push_all(first);
        if !rest.is_empty() {
            out.push(b'.');
            out.push_all(rest);
        }
        out.push(b'e');
        let exp = point - 1;
        if exp < 0 {
            out.push(b'-');
        }
        let e = exp.unsigned_abs();
        if e >= 100 {
            out.push(b'0' + (e / 100) as u8);
        }
        if e >= 10 {
            out.push(b'0' + (e / 10 % 10) as u8);
        }
        out.push(b'0' + (e % 10) as u8);
    }
}

/// Whether Ryū's `d` (decimal point at `point`) for `v` may be one of two equally near
/// shortest decimals. A tie needs the exact value to sit halfway between two n-digit
/// decimals: its own expansion is then n + 1 digits ending in 5. The exact value m·2^e
/// (m odd) is an integer for e ≥ 0, never such a midpoint; for e < 0 it has −e fractional
/// digits, point − e significant ones. So a tie needs e < 0, more exact digits than Ryū's n
/// but at most 18, and Ryū's last digit even (it rounds ties to even).
fn maybe_tie(v: f64, d: &Digits, point: i32) -> bool {
    let bits = v.to_bits();
    let raw_exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (m, mut e) = if raw_exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), raw_exp - 1075)
    };
    if m == 0 {
        return false;
    }
    e += m.trailing_zeros() as i32;
    let exact = point - e;
    let n = d.len as i32;
    e < 0 && n < exact && exact <= 18 && d.buf[d.len - 1] % 2 == 0
}

/// Significant decimal digits, at most 17 for an f64.
struct Digits {
    buf: [u8; 32],
    len: usize,
}

/// Sign, significant digits (no leading or trailing zeros) and the position of the decimal
/// point relative to the first of them (value = 0.d₁d₂… × 10^point) of Ryū's text of a
/// finite, non-zero number (`1.5`, `0.0001234`, `1e-7`, `1.2345e20`, `100.0`), in one pass
/// over its bytes.
fn decompose(text: &str) -> (bool, Digits, i32) {
    let bytes = text.as_bytes();
    let mut d = Digits {
        buf: [b'0'; 32],
        len: 0,
    };
    let mut k = 0;
    let negative = bytes.first() == Some(&b'-');
    if negative {
        k = 1;
    }
    // Digits before the point (or the exponent) count towards it; leading zeros move it.
    let mut point = 0i32;
    let mut seen_point = false;
    while let Some(&b) = bytes.get(k) {
        match b {
            b'0'..=b'9' => {
                if d.len == 0 && b == b'0' {
                    if seen_point {
                        point -= 1;
                    }
                } else {
                    if !seen_point {
                        point += 1;
                    }
                    if d.len < d.buf.len() {
                        d.buf[d.len] = b;
                        d.len += 1;
                    }
                }
            }
            b'.' => seen_point = true,
            _ => break,
        }
        k += 1;
    }
    // The exponent, if any, after the `e`.
    if bytes.get(k) == Some(&b'e') {
        k += 1;
        let neg = bytes.get(k) == Some(&b'-');
        if neg {
            k += 1;
        }
        let mut e = 0i32;
        while let Some(&b) = bytes.get(k) {
            e = 10 * e + i32::from(b - b'0');
            k += 1;
        }
        point += if neg { -e } else { e };
    }
    while d.len > 1 && d.buf[d.len - 1] == b'0' {
        d.len -= 1;
    }
    (negative, d, point)
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
        ] {
            assert_eq!(ours(v), std_text(v), "{v:?}");
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
