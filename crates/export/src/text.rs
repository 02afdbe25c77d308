//! Numbers as text, fast, and byte-identical to Rust's `Display`.
//!
//! The text formats (OBJ above all: a city is millions of coordinates) spend most of
//! their time turning numbers into decimal text. [`push_f32`] writes exactly what
//! `format!("{x}")` writes, several times faster: it takes the shortest round-trip digits
//! from `zmij` (Schubfach), breaks ties the way `core` does, and lays them out in plain
//! notation. That it matches `core` for every one of the 2³² `f32` bit patterns is checked
//! by the ignored test `f32_text_matches_display_for_every_f32` (about six minutes on
//! two cores); a property test samples it on every run.

/// Appends `x` exactly as `format!("{x}")` would: the shortest decimal that reads back to
/// the same `f32`, in plain notation (`0.000001`, `123456790`, `-0`), a midpoint between
/// two shortest candidates rounded away from zero; `NaN`, `inf`, `-inf` as `core` spells
/// them.
pub(crate) fn push_f32(out: &mut Vec<u8>, x: f32) {
    if !x.is_finite() {
        use std::io::Write;
        // Writing into a vector cannot fail.
        let _ = write!(out, "{x}");
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let text = buffer.format_finite(x).as_bytes();
    let (negative, text) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, text),
    };
    // zmij writes `digits[.digits][e±exponent]`; read the significant digits `d` and the
    // decimal exponent `q` of the value d × 10^q.
    let (mantissa, exponent) = match text.iter().position(|&c| c == b'e') {
        Some(i) => (
            text.get(..i).unwrap_or_default(),
            parse_exponent(text.get(i + 1..).unwrap_or_default()),
        ),
        None => (text, 0),
    };
    let mut d: u64 = 0;
    let mut fraction_digits = 0i32;
    let mut after_point = false;
    for &c in mantissa {
        if c == b'.' {
            after_point = true;
        } else {
            d = d * 10 + u64::from(c.wrapping_sub(b'0'));
            fraction_digits += i32::from(after_point);
        }
    }
    let mut q = exponent - fraction_digits;
    if negative {
        out.push(b'-');
    }
    if d == 0 {
        out.push(b'0');
        return;
    }
    strip_zeros(&mut d, &mut q);
    // A value exactly halfway between two shortest candidates: zmij rounds to the even
    // one, `core` away from zero. Both read back to `x`.
    if is_midpoint_above(d, q, x) {
        d += 1;
        strip_zeros(&mut d, &mut q);
    }
    let mut digits = itoa::Buffer::new();
    let digits = digits.format(d).as_bytes();
    let n = digits.len() as i32;
    // The value is 0.digits × 10^k.
    let k = n + q;
    if k <= 0 {
        out.extend_from_slice(b"0.");
        out.resize(out.len() + (-k) as usize, b'0');
        out.extend_from_slice(digits);
    } else if k < n {
        let (whole, fraction) = digits.split_at(k as usize);
        out.extend_from_slice(whole);
        out.push(b'.');
        out.extend_from_slice(fraction);
    } else {
        out.extend_from_slice(digits);
        out.resize(out.len() + (k - n) as usize, b'0');
    }
}

/// Moves trailing zeros of `d` (non-zero) into the exponent `q`.
fn strip_zeros(d: &mut u64, q: &mut i32) {
    while *d != 0 && d.is_multiple_of(10) {
        *d /= 10;
        *q += 1;
    }
}

/// Appends `n` in decimal.
pub(crate) fn push_u64(out: &mut Vec<u8>, n: u64) {
    out.extend_from_slice(itoa::Buffer::new().format(n).as_bytes());
}

/// The exponent after zmij's `e`: an optional sign and decimal digits.
fn parse_exponent(text: &[u8]) -> i32 {
    let (sign, digits) = match text.split_first() {
        Some((b'-', rest)) => (-1, rest),
        Some((b'+', rest)) => (1, rest),
        _ => (1, text),
    };
    sign * digits
        .iter()
        .fold(0i32, |e, &c| e * 10 + i32::from(c.wrapping_sub(b'0')))
}

