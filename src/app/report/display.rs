//! Numbers as a table shows them: rounded to what they mean, a zero printed as `0`
//! (never `-0.0000`, nor round-off such as `-3.0e-34 J` beside values of 1e-16 J). JSON
//! keeps every digit.

/// `value` with `decimals` decimals, or `0` where it rounds to zero there.
pub fn fixed(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0".into()
    } else {
        text
    }
}

/// `value` in scientific notation with `decimals` decimals, or `0` where it is zero or
/// round-off of a calculation whose values are of size `scale`: |value| ≤ 1e-12·scale.
pub fn sci(value: f64, decimals: usize, scale: f64) -> String {
    if value == 0.0 || value.abs() <= 1e-12 * scale.abs() {
        "0".into()
    } else {
        format!("{value:.decimals$e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeros_and_round_off_print_as_zero() {
        assert_eq!(fixed(-0.00004, 4), "0");
        assert_eq!(fixed(0.0, 4), "0");
        assert_eq!(fixed(-0.00051, 4), "-0.0005");
        assert_eq!(fixed(90.000000000001, 4), "90.0000");
        assert_eq!(sci(-3.0459e-34, 4, 1.2566e-16), "0");
        assert_eq!(sci(0.0, 4, 0.0), "0");
        assert_eq!(sci(3.2782e-18, 4, 1.2566e-16), "3.2782e-18");
    }
}
