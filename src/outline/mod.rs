//! Pixel outlines to polygons and smooth loops: the potrace-like steps
//! (Selinger 2003, §2.1–2.3) and the corner finder.

pub mod chain;
pub mod corner;
pub mod corridor;
pub(crate) mod line_ends;
pub mod paths;
pub(crate) mod polygon;
pub mod smooth;
pub(crate) mod tips;
pub(crate) mod vertices;
