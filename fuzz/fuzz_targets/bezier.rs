//! The Bézier patch readers: every input is read both as Newell's "patches + vertices" format
//! (`BezierPatches::parse_newell`) and as `.bpt` (`BezierPatches::parse_bpt`); a patch set
//! read is measured (`bounding_box`, `diagonal`), which must be finite.

#![no_main]

use libfuzzer_sys::fuzz_target;
use subtess::BezierPatches;

fn check(patches: &BezierPatches) {
    assert!(!patches.is_empty(), "a patch set read has patches");
    let diagonal = patches.diagonal();
    assert!(
        diagonal.is_finite(),
        "the readers bound coordinates, so the bounding box is finite: {diagonal}"
    );
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(patches) = BezierPatches::parse_newell(text, "fuzz.txt") {
        check(&patches);
    }
    if let Ok(patches) = BezierPatches::parse_bpt(text, "fuzz.bpt") {
        check(&patches);
    }
});
