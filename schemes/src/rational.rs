//! Rational numbers as the command lines and JSON write them (DESIGN.md: `1/3`, `0`, `2/5`):
//! one grammar for `stencilgen` and `subtess`, each of which adds its own domain checks.

use std::fmt;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;

/// What is wrong with a rational's text, in words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RationalSyntaxError(pub String);

impl fmt::Display for RationalSyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for RationalSyntaxError {}

/// Parse `p/q` (a sign on `p` only; `q > 0`), an integer, or a decimal like `0.25` or `-.5`,
/// taken exactly (a decimal is `digits / 10^k`, never a float).
pub fn parse_rational(text: &str) -> Result<BigRational, RationalSyntaxError> {
    let bad = |reason: &str| RationalSyntaxError(reason.to_owned());
    let s = text.trim();
    if s.is_empty() {
        return Err(bad(
            "it is empty; write a rational p/q, an integer or a decimal",
        ));
    }
    let integer = |digits: &str, what: &str| -> Result<BigInt, RationalSyntaxError> {
        let unsigned = digits.strip_prefix(['+', '-']).unwrap_or(digits);
        if unsigned.is_empty() || !unsigned.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad(&format!("the {what} `{digits}` is not an integer")));
        }
        digits
            .parse::<BigInt>()
            .map_err(|_| bad(&format!("the {what} `{digits}` is not an integer")))
    };
    let value = if let Some((p, q)) = s.split_once('/') {
        let (p, q) = (p.trim(), q.trim());
        let numerator = integer(p, "numerator")?;
        if q.starts_with(['+', '-']) {
            return Err(bad("the denominator must be written without a sign"));
        }
        let denominator = integer(q, "denominator")?;
        if denominator.is_zero() {
            return Err(bad("the denominator is 0"));
        }
        BigRational::new(numerator, denominator)
    } else if let Some((whole, fraction)) = s.split_once('.') {
        let negative = whole.starts_with('-');
        let digits = whole.strip_prefix(['+', '-']).unwrap_or(whole);
        if (digits.is_empty() && fraction.is_empty())
            || !digits
                .bytes()
                .chain(fraction.bytes())
                .all(|b| b.is_ascii_digit())
        {
            return Err(bad(
                "it is not a number; write a rational p/q, an integer or a decimal like 0.25",
            ));
        }
        let all: BigInt = format!("{digits}{fraction}")
            .parse()
            .map_err(|_| bad("it is not a decimal number"))?;
        let scale = num_traits::pow(BigInt::from(10), fraction.len());
        let magnitude = BigRational::new(all, scale);
        if negative {
            -magnitude
        } else {
            magnitude
        }
    } else {
        BigRational::from_integer(integer(s, "value")?)
    };
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ratio(p: i64, q: i64) -> BigRational {
        BigRational::new(BigInt::from(p), BigInt::from(q))
    }

    #[test]
    fn rationals_integers_and_decimals_are_exact() {
        for (text, value) in [
            ("1/3", ratio(1, 3)),
            (" 2/4 ", ratio(1, 2)),
            ("-3/5", ratio(-3, 5)),
            ("0", ratio(0, 1)),
            ("7", ratio(7, 1)),
            ("0.25", ratio(1, 4)),
            (".1", ratio(1, 10)),
            ("-.5", ratio(-1, 2)),
            ("1.", ratio(1, 1)),
        ] {
            assert_eq!(parse_rational(text), Ok(value), "{text}");
        }
        for (text, needle) in [
            ("", "empty"),
            ("1/0", "denominator is 0"),
            ("a/3", "numerator `a`"),
            ("1/x", "denominator `x`"),
            ("1/-2", "without a sign"),
            ("1/2/3", "denominator `2/3`"),
            ("0.2.5", "not a number"),
            ("1e-3", "not an integer"),
            (".", "not a number"),
        ] {
            let e = parse_rational(text).expect_err(text).to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }
}
