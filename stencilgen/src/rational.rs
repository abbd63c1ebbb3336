//! Rational numbers as written on the command line and in JSON: `p/q`, or an integer `p`
//! (DESIGN.md conventions).

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;

use crate::StencilError;

/// Parse `p/q` or `p` (optional sign on `p`; `q > 0`).
pub fn parse_rational(text: &str) -> Result<BigRational, StencilError> {
    let bad = |why: &str| StencilError::OutOfDomain {
        what: format!("`{text}` is not a rational number p/q: {why}"),
    };
    let (p, q) = match text.trim().split_once('/') {
        Some((p, q)) => (p.trim(), q.trim()),
        None => (text.trim(), "1"),
    };
    let p: BigInt = p
        .parse()
        .map_err(|_| bad("the numerator is not an integer"))?;
    let q: BigInt = q
        .parse()
        .map_err(|_| bad("the denominator is not an integer"))?;
    if q.is_zero() {
        return Err(bad("the denominator is zero"));
    }
    if q < BigInt::zero() {
        return Err(bad("the denominator is negative"));
    }
    Ok(BigRational::new(p, q))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_design_syntax() {
        assert_eq!(
            parse_rational("1/3").map(|r| r.to_string()),
            Ok("1/3".to_owned())
        );
        assert_eq!(
            parse_rational("2/4").map(|r| r.to_string()),
            Ok("1/2".to_owned())
        );
        assert_eq!(
            parse_rational("0").map(|r| r.to_string()),
            Ok("0".to_owned())
        );
        assert_eq!(
            parse_rational("-3/5").map(|r| r.to_string()),
            Ok("-3/5".to_owned())
        );
        for bad in ["", "1/0", "a/2", "1/2/3", "0.5", "1/-2"] {
            assert!(parse_rational(bad).is_err(), "{bad}");
        }
    }
}
