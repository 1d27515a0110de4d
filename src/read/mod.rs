//! Files in: raster images (decoding, lighting), SVG through one usvg
//! adaptor, sketches, style files, and inputs read as layers of ink.

pub mod image;
pub mod ink;
pub mod lighting;
pub mod sketch;
pub mod style;
pub mod svg;

/// How inputs are read.
#[derive(Clone, Debug)]
pub struct InputOptions {
    /// Longest side in pixels at which SVG input is rasterized (default
    /// 1024). Raster input is used at its own size.
    pub resolution: u32,
    /// Trace the paper instead of the ink.
    pub invert: bool,
    /// One layer per fill colour instead of one layer of all ink.
    pub layers: bool,
}

impl Default for InputOptions {
    fn default() -> Self {
        InputOptions {
            resolution: 1024,
            invert: false,
            layers: false,
        }
    }
}
