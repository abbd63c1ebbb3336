//! Rational numbers as written on the command line and in JSON (DESIGN.md conventions; the
//! grammar is `schemes::rational`'s), and their nearest f64, for rationals too large for a
//! plain division.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::ToPrimitive;

use crate::StencilError;

/// Parse a rational in the one grammar of the command lines ([`schemes::rational::parse_rational`]:
/// `p/q`, an integer, or an exact decimal).
pub fn parse_rational(text: &str) -> Result<BigRational, StencilError> {
    schemes::rational::parse_rational(text).map_err(|why| StencilError::OutOfDomain {
        what: format!("`{text}` is not a rational number p/q: {why}"),
    })
}

/// The f64 nearest to a rational whose numerator and denominator may both overflow f64:
/// both are shifted down to 64 significant bits first, so the quotient keeps full precision.
pub fn rational_to_f64(r: &BigRational) -> f64 {
    let (num, den) = (r.numer(), r.denom());
    let shift = |x: &BigInt| x.bits().saturating_sub(64);
    let (sn, sd) = (shift(num), shift(den));
    let n = (num >> sn).to_f64().unwrap_or(f64::NAN);
    let d = (den >> sd).to_f64().unwrap_or(f64::NAN);
    (n / d) * (sn as f64 - sd as f64).exp2()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_rationals_convert_without_overflow() {
        let big = BigInt::from(3u8).pow(1000);
        let r = BigRational::new(big.clone() * 2, big * 3);
        assert!((rational_to_f64(&r) - 2.0 / 3.0).abs() < 1e-15);
        let small = BigRational::new(BigInt::from(-1), BigInt::from(5589));
        assert_eq!(rational_to_f64(&small), -1.0 / 5589.0);
    }

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
        // Decimals are exact rationals too (the grammar is schemes::rational's, shared with
        // `subtess`).
        assert_eq!(
            parse_rational("0.5").map(|r| r.to_string()),
            Ok("1/2".to_owned())
        );
        for bad in ["", "1/0", "a/2", "1/2/3", "1/-2"] {
            assert!(parse_rational(bad).is_err(), "{bad}");
        }
    }
}
