//! Raster files (PNG, JPEG, …) to ink coverage, for [`super::ink`]:
//! decoding with the canvas limits checked first, coverage as alpha or
//! darkness, binary bitmaps recognised (and kept as their ink
//! [`Bitmap`]), or colours quantized into layers.

use super::lighting::Lighting;
use super::ImageOptions;
use crate::error::{Error, Result};
use crate::io;
use crate::outline::paths::Bitmap;
use crate::raster::regions::Partition;
use crate::raster::{Coverage, Grid};
use crate::svg_out::Color;
use rayon::prelude::*;

/// Decodes raster bytes, refusing oversized images before decoding, and
/// turns the picture as its Exif orientation says (as viewers show it).
pub fn decode_raster(bytes: &[u8]) -> Result<image::DynamicImage> {
    let bad = |e: &dyn std::fmt::Display| Error::Image(e.to_string());
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| bad(&e))?;
    if reader.format().is_none() {
        return Err(Error::Image(
            "unknown format (expected PNG, JPEG, BMP, GIF, TIFF, WebP or SVG)".into(),
        ));
    }
    let (w, h) = reader.into_dimensions().map_err(|e| bad(&e))?;
    io::check_canvas(w as u64, h as u64)?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| bad(&e))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(io::MAX_SIDE as u32);
    limits.max_image_height = Some(io::MAX_SIDE as u32);
    limits.max_alloc = Some(io::MAX_PIXELS * 8);
    reader.limits(limits);
    // Turned as it displays: a phone photo of a sketch is stored sideways
    // with an Exif orientation that viewers apply.
    let mut decoder = reader.into_decoder().map_err(|e| bad(&e))?;
    let orientation = image::ImageDecoder::orientation(&mut decoder)
        .unwrap_or(image::metadata::Orientation::NoTransforms);
    let mut img = image::DynamicImage::from_decoder(decoder).map_err(|e| bad(&e))?;
    img.apply_orientation(orientation);
    Ok(img)
}

/// A decoded raster's ink coverage, before any SDF is built.
pub(super) enum RasterCoverage {
    /// One layer of exactly 0/1 coverage, as the bitmap of its ink.
    Binary {
        w: usize,
        h: usize,
        color: Color,
        bits: Bitmap,
    },
    /// Layers (bottom first) of fractional coverage.
    Layers {
        w: usize,
        h: usize,
        layers: Vec<(Color, Coverage)>,
    },
}

/// Decodes raster bytes into ink coverage: alpha or darkness, one layer or
/// quantized colour layers; with the uneven light of a photo, when it was
/// measured and divided out first.
pub(super) fn raster_coverage(
    bytes: &[u8],
    opts: &ImageOptions,
) -> Result<(RasterCoverage, Option<Lighting>)> {
    let img = decode_raster(bytes)?;
    // A grey picture, stored as grey or as colour with three equal
    // channels (a scan saved as RGB), is read by its 256 levels.
    let grey = match (&img, opts.layers) {
        (image::DynamicImage::ImageLuma8(grey), false) => Some(std::borrow::Cow::Borrowed(grey)),
        (image::DynamicImage::ImageRgb8(rgb), false) => {
            grey_of_rgb(rgb).map(std::borrow::Cow::Owned)
        }
        _ => None,
    };
    if let Some(grey) = grey {
        let (w, h) = (grey.width() as usize, grey.height() as usize);
        // A photo's uneven light divided out first (see `lighting`).
        let raw = grey.as_raw();
        let luma = |x: usize, y: usize| raw.get(y * w + x).copied().unwrap_or(255);
        if let Some(light) = Lighting::measure(w, h, luma) {
            let mut even = grey.into_owned();
            light.flatten_grey(&mut even);
            return Ok((grey_coverage(&even, opts.invert), Some(light)));
        }
        return Ok((grey_coverage(&grey, opts.invert), None));
    }
    let (w, h) = (img.width() as usize, img.height() as usize);
    // RGBA pixels, read straight from the decoder's colour bytes where it
    // holds 8-bit RGB or RGBA (one copy), else converted.
    let mut px: Vec<[u8; 4]> = match img {
        image::DynamicImage::ImageRgb8(rgb) => rgb
            .as_raw()
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        image::DynamicImage::ImageRgba8(rgba) => rgba
            .as_raw()
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect(),
        other => other.to_rgba8().pixels().map(|p| p.0).collect(),
    };
    let mut lighting = None;
    if px.iter().all(|p| p[3] == 255) {
        let at = |x: usize, y: usize| {
            px.get(y * w + x).map_or(255, |p| {
                crate::raster::round_positive(luma(p) * 255.0) as u8
            })
        };
        lighting = Lighting::measure(w, h, at);
        if let Some(light) = &lighting {
            light.flatten_rgba(&mut px);
        }
    }
    Ok((pixel_coverage(&px, w, h, opts), lighting))
}

/// A raster's pixels read as regions of its palette's colours (see
/// [`crate::raster::regions`]): the partition and each colour, the
/// paper's first; with the uneven light of a photo divided out first, as
/// for the layers.
pub(super) fn raster_partition(bytes: &[u8]) -> Result<(Partition, Vec<Color>, Option<Lighting>)> {
    let img = decode_raster(bytes)?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let mut px: Vec<[u8; 4]> = match img {
        image::DynamicImage::ImageRgb8(rgb) => rgb
            .as_raw()
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        image::DynamicImage::ImageRgba8(rgba) => rgba
            .as_raw()
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect(),
        other => other.to_rgba8().pixels().map(|p| p.0).collect(),
    };
    let mut lighting = None;
    if px.iter().all(|p| p[3] == 255) {
        let at = |x: usize, y: usize| {
            px.get(y * w + x).map_or(255, |p| {
                crate::raster::round_positive(luma(p) * 255.0) as u8
            })
        };
        lighting = Lighting::measure(w, h, at);
        if let Some(light) = &lighting {
            light.flatten_rgba(&mut px);
        }
    }
    let (partition, colours) = pixel_partition(&px, w, h)?;
    Ok((partition, colours, lighting))
}

/// `w` × `h` RGBA pixels as regions of their palette's colours, with the
/// colours (the paper's first).
pub(super) fn pixel_partition(
    px: &[[u8; 4]],
    w: usize,
    h: usize,
) -> Result<(Partition, Vec<Color>)> {
    let has_alpha = px.iter().any(|p| p[3] < 255);
    let palette = Palette::of(px, w, h, has_alpha, false);
    let mut mixes = vec![(0u8, 0u8, 1f32); w * h];
    mixes
        .par_chunks_mut((MIX_ROWS * w).max(1))
        .enumerate()
        .for_each(|(band, out)| {
            let first = band * MIX_ROWS;
            palette.mixes(
                px,
                w,
                first..(first + MIX_ROWS).min(h),
                &mut |i, (a, b, t)| {
                    out[i - first * w] = (a as u8, b as u8, t);
                },
            )
        });
    let k = palette.colours.len();
    let colours = (0..k).map(|j| palette.colour(j)).collect();
    let partition = Partition::new(w, h, k, mixes)
        .ok_or_else(|| Error::invalid("the picture's colours do not make a partition"))?;
    Ok((partition, colours))
}

/// `rgb` as a grey image when every pixel's three channels are equal,
/// else `None` (found at the first coloured pixel). Checked in one pass
/// and copied in another, which knows its length (no growth check per
/// pixel).
fn grey_of_rgb(rgb: &image::RgbImage) -> Option<image::GrayImage> {
    let raw = rgb.as_raw();
    if !raw.chunks_exact(3).all(|c| c[0] == c[1] && c[1] == c[2]) {
        return None;
    }
    let grey: Vec<u8> = raw.chunks_exact(3).map(|c| c[0]).collect();
    image::GrayImage::from_raw(rgb.width(), rgb.height(), grey)
}

