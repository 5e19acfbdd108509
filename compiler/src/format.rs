//! How numbers are printed, the same way in every output.
//!
//! Data outputs (`--csv`, `--json`) print each number as its shortest
//! round-trip decimal: the fewest digits that read back as the same `f64`,
//! bit for bit. Nothing is rounded away, so a value that is round-off of
//! zero stays what it is (`-1.2722218725854064e-14`), but it is never
//! spelled out in thirty digits: outside 1e-5 ≤ |x| < 1e16 the number is
//! written with an exponent. [`number`] is exactly the text `serde_json`
//! writes for the same number, so a value reads the same in CSV and JSON.
//!
//! Text meant for people (summaries, plan explanations) rounds to a fixed
//! number of decimals ([`rounded`]: four in [`crate::plan::num`], nine for
//! break points), and switches to the exponent form from 1e16 on, where
//! decimals would print hundreds of digits (`--to 1e308`).

/// `x` as its shortest round-trip decimal, in JSON's layout: `0.5`,
/// `-180.0`, `1e+308`, `-1.2722218725854064e-14`; `NaN`, `inf` and `-inf`
/// for what JSON has no number for (JSON writes `null`).
pub fn number(x: f64) -> String {
    if x.is_finite() {
        // Writing an f64 to a String cannot fail.
        serde_json::to_string(&x).unwrap_or_else(|_| format!("{x:e}"))
    } else {
        format!("{x}")
    }
}

/// `x` for people: rounded to `decimals`, trailing zeros dropped, `-0`
/// printed `0`; from 1e16 on, [`number`]'s exponent form (`1e+308`), as
/// decimals there are noise and the digits before them hundreds.
pub fn rounded(x: f64, decimals: usize) -> String {
    if x.abs() >= 1e16 {
        return number(x);
    }
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// A distance for people (the reports of `assemble` and of joints in
/// conflict): 4 decimals, or two significant digits below 1e-3.
pub fn length(x: f64) -> String {
    if x >= 1e-3 {
        rounded(x, 4)
    } else {
        format!("{x:.1e}")
    }
}

/// A count with thousands separators: 1990 → "1,990" (legends, summaries).
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{number, rounded};

    #[test]
    fn rounded_numbers_are_short() {
        assert_eq!(rounded(57.29577951308232, 4), "57.2958");
        assert_eq!(rounded(-1.2722218725854064e-14, 4), "0");
        assert_eq!(rounded(-180.0, 4), "-180");
        assert_eq!(rounded(1e308, 4), "1e+308");
        assert_eq!(rounded(-1e16, 9), "-1e+16");
        assert_eq!(rounded(9.9e15, 0), "9900000000000000");
        assert_eq!(rounded(f64::NAN, 4), "NaN");
    }

    #[test]
    fn numbers_are_shortest_round_trip_and_never_long() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -180.0,
            0.1,
            1.0 / 3.0,
            -1.2722218725854064e-14,
            1e-5,
            9.99e-6,
            123456.789,
            1e15,
            1e16,
            1e308,
            f64::MIN_POSITIVE,
            5e-324,
            -f64::MAX,
        ] {
            let s = number(x);
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x:?} printed {s}");
            assert!(s.len() <= 24, "{x:?} printed {s} ({} characters)", s.len());
            // The same text as JSON's.
            assert_eq!(s, serde_json::json!(x).to_string());
        }
        assert_eq!(number(-1.2722218725854064e-14), "-1.2722218725854064e-14");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(-180.0), "-180.0");
        assert_eq!(number(1e308), "1e+308");
        assert_eq!(number(f64::NAN), "NaN");
        assert_eq!(number(f64::NEG_INFINITY), "-inf");
    }
}