/// Whether |x| is exactly (d + ½) × 10^q, in exact integer arithmetic.
///
/// |x| = m × 2^e. The equation (2d + 1) × 10^q = m × 2^(e+1) holds exactly when both
/// sides have the same part prime to 10 and the same powers of 2 and of 5; 2d + 1 is odd,
/// so its powers of 2 come from 10^q alone.
fn is_midpoint_above(d: u64, q: i32, x: f32) -> bool {
    let bits = x.to_bits() & 0x7fff_ffff;
    let (mut m, mut e) = (u64::from(bits & 0x7f_ffff), (bits >> 23) as i32);
    if e == 0 {
        e = 1; // subnormal
    } else {
        m |= 1 << 23;
    }
    e -= 150;
    if m == 0 {
        return false;
    }
    let Some(lhs) = d.checked_mul(2).and_then(|v| v.checked_add(1)) else {
        return false;
    };
    let (a, fives_a) = without_fives(lhs);
    let twos_m = m.trailing_zeros() as i32;
    let (b, fives_m) = without_fives(m >> twos_m);
    a == b && q == e + 1 + twos_m && q + fives_a == fives_m
}

/// `v` without its factors of 5, and how many there were.
fn without_fives(mut v: u64) -> (u64, i32) {
    let mut count = 0;
    while v != 0 && v.is_multiple_of(5) {
        v /= 5;
        count += 1;
    }
    (v, count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn text(x: f32) -> String {
        let mut out = Vec::new();
        push_f32(&mut out, x);
        String::from_utf8(out).unwrap_or_default()
    }

    #[test]
    fn known_values_match_display() {
        let cases = [
            0.0f32,
            -0.0,
            1.0,
            -1.5,
            0.1,
            1e-7,
            1.0e20,
            123_456_790.0,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            f32::EPSILON,
            f32::from_bits(1), // the smallest subnormal
            f32::from_bits(0x007f_ffff),
            // Midpoints between two shortest candidates, where zmij alone rounds to even.
            f32::from_bits(0x4001_4000), // 2.01953125: 2.0195313
            f32::from_bits(0x4000_4000), // 2.00390625: 2.0039063
            16_777_216.0,
            0.3,
            2.5,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for x in cases {
            assert_eq!(text(x), format!("{x}"), "bits {:#x}", x.to_bits());
        }
    }

    #[test]
    fn integers_match_display() {
        for n in [
            0u64,
            1,
            9,
            10,
            99,
            100,
            12_345,
            u64::from(u32::MAX),
            u64::MAX,
        ] {
            let mut out = Vec::new();
            push_u64(&mut out, n);
            assert_eq!(out, n.to_string().into_bytes());
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        #[test]
        fn any_f32_matches_display(bits in any::<u32>()) {
            let x = f32::from_bits(bits);
            prop_assert_eq!(text(x), format!("{x}"));
        }

        /// Values with few binary digits, where midpoints live.
        #[test]
        fn short_f32_match_display(m in 0u32..(1 << 12), e in -40i32..40) {
            let x = m as f32 * 2f32.powi(e);
            prop_assert_eq!(text(x), format!("{x}"));
        }
    }

    /// Every `f32` bit pattern (about six minutes on two cores in release mode):
    /// `cargo test -p polis-export --release -- --ignored f32_text_matches_display`.
    #[test]
    #[ignore]
    fn f32_text_matches_display_for_every_f32() {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let total = 1u64 << 32;
        let per = total.div_ceil(threads);
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                std::thread::spawn(move || {
                    let (mut ours, mut theirs) = (Vec::new(), String::new());
                    let mut wrong = Vec::new();
                    for bits in t * per..((t + 1) * per).min(total) {
                        let x = f32::from_bits(bits as u32);
                        ours.clear();
                        theirs.clear();
                        push_f32(&mut ours, x);
                        use std::fmt::Write;
                        let _ = write!(theirs, "{x}");
                        if ours != theirs.as_bytes() && wrong.len() < 10 {
                            wrong.push(bits as u32);
                        }
                    }
                    wrong
                })
            })
            .collect();
        let wrong: Vec<u32> = handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect();
        assert!(wrong.is_empty(), "differs from Display at bits {wrong:x?}");
    }
}