/// The ink coverage of `w` × `h` RGBA pixels (not premultiplied), row by
/// row: alpha when any pixel is transparent, else darkness; one layer, or
/// quantized colour layers with `--layers`.
pub(super) fn pixel_coverage(
    px: &[[u8; 4]],
    w: usize,
    h: usize,
    opts: &ImageOptions,
) -> RasterCoverage {
    let has_alpha = px.iter().any(|p| p[3] < 255);
    let layers = if opts.layers {
        quantized_layers(px, w, h, has_alpha, opts.invert, false)
    } else {
        Vec::new()
    };
    if !layers.is_empty() {
        RasterCoverage::Layers { w, h, layers }
    } else {
        // One layer: without `--layers`, or with it when no colour but the
        // paper fills patches of its own (a drawing in thin anti-aliased
        // lines, every ink pixel of which borders paper or a lighter edge
        // pixel): the drawing is its one ink, read as without `--layers`.
        // Raw coverage (alpha, or darkness on an opaque image), then put on
        // the scale of the image's own paper and ink.
        let raw: Vec<f32> = px
            .par_iter()
            .map(|p| {
                if has_alpha {
                    p[3] as f32 / 255.0
                } else {
                    1.0 - luma(p)
                }
            })
            .collect();
        let scale = InkScale::of_values(&raw);
        if !has_alpha && !one_ink(px, &raw, scale) {
            // Several inks: all of them, however light, each pixel read as
            // its mix of an ink or two and the paper (the bottom layer of
            // `--layers`' stack), filled black.
            if let Some((_, all)) = quantized_layers(px, w, h, false, false, true)
                .into_iter()
                .next()
            {
                let cov = if opts.invert {
                    all.map(|c| 1.0 - c)
                } else {
                    all
                };
                return RasterCoverage::Layers {
                    w,
                    h,
                    layers: vec![(Color::BLACK, cov)],
                };
            }
        }
        let cov = Grid::from_vec(
            w,
            h,
            raw.par_iter()
                .map(|&c| {
                    let c = scale.coverage(c);
                    if opts.invert {
                        1.0 - c
                    } else {
                        c
                    }
                })
                .collect(),
        )
        .expect("sizes match");
        // Traced paper is drawn as black ink: its own colour is the paper's.
        let color = if opts.invert {
            Color::BLACK
        } else {
            mean_ink_colour(px, &cov)
        };
        // A binary bitmap stands for a smooth outline within half a pixel
        // of its staircase (see `binary`); anti-aliased coverage says where
        // the edge is.
        if crate::raster::is_binary(&cov) {
            let bits = Bitmap::from_coverage(&cov);
            RasterCoverage::Binary { w, h, color, bits }
        } else {
            RasterCoverage::Layers {
                w,
                h,
                layers: vec![(color, cov)],
            }
        }
    }
}

/// [`raster_coverage`] of an 8-bit grey image without a colour copy: the
/// same coverage (darkness through [`luma`], so byte for byte what the RGBA
/// path gives) and the same mean ink colour, grey.
fn grey_coverage(grey: &image::GrayImage, invert: bool) -> RasterCoverage {
    let (w, h) = (grey.width() as usize, grey.height() as usize);
    let raw = grey.as_raw();
    let raw = raw.get(..w * h).unwrap_or(raw);
    // One pass over the bytes (in parallel; integer counts, so in any
    // order): how many pixels hold each grey level. Whether every level
    // present has coverage exactly 0 or 1, and the sum and count of the
    // fully inked pixels' levels, are then read off the 256 counts.
    let counts = raw
        .par_chunks(1 << 16)
        .map(|chunk| {
            let mut counts = [0u32; 256];
            for &v in chunk {
                counts[usize::from(v)] += 1;
            }
            counts
        })
        .reduce(
            || [0u32; 256],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
                a
            },
        );
    // Darkness of each of the 256 grey levels, and the image's paper and
    // ink on that scale (darkness bins run the other way: bin 255 − v).
    let dark: [f32; 256] = std::array::from_fn(|v| {
        let g = v as u8;
        1.0 - luma(&[g, g, g, 255])
    });
    let scale =
        InkScale::from_histogram(&std::array::from_fn(|b| u64::from(counts[255 - b])), |b| {
            dark[255 - b]
        });
    // Coverage of each level, computed once.
    let level: [f32; 256] = std::array::from_fn(|v| {
        let c = scale.coverage(dark[v]);
        if invert {
            1.0 - c
        } else {
            c
        }
    });
    let (mut binary, mut sum, mut n) = (true, 0u64, 0u64);
    for ((v, &count), &c) in counts.iter().enumerate().zip(&level) {
        if count == 0 {
            continue;
        }
        binary &= c == 0.0 || c == 1.0;
        if c > 0.95 {
            sum += v as u64 * u64::from(count);
            n += u64::from(count);
        }
    }
    // Traced paper is drawn as black ink: its own colour is the paper's.
    let color = match sum.checked_div(n) {
        Some(g) if !invert => Color::rgb(g as u8, g as u8, g as u8),
        _ => Color::BLACK,
    };
    if binary && raw.len() == w * h {
        // Straight to the ink bitmap: no coverage grid in between.
        let bits = Bitmap::from_rows(w, h, raw, |&v| level[usize::from(v)] >= 0.5);
        return RasterCoverage::Binary { w, h, color, bits };
    }
    let cov = Grid::from_vec(w, h, raw.iter().map(|&v| level[usize::from(v)]).collect())
        .unwrap_or_else(|| {
            Grid::from_fn(w, h, |x, y| {
                raw.get(y * w + x).map_or(0.0, |&v| level[usize::from(v)])
            })
        });
    RasterCoverage::Layers {
        w,
        h,
        layers: vec![(color, cov)],
    }
}

/// Raw coverage (alpha or darkness) below which, above the paper's own,
/// a pixel is still paper: off-white paper, scanner noise, JPEG ringing.
const PAPER_NOISE: f32 = 0.1;

/// Share of the inked pixels that may be darker than the level taken for
/// the ink (stray dark specks on a coloured drawing).
const INK_OUTLIERS: f64 = 0.001;

/// Where a raster's paper and its ink lie on the raw coverage scale
/// (alpha, or darkness `1 − luma`). Coverage is the share of ink in a
/// pixel, so a pixel is read as `(c − paper) / (ink − paper)`: a drawing
/// in yellow or light-grey ink traces as a drawing (its strokes' raw
/// darkness, 0.2–0.4, is under one half), its anti-aliased edges at their
/// true share, and black ink on white paper (paper 0, ink 1) exactly as
/// the raw value. A picture in several inks is not put on one scale (see
/// [`one_ink`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct InkScale {
    /// Raw coverage of the paper: the most common level under
    /// [`PAPER_NOISE`].
    paper: f32,
    /// Raw coverage of the ink: of the pixels at least [`PAPER_NOISE`]
    /// above the paper, the darkest level with no more than
    /// [`INK_OUTLIERS`] of them darker still.
    ink: f32,
    /// Raw coverage up to which the paper's own grain reaches: the darkest
    /// level of the paper's peak ([`paper_peak`]); the paper itself on a
    /// clean picture.
    grain: f32,
}

/// Share of the paper's most common level's count down to which the
/// levels next to it still belong to the paper's peak (about 2.8 σ of
/// Gaussian grain; an anti-aliased edge's levels hold a small fraction of
/// the paper's).
const GRAIN_PEAK_SHARE: f64 = 0.02;

/// The bins `lo..=hi` of the paper's peak round its most common bin
/// `paper`: walking lighter and darker from it, the unbroken runs whose
/// counts stay at or above [`GRAIN_PEAK_SHARE`] of the paper's count
/// (bins are lightest first, so darker is higher). One bin on clean paper.
fn paper_peak(counts: &[u64; 256], paper: usize) -> (usize, usize) {
    let least = counts[paper] as f64 * GRAIN_PEAK_SHARE;
    let in_peak = |b: usize| counts[b] > 0 && counts[b] as f64 >= least;
    let (mut lo, mut hi) = (paper, paper);
    while lo > 0 && in_peak(lo - 1) {
        lo -= 1;
    }
    while hi + 1 < 256 && in_peak(hi + 1) {
        hi += 1;
    }
    (lo, hi)
}

impl InkScale {
    /// Raw values as they are: paper 0, ink 1.
    const RAW: InkScale = InkScale {
        paper: 0.0,
        ink: 1.0,
        grain: 0.0,
    };

