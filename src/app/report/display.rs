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
