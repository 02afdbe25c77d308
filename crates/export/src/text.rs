//! Numbers as text, fast, and byte-identical to Rust's `Display`.
//!
//! The text formats (OBJ above all: a city is millions of coordinates) spend most of
//! their time turning numbers into decimal text. [`push_f32`] writes exactly what
//! `format!("{x}")` writes, several times faster: it takes the shortest round-trip digits
//! from `zmij` (Schubfach), breaks ties the way `core` does, and lays them out in plain
//! notation. That it matches `core` for every one of the 2³² `f32` bit patterns is checked
//! by the ignored test `f32_text_matches_display_for_every_f32` (about five minutes on
//! two cores); a property test samples it on every run. [`F32Texts`] keeps the texts of
//! recent values for writers that repeat values often.

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
    // Whole numbers below 2^24 (every such `f32` is exact; normals and texture
    // coordinates are often 0 or ±1): their digits, with the sign `core` writes (`-0`).
    if x.abs() < 16_777_216.0 && x == x.trunc() {
        if x.is_sign_negative() {
            out.push(b'-');
        }
        push_u64(out, x.abs() as u64);
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let text = buffer.format_finite(x).as_bytes();
    // Most values: zmij wrote plain `[-]digits.digits` without a trailing zero, which is
    // `core`'s text too unless x is a midpoint (the last digit's exponent rules that out).
    if let Some(dot) = text.iter().position(|&c| c == b'.') {
        let fraction = text.get(dot + 1..).unwrap_or_default();
        if fraction.last().is_some_and(|&c| c != b'0')
            && fraction.iter().all(u8::is_ascii_digit)
            && !midpoint_exponent(-(fraction.len() as i32), x)
        {
            out.extend_from_slice(text);
            return;
        }
    }
    let (negative, text) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, text),
    };
    // zmij writes `digits[.digits][e±exponent]`. Keep the significant digits (leading
    // zeros dropped) and the decimal exponent `q`: the value is digits × 10^q.
    let mut digits = [0u8; 24];
    let mut n = 0;
    let mut q = 0i32;
    let mut after_point = false;
    for (i, &c) in text.iter().enumerate() {
        match c {
            b'.' => after_point = true,
            b'e' => {
                q += parse_exponent(text.get(i + 1..).unwrap_or_default());
                break;
            }
            _ => {
                if (n > 0 || c != b'0')
                    && let Some(slot) = digits.get_mut(n)
                {
                    *slot = c;
                    n += 1;
                }
                q -= i32::from(after_point);
            }
        }
    }
    while n > 0 && digits.get(n - 1) == Some(&b'0') {
        n -= 1;
        q += 1;
    }
    out.reserve(64);
    if negative {
        out.push(b'-');
    }
    let digits = digits.get(..n).unwrap_or_default();
    if digits.is_empty() {
        out.push(b'0');
        return;
    }
    // A value exactly halfway between two shortest candidates: zmij rounds to the even
    // one, `core` away from zero. Both read back to `x`.
    if is_midpoint_above(digits, q, x) {
        let mut up = value(digits) + 1;
        strip_zeros(&mut up, &mut q);
        let mut text = itoa::Buffer::new();
        push_plain(out, text.format(up).as_bytes(), q);
    } else {
        push_plain(out, digits, q);
    }
}

/// Appends digits × 10^q in plain notation, as `core` lays out a shortest `Display`.
fn push_plain(out: &mut Vec<u8>, digits: &[u8], q: i32) {
    let n = digits.len() as i32;
    // The value is 0.digits × 10^k.
    let k = n + q;
    let zeros = |out: &mut Vec<u8>, count: i32| {
        for _ in 0..count {
            out.push(b'0');
        }
    };
    let push_all = |out: &mut Vec<u8>, bytes: &[u8]| {
        for &c in bytes {
            out.push(c);
        }
    };
    if k <= 0 {
        out.push(b'0');
        out.push(b'.');
        zeros(out, -k);
        push_all(out, digits);
    } else if k < n {
        let (whole, fraction) = digits.split_at(k as usize);
        push_all(out, whole);
        out.push(b'.');
        push_all(out, fraction);
    } else {
        push_all(out, digits);
        zeros(out, k - n);
    }
}