    /// The scale of a histogram of raw coverage in 256 bins, lightest
    /// first; `value(b)` is the raw coverage of bin `b`'s pixels (for a
    /// bin holding several values, its largest). [`InkScale::RAW`] when no
    /// pixel stands out from the paper.
    fn from_histogram(counts: &[u64; 256], value: impl Fn(usize) -> f32) -> InkScale {
        let held = |b: &usize| counts[*b] > 0;
        let paper_bin = (0..256)
            .filter(held)
            .filter(|&b| value(b) < PAPER_NOISE)
            .max_by_key(|&b| (counts[b], std::cmp::Reverse(b)));
        // Grainy paper is a peak of levels: the paper is its mean, and the
        // grain reaches its darkest level. On clean paper, one level.
        let (paper, grain) = match paper_bin {
            None => (0.0, 0.0),
            Some(b) => {
                let (lo, hi) = paper_peak(counts, b);
                if lo == hi {
                    (value(b), value(b))
                } else {
                    let (sum, n) = (lo..=hi).fold((0.0, 0u64), |(s, n), k| {
                        (s + f64::from(value(k)) * counts[k] as f64, n + counts[k])
                    });
                    ((sum / n.max(1) as f64) as f32, value(hi))
                }
            }
        };
        // The ink's darkest level is as far past the ink as the grain
        // reaches past the paper.
        let spread = grain - paper;
        let inked: Vec<usize> = (0..256)
            .filter(held)
            .filter(|&b| value(b) >= paper + PAPER_NOISE)
            .collect();
        let total: u64 = inked.iter().map(|&b| counts[b]).sum();
        let allowed = (total as f64 * INK_OUTLIERS) as u64;
        let mut darker = 0u64;
        for &b in inked.iter().rev() {
            darker += counts[b];
            if darker > allowed {
                return InkScale {
                    paper,
                    ink: (value(b) - spread).max(paper + PAPER_NOISE),
                    grain: grain.min(paper + PAPER_NOISE),
                };
            }
        }
        InkScale::RAW
    }

    /// The scale of raw coverage values in 0..=1 (binned by 1/255).
    fn of_values(raw: &[f32]) -> InkScale {
        let (counts, top) = raw
            .par_chunks(1 << 16)
            .map(|chunk| {
                let (mut counts, mut top) = ([0u64; 256], [0f32; 256]);
                for &c in chunk {
                    let b = coverage_bin(c);
                    counts[b] += 1;
                    top[b] = top[b].max(c);
                }
                (counts, top)
            })
            .reduce(
                || ([0u64; 256], [0f32; 256]),
                |(mut n, mut t), (m, u)| {
                    for b in 0..256 {
                        n[b] += m[b];
                        t[b] = t[b].max(u[b]);
                    }
                    (n, t)
                },
            );
        InkScale::from_histogram(&counts, |b| top[b])
    }

    /// A raw value's coverage, 0 (paper) to 1 (ink).
    fn coverage(&self, c: f32) -> f32 {
        if *self == InkScale::RAW {
            return c;
        }
        // The paper's grain is paper: a pixel within it reads 0. Grain
        // left on the paper round a hairline would join its faint edge
        // pixels into long runs of "ink" and hide that the line is thin
        // (`sdf::ThinRuns`), and the line would break where its pixels
        // are under one half.
        if c <= self.grain {
            return 0.0;
        }
        ((c - self.paper) / (self.ink - self.paper)).clamp(0.0, 1.0)
    }
}

/// The bin (0..=255) of raw coverage `c` for [`InkScale::of_values`]:
/// `c` held to 0..=1, times 255, rounded half up as
/// [`crate::raster::round_positive`] rounds
/// ([`crate::raster::round_to_byte`]).
fn coverage_bin(c: f32) -> usize {
    usize::from(crate::raster::round_to_byte(c.clamp(0.0, 1.0) * 255.0))
}

/// Largest distance (RGB, 0..=1 per channel) from the mix of paper and
/// ink at which a pixel still counts as that mix, for [`one_ink`].
const MIX_TOLERANCE: f32 = 0.1;

