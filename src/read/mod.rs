//! Files in: raster images (decoding, lighting), SVG through one usvg
//! adaptor, sketches, style files, and inputs read as layers of ink.

pub mod image;
pub mod ink;
pub mod lighting;
pub mod sketch;
pub mod style;
pub mod svg;

/// How a picture is read as ink.
#[derive(Clone, Debug)]
pub struct ImageOptions {
    /// Longest side, px, at which SVG input is rasterized (at least 1;
    /// default 1024). Raster input is read at its own size.
    pub resolution: u32,
    /// Read the paper as ink and the ink as paper (default `false`).
    pub invert: bool,
    /// One layer per fill colour (SVG) or quantized colour (raster)
    /// instead of one layer of all ink (default `false`).
    pub layers: bool,
}

impl Default for ImageOptions {
    fn default() -> Self {
        ImageOptions {
            resolution: 1024,
            invert: false,
            layers: false,
        }
    }
}

impl ImageOptions {
    /// Checks every value's range.
    pub fn validate(&self) -> crate::error::Result<()> {
        if self.resolution == 0 {
            return Err(crate::error::Error::Option {
                name: "resolution",
                reason: "must be at least 1 px".into(),
            });
        }
        Ok(())
    }
}
