//! The per-face rates file (`subtess tessellate --rates FILE`): the first two bytes are the
//! mesh's face count (little-endian), the rest the file's text, given to
//! `tessellate::rates::parse_rates`. What it returns must be one rate per face, each in
//! `1..=MAX_SELECTED_RATE`.

#![no_main]

use libfuzzer_sys::fuzz_target;
use subtess::tessellate::rates::{parse_rates, MAX_SELECTED_RATE};

fuzz_target!(|data: &[u8]| {
    let [low, high, rest @ ..] = data else {
        return;
    };
    let faces = usize::from(u16::from_le_bytes([*low, *high]));
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    if let Ok(rates) = parse_rates(text, faces) {
        assert_eq!(rates.len(), faces, "one rate per face");
        assert!(
            rates.iter().all(|r| (1..=MAX_SELECTED_RATE).contains(r)),
            "rates in range: {rates:?}"
        );
    }
});
