//! Numbers as text, byte for byte as Rust's `{}` formatting writes them, without the cost of
//! the formatting machinery per number.
//!
//! Floats: `ryu` finds the shortest digits that read back as the same `f64` (as the
//! standard library's `{}` does: shortest, then closest), in its own layout (`1e-7`,
//! `1.0`); the digits are laid out again as `{}` lays them out, in full positional notation
//! (`0.0000001`, `1`). The tests compare the two on millions of values.

use std::io::Write;

/// Appends `values` separated by spaces, each as `{}` writes it.
pub(crate) fn push_f64s(buf: &mut Vec<u8>, values: &[f64]) {
    for (k, &x) in values.iter().enumerate() {
        if k > 0 {
            buf.push(b' ');
        }
        push_f64(buf, x);
    }
}

/// Appends `x` as `format!("{x}")` writes it.
#[inline]
pub(crate) fn push_f64(buf: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        let _ = write!(buf, "{x}");
        return;
    }
    let mut ryu = ryu::Buffer::new();
    let shortest = ryu.format_finite(x).as_bytes();
    // Without an exponent ryu's layout is positional already (`{}` leaves out a fraction of
    // `.0`); only a tie can change a digit, and it needs `x`'s binary exponent to be the
    // one of the halfway value (see `rounds_up_on_tie`).
    if !shortest.contains(&b'e') {
        let plain = shortest.strip_suffix(b".0").unwrap_or(shortest);
        let halfway_exponent = match plain.iter().position(|&b| b == b'.') {
            Some(dot) => -((plain.len() - dot) as i32),
            None => -1,
        };
        if x == 0.0 || odd_mantissa(x).1 != halfway_exponent {
            buf.extend_from_slice(plain);
            return;
        }
    }
    let (negative, unsigned) = match shortest.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, shortest),
    };
    if negative {
        buf.push(b'-');
    }
    let (mut digits, point) = split_decimal(unsigned);
    if rounds_up_on_tie(x, &digits, point) {
        digits.bytes[digits.len - 1] += 1;
    }
    push_positional(buf, digits.as_slice(), point);
}

/// Whether `x` lies exactly halfway between `digits` (as `ryu` chose them, the even one on a
/// tie) and the next number of as many digits: `{}` then takes the one above.
///
/// With `n` digits and the point after `point` of them, the halfway value is
/// `M * 10^p` with `M = 10 N + 5` (odd) and `p = point - n - 1`. Writing `|x| = m * 2^e`
/// with `m` odd, a tie needs `p < 0` (for `p >= 0`, `m` would be `M * 5^p`, more than the
/// 53 bits of a mantissa when `n >= 16`), then `e = p` and `m * 5^-p = M`. Fewer than 16
/// digits never tie: the halfway gap, 10^-n of `x`, would exceed half an ulp.
fn rounds_up_on_tie(x: f64, digits: &Digits, point: i32) -> bool {
    let n = digits.len;
    if n < 16 || digits.bytes[n - 1] % 2 != 0 {
        return false;
    }
    let (m, e) = odd_mantissa(x);
    let p = point - n as i32 - 1;
    if e != p || !(-27..0).contains(&p) {
        return false;
    }
    let big_n = digits
        .as_slice()
        .iter()
        .fold(0u128, |v, &d| v * 10 + u128::from(d - b'0'));
    u128::from(m) * 5u128.pow((-p) as u32) == big_n * 10 + 5
}

/// `|x|` as `m * 2^e` with `m` odd (`x` finite and not zero).
fn odd_mantissa(x: f64) -> (u64, i32) {
    let bits = x.abs().to_bits();
    let (biased, fraction) = ((bits >> 52) as i32, bits & ((1 << 52) - 1));
    let (m, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1 << 52), biased - 1075)
    };
    let zeros = m.trailing_zeros().min(63);
    (m >> zeros, e + zeros as i32)
}

/// The significant digits of ryu's unsigned text (no leading or trailing zeros) and where
/// the decimal point goes: after the first `point` of them (`point <= 0`: zeros first).
#[inline]
fn split_decimal(text: &[u8]) -> (Digits, i32) {
    let (mantissa, exponent) = match text.iter().position(|&b| b == b'e') {
        Some(e) => (&text[..e], parse_exponent(&text[e + 1..])),
        None => (text, 0),
    };
    let mut digits = Digits::default();
    let (mut point, mut leading_zeros) = (mantissa.len() as i32, 0);
    for (k, &b) in mantissa.iter().enumerate() {
        if b == b'.' {
            point = k as i32;
        } else if digits.len > 0 || b != b'0' {
            digits.push(b);
        } else {
            leading_zeros += 1;
        }
    }
    while digits.len > 0 && digits.bytes[digits.len - 1] == b'0' {
        digits.len -= 1;
    }
    (digits, point - leading_zeros + exponent)
}