/// The number decimal `digits` spell (at most 18 of them, so it fits).
fn value(digits: &[u8]) -> u64 {
    digits
        .iter()
        .fold(0u64, |d, &c| d * 10 + u64::from(c.wrapping_sub(b'0')))
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
    // One and two digits (an OBJ face's relative indices, mostly) without itoa's buffer.
    if n < 10 {
        out.push(b'0' + n as u8);
    } else if n < 100 {
        out.extend_from_slice(&[b'0' + (n / 10) as u8, b'0' + (n % 10) as u8]);
    } else {
        out.extend_from_slice(itoa::Buffer::new().format(n).as_bytes());
    }
}

/// The texts of the `f32` values [`push_f32`] wrote last, by their bits: a
/// direct-mapped table of [`F32Texts::SLOTS`] slots, each holding one value's text (up to
/// 15 bytes; longer texts are not kept). A text format repeats values often (a city's
/// storey heights, a facade's texture coordinates, its normals): in `citygen`'s OBJ
/// about three of five non-whole values are found here instead of being formatted again.
pub(crate) struct F32Texts {
    slots: Vec<F32Slot>,
}

/// One slot of [`F32Texts`]: the bits of a value and its text (`len` 0: empty).
#[derive(Clone, Copy, Default)]
struct F32Slot {
    bits: u32,
    len: u8,
    text: [u8; 15],
}

impl F32Texts {
    /// log₂ of the number of slots (4,096 slots of 20 bytes: 80 KiB).
    const SLOT_BITS: u32 = 12;
    /// The number of slots.
    pub(crate) const SLOTS: usize = 1 << Self::SLOT_BITS;

    /// An empty table.
    pub(crate) fn new() -> Self {
        F32Texts {
            slots: vec![F32Slot::default(); Self::SLOTS],
        }
    }

    /// The slot of a value's bits: Fibonacci hashing, the top bits of the product, so
    /// nearby values spread.
    fn slot_of(bits: u32) -> usize {
        (bits.wrapping_mul(0x9e37_79b1) >> (32 - Self::SLOT_BITS)) as usize
    }

    /// Appends `x` exactly as [`push_f32`] does, from the table when `x`'s bits are in
    /// its slot.
    pub(crate) fn push(&mut self, out: &mut Vec<u8>, x: f32) {
        let bits = x.to_bits();
        let Some(slot) = self.slots.get_mut(Self::slot_of(bits)) else {
            push_f32(out, x);
            return;
        };
        if slot.len != 0 && slot.bits == bits {
            // The whole slot (a copy of fixed size), then cut back to the text.
            let end = out.len() + usize::from(slot.len);
            out.extend_from_slice(&slot.text);
            out.truncate(end);
            return;
        }
        let start = out.len();
        push_f32(out, x);
        let text = out.get(start..).unwrap_or_default();
        if let Some(room) = slot.text.get_mut(..text.len()) {
            room.copy_from_slice(text);
            slot.bits = bits;
            slot.len = text.len() as u8;
        }
    }
}

