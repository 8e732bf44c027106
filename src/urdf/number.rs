//! Decimal numbers of attribute values, read as Rust's `str::parse::<f64>` reads them, with
//! the exact case first: a number written with at most 19 digits whose value is `m · 10^e`,
//! `m ≤ 2^53` and `|e| ≤ 22`, is `m` (exact as an `f64`) multiplied or divided by `10^|e|`
//! (exact too), one correctly rounded operation: the nearest `f64` to the decimal, which is
//! what `parse` returns (its own fast path computes the same product). Every other text
//! (more digits, larger exponents, whitespace, `inf`, `.5`, malformed) goes to `parse`.

/// The exact powers of ten of `f64`, `10^0` to `10^22`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// `s` as a finite number: `[+-]digits[.digits][(e|E)[+-]digits]` in the exact case, else
/// `str::parse` (`None` if it fails or the value is not finite).
#[inline]
pub(super) fn finite(s: &str) -> Option<f64> {
    match exact(s.as_bytes()) {
        Some(v) => Some(v),
        None => s.parse::<f64>().ok().filter(|v| v.is_finite()),
    }
}

/// `s` without its surrounding whitespace as a finite number ([`finite`]; the exact case is
/// tried on `s` first, which then has none).
#[inline]
pub(super) fn finite_trimmed(s: &str) -> Option<f64> {
    exact(s.as_bytes()).or_else(|| finite(s.trim()))
}

/// The value of `b` in the exact case; `None` otherwise (which does not mean that `b` is not a
/// number).
fn exact(b: &[u8]) -> Option<f64> {
    let (negative, mut i) = match b.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    let mut m = 0u64;
    let mut digits = 0usize;
    let int_from = i;
    while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|&d| d < 10) {
        m = m * 10 + u64::from(d);
        digits += 1;
        i += 1;
        if digits > 19 {
            return None;
        }
    }
    if i == int_from {
        return None;
    }
    let mut e = 0i32;
    if b.get(i) == Some(&b'.') {
        i += 1;
        let frac_from = i;
        while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|&d| d < 10) {
            m = m * 10 + u64::from(d);
            digits += 1;
            i += 1;
            e -= 1;
            if digits > 19 {
                return None;
            }
        }
        if i == frac_from {
            return None;
        }
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        i += 1;
        let negative_exp = match b.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let exp_from = i;
        let mut x = 0i32;
        while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|&d| d < 10) {
            x = x * 10 + i32::from(d);
            i += 1;
            if i - exp_from > 3 {
                return None;
            }
        }
        if i == exp_from {
            return None;
        }
        e += if negative_exp { -x } else { x };
    }
    if i != b.len() || m > 1 << 53 || !(-22..=22).contains(&e) {
        return None;
    }
    let v = m as f64;
    let v = if e < 0 {
        v / POW10[(-e) as usize]
    } else {
        v * POW10[e as usize]
    };
    Some(if negative { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact case and `str::parse` give the same bits, and the exact case is taken where
    /// it should be.
    #[test]
    fn same_bits_as_parse() {
        let cases = [
            "0",
            "-0",
            "+0",
            "1",
            "0.1",
            "-0.1",
            "1e-4",
            "3.4e-3",
            "7.5E-3",
            "0.30000000000000004",
            "9007199254740992",
            "9007199254740993",
            "1e22",
            "1e23",
            "1e-22",
            "1e-23",
            "123.456",
            "-2.5e+3",
            "0.000",
            "00012",
            "1234567890123456789",
            "12345678901234567890",
            "1.",
            ".5",
            "1e",
            "1e+",
            "-",
            "+",
            "",
            " 1",
            "1 ",
            "inf",
            "NaN",
            "1e400",
            "1e0001",
            "4.9e-324",
            "1.7976931348623157e308",
            "3.14159265358979",
            "-1.5707963267948966",
            "0x10",
            "1_0",
            "1..2",
            "1e-1e",
            "2.220446049250313e-16",
        ];
        for s in cases {
            let want = s.parse::<f64>().ok().filter(|v| v.is_finite());
            let got = finite(s);
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{s:?}");
        }
        for s in [
            "0.1",
            "-0",
            "1e-4",
            "3.4e-3",
            "9007199254740992",
            "1e22",
            "-2.5e+3",
        ] {
            assert!(exact(s.as_bytes()).is_some(), "{s:?} should be exact");
        }
        for s in [
            "9007199254740993",
            "1e23",
            "12345678901234567890",
            "1.",
            ".5",
            " 1",
        ] {
            assert!(exact(s.as_bytes()).is_none(), "{s:?} should go to parse");
        }
    }

    /// Every decimal of up to 6 digits with every exponent in [−25, 25]: the same bits.
    #[test]
    fn same_bits_on_a_grid() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let m = seed % 1_000_000;
            let point = (seed >> 20) % 8;
            let e = ((seed >> 24) % 51) as i32 - 25;
            let digits = format!("{m:06}");
            let (a, b) = digits.split_at(point.min(6) as usize);
            let s = match (a.is_empty(), b.is_empty()) {
                (true, _) => format!("0.{b}e{e}"),
                (_, true) => format!("{a}e{e}"),
                _ => format!("{a}.{b}e{e}"),
            };
            let want = s.parse::<f64>().ok().filter(|v| v.is_finite());
            assert_eq!(
                finite(&s).map(f64::to_bits),
                want.map(f64::to_bits),
                "{s:?}"
            );
        }
    }
}