/// Whether an opaque image's inked pixels are all mixes of one ink with the
/// paper (anti-aliased edges of a one-colour drawing): no more than 10 % of
/// the pixels above the paper (a JPEG's chroma bleeding puts about 4 % of
/// a small drawing's off the line) lie farther than [`MIX_TOLERANCE`] from the
/// RGB segment between the paper's and the ink's mean colours. Only then
/// is the image's coverage put on [`InkScale`]; a drawing in several inks
/// is read through its palette instead (the union of all inks, so its
/// lighter inks are not measured against the darkest).
fn one_ink(px: &[[u8; 4]], raw: &[f32], scale: InkScale) -> bool {
    if scale == InkScale::RAW {
        return true;
    }
    let rgb = |p: &[u8; 4]| [p[0], p[1], p[2]].map(|v| v as f32 / 255.0);
    // The mean colours of the pixels at the paper's and at the ink's
    // level, summed over fixed chunks in parallel and the chunks added in
    // order. (Each channel is a multiple of 2⁻³¹ under 1, so in f64 the
    // sums of up to 4 M pixels are exact in any order.)
    type Sums = ([f64; 3], u64);
    let add = |(mut s, n): Sums, p: &[u8; 4]| {
        for (a, b) in s.iter_mut().zip(rgb(p)) {
            *a += f64::from(b);
        }
        (s, n + 1)
    };
    let near = |c: f32, level: f32| (c - level).abs() <= 1.0 / 255.0;
    let chunks: Vec<(Sums, Sums)> = px
        .par_chunks(ONE_INK_CHUNK)
        .zip(raw.par_chunks(ONE_INK_CHUNK))
        .map(|(ps, cs)| {
            ps.iter().zip(cs).fold(
                (([0f64; 3], 0u64), ([0f64; 3], 0u64)),
                |(paper, ink), (p, &c)| {
                    (
                        if near(c, scale.paper) {
                            add(paper, p)
                        } else {
                            paper
                        },
                        if near(c, scale.ink) { add(ink, p) } else { ink },
                    )
                },
            )
        })
        .collect();
    let total = |pick: fn(&(Sums, Sums)) -> &Sums| {
        let (sum, n) = chunks
            .iter()
            .map(pick)
            .fold(([0f64; 3], 0u64), |(mut s, n), (t, m)| {
                for (a, b) in s.iter_mut().zip(t) {
                    *a += b;
                }
                (s, n + m)
            });
        sum.map(|v| (v / n.max(1) as f64) as f32)
    };
    let (paper, ink) = (total(|c| &c.0), total(|c| &c.1));
    let d: [f32; 3] = std::array::from_fn(|k| ink[k] - paper[k]);
    let len2: f32 = d.iter().map(|v| v * v).sum();
    // Inked pixels, and those off the paper–ink segment (integer counts,
    // so in any order).
    let (inked, off) = px
        .par_chunks(ONE_INK_CHUNK)
        .zip(raw.par_chunks(ONE_INK_CHUNK))
        .map(|(ps, cs)| {
            let (mut inked, mut off) = (0u64, 0u64);
            for (p, &c) in ps.iter().zip(cs) {
                if c < scale.paper + PAPER_NOISE {
                    continue;
                }
                inked += 1;
                let q = rgb(p);
                let v: [f32; 3] = std::array::from_fn(|k| q[k] - paper[k]);
                let t = if len2 > 0.0 {
                    (v.iter().zip(&d).map(|(a, b)| a * b).sum::<f32>() / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let dist2: f32 = v.iter().zip(&d).map(|(a, b)| (a - t * b).powi(2)).sum();
                if dist2 > MIX_TOLERANCE * MIX_TOLERANCE {
                    off += 1;
                }
            }
            (inked, off)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    off * 10 <= inked
}

/// Pixels per chunk of [`one_ink`]'s parallel passes (fixed, so its sums
/// do not depend on the thread count).
const ONE_INK_CHUNK: usize = 1 << 16;

fn luma(p: &[u8; 4]) -> f32 {
    (0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32) / 255.0
}

/// The mean colour of fully inked pixels, black when there are none.
fn mean_ink_colour(px: &[[u8; 4]], cov: &Coverage) -> Color {
    let mut sum = [0u64; 3];
    let mut n = 0u64;
    for (p, &c) in px.iter().zip(cov.data()) {
        if c > 0.95 {
            for k in 0..3 {
                sum[k] += p[k] as u64;
            }
            n += 1;
        }
    }
    if n == 0 {
        return Color::BLACK;
    }
    Color::rgb((sum[0] / n) as u8, (sum[1] / n) as u8, (sum[2] / n) as u8)
}

/// A colour raster's palette of dominant colours, the paper's first (the
/// most common colour on the border, white when none), and how each
/// pixel is read as a mix of two of them.
struct Palette {
    /// Colours (RGB, 0..=255), the paper's first.
    colours: Vec<[f32; 3]>,
    /// Pairs `(a ≤ b)` of palette indices with the difference of their
    /// colours and its squared length.
    pairs: Vec<(usize, usize, [f32; 3], f32)>,
    has_alpha: bool,
}

/// Squared distance between two RGB colours.
fn dist2(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>()
}

/// The 12-bit histogram key of an RGB colour (4 bits a channel).
fn colour_key(c: &[f32; 3]) -> u32 {
    ((c[0] as u32 >> 4) << 8) | ((c[1] as u32 >> 4) << 4) | (c[2] as u32 >> 4)
}

/// [`colour_key`] of an opaque pixel's colour, from its bytes.
fn byte_key(p: &[u8; 4]) -> u16 {
    (u16::from(p[0] >> 4) << 8) | (u16::from(p[1] >> 4) << 4) | u16::from(p[2] >> 4)
}

impl Palette {
    /// The palette of `w` × `h` RGBA pixels (see [`quantized_layers`]):
    /// colours that fill patches of their own, most common first, at
    /// least 48 levels apart, at most 8, the paper moved to the front;
    /// only the paper with `paper_only`.
    fn of(px: &[[u8; 4]], w: usize, h: usize, has_alpha: bool, paper_only: bool) -> Palette {
        let rgb = |p: &[u8; 4]| composite(p, has_alpha);
        // An opaque pixel's key is read off its bytes (its composite is
        // the bytes themselves).
        let keys: Vec<u16> = if has_alpha {
            px.par_iter().map(|p| colour_key(&rgb(p)) as u16).collect()
        } else {
            px.par_iter().map(byte_key).collect()
        };
        // Per colour bin: pixels, pixels inside a patch of the colour (their
        // four neighbours in the same bin), and the sum of the colours.
        // (Keys are 12 bits: one slot per key, visited in key order.) Bands
        // of rows are counted in parallel and added up in order, so the sums
        // do not depend on the thread count.
        type Bin = (u64, u64, [f64; 3]);
        const BAND: usize = 64;
        let bands: Vec<Vec<Bin>> = (0..h.div_ceil(BAND))
            .into_par_iter()
            .map(|band| {
                let mut hist: Vec<Bin> = vec![(0, 0, [0.0; 3]); 1 << 12];
                // An opaque pixel's colour is its bytes: summed as
                // integers, and as floats once per band (exact either
                // way, so the sums are the same).
                let mut bytes: Vec<[u64; 3]> = if has_alpha {
                    Vec::new()
                } else {
                    vec![[0; 3]; 1 << 12]
                };
                for y in band * BAND..((band + 1) * BAND).min(h) {
                    let row = y * w;
                    for x in 0..w {
                        let i = row + x;
                        let k = keys[i];
                        let interior = x > 0
                            && y > 0
                            && x + 1 < w
                            && y + 1 < h
                            && keys[i - 1] == k
                            && keys[i + 1] == k
                            && keys[i - w] == k
                            && keys[i + w] == k;
                        let Some(e) = hist.get_mut(usize::from(k)) else {
                            continue;
                        };
                        e.0 += 1;
                        e.1 += u64::from(interior);
                        if let Some(b) = bytes.get_mut(usize::from(k)) {
                            let p = &px[i];
                            for (sum, &v) in b.iter_mut().zip(p) {
                                *sum += u64::from(v);
                            }
                        } else {
                            for (sum, v) in e.2.iter_mut().zip(rgb(&px[i])) {
                                *sum += v as f64;
                            }
                        }
                    }
                }
                for (e, b) in hist.iter_mut().zip(&bytes) {
                    e.2 = b.map(|v| v as f64);
                }
                hist
            })
            .collect();
        let mut hist: Vec<Bin> = vec![(0, 0, [0.0; 3]); 1 << 12];
        for band in &bands {
            for (e, b) in hist.iter_mut().zip(band) {
                e.0 += b.0;
                e.1 += b.1;
                for (s, v) in e.2.iter_mut().zip(b.2) {
                    *s += v;
                }
            }
        }
        drop(bands);
        // A colour that only lines the edges of others (the greys of
        // anti-aliasing between black ink and white paper) is a mix, not an
        // ink: a palette colour must fill patches of its own.
        let min_interior = ((w * h) as u64 / 2000).max(1);
        let mut bins: Vec<(u64, [f32; 3])> = hist
            .iter()
            .filter(|(n, interior, _)| *n > 0 && *interior >= min_interior)
            .map(|(n, _, s)| (*n, [0, 1, 2].map(|k| (s[k] / *n as f64) as f32)))
            .collect();
        bins.sort_by(|a, b| {
            b.0.cmp(&a.0)
                .then(a.1.partial_cmp(&b.1).unwrap_or(std::cmp::Ordering::Equal))
        });
        let min_count = ((w * h) as u64 / 500).max(1);
        let mut palette: Vec<[f32; 3]> = Vec::new();
        for (n, c) in &bins {
            if *n < min_count || palette.len() >= 8 {
                break;
            }
            if palette.iter().all(|p| dist2(p, c) > 48.0 * 48.0) {
                palette.push(*c);
            }
        }
        // Paper: the most common colour on the border (white if none).
        // (The border's pixels only: the top and bottom rows and the first
        // and last columns between them, each pixel once.)
        let mut border = vec![0usize; 1 << 12];
        let top_bottom = if h > 1 { vec![0, h - 1] } else { vec![0] };
        let sides = if w > 1 { vec![0, w - 1] } else { vec![0] };
        let rows = top_bottom
            .iter()
            .flat_map(|&y| (0..w).map(move |x| y * w + x));
        let columns = (1..h.saturating_sub(1)).flat_map(|y| sides.iter().map(move |&x| y * w + x));
        for i in rows.chain(columns) {
            if let Some(n) = keys.get(i).and_then(|&k| border.get_mut(usize::from(k))) {
                *n += 1;
            }
        }
        let paper_key = border
            .iter()
            .enumerate()
            .filter(|(_, &n)| n > 0)
            .max_by_key(|(k, &n)| (n, std::cmp::Reverse(*k)))
            .map(|(k, _)| k as u32);
        let paper = palette
            .iter()
            .position(|p| Some(colour_key(p)) == paper_key)
            .or_else(|| {
                palette
                    .iter()
                    .position(|p| dist2(p, &[255.0; 3]) < 48.0 * 48.0)
            });
        let paper_colour = paper.map(|i| palette[i]).unwrap_or([255.0; 3]);
        if let Some(i) = paper {
            palette.remove(i);
        }
        palette.insert(0, paper_colour);
        if paper_only {
            palette.truncate(1);
        }
        let k = palette.len();
        // The pairs (a ≤ b) with their difference and its squared length,
        // computed once.
        let pairs = (0..k)
            .flat_map(|a| (a..k).map(move |b| (a, b)))
            .map(|(a, b)| {
                let (pa, pb) = (&palette[a], &palette[b]);
                let d = [0, 1, 2].map(|j| pa[j] - pb[j]);
                let dd: f32 = d.iter().map(|v| v * v).sum();
                (a, b, d, dd)
            })
            .collect();
        Palette {
            colours: palette,
            pairs,
            has_alpha,
        }
    }

    /// Pixel `p` as a mix of its two nearest palette colours `(a, b, t)`:
    /// `t` of colour `a` and `1 − t` of colour `b` (`a ≤ b`), the mix
    /// nearest to the pixel's colour over all pairs.
    fn mix(&self, p: &[u8; 4]) -> (usize, usize, f32) {
        let c = composite(p, self.has_alpha);
        let mut best = (f32::MAX, 0usize, 0usize, 1.0f32);
        for &(a, b, d, dd) in &self.pairs {
            let pb = &self.colours[b];
            let t = if dd > 0.0 {
                (((0..3).map(|j| (c[j] - pb[j]) * d[j]).sum::<f32>()) / dd).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let mix = [0, 1, 2].map(|j| pb[j] + t * d[j]);
            let e = dist2(&mix, &c);
            if e < best.0 {
                best = (e, a, b, t);
            }
        }
        (best.1, best.2, best.3)
    }

    /// Calls `each(i, mix)` for every pixel `i` of rows `rows` of the
    /// `w`-wide `px`, in order. A pixel's mix depends on its value alone,
    /// so it is looked up in a small table of the values met last (flat
    /// art repeats a few values, a scan's noisy paper a few thousand)
    /// before it is worked out.
    fn mixes(
        &self,
        px: &[[u8; 4]],
        w: usize,
        rows: std::ops::Range<usize>,
        each: &mut dyn FnMut(usize, (usize, usize, f32)),
    ) {
        const CACHE: usize = 1 << 12;
        let mut cache = vec![(0u32, false, (0usize, 0usize, 0f32)); CACHE];
        for y in rows {
            for (x, p) in px[y * w..(y + 1) * w].iter().enumerate() {
                let v = u32::from_le_bytes(*p);
                let slot = (v.wrapping_mul(0x9e37_79b1) >> 20) as usize % CACHE;
                let mix = match cache[slot] {
                    (cv, true, mix) if cv == v => mix,
                    _ => {
                        let mix = self.mix(p);
                        cache[slot] = (v, true, mix);
                        mix
                    }
                };
                each(y * w + x, mix);
            }
        }
    }

    /// Palette colour `k` as an output colour.
    fn colour(&self, k: usize) -> Color {
        let c = self.colours[k];
        Color::rgb(c[0].round() as u8, c[1].round() as u8, c[2].round() as u8)
    }
}

/// An RGBA pixel composited over white (transparency reads as paper),
/// RGB 0..=255.
fn composite(p: &[u8; 4], has_alpha: bool) -> [f32; 3] {
    if !has_alpha {
        return [f32::from(p[0]), f32::from(p[1]), f32::from(p[2])];
    }
    let a = p[3] as f32 / 255.0;
    [0, 1, 2].map(|k| p[k] as f32 * a + 255.0 * (1.0 - a))
}

/// Rows per band of the per-pixel passes.
const MIX_ROWS: usize = 16;

/// Splits a colour raster into stacked layers: a palette of dominant colours
/// (the paper colour, most common on the border, excluded), each pixel
/// explained as a mix of its two nearest palette colours (anti-aliasing),
/// and layer `k` covering its own colour and every colour stacked above it.
fn quantized_layers(
    px: &[[u8; 4]],
    w: usize,
    h: usize,
    has_alpha: bool,
    invert: bool,
    union_only: bool,
) -> Vec<(Color, Coverage)> {
    let palette = Palette::of(px, w, h, has_alpha, invert);
    let k = palette.colours.len();
    let w1 = w.max(1);
    if union_only && !invert {
        // Only the bottom of the stack (every ink), black; nothing when the
        // palette holds no ink. A pixel's ink is the share of its mix that
        // is not paper (colour 0), added up as the layers' weights are.
        if k < 2 {
            return Vec::new();
        }
        let mut all = vec![0f32; w * h];
        all.par_chunks_mut(MIX_ROWS * w1)
            .enumerate()
            .for_each(|(band, out)| {
                let first = band * MIX_ROWS;
                palette.mixes(
                    px,
                    w,
                    first..(first + MIX_ROWS).min(h),
                    &mut |i, (a, b, t)| {
                        out[i - first * w] = if a >= 1 {
                            (t + (1.0 - t)).min(1.0)
                        } else if b >= 1 {
                            (1.0 - t).min(1.0)
                        } else {
                            0.0
                        };
                    },
                )
            });
        return Grid::from_vec(w, h, all)
            .map(|g| vec![(Color::BLACK, g)])
            .unwrap_or_default();
    }
    // Per pixel, the weights of its two nearest palette colours (each
    // band of rows writes its own pixels' `k` weights).
    let mut weights = vec![0f32; w * h * k];
    weights
        .par_chunks_mut((MIX_ROWS * k * w).max(1))
        .enumerate()
        .for_each(|(band, out)| {
            let first = band * MIX_ROWS;
            palette.mixes(
                px,
                w,
                first..(first + MIX_ROWS).min(h),
                &mut |i, (a, b, t)| {
                    let wt = &mut out[(i - first * w) * k..(i - first * w + 1) * k];
                    if let Some(x) = wt.get_mut(a) {
                        *x += t;
                    }
                    if let Some(x) = wt.get_mut(b) {
                        *x += 1.0 - t;
                    }
                },
            )
        });
    if invert {
        let cov = Grid::from_fn(w, h, |x, y| weights[(y * w + x) * k]);
        let c = palette.colours[0];
        return vec![(Color::rgb(c[0] as u8, c[1] as u8, c[2] as u8), cov)];
    }
    if union_only {
        return Vec::new();
    }
    // Stack by area, largest at the bottom.
    let mut order: Vec<usize> = (1..k).collect();
    let mut areas = vec![0f64; k];
    for wt in weights.chunks_exact(k.max(1)) {
        for (a, &v) in areas.iter_mut().zip(wt) {
            *a += v as f64;
        }
    }
    order.sort_by(|&a, &b| areas[b].total_cmp(&areas[a]).then(a.cmp(&b)));
    order
        .iter()
        .enumerate()
        .filter(|(_, &j)| areas[j] > 0.0)
        .map(|(pos, &j)| {
            let above = &order[pos..];
            let cov = Grid::from_vec(
                w,
                h,
                weights
                    .par_chunks(k.max(1))
                    .map(|wt| above.iter().map(|&m| wt[m]).sum::<f32>().min(1.0))
                    .collect(),
            )
            .unwrap_or_else(|| Grid::new(w, h, 0.0));
            (palette.colour(j), cov)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A drawing in one colour of thin anti-aliased lines has no palette
    /// colour but the paper (no ink pixel has four neighbours of its own
    /// colour): with `--layers` it is still traced, as one layer, the
    /// coverage it has without `--layers`.
    #[test]
    fn layers_of_a_thin_line_drawing_are_its_one_ink() {
        let (w, h) = (64usize, 48usize);
        // A 1.2-px line from (4, 6) to (60, 40), anti-aliased by its
        // distance, in dark blue on white.
        let (a, b) = (kurbo::Point::new(4.0, 6.0), kurbo::Point::new(60.0, 40.0));
        let px: Vec<[u8; 4]> = (0..w * h)
            .map(|i| {
                let p = kurbo::Point::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                let d = crate::raster::sdf::point_segment_distance(p, kurbo::Line::new(a, b));
                let c = (0.6 - d + 0.5).clamp(0.0, 1.0);
                let mix = |ink: f64| (255.0 * (1.0 - c) + ink * c).round() as u8;
                [mix(20.0), mix(30.0), mix(90.0), 255]
            })
            .collect();
        let plain = pixel_coverage(&px, w, h, &ImageOptions::default());
        let layered = pixel_coverage(
            &px,
            w,
            h,
            &ImageOptions {
                layers: true,
                ..ImageOptions::default()
            },
        );
        let one = |r: &RasterCoverage| match r {
            RasterCoverage::Layers { layers, .. } if layers.len() == 1 => {
                Some((layers[0].0, layers[0].1.data().to_vec()))
            }
            _ => None,
        };
        let (colour, cov) = one(&plain).expect("one anti-aliased layer");
        assert!(cov.iter().filter(|&&c| c >= 0.5).count() > 40);
        assert_eq!(one(&layered), Some((colour, cov)));
    }

    /// A colour image whose every pixel is grey is its grey image; one
    /// coloured pixel anywhere (the last one too) makes it a colour image.
    #[test]
    fn grey_of_rgb_reads_grey_pixels_and_refuses_colour() {
        let (w, h) = (7u32, 5u32);
        let grey: Vec<u8> = (0..w * h).map(|i| (i * 37 % 256) as u8).collect();
        let rgb: Vec<u8> = grey.iter().flat_map(|&v| [v, v, v]).collect();
        let img = image::RgbImage::from_raw(w, h, rgb.clone()).expect("sizes");
        let got = grey_of_rgb(&img).expect("grey");
        assert_eq!((got.width(), got.height()), (w, h));
        assert_eq!(got.as_raw(), &grey);
        for at in [0, 17, rgb.len() - 1] {
            let mut c = rgb.clone();
            c[at] ^= 1;
            let img = image::RgbImage::from_raw(w, h, c).expect("sizes");
            assert!(grey_of_rgb(&img).is_none(), "byte {at}");
        }
    }

    /// The bin is `round_positive` of 255 × the clamped value, at every
    /// half-way point between bins and one and two ulps either side, at
    /// the float just under 0.5 / 255, and out of range.
    #[test]
    fn coverage_bins_round_as_round_positive() {
        let want =
            |c: f32| (crate::raster::round_positive(c.clamp(0.0, 1.0) * 255.0) as usize).min(255);
        let mut values = vec![
            -1.0f32,
            -0.0,
            0.0,
            1.0,
            1.5,
            f32::MIN_POSITIVE,
            0.49999997 / 255.0,
        ];
        for k in 0..=256u32 {
            for c in [(k as f32 + 0.5) / 255.0, k as f32 / 255.0] {
                let b = c.to_bits();
                values.extend(
                    [b.saturating_sub(2), b.saturating_sub(1), b, b + 1, b + 2].map(f32::from_bits),
                );
            }
        }
        for c in values {
            assert_eq!(coverage_bin(c), want(c), "{c:e}");
        }
    }

    proptest! {
        #[test]
        fn coverage_bins_match_round_positive_anywhere(c in -0.5f32..1.5) {
            let want = (crate::raster::round_positive(c.clamp(0.0, 1.0) * 255.0) as usize).min(255);
            prop_assert_eq!(coverage_bin(c), want);
        }
    }

    /// An opaque pixel's colour and key read off its bytes are the
    /// composite's, for every level of each channel.
    #[test]
    fn opaque_pixels_key_by_their_bytes() {
        for v in 0..=255u8 {
            for p in [
                [v, 0, 0, 255],
                [0, v, 0, 255],
                [0, 0, v, 255],
                [v, 255 - v, v / 3, 255],
            ] {
                let slow = [0, 1, 2].map(|k| p[k] as f32 * 1.0 + 255.0 * (1.0 - 1.0));
                assert_eq!(composite(&p, false), slow);
                assert_eq!(u32::from(byte_key(&p)), colour_key(&slow));
            }
        }
    }

    /// The grey path as first written: a coverage grid (darkness on the
    /// image's [`InkScale`], as the colour path measures it), checked for
    /// 0/1 values, then the bitmap of its ink; the mean level of pixels
    /// with coverage above 0.95.
    fn reference(grey: &image::GrayImage, invert: bool) -> (bool, Color, Coverage) {
        let dark = |g: u8| 1.0 - luma(&[g, g, g, 255]);
        let raw: Vec<f32> = grey.pixels().map(|p| dark(p[0])).collect();
        let scale = InkScale::of_values(&raw);
        let cov = Grid::from_fn(grey.width() as usize, grey.height() as usize, |x, y| {
            let g = grey.get_pixel(x as u32, y as u32)[0];
            let c = scale.coverage(dark(g));
            if invert {
                1.0 - c
            } else {
                c
            }
        });
        let (mut sum, mut n) = (0u64, 0u64);
        for (p, &c) in grey.pixels().zip(cov.data()) {
            if c > 0.95 {
                sum += p[0] as u64;
                n += 1;
            }
        }
        let color = match sum.checked_div(n) {
            Some(g) if !invert => Color::rgb(g as u8, g as u8, g as u8),
            _ => Color::BLACK,
        };
        (crate::raster::is_binary(&cov), color, cov)
    }

    /// The palette quantization as first written (every pixel's colour
    /// and key held, the mix worked out for every pixel not equal to the
    /// one before it, the weights of every layer held): the oracle of the
    /// cached, banded version.
    #[allow(clippy::type_complexity)]
    fn quantized_reference(
        px: &[[u8; 4]],
        w: usize,
        h: usize,
        has_alpha: bool,
        invert: bool,
        union_only: bool,
    ) -> Vec<(Color, Coverage)> {
        // Composite over white so transparency reads as paper.
        let rgb: Vec<[f32; 3]> = px
            .iter()
            .map(|p| {
                let a = if has_alpha { p[3] as f32 / 255.0 } else { 1.0 };
                [0, 1, 2].map(|k| p[k] as f32 * a + 255.0 * (1.0 - a))
            })
            .collect();
        let key = |c: &[f32; 3]| {
            ((c[0] as u32 >> 4) << 8) | ((c[1] as u32 >> 4) << 4) | (c[2] as u32 >> 4)
        };
        let keys: Vec<u32> = rgb.iter().map(key).collect();
        // Per colour bin: pixels, pixels inside a patch of the colour (their
        // four neighbours in the same bin), and the sum of the colours.
        // (Keys are 12 bits: one slot per key, visited in key order.)
        let mut hist = vec![(0u64, 0u64, [0f64; 3]); 1 << 12];
        for (i, c) in rgb.iter().enumerate() {
            let (x, y) = (i % w, i / w);
            let k = keys[i];
            let interior = x > 0
                && y > 0
                && x + 1 < w
                && y + 1 < h
                && [i - 1, i + 1, i - w, i + w].iter().all(|&j| keys[j] == k);
            let Some(e) = hist.get_mut(k as usize) else {
                continue;
            };
            e.0 += 1;
            e.1 += u64::from(interior);
            for (sum, &v) in e.2.iter_mut().zip(c) {
                *sum += v as f64;
            }
        }
        // A colour that only lines the edges of others (the greys of
        // anti-aliasing between black ink and white paper) is a mix, not an
        // ink: a palette colour must fill patches of its own.
        let min_interior = ((w * h) as u64 / 2000).max(1);
        let mut bins: Vec<(u64, [f32; 3])> = hist
            .iter()
            .filter(|(n, interior, _)| *n > 0 && *interior >= min_interior)
            .map(|(n, _, s)| (*n, [0, 1, 2].map(|k| (s[k] / *n as f64) as f32)))
            .collect();
        bins.sort_by(|a, b| {
            b.0.cmp(&a.0)
                .then(a.1.partial_cmp(&b.1).unwrap_or(std::cmp::Ordering::Equal))
        });
        let min_count = ((w * h) as u64 / 500).max(1);
        let dist2 = |a: &[f32; 3], b: &[f32; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>();
        let mut palette: Vec<[f32; 3]> = Vec::new();
        for (n, c) in &bins {
            if *n < min_count || palette.len() >= 8 {
                break;
            }
            if palette.iter().all(|p| dist2(p, c) > 48.0 * 48.0) {
                palette.push(*c);
            }
        }
        // Paper: the most common colour on the border (white if none).
        let mut border = vec![0usize; 1 << 12];
        for (i, c) in rgb.iter().enumerate() {
            let (x, y) = (i % w, i / w);
            if x == 0 || y == 0 || x + 1 == w || y + 1 == h {
                if let Some(n) = border.get_mut(key(c) as usize) {
                    *n += 1;
                }
            }
        }
        let paper_key = border
            .iter()
            .enumerate()
            .filter(|(_, &n)| n > 0)
            .max_by_key(|(k, &n)| (n, std::cmp::Reverse(*k)))
            .map(|(k, _)| k as u32);
        let paper = palette
            .iter()
            .position(|p| Some(key(p)) == paper_key)
            .or_else(|| {
                palette
                    .iter()
                    .position(|p| dist2(p, &[255.0; 3]) < 48.0 * 48.0)
            });
        let paper_colour = paper.map(|i| palette[i]).unwrap_or([255.0; 3]);
        if let Some(i) = paper {
            palette.remove(i);
        }
        palette.insert(0, paper_colour);
        if invert {
            // Inverting swaps the roles: trace the paper as the only layer.
            palette.truncate(1);
        }
        let k = palette.len();
        // Per pixel, weights of its two nearest palette colours (pixels in
        // parallel: each writes its own `k` weights).
        // The pairs (a ≤ b) with their difference and its squared length,
        // computed once.
        let pairs: Vec<(usize, usize, [f32; 3], f32)> = (0..k)
            .flat_map(|a| (a..k).map(move |b| (a, b)))
            .map(|(a, b)| {
                let (pa, pb) = (&palette[a], &palette[b]);
                let d = [0, 1, 2].map(|j| pa[j] - pb[j]);
                let dd: f32 = d.iter().map(|v| v * v).sum();
                (a, b, d, dd)
            })
            .collect();
        let nearest_mix = |c: &[f32; 3]| {
            let mut best = (f32::MAX, 0usize, 0usize, 1.0f32);
            for &(a, b, d, dd) in &pairs {
                let pb = &palette[b];
                let t = if dd > 0.0 {
                    (((0..3).map(|j| (c[j] - pb[j]) * d[j]).sum::<f32>()) / dd).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let mix = [0, 1, 2].map(|j| pb[j] + t * d[j]);
                let e = dist2(&mix, c);
                if e < best.0 {
                    best = (e, a, b, t);
                }
            }
            (best.1, best.2, best.3)
        };
        // A pixel with the value of the one before it in its row takes that
        // one's mix (flat art is long runs of one value); rows in parallel.
        let value = |p: &[u8; 4]| u32::from_le_bytes(*p);
        let mut weights = vec![0f32; w * h * k];
        weights
            .par_chunks_mut((k * w).max(1))
            .zip(px.par_chunks(w.max(1)).zip(rgb.par_chunks(w.max(1))))
            .for_each(|(row, (prow, crow))| {
                let mut last: Option<(u32, (usize, usize, f32))> = None;
                for ((wt, p), c) in row.chunks_mut(k.max(1)).zip(prow).zip(crow) {
                    let v = value(p);
                    let (a, b, t) = match last {
                        Some((lv, mix)) if lv == v => mix,
                        _ => {
                            let mix = nearest_mix(c);
                            last = Some((v, mix));
                            mix
                        }
                    };
                    if let Some(x) = wt.get_mut(a) {
                        *x += t;
                    }
                    if let Some(x) = wt.get_mut(b) {
                        *x += 1.0 - t;
                    }
                }
            });
        if invert {
            let cov = Grid::from_fn(w, h, |x, y| weights[(y * w + x) * k]);
            let c = palette[0];
            return vec![(Color::rgb(c[0] as u8, c[1] as u8, c[2] as u8), cov)];
        }
        if union_only {
            // Only the bottom of the stack (every ink), black; nothing when the
            // palette holds no ink.
            if k < 2 {
                return Vec::new();
            }
            let all: Vec<f32> = weights
                .par_chunks(k)
                .map(|wt| wt.iter().skip(1).sum::<f32>().min(1.0))
                .collect();
            return Grid::from_vec(w, h, all)
                .map(|g| vec![(Color::BLACK, g)])
                .unwrap_or_default();
        }
        // Stack by area, largest at the bottom.
        let mut order: Vec<usize> = (1..k).collect();
        let area = |j: usize| (0..w * h).map(|i| weights[i * k + j] as f64).sum::<f64>();
        let areas: Vec<f64> = (0..k).map(area).collect();
        order.sort_by(|&a, &b| areas[b].total_cmp(&areas[a]).then(a.cmp(&b)));
        order
            .iter()
            .enumerate()
            .filter(|(_, &j)| areas[j] > 0.0)
            .map(|(pos, &j)| {
                let above = &order[pos..];
                let cov = Grid::from_fn(w, h, |x, y| {
                    let i = y * w + x;
                    above
                        .iter()
                        .map(|&m| weights[i * k + m])
                        .sum::<f32>()
                        .min(1.0)
                });
                let c = palette[j];
                (
                    Color::rgb(c[0].round() as u8, c[1].round() as u8, c[2].round() as u8),
                    cov,
                )
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// The banded, cached quantization gives the reference's layers,
        /// colours and coverages bit for bit: flat art with anti-aliased
        /// mixes, noise (every pixel its own value), transparency, the
        /// union of all inks and the paper alone.
        #[test]
        fn quantized_layers_match_the_reference(
            w in 1usize..70,
            h in 1usize..90,
            inks in 1usize..4,
            noise in 0u8..12,
            alpha in any::<bool>(),
            invert in any::<bool>(),
            union_only in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let colours = [[250u8, 245, 230], [20, 20, 30], [200, 60, 40], [40, 90, 200]];
            let mut state = seed | 1;
            let mut rnd = move || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state
            };
            let px: Vec<[u8; 4]> = (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as f64, (i / w) as f64);
                    // Discs of each ink on the paper, blended at their rims.
                    let mut c = colours[0].map(f64::from);
                    for (k, ink) in colours.iter().enumerate().take(inks + 1).skip(1) {
                        let (cx, cy) = (w as f64 * k as f64 / (inks + 1) as f64, h as f64 / 2.0);
                        let cov = (0.5 - ((x - cx).hypot(y - cy) - 0.3 * w.min(h) as f64)).clamp(0.0, 1.0);
                        for (v, &i) in c.iter_mut().zip(ink) {
                            *v += cov * (f64::from(i) - *v);
                        }
                    }
                    let mut out = [255u8; 4];
                    for j in 0..3 {
                        let r = (rnd() % (2 * u64::from(noise) + 1)) as f64 - f64::from(noise);
                        out[j] = (c[j] + r).round().clamp(0.0, 255.0) as u8;
                    }
                    if alpha {
                        out[3] = (rnd() % 256) as u8;
                    }
                    out
                })
                .collect();
            let union_only = union_only && !invert;
            let got = quantized_layers(&px, w, h, alpha, invert, union_only);
            let want = quantized_reference(&px, w, h, alpha, invert, union_only);
            prop_assert_eq!(got.len(), want.len());
            for ((gc, gcov), (wc, wcov)) in got.iter().zip(&want) {
                prop_assert_eq!(gc, wc);
                prop_assert_eq!(gcov.data(), wcov.data());
            }
        }
    }

    /// A grey picture stored as colour (three equal channels) traces as
    /// the same picture stored as grey, byte for byte.
    #[test]
    fn grey_stored_as_colour_reads_as_grey() {
        let (w, h) = (90u32, 70u32);
        let grey = image::GrayImage::from_fn(w, h, |x, y| {
            let d = (f64::from(x) - 40.0).hypot(f64::from(y) - 30.0) - 20.0;
            image::Luma([(255.0 * (0.5 + d).clamp(0.0, 1.0)).round() as u8])
        });
        let rgb = image::RgbImage::from_fn(w, h, |x, y| {
            let g = grey.get_pixel(x, y)[0];
            image::Rgb([g, g, g])
        });
        let bytes = |img: image::DynamicImage| {
            let mut out = std::io::Cursor::new(Vec::new());
            img.write_to(&mut out, image::ImageFormat::Png)
                .expect("encodes");
            out.into_inner()
        };
        let opts = ImageOptions::default();
        let (a, _) = raster_coverage(&bytes(grey.into()), &opts).expect("reads");
        let (b, _) = raster_coverage(&bytes(rgb.into()), &opts).expect("reads");
        match (a, b) {
            (
                RasterCoverage::Layers { layers: la, .. },
                RasterCoverage::Layers { layers: lb, .. },
            ) => {
                assert_eq!(la.len(), 1);
                assert_eq!(la[0].0, lb[0].0);
                assert_eq!(la[0].1.data(), lb[0].1.data());
            }
            _ => panic!("an anti-aliased disc reads as one layer of coverage"),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Straight from the bytes: the same binary verdict, ink, colour
        /// and (otherwise) coverage as through the coverage grid.
        #[test]
        fn grey_bytes_read_as_through_coverage(
            w in 1u32..40,
            h in 1u32..30,
            levels in prop::collection::vec(any::<u8>(), 1..4),
            binary in any::<bool>(),
            invert in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let grey = image::GrayImage::from_fn(w, h, |x, y| {
                let k = (seed ^ (x as u64 * 31 + y as u64 * 1009)).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 60;
                if binary {
                    image::Luma([if k.is_multiple_of(2) { 0 } else { 255 }])
                } else {
                    image::Luma([levels[k as usize % levels.len()]])
                }
            });
            let (is_bin, color, cov) = reference(&grey, invert);
            match grey_coverage(&grey, invert) {
                RasterCoverage::Binary { w: bw, h: bh, color: c, bits } => {
                    prop_assert!(is_bin);
                    prop_assert_eq!((bw, bh), (w as usize, h as usize));
                    prop_assert_eq!(c, color);
                    let ink = bits.to_coverage();
                    prop_assert_eq!(ink.data(), cov.data());
                }
                RasterCoverage::Layers { layers, .. } => {
                    prop_assert!(!is_bin);
                    prop_assert_eq!(layers.len(), 1);
                    prop_assert_eq!(layers[0].0, color);
                    prop_assert_eq!(layers[0].1.data(), cov.data());
                }
            }
        }
    }

    /// Anti-aliasing greys are not inks: black hairlines and a black disc,
    /// anti-aliased on white (thousands of pixels at a few grey levels),
    /// give one black layer; a grey that fills a patch of its own is a
    /// second layer.
    #[test]
    fn anti_aliasing_greys_make_no_layer_but_a_grey_patch_does() {
        let (w, h) = (160usize, 120usize);
        let picture = |grey_patch: bool| -> Vec<[u8; 4]> {
            (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                    // Hairlines 1 px wide straddling two rows: 50 % each.
                    let line = (y % 8.0 - 4.0).abs() < 1.0 && x > 90.0;
                    let d = (x - 45.0).hypot(y - 60.0) - 30.0;
                    let disc = (0.5 - d).clamp(0.0, 1.0);
                    let c = if line { 0.5 } else { disc };
                    let v = if grey_patch && x > 100.0 && y < 40.0 {
                        128
                    } else {
                        (255.0 * (1.0 - c)).round() as u8
                    };
                    [v, v, v, 255]
                })
                .collect()
        };
        let layers = quantized_layers(&picture(false), w, h, false, false, false);
        assert_eq!(
            layers.len(),
            1,
            "{:?}",
            layers.iter().map(|l| l.0).collect::<Vec<_>>()
        );
        assert!(layers[0].0 == Color::rgb(0, 0, 0), "{:?}", layers[0].0);
        let layers = quantized_layers(&picture(true), w, h, false, false, false);
        assert_eq!(layers.len(), 2);
    }

    /// Black ink on white reads as it is; one lighter ink is put on its
    /// own scale (stray darker specks ignored); paper alone stays raw.
    #[test]
    fn ink_scale_reads_the_drawing_not_the_darkness() {
        let hist = |pairs: &[(usize, u64)]| {
            let mut h = [0u64; 256];
            for &(b, n) in pairs {
                h[b] = n;
            }
            h
        };
        let value = |b: usize| b as f32 / 255.0;
        // Black on white, anti-aliased.
        let black = InkScale::from_histogram(&hist(&[(0, 9000), (128, 40), (255, 500)]), value);
        assert_eq!(black, InkScale::RAW);
        assert_eq!(black.coverage(0.3), 0.3);
        // Yellow (darkness 0.3) on off-white (0.04), with one black speck.
        let yellow =
            InkScale::from_histogram(&hist(&[(10, 9000), (40, 30), (77, 3000), (255, 1)]), value);
        assert_eq!((yellow.paper, yellow.ink), (value(10), value(77)));
        assert_eq!(yellow.coverage(value(77)), 1.0);
        assert_eq!(yellow.coverage(value(10)), 0.0);
        assert!((yellow.coverage(0.5 * (value(10) + value(77))) - 0.5).abs() < 1e-6);
        assert_eq!(yellow.coverage(1.0), 1.0);
        // Nothing above the paper noise.
        let blank = InkScale::from_histogram(&hist(&[(0, 9000), (12, 30)]), value);
        assert_eq!(blank, InkScale::RAW);
    }

    /// Grainy paper is a peak of levels: the paper is read at the peak's
    /// mean, the ink as far inside its darkest level as the grain reaches
    /// past the paper, and every level of the grain as paper; an
    /// anti-aliased edge's few pixels next to clean paper are not grain.
    #[test]
    fn grainy_paper_is_measured_as_a_peak() {
        let value = |b: usize| b as f32 / 255.0;
        let mut h = [0u64; 256];
        // Paper at 20 ± 4 (flat grain), ink at 200 ± 4, a few edge pixels.
        h[16..=24].fill(1000);
        h[196..=204].fill(300);
        for b in (40..180).step_by(10) {
            h[b] = 5;
        }
        let s = InkScale::from_histogram(&h, value);
        assert!((s.paper - value(20)).abs() < 1e-6, "{s:?}");
        assert!((s.grain - value(24)).abs() < 1e-6, "{s:?}");
        assert!((s.ink - value(200)).abs() < 1e-6, "{s:?}");
        assert_eq!(s.coverage(value(24)), 0.0);
        assert_eq!(s.coverage(value(16)), 0.0);
        assert!(s.coverage(value(25)) > 0.0);
        assert!((s.coverage(value(110)) - 0.5).abs() < 1e-6);
        assert_eq!(s.coverage(value(204)), 1.0);
        // One level of paper (a clean scan): its neighbours' edge pixels
        // are not grain, and nothing changes.
        let mut clean = [0u64; 256];
        clean[20] = 9000;
        clean[21] = 40;
        clean[200] = 3000;
        let c = InkScale::from_histogram(&clean, value);
        assert_eq!(
            (c.paper, c.grain, c.ink),
            (value(20), value(20), value(200))
        );
        assert!(c.coverage(value(21)) > 0.0);
    }

    /// A drawing in one light ink traces as a drawing, in its colour; two
    /// inks are told apart from one.
    #[test]
    fn one_light_ink_is_traced_and_two_inks_are_told_apart() {
        let (w, h) = (64usize, 48usize);
        let picture = |second: bool| -> Vec<[u8; 4]> {
            (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                    let c = (0.5 - ((x - 24.0).hypot(y - 24.0) - 12.0)).clamp(0.0, 1.0);
                    let ink = [240.0, 200.0, 40.0];
                    let mix = |k: usize| (255.0 + c * (ink[k] - 255.0)).round() as u8;
                    if second && x > 40.0 && y < 20.0 {
                        [20, 40, 160, 255]
                    } else {
                        [mix(0), mix(1), mix(2), 255]
                    }
                })
                .collect()
        };
        let raw_of = |px: &[[u8; 4]]| px.iter().map(|p| 1.0 - luma(p)).collect::<Vec<f32>>();
        let one = picture(false);
        let raw = raw_of(&one);
        let scale = InkScale::of_values(&raw);
        assert!(one_ink(&one, &raw, scale));
        // Every pixel reads as the share of the disc it holds (a yellow
        // disc's centre is 0.3 dark: raw, nothing of it would be ink).
        assert_eq!(scale.coverage(raw[24 * w + 24]), 1.0);
        let mut rim = 0;
        for (i, &r) in raw.iter().enumerate() {
            let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            let c = (0.5 - ((x - 24.0).hypot(y - 24.0) - 12.0)).clamp(0.0, 1.0);
            let read = f64::from(scale.coverage(r));
            assert!((read - c).abs() < 0.02, "({x}, {y}): {read} for {c}");
            rim += usize::from(c > 0.05 && c < 0.95);
        }
        assert!(rim > 40, "{rim} rim pixels");
        let two = picture(true);
        let raw = raw_of(&two);
        assert!(!one_ink(&two, &raw, InkScale::of_values(&raw)));
    }
}
