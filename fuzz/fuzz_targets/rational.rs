//! `eval`'s rational parameters (`subtess::parse_rational`): what it accepts lies in `[0, 1]`
//! with a numerator and denominator of at most `MAX_RATIONAL_BITS` bits.

#![no_main]

use libfuzzer_sys::fuzz_target;
use num_traits::Signed;
use subtess::eval::exact_eval::MAX_RATIONAL_BITS;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(value) = subtess::parse_rational(text) {
        assert!(
            value.numer().bits() <= MAX_RATIONAL_BITS && value.denom().bits() <= MAX_RATIONAL_BITS
        );
        assert!(
            !value.numer().is_negative() && value.numer() <= value.denom(),
            "{value} in [0, 1]"
        );
    }
});
