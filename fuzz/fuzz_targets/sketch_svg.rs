//! The sketch SVG reader on any bytes: an error or a sketch that keeps
//! its invariants, never a panic or an unbounded allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

mod check;

fuzz_target!(|data: &[u8]| {
    if let Ok(sketch) = flourish::Sketch::from_svg(data) {
        check::sketch(&sketch);
    }
});
