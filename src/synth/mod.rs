//! Texture synthesis building blocks shared by the raster modes: oriented
//! neighbourhoods, their PCA reduction and nearest-neighbour index.

pub mod neighbourhood;
