//! Rational numbers as written on the command line and in JSON (DESIGN.md conventions; the
//! grammar is `schemes::rational`'s), and their nearest f64, for rationals too large for a
//! plain division.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::ToPrimitive;

use crate::StencilError;

/// The most characters (after trimming) a rational argument may have, checked before
/// parsing: big integers parse in time quadratic in their digits.
pub const MAX_RATIONAL_CHARS: usize = 64;

/// The most bits the numerator and the denominator of a rational argument may have, in
/// lowest terms: `1/2^63` is the finest power of two (subtess's `eval` takes the same).
pub const MAX_RATIONAL_BITS: u64 = 64;

/// Parse a rational in the one grammar of the command lines ([`schemes::rational::parse_rational`]:
/// `p/q`, an integer, or an exact decimal), of at most [`MAX_RATIONAL_CHARS`] characters and
/// with a numerator and denominator of at most [`MAX_RATIONAL_BITS`] bits. Messages quote the
/// text through [`crate::excerpt`].
pub fn parse_rational(text: &str) -> Result<BigRational, StencilError> {
    let bad = |why: String| StencilError::OutOfDomain {
        what: format!(
            "`{}` is not a rational number p/q: {why}",
            crate::excerpt(text)
        ),
    };
    let chars = text.trim().chars().count();
    if chars > MAX_RATIONAL_CHARS {
        return Err(bad(format!(
            "{chars} characters; a rational argument is at most {MAX_RATIONAL_CHARS} (numerator and denominator of at most {MAX_RATIONAL_BITS} bits)"
        )));
    }
    let value = schemes::rational::parse_rational(text).map_err(|why| bad(why.to_string()))?;
    if value.numer().bits() > MAX_RATIONAL_BITS || value.denom().bits() > MAX_RATIONAL_BITS {
        return Err(bad(format!(
            "in lowest terms its numerator or denominator has more than {MAX_RATIONAL_BITS} bits"
        )));
    }
    Ok(value)
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
    fn rationals_are_bounded_in_characters_and_bits() {
        let finest = format!("1/{}", BigInt::from(2u8).pow(63));
        assert_eq!(parse_rational(&finest).map(|r| r.denom().bits()), Ok(64));
        let too_fine = format!("1/{}", BigInt::from(2u8).pow(64));
        let message = parse_rational(&too_fine).expect_err("65 bits").to_string();
        assert!(message.contains("more than 64 bits"), "{message}");
        // 2^64/2^64 is 1 in lowest terms.
        let one = format!("{0}/{0}", BigInt::from(2u8).pow(64));
        assert_eq!(
            parse_rational(&one).map(|r| r.to_string()),
            Ok("1".to_owned())
        );
        let long = format!("1/1{}", "0".repeat(1_000_000));
        let message = parse_rational(&long).expect_err("too long").to_string();
        assert!(message.contains("1000003 characters"), "{message}");
        assert!(message.len() < 300, "{}", message.len());
        let spaced = format!("  {}  ", "1".repeat(MAX_RATIONAL_CHARS - 1) + "/");
        assert!(!parse_rational(&spaced)
            .expect_err("no denominator")
            .to_string()
            .contains("characters"));
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
