//! # flourish
//!
//! Turns rough sketch SVGs into decorative SVGs by example, and traces
//! bitmaps and signed distance fields into compact Bézier outlines.
//!
//! The raster modes all meet in one type, [`raster::Sdf`]: a grid of signed
//! distances (negative inside ink, in pixels) with the transform back to the
//! input's units. [`trace`] turns it into Bézier outlines and [`svg_out`]
//! writes them. See `ARCHITECTURE.md` for the stage graph.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod brush;
pub mod diff;
pub mod error;
pub mod field;
pub mod fill;
pub mod io;
pub mod outline;
pub mod pattern;
pub mod raster;
pub mod read;
pub mod render;
pub mod rng;
pub mod svg_out;
pub mod trace;

pub use error::{Error, Result};
