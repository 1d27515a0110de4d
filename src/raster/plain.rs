//! Compact binary (serde) encoding of grids and sample vectors: samples are
//! written as one little-endian byte string, so caches load at memory speed
//! instead of one serde call per number.
//!
//! Decoding checks that the byte count matches the declared size, so a
//! truncated or corrupt cache fails to decode instead of building a grid
//! whose size disagrees with its data.

use super::Grid;
use serde::de::{self, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A sample type with a fixed-size little-endian encoding.
pub trait Plain: Copy {
    /// Encoded size in bytes.
    const BYTES: usize;
    /// Appends the encoding of `self`.
    fn put(self, out: &mut Vec<u8>);
    /// Decodes from exactly [`Plain::BYTES`] bytes.
    fn get(b: &[u8]) -> Self;
}

/// `Plain` for a number type as its little-endian bytes.
macro_rules! plain_le {
    ($($t:ty),*) => {$(
        impl Plain for $t {
            const BYTES: usize = std::mem::size_of::<$t>();
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn get(b: &[u8]) -> Self {
                let mut a = [0u8; std::mem::size_of::<$t>()];
                a.copy_from_slice(&b[..std::mem::size_of::<$t>()]);
                <$t>::from_le_bytes(a)
            }
        }
    )*};
}

plain_le!(f32, u32, u16, i16, u8);

impl Plain for bool {
    const BYTES: usize = 1;
    fn put(self, out: &mut Vec<u8>) {
        out.push(self as u8);
    }
    fn get(b: &[u8]) -> Self {
        b[0] != 0
    }
}

impl<T: Plain, const N: usize> Plain for [T; N] {
    const BYTES: usize = T::BYTES * N;
    fn put(self, out: &mut Vec<u8>) {
        for v in self {
            v.put(out);
        }
    }
    fn get(b: &[u8]) -> Self {
        std::array::from_fn(|i| T::get(&b[i * T::BYTES..(i + 1) * T::BYTES]))
    }
}

fn encode<T: Plain>(data: &[T]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len() * T::BYTES);
    for &v in data {
        v.put(&mut out);
    }
    out
}

fn decode<T: Plain>(bytes: &[u8]) -> Vec<T> {
    if T::BYTES == 0 {
        return Vec::new();
    }
    bytes.chunks_exact(T::BYTES).map(T::get).collect()
}

/// Samples decoded straight from a serde byte string (borrowed or owned),
/// one pass, no intermediate copy.
struct Decoded<T>(Vec<T>);

impl<'de, T: Plain> Deserialize<'de> for Decoded<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Plain> Visitor<'de> for V<T> {
            type Value = Decoded<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a byte string of samples")
            }
            fn visit_bytes<E: de::Error>(self, v: &[u8]) -> Result<Decoded<T>, E> {
                if T::BYTES == 0 || !v.len().is_multiple_of(T::BYTES) {
                    return Err(E::custom("sample data has a partial sample"));
                }
                Ok(Decoded(decode(v)))
            }
        }
        d.deserialize_bytes(V(std::marker::PhantomData))
    }
}

impl<T: Plain> Serialize for Grid<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(3)?;
        t.serialize_element(&(self.width as u64))?;
        t.serialize_element(&(self.height as u64))?;
        let bytes = encode(&self.data);
        t.serialize_element(&BytesRef(&bytes))?;
        t.end()
    }
}

/// Serializes a byte slice as a serde byte string (not a sequence).
struct BytesRef<'a>(&'a [u8]);

impl Serialize for BytesRef<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(self.0)
    }
}

impl<'de, T: Plain> Deserialize<'de> for Grid<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Plain> Visitor<'de> for V<T> {
            type Value = Grid<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a grid (width, height, samples)")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Grid<T>, A::Error> {
                let w: u64 = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let h: u64 = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(1, &self))?;
                let Decoded(data) = seq
                    .next_element::<Decoded<T>>()?
                    .ok_or_else(|| de::Error::invalid_length(2, &self))?;
                if w.checked_mul(h) != Some(data.len() as u64) {
                    return Err(de::Error::custom("grid size does not match its data"));
                }
                Grid::from_vec(w as usize, h as usize, data)
                    .ok_or_else(|| de::Error::custom("grid size does not match its data"))
            }
        }
        d.deserialize_tuple(3, V(std::marker::PhantomData))
    }
}

/// Steps per pixel of a quantized signed distance ([`sdf16`]).
pub const SDF_STEPS: f32 = 128.0;
/// Largest magnitude of a quantized signed distance, px.
pub const SDF_LIMIT: f32 = 255.0;