/// `ryu`'s exponent: an optional `-` and decimal digits.
#[inline]
fn parse_exponent(text: &[u8]) -> i32 {
    let (sign, digits) = match text.split_first() {
        Some((b'-', rest)) => (-1, rest),
        _ => (1, text),
    };
    sign * digits
        .iter()
        .fold(0i32, |e, &d| e * 10 + i32::from(d - b'0'))
}

/// The digits of `ryu`'s text after its leading zeros: at most 17 significant ones, then
/// at most the zeros of a 16-digit integer part.
#[derive(Default)]
struct Digits {
    bytes: [u8; 32],
    len: usize,
}

impl Digits {
    #[inline]
    fn push(&mut self, b: u8) {
        self.bytes[self.len.min(31)] = b;
        self.len = (self.len + 1).min(32);
    }

    fn as_slice(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

/// Appends digits `d` with the decimal point after `point` of them, as `{}` does: `0.` and
/// zeros first when `point <= 0`, zeros after when `point >= d.len()`, and no fraction when
/// there is none (`0` for zero).
#[inline]
fn push_positional(buf: &mut Vec<u8>, d: &[u8], point: i32) {
    if d.is_empty() {
        buf.push(b'0');
    } else if point <= 0 {
        buf.extend_from_slice(b"0.");
        buf.resize(buf.len() + (-point) as usize, b'0');
        buf.extend_from_slice(d);
    } else if point as usize >= d.len() {
        buf.extend_from_slice(d);
        buf.resize(buf.len() + (point as usize - d.len()), b'0');
    } else {
        let (int, frac) = d.split_at(point as usize);
        buf.extend_from_slice(int);
        buf.push(b'.');
        buf.extend_from_slice(frac);
    }
}

/// Appends `x` in decimal, as `format!("{x}")` writes it.
#[inline]
pub(crate) fn push_u64(buf: &mut Vec<u8>, mut x: u64) {
    // Digits from the last, turned around in place.
    let start = buf.len();
    loop {
        buf.push(b'0' + (x % 10) as u8);
        x /= 10;
        if x == 0 {
            break;
        }
    }
    buf[start..].reverse();
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(x: f64) {
        let mut b = Vec::new();
        push_f64(&mut b, x);
        assert_eq!(
            std::str::from_utf8(&b).unwrap(),
            format!("{x}"),
            "bits {:#x}",
            x.to_bits()
        );
    }

    #[test]
    fn floats_read_as_display_writes_them() {
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            1e-7,
            1e-5,
            1e15,
            1e16,
            1e17,
            1e21,
            1e22,
            1e23,
            123456789012345680.0,
            9007199254740993.0,
            0.30000000000000004,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            5e-324,
            f64::from_bits(0x000f_ffff_ffff_ffff),
            1.7976931348623157e308,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        special.iter().for_each(|&x| check(x));
        for e in -330..310 {
            for m in [1.0, 1.5, 2.0, 3.0, 9.999999999999999, 4.35, 7.0] {
                check(m * 10f64.powi(e));
                check(-m * 10f64.powi(e));
            }
        }
        for k in -1100..1030 {
            check(2f64.powi(k));
            check(2f64.powi(k) * 3.0);
        }
    }

    #[test]
    fn floats_of_every_kind_match_display() {
        let mut s = 0x9e3779b97f4a7c15u64;
        for i in 0..4_000_000u64 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let x = match i % 5 {
                0 => f64::from_bits(s),
                // Few bits over a small power of two: where exact ties live.
                4 => (s >> (11 + s % 40)) as f64 / (1u64 << (s >> 58)) as f64,
                // Coordinates as meshes hold them, integers, short decimals.
                1 => (s >> 11) as f64 / (1u64 << 53) as f64 * 8.0 - 4.0,
                2 => ((s >> 40) as i64 - (1 << 23)) as f64,
                _ => ((s >> 44) as f64) / 1000.0,
            };
            check(x);
        }
    }

    #[test]
    fn integers_read_as_display_writes_them() {
        for x in [0u64, 1, 9, 10, 99, 100, 4294967295, 4294967296, u64::MAX] {
            let mut b = Vec::new();
            push_u64(&mut b, x);
            assert_eq!(std::str::from_utf8(&b).unwrap(), x.to_string());
        }
    }
}
