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
//! Text meant for people (summaries, plan explanations) rounds to four
//! decimals ([`crate::plan::num`]), and also switches to the exponent form
//! beyond 1e16, where four decimals would print hundreds of digits.

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

#[cfg(test)]
mod tests {
    use super::number;

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
