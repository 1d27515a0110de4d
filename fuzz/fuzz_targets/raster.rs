//! The picture readers (PNG, JPEG, BMP, GIF, TIFF, WebP, SVG) on any
//! bytes, then the tracer on what they read: an error or a valid output.
#![no_main]

use flourish::{Image, ImageOptions, TraceOptions};
use libfuzzer_sys::fuzz_target;

mod check;

fuzz_target!(|data: &[u8]| {
    let Some((&flags, bytes)) = data.split_first() else {
        return;
    };
    let opts = ImageOptions {
        resolution: 64,
        invert: flags & 1 != 0,
        layers: flags & 2 != 0,
    };
    if let Ok(image) = Image::from_bytes(bytes, &opts) {
        if let Ok(out) = flourish::trace(&image, &TraceOptions::default()) {
            check::output(&out);
        }
    }
});