impl Default for F32Texts {
    fn default() -> Self {
        F32Texts::new()
    }
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

/// Whether |x| is exactly (d + ½) × 10^q, where d is the number `digits` spell, in exact
/// integer arithmetic.
///
/// |x| = m × 2^e. The equation (2d + 1) × 10^q = m × 2^(e+1) holds exactly when both
/// sides have the same powers of 2 and of 5 and the same part prime to 10; 2d + 1 is odd,
/// so its power of 2 comes from 10^q alone, which is checked first and rules out almost
/// every value.
fn is_midpoint_above(digits: &[u8], q: i32, x: f32) -> bool {
    if !midpoint_exponent(q, x) || digits.len() > 18 {
        return false;
    }
    let (m, _) = mantissa(x);
    let twos_m = m.trailing_zeros() as i32;
    let (a, fives_a) = without_fives(2 * value(digits) + 1);
    let (b, fives_m) = without_fives(m >> twos_m);
    a == b && q + fives_a == fives_m
}

/// |x| = m × 2^e with m an integer (the significand with its hidden bit).
fn mantissa(x: f32) -> (u64, i32) {
    let bits = x.to_bits() & 0x7fff_ffff;
    let (mut m, mut e) = (u64::from(bits & 0x7f_ffff), (bits >> 23) as i32);
    if e == 0 {
        e = 1; // subnormal
    } else {
        m |= 1 << 23;
    }
    (m, e - 150)
}

/// Whether digits whose last one stands for 10^q can make x a midpoint (d + ½) × 10^q:
/// the powers of 2 of both sides must agree, q = e + 1 + (trailing zeros of m), which
/// rules out almost every value before any digit is read.
fn midpoint_exponent(q: i32, x: f32) -> bool {
    let (m, e) = mantissa(x);
    m != 0 && q == e + 1 + m.trailing_zeros() as i32
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
        let edges = [
            16_777_215.0f32,
            -16_777_215.0,
            16_777_216.0,
            16_777_218.0,
            -1.0,
            0.5,
        ];
        for x in cases.into_iter().chain(edges) {
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

    /// The table writes what `push_f32` writes, whether the value is in it or not,
    /// and keeps no stale text when two values share a slot.
    #[test]
    fn f32_texts_match_push_f32() {
        let mut table = F32Texts::new();
        let mut values: Vec<f32> = (0..20_000u32)
            .map(|i| f32::from_bits(i.wrapping_mul(2_654_435_761)))
            .collect();
        // Repeats, whole numbers, signed zeros, texts longer than a slot, non-finite values.
        values.extend([0.0, -0.0, 1.0, -1.0, 0.25, 1e-7, -1.234_567_8e-12, f32::MAX]);
        values.extend([f32::NAN, f32::INFINITY, f32::MIN_POSITIVE, 3.5, 3.5, -0.0]);
        let again = values.clone();
        values.extend(again.iter().rev());
        let (mut ours, mut plain) = (Vec::new(), Vec::new());
        for &x in &values {
            table.push(&mut ours, x);
            ours.push(b' ');
            push_f32(&mut plain, x);
            plain.push(b' ');
        }
        assert_eq!(ours, plain);
    }

    /// Values that share a slot, written in turns: each is written as `push_f32` writes
    /// it (a slot holds the last one only).
    #[test]
    fn f32_texts_keep_values_of_one_slot_apart() {
        let slot = |x: f32| F32Texts::slot_of(x.to_bits());
        let first = 1.234_5_f32;
        let same: Vec<f32> = (1..u32::MAX)
            .map(|k| f32::from_bits(first.to_bits().wrapping_add(k)))
            .filter(|&x| slot(x) == slot(first))
            .take(5)
            .chain([first])
            .collect();
        assert_eq!(same.len(), 6);
        let mut table = F32Texts::new();
        for _ in 0..3 {
            for &x in same.iter().chain(same.iter().rev()) {
                let (mut ours, mut plain) = (Vec::new(), Vec::new());
                table.push(&mut ours, x);
                push_f32(&mut plain, x);
                assert_eq!(ours, plain, "bits {:#x}", x.to_bits());
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        #[test]
        fn any_f32_matches_display(bits in any::<u32>()) {
            let x = f32::from_bits(bits);
            prop_assert_eq!(text(x), format!("{x}"));
        }

        /// Whole numbers, on both sides of 2^24 where the whole-number path ends.
        #[test]
        fn whole_f32_match_display(n in -(1i32 << 25)..(1 << 25)) {
            let x = n as f32;
            prop_assert_eq!(text(x), format!("{x}"));
            prop_assert_eq!(text(x * 64.0), format!("{}", x * 64.0));
        }

        /// Values with few binary digits, where midpoints live.
        #[test]
        fn short_f32_match_display(m in 0u32..(1 << 12), e in -40i32..40) {
            let x = m as f32 * 2f32.powi(e);
            prop_assert_eq!(text(x), format!("{x}"));
        }
    }

    /// Every `f32` bit pattern (about five minutes on two cores in release mode):
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