/// Rounds signed distances (px) to the precision [`sdf16`] stores them
/// with: multiples of 1/[`SDF_STEPS`] px, clamped to ±[`SDF_LIMIT`] px.
pub fn quantize_sdf(g: &mut Grid<f32>) {
    for v in g.data_mut() {
        *v = (v.clamp(-SDF_LIMIT, SDF_LIMIT) * SDF_STEPS).round() / SDF_STEPS;
    }
}

/// `#[serde(with = "crate::raster::plain::sdf16")]` for a `Grid<f32>` of
/// signed distances already rounded by [`quantize_sdf`]: stored as 16-bit
/// integers (half the bytes), decoded exactly.
pub mod sdf16 {
    use super::*;

    /// Serializes `g` as a grid of `i16` steps.
    pub fn serialize<S: Serializer>(g: &Grid<f32>, s: S) -> Result<S::Ok, S::Error> {
        g.map(|v| (v.clamp(-SDF_LIMIT, SDF_LIMIT) * SDF_STEPS).round() as i16)
            .serialize(s)
    }

    /// Deserializes a grid written by [`serialize`].
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Grid<f32>, D::Error> {
        let g = Grid::<i16>::deserialize(d)?;
        Ok(g.map(|v| v as f32 / SDF_STEPS))
    }
}

/// `#[serde(with = "crate::raster::plain::bits")]` for a `Grid<bool>`:
/// eight samples per byte.
pub mod bits {
    use super::*;

    /// Serializes `g` as (width, height, packed bits).
    pub fn serialize<S: Serializer>(g: &Grid<bool>, s: S) -> Result<S::Ok, S::Error> {
        let mut packed = vec![0u8; g.data().len().div_ceil(8)];
        for (i, &b) in g.data().iter().enumerate() {
            if b {
                packed[i / 8] |= 1 << (i % 8);
            }
        }
        let mut t = s.serialize_tuple(3)?;
        t.serialize_element(&(g.width() as u64))?;
        t.serialize_element(&(g.height() as u64))?;
        t.serialize_element(&BytesRef(&packed))?;
        t.end()
    }

    /// Deserializes a grid written by [`serialize`].
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Grid<bool>, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Grid<bool>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a bit grid (width, height, bits)")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Grid<bool>, A::Error> {
                let w: u64 = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let h: u64 = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(1, &self))?;
                let Decoded(packed) = seq
                    .next_element::<Decoded<u8>>()?
                    .ok_or_else(|| de::Error::invalid_length(2, &self))?;
                let n = w
                    .checked_mul(h)
                    .filter(|&n| n.div_ceil(8) == packed.len() as u64);
                let Some(n) = n else {
                    return Err(de::Error::custom("bit grid size does not match its data"));
                };
                let data = (0..n as usize)
                    .map(|i| packed[i / 8] & (1 << (i % 8)) != 0)
                    .collect();
                Grid::from_vec(w as usize, h as usize, data)
                    .ok_or_else(|| de::Error::custom("bit grid size does not match its data"))
            }
        }
        d.deserialize_tuple(3, V)
    }
}

/// `#[serde(with = "crate::raster::plain::vec")]` for a `Vec<T: Plain>`
/// field: one byte string instead of a sequence of numbers.
pub mod vec {
    use super::*;

    /// Serializes `v` as one byte string.
    pub fn serialize<T: Plain, S: Serializer>(v: &[T], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(&encode(v))
    }

    /// Deserializes a byte string written by [`serialize`]; fails when its
    /// length is not a whole number of samples.
    pub fn deserialize<'de, T: Plain, D: Deserializer<'de>>(d: D) -> Result<Vec<T>, D::Error> {
        Ok(Decoded::<T>::deserialize(d)?.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_round_trip_and_bad_sizes_fail() {
        let g = Grid::from_fn(3, 2, |x, y| [x as f32 * 0.5, -(y as f32)]);
        let bytes = postcard::to_stdvec(&g).unwrap();
        let back: Grid<[f32; 2]> = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(back, g);
        // Truncated: the byte string is shorter than declared.
        assert!(postcard::from_bytes::<Grid<[f32; 2]>>(&bytes[..bytes.len() - 3]).is_err());
        // A lying size: 3×2 data declared as 4×2.
        let mut bad = bytes.clone();
        bad[0] = 4;
        assert!(postcard::from_bytes::<Grid<[f32; 2]>>(&bad).is_err());
        let m = Grid::from_fn(5, 1, |x, _| x % 2 == 0);
        let back: Grid<bool> = postcard::from_bytes(&postcard::to_stdvec(&m).unwrap()).unwrap();
        assert_eq!(back, m);
    }
}
