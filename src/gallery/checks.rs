//! The gallery's cases and what each is measured by.
//!
//! - fill (art-pattern-level-sets.txt §2–3): no refusal; neither empty nor
//!   solid; each colour layer's ink within 15 % of the swatch's own; no ink
//!   outside the region beyond the tracing tolerance; forks of the top
//!   layer's bands and the regularity of its gaps within 20 % of the
//!   swatch's own (`fill::continuity`); the finest level's synthesis energy
//!   below its initialization's. The swatches' own figures are pooled over
//!   all of a style's swatches: a seamless tile measured on its 3 × 3
//!   repetition's centre copy, any other swatch on itself more than 6 px
//!   inside its shape (a motif on paper) or its border; ink as a share of
//!   the pattern (a motif's shape, not the paper round it). Gap regularity
//!   is left out for a region too narrow to hold a whole gap. Each fill
//!   figure is the median over seeds 0, 1 and 2 ([`FILL_SEEDS`]).
//! - pattern (stroke-pattern-synthesis.txt §3): elements placed, their
//!   nearest-neighbour spacing within 20 % of the example's, no element's
//!   ink over another's, of its own stroke or any other (`overlap`: the
//!   share of ink drawn twice, each element rendered on its own at 4 px
//!   per unit).
//! - brush (decobrush.txt §5–7): ink covers 95 % of the path within half
//!   a width, or 95 % of what the exemplars cover of their own spines
//!   within half their width when that is less (an exemplar drawn on one
//!   side of its spine, or a lattice with gaps along it, leaves some of
//!   its spine bare: the ornament then must do as its exemplars do, not
//!   more); none beyond 1.5 widths, no piece smaller than the exemplars'
//!   smallest drawn element, structure density within 30 % of the
//!   exemplars', line thicknesses closer to the exemplars' than half the
//!   art brush's distance; in a library of several exemplars, no stretch
//!   of one drawn more than twice in a row (`repeats`, the longest run of
//!   consecutive matched segments on one exemplar stretch,
//!   [`crate::brush::matching::longest_repeat`]).
//! - trace: the render of the output matches the drawing's own render
//!   (IoU of the ink at the bitmap's size); a drawing in several colours,
//!   traced `--layers --cutout` too and rendered at 4× without
//!   anti-aliasing, leaves no pixel uncovered (`cutout-gaps`) and none
//!   covered twice (`cutout-overlaps`), and no colour's IoU with the
//!   drawing's is lower than stacked mode's (`cutout-iou`, the worst
//!   difference); the default trace (every ink in
//!   one layer) makes at most 0.8× the segments potrace makes of the
//!   bitmap thresholded at one half (`segments-vs-potrace`, `potrace -s -t
//!   3`, issue 24).

use crate::brush::measure::{ink, ExemplarFigures, Fidelity};
use crate::brush::output::{brush_sketch, out_per_fine};
use crate::brush::pipeline::Settings;
use crate::fill::continuity::{junctions, pieces, regular_gaps};
use crate::fill::tile::Tile;
use crate::library::{Style, StyleOptions};
use crate::raster::Grid;
use crate::read::sketch;
use crate::read::style::StyleKind;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One measured figure of a case and its threshold.
#[derive(Clone, Debug)]
pub(super) struct Check {
    /// Short name, one word (e.g. `ink`, `coverage`).
    pub(super) name: String,
    /// The figure; `None` when the case was refused.
    pub(super) value: Option<f64>,
    /// Whether it meets its threshold.
    pub(super) ok: bool,
    /// Whether a larger figure is better.
    pub(super) higher_is_better: bool,
    /// The threshold, in words.
    pub(super) wanted: String,
    /// The threshold (`None` for a figure that is only recorded, or a
    /// case that did not run).
    pub(super) limit: Option<f64>,
}

impl Check {
    /// A figure that must be at least `min`.
    fn at_least(name: &str, value: f64, min: f64) -> Check {
        Check {
            name: name.into(),
            value: None,
            ok: false,
            higher_is_better: true,
            wanted: format!("≥ {min}"),
            limit: Some(min),
        }
        .measured(value)
    }

    /// A figure that must be at most `max`.
    fn at_most(name: &str, value: f64, max: f64) -> Check {
        Check {
            name: name.into(),
            value: None,
            ok: false,
            higher_is_better: false,
            wanted: format!("≤ {max}"),
            limit: Some(max),
        }
        .measured(value)
    }

    /// This check with figure `value`, judged against its threshold (a
    /// recorded figure keeps its verdict).
    fn measured(self, value: f64) -> Check {
        let ok = match self.limit {
            Some(l) if self.higher_is_better => value >= l,
            Some(l) => value <= l,
            None => self.ok,
        };
        Check {
            value: Some(value),
            ok,
            ..self
        }
    }

    /// The case did not run: `runs` fails.
    fn refused() -> Check {
        Check {
            name: "runs".into(),
            value: None,
            ok: false,
            higher_is_better: true,
            wanted: "no refusal".into(),
            limit: None,
        }
    }

    /// The figure as the report and the list show it.
    pub(super) fn shown(&self) -> String {
        match self.value {
            Some(v) => format!("{v:.4}"),
            None => "refused".into(),
        }
    }

    /// Whether the figure is worse than `listed` by more than `drift`
    /// (relative, with a floor of 0.001 absolute).
    pub(super) fn worse_than(&self, listed: f64, drift: f64) -> bool {
        let Some(v) = self.value else { return true };
        let slack = (drift * listed.abs()).max(1e-3);
        if self.higher_is_better {
            v < listed - slack
        } else {
            v > listed + slack
        }
    }
}

/// A finished case.
#[derive(Clone, Debug)]
pub(super) struct Case {
    /// `MODE--STYLE--SKETCH`.
    pub(super) name: String,
    /// The style folder (for the sheet's swatch panel).
    pub(super) style: PathBuf,
    /// The sketch or bitmap.
    pub(super) input: PathBuf,
    /// The output SVG, when it ran.
    pub(super) output: Option<PathBuf>,
    /// Why it was refused.
    pub(super) error: Option<String>,
    /// Its checks; a refused case has the one failing `runs`.
    pub(super) checks: Vec<Check>,
    /// Wall-clock seconds of the mode itself.
    pub(super) secs: f64,
}

impl Case {
    /// One line for the log.
    pub(super) fn line(&self) -> String {
        let figures: Vec<String> = self
            .checks
            .iter()
            .map(|c| format!("{} {}{}", c.name, c.shown(), if c.ok { "" } else { "!" }))
            .collect();
        let err = self
            .error
            .as_deref()
            .map(|e| format!(" ({e})"))
            .unwrap_or_default();
        format!(
            "{} {:.2} s: {}{err}",
            self.name,
            self.secs,
            figures.join(", ")
        )
    }
}

/// A case to run.
pub(super) struct Plan {
    mode: &'static str,
    style: PathBuf,
    input: PathBuf,
}

impl Plan {
    /// `MODE--STYLE--INPUT`.
    pub(super) fn name(&self) -> String {
        let stem = |p: &Path| {
            p.file_stem()
                .or_else(|| p.file_name())
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        if self.mode == "trace" {
            format!("trace--{}", stem(&self.input))
        } else {
            format!(
                "{}--{}--{}",
                self.mode,
                stem(&self.style),
                stem(&self.input)
            )
        }
    }

    /// Runs the case, writes its output into `out/MODE/`, and measures it.
    pub(super) fn run(&self, out: &Path) -> Case {
        let name = self.name();
        let t = Instant::now();
        let result = match self.mode {
            "fill" => over_seeds(&FILL_SEEDS, |seed| fill(&self.style, &self.input, seed)),
            "pattern" => pattern(&self.style, &self.input),
            "brush" => over_seeds(&[0], |seed| brush(&self.style, &self.input, seed)),
            _ => trace(&self.input),
        };
        let secs = t.elapsed().as_secs_f64();
        let mut case = Case {
            name: name.clone(),
            style: self.style.clone(),
            input: self.input.clone(),
            output: None,
            error: None,
            checks: Vec::new(),
            secs,
        };
        match result {
            Ok((svg, checks)) => {
                let dir = out.join(self.mode);
                let _ = std::fs::create_dir_all(&dir);
                let path = dir.join(format!("{name}.svg"));
                if std::fs::write(&path, svg).is_ok() {
                    case.output = Some(path);
                }
                case.checks = checks;
            }
            Err(e) => {
                case.error = Some(e.to_string());
                case.checks = vec![Check::refused()];
            }
        }
        case
    }
}

/// The `.svg` files of `dir` whose names start with `prefix`, sorted.
fn svgs(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().is_some_and(|e| e == "svg")
                        && p.file_name()
                            .is_some_and(|n| n.to_string_lossy().starts_with(prefix))
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The kind a style folder's `style.toml` declares, read without checking
/// the rest (a style the library refuses is a case all the same).
fn kind_of(dir: &Path) -> Option<StyleKind> {
    #[derive(serde::Deserialize)]
    struct Kind {
        kind: StyleKind,
    }
    let text = std::fs::read_to_string(dir.join(crate::read::style::STYLE_FILE)).ok()?;
    toml::from_str::<Kind>(&text).ok().map(|k| k.kind)
}

/// The style folders of `dir` of `kind`, sorted.
fn styles(dir: &Path, kind: StyleKind) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| kind_of(p) == Some(kind))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The cases of `mode`: the art's and the shipped styles of its kind on
/// the art's sketches and the samples.
pub(super) fn plan(mode: &'static str, art: &Path, root: &Path) -> Vec<Plan> {
    let cross = |kind: StyleKind, shipped: bool, inputs: Vec<PathBuf>| -> Vec<Plan> {
        let mut dirs = styles(&art.join("styles"), kind);
        if shipped {
            dirs.extend(styles(&root.join("styles"), kind));
        }
        dirs.iter()
            .flat_map(|s| {
                inputs.iter().map(move |i| Plan {
                    mode,
                    style: s.clone(),
                    input: i.clone(),
                })
            })
            .collect()
    };
    match mode {
        "fill" => {
            let mut inputs = svgs(&art.join("sketches"), "region-");
            inputs.extend(
                ["circle", "star", "letter", "frame", "combed"]
                    .iter()
                    .map(|s| root.join("samples/fill").join(format!("{s}.svg"))),
            );
            cross(StyleKind::Fill, true, inputs)
        }
        "pattern" => cross(StyleKind::Pattern, false, svgs(&art.join("sketches"), "")),
        "brush" => {
            let mut inputs = svgs(&art.join("sketches"), "brush-");
            inputs.extend(
                svgs(&root.join("samples/brush"), "")
                    .into_iter()
                    .filter(|p| !p.to_string_lossy().ends_with("-refine.svg")),
            );
            cross(StyleKind::Brush, true, inputs)
        }
        _ => {
            let mut pngs: Vec<PathBuf> = std::fs::read_dir(art.join("trace"))
                .map(|r| {
                    r.filter_map(|e| e.ok().map(|e| e.path()))
                        .filter(|p| p.extension().is_some_and(|e| e == "png"))
                        .collect()
                })
                .unwrap_or_default();
            pngs.sort();
            pngs.into_iter()
                .map(|p| Plan {
                    mode,
                    style: PathBuf::new(),
                    input: p,
                })
                .collect()
        }
    }
}

type Outcome = crate::Result<(String, Vec<Check>)>;

/// The seeds a fill case is run with: a fill's forks and gaps are counts
/// over a few motifs, and one seed's synthesis can land well off the
/// method's typical figure either way, so each figure is the median of
/// three seeds.
const FILL_SEEDS: [u64; 3] = [0, 1, 2];

/// The seeds a case is run with: `FLOURISH_GALLERY_SEEDS` (a comma list,
/// to measure other seeds; the shortfalls are listed for the defaults),
/// or `default`.
fn seeds(default: &[u64]) -> Vec<u64> {
    std::env::var("FLOURISH_GALLERY_SEEDS")
        .ok()
        .map(|s| {
            s.split(',')
                .filter_map(|t| t.trim().parse().ok())
                .collect::<Vec<u64>>()
        })
        .filter(|v| !v.is_empty())
        .unwrap_or_else(|| default.to_vec())
}

/// A case run once per seed of [`seeds`]: the first seed's output, and
/// each check's median figure over the seeds that measured it (the lower
/// middle one of an even count), judged against its threshold again. A
/// refusal at any seed is the case's refusal.
fn over_seeds(default: &[u64], run: impl Fn(u64) -> Outcome) -> Outcome {
    let seeds = seeds(default);
    let mut runs = Vec::with_capacity(seeds.len());
    for &seed in &seeds {
        runs.push(run(seed)?);
    }
    let mut runs = runs.into_iter();
    let Some((svg, first)) = runs.next() else {
        return Err(crate::Error::invalid("no seed to run"));
    };
    let rest: Vec<Vec<Check>> = runs.map(|(_, c)| c).collect();
    let checks = first
        .into_iter()
        .map(|c| {
            let mut values: Vec<f64> = std::iter::once(c.value)
                .chain(
                    rest.iter()
                        .filter_map(|r| r.iter().find(|o| o.name == c.name).map(|o| o.value)),
                )
                .flatten()
                .collect();
            if values.is_empty() {
                return c;
            }
            values.sort_by(f64::total_cmp);
            c.measured(values[(values.len() - 1) / 2])
        })
        .collect();
    Ok((svg, checks))
}

/// Loads a style with its analysis cached in this checkout's
/// `target/gallery-cache`: a cache shared by several checkouts could hand
/// one the analysis another's code made.
fn load(style: &Path) -> crate::Result<Style> {
    Style::load(
        style,
        &StyleOptions {
            cache_dir: Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("target/gallery-cache")),
            ..StyleOptions::default()
        },
    )
}

/// The worst of `values` (the smallest when larger is better), or `ok`'s
/// value when there are none.
fn worst(values: impl Iterator<Item = f64>, higher_is_better: bool, none: f64) -> f64 {
    values
        .fold(None, |acc: Option<f64>, v| {
            Some(match acc {
                None => v,
                Some(a) if higher_is_better => a.min(v),
                Some(a) => a.max(v),
            })
        })
        .unwrap_or(none)
}

/// Forks of the top layer's bands per 10⁴ px and the share of regular
/// gaps of the bottom layer, where `counted` (the tile's centre copy, or
/// the region's inside more than 6 px from its outline); no share when no
/// gap lies wholly where counted.
fn continuity(
    bottom: &Grid<bool>,
    top: &Grid<bool>,
    counted: &Grid<bool>,
    gap: f64,
) -> (f64, Option<f64>) {
    let area = counted.data().iter().filter(|&&c| c).count().max(1) as f64;
    let forks = junctions(top, counted, 4) as f64 * 1e4 / area;
    let paper = Grid::from_fn(bottom.width(), bottom.height(), |x, y| !bottom.get(x, y));
    // A region too narrow to hold a whole gap says nothing of their
    // regularity.
    let whole = pieces(&paper, counted).iter().any(|p| p.within);
    let gaps = (gap > 0.0 && whole).then(|| regular_gaps(&paper, counted, gap, 1.6));
    (forks, gaps)
}

/// One swatch as the checks see it: its bottom and top layers' ink and
/// where it counts. A seamless tile is measured on its 3 × 3 repetition's
/// centre copy (so bands crossing its seams are whole); any other swatch
/// on its own shape, more than 6 px inside it.
struct SwatchInk {
    bottom: Grid<bool>,
    top: Grid<bool>,
    counted: Grid<bool>,
    /// Areas of its gaps (paper pieces): a tile's that touch the centre
    /// copy without reaching the repetition's edge, a swatch's that lie
    /// wholly where counted.
    gaps: Vec<usize>,
}

impl SwatchInk {
    fn of(tile: &Tile) -> SwatchInk {
        let nl = tile.layers.len();
        let (tw, th) = (tile.width(), tile.height());
        if tile.periodic {
            let rep = |k: usize| {
                Grid::from_fn(3 * tw, 3 * th, |x, y| {
                    tile.layers[k].sdf.get(x % tw, y % th) < 0.0
                })
            };
            let bottom = rep(0);
            let counted = Grid::from_fn(3 * tw, 3 * th, |x, y| {
                (tw..2 * tw).contains(&x) && (th..2 * th).contains(&y)
            });
            let inner = Grid::from_fn(3 * tw, 3 * th, |x, y| {
                x > 0 && y > 0 && x + 1 < 3 * tw && y + 1 < 3 * th
            });
            let paper = bottom.map(|b| !b);
            let gaps = pieces(&paper, &inner)
                .into_iter()
                .zip(pieces(&paper, &counted))
                .filter(|(a, c)| a.within && c.touches)
                .map(|(a, _)| a.area)
                .collect();
            SwatchInk {
                bottom,
                top: rep(nl - 1),
                counted,
                gaps,
            }
        } else {
            let shape = tile
                .shape
                .clone()
                .unwrap_or_else(|| Grid::new(tw, th, true));
            let d2 = crate::raster::edt::squared_edt(&shape.map(|s| !s));
            let layer = |k: usize| tile.layers[k].sdf.map(|d| d < 0.0);
            let bottom = layer(0);
            let counted = Grid::from_fn(tw, th, |x, y| {
                x >= 6 && y >= 6 && x + 6 < tw && y + 6 < th && d2.get(x, y) > 36.0
            });
            let gaps = pieces(&bottom.map(|b| !b), &counted)
                .into_iter()
                .filter(|p| p.within)
                .map(|p| p.area)
                .collect();
            SwatchInk {
                bottom,
                top: layer(nl - 1),
                counted,
                gaps,
            }
        }
    }
}

fn fill(style: &Path, input: &Path, seed: u64) -> Outcome {
    let st = load(style)?;
    let fs = st.fill()?;
    let sk = sketch::load(input)?;
    let out = crate::fill::fill_sketch(
        &sk,
        |_| Ok((st.name(), fs)),
        &crate::fill::FillOptions {
            seed,
            ..crate::fill::FillOptions::default()
        },
    )?;
    let svg = out.to_document().to_svg();
    let tiles = &fs.tiles;
    let nl = tiles[0].layers.len();
    // The swatches' own figures, pooled: ink per layer over their
    // patterns, forks per 10⁴ counted px, the median gap and the share of
    // regular gaps.
    let inks: Vec<SwatchInk> = tiles.iter().map(SwatchInk::of).collect();
    let area: usize = tiles.iter().map(|t| t.area()).sum();
    let own_ink =
        |k: usize| tiles.iter().map(|t| t.ink_px(k)).sum::<usize>() as f64 / area.max(1) as f64;
    let mut gap_areas: Vec<usize> = inks.iter().flat_map(|s| s.gaps.clone()).collect();
    gap_areas.sort_unstable();
    let gap = gap_areas
        .get(gap_areas.len() / 2)
        .map_or(0.0, |&a| a as f64);
    let counted_px: usize = inks
        .iter()
        .map(|s| s.counted.data().iter().filter(|&&c| c).count())
        .sum();
    let tile_forks = inks
        .iter()
        .map(|s| junctions(&s.top, &s.counted, 4))
        .sum::<usize>() as f64
        * 1e4
        / counted_px.max(1) as f64;
    let tile_gaps = (gap > 0.0).then(|| {
        let (ok, all) = inks.iter().fold((0.0, 0.0), |(ok, all), s| {
            let paper = s.bottom.map(|b| !b);
            let n = pieces(&paper, &s.counted)
                .iter()
                .filter(|p| p.within)
                .count() as f64;
            (ok + regular_gaps(&paper, &s.counted, gap, 1.6) * n, all + n)
        });
        if all > 0.0 {
            ok / all
        } else {
            0.0
        }
    });
    let mut ink_err: Vec<f64> = Vec::new();
    let mut blank: Vec<f64> = Vec::new();
    let mut outside: Vec<f64> = Vec::new();
    let mut forks: Vec<f64> = Vec::new();
    let mut gaps: Vec<f64> = Vec::new();
    let mut energy: Vec<f64> = Vec::new();
    for r in &out.regions {
        let mask = &r.region.mask;
        let area = r.region.area.max(1) as f64;
        let fraction = |k: usize| {
            r.layers[k]
                .data()
                .iter()
                .zip(mask.data())
                .filter(|(d, m)| **m && **d < 0.0)
                .count() as f64
                / area
        };
        for k in 0..nl {
            let own = own_ink(k);
            if own >= 0.01 {
                ink_err.push((fraction(k) / own - 1.0).abs());
            }
        }
        let f = fraction(0);
        blank.push(f.min(1.0 - f));
        // Curve points outside the region, region px beyond its outline.
        let to_px = r.region.sdf.to_user.inverse();
        let far = r
            .paths
            .iter()
            .flatten()
            .flat_map(|p| p.segments())
            .flat_map(|s| (0..8).map(move |k| kurbo::ParamCurve::eval(&s, k as f64 / 8.0)))
            .map(|p| r.region.sdf.value(to_px * p))
            .fold(0.0f64, f64::max);
        outside.push(far);
        let (w, h) = (mask.width(), mask.height());
        let counted = r.region.sdf.dist.map(|d| d < -6.0);
        let layer =
            |k: usize| Grid::from_fn(w, h, |x, y| mask.get(x, y) && r.layers[k].get(x, y) < 0.0);
        let (fk, gp) = continuity(&layer(0), &layer(nl - 1), &counted, gap);
        forks.push((fk - tile_forks).abs() / tile_forks.max(1.0));
        if let (Some(g), Some(t)) = (gp, tile_gaps) {
            if t > 0.0 {
                gaps.push(g / t);
            }
        }
        if let Some(fine) = r.energy.last() {
            if let (Some(&first), Some(&last)) = (fine.first(), fine.last()) {
                energy.push(last / first.max(1e-12));
            }
        }
    }
    let mut checks = vec![
        Check::at_least("blank", worst(blank.into_iter(), true, 0.0), 0.02),
        Check::at_most("ink", worst(ink_err.into_iter(), false, 0.0), 0.15),
        Check::at_most("outside", worst(outside.into_iter(), false, 0.0), 0.5),
        Check::at_most("forks", worst(forks.into_iter(), false, 0.0), 0.2),
    ];
    if !gaps.is_empty() {
        checks.push(Check::at_least(
            "gaps",
            worst(gaps.into_iter(), true, 1.0),
            0.8,
        ));
    }
    checks.push(Check::at_most(
        "energy",
        worst(energy.into_iter(), false, 0.0),
        0.9999,
    ));
    Ok((svg, checks))
}

/// Mean distance from each point to its nearest other point.
fn mean_nearest(pts: &[kurbo::Point]) -> Option<f64> {
    if pts.len() < 2 {
        return None;
    }
    let sum: f64 = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            pts.iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, q)| p.distance(*q))
                .fold(f64::MAX, f64::min)
        })
        .sum();
    Some(sum / pts.len() as f64)
}

fn pattern(style: &Path, input: &Path) -> Outcome {
    let st = load(style)?;
    let ps = st.pattern()?.clone();
    let sk = sketch::load(input)?;
    let out = crate::pattern::synthesize_sketch(
        &sk,
        |_| Ok(ps.clone()),
        &crate::pattern::PatternOptions::default(),
    )?;
    let svg = out.to_document().to_svg();
    let own = mean_nearest(&ps.reference.dist.centres).unwrap_or(0.0);
    let mut spacing = Vec::new();
    let mut placed = f64::INFINITY;
    for q in &out.queries {
        let centres: Vec<kurbo::Point> = q.elements.iter().map(|e| e.centre).collect();
        placed = placed.min(centres.len() as f64);
        if let Some(m) = mean_nearest(&centres) {
            spacing.push((m / own - 1.0).abs());
        }
    }
    // All queries together: elements of two strokes must not overlap
    // either.
    let overlap = overlapping_ink(
        out.queries
            .iter()
            .flat_map(|q| q.elements.iter().map(move |e| (&*q.style, e))),
    )?;
    Ok((
        svg,
        vec![
            Check::at_least("placed", placed, 2.0),
            Check::at_most("spacing", worst(spacing.into_iter(), false, 0.0), 0.2),
            Check::at_most("overlap", overlap, 0.0),
        ],
    ))
}

/// Pixels per user unit at which [`overlapping_ink`] renders elements.
const OVERLAP_PX: f64 = 4.0;

/// The share of the ink of `elements` drawn by two or more: each placed
/// element rendered on its own at [`OVERLAP_PX`] px per unit, a pixel
/// inked where its coverage is over a half, and the pixels inked by two
/// elements counted against all inked pixels. Touching elements share
/// no pixel over half covered by both; any real overlap wider than a
/// quarter unit does.
fn overlapping_ink<'a>(
    elements: impl Iterator<
        Item = (
            &'a crate::pattern::PatternStyle,
            &'a crate::pattern::PlacedElement,
        ),
    >,
) -> crate::Result<f64> {
    use crate::svg_out::{Document, Group};
    let mut count: std::collections::HashMap<(i64, i64), u8> = Default::default();
    for (style, e) in elements {
        let shapes: Vec<_> = style
            .element_shapes(e.element)
            .map(|s| {
                let mut s = s.clone();
                s.path.apply_affine(e.transform);
                s
            })
            .collect();
        let Some(bbox) = shapes
            .iter()
            .map(|s| {
                let grow = s.stroke.as_ref().map_or(0.0, |k| k.width) + 1.0;
                kurbo::Shape::bounding_box(&s.path).inflate(grow, grow)
            })
            .reduce(|a, b| a.union(b))
        else {
            continue;
        };
        // Snapped to the pixel grid, so that all elements share it.
        let (x0, y0) = (
            (bbox.x0 * OVERLAP_PX).floor(),
            (bbox.y0 * OVERLAP_PX).floor(),
        );
        let (x1, y1) = ((bbox.x1 * OVERLAP_PX).ceil(), (bbox.y1 * OVERLAP_PX).ceil());
        let mut doc = Document::new(x1 - x0, y1 - y0, 4);
        doc.view_box = kurbo::Rect::new(
            x0 / OVERLAP_PX,
            y0 / OVERLAP_PX,
            x1 / OVERLAP_PX,
            y1 / OVERLAP_PX,
        );
        doc.groups.push(Group {
            id: "e".into(),
            shapes,
        });
        let tree = crate::read::svg::parse_svg(doc.to_svg().as_bytes())?;
        let pix = crate::render::render_tree(&tree, None, None)?;
        let w = pix.width() as usize;
        for (i, px) in pix.pixels().iter().enumerate() {
            if px.alpha() > 127 {
                let at = (x0 as i64 + (i % w) as i64, y0 as i64 + (i / w) as i64);
                let c = count.entry(at).or_default();
                *c = c.saturating_add(1);
            }
        }
    }
    let inked = count.len();
    let twice = count.values().filter(|&&c| c > 1).count();
    Ok(if inked == 0 {
        0.0
    } else {
        twice as f64 / inked as f64
    })
}

fn brush(style: &Path, input: &Path, seed: u64) -> Outcome {
    let st = load(style)?;
    let bs = st.brush()?;
    let sk = sketch::load(input)?;
    let keep = Settings {
        discard_fields: false,
        seed,
        ..Settings::default()
    };
    let out = brush_sketch(bs, &sk, &keep)?;
    let art = brush_sketch(
        bs,
        &sk,
        &Settings {
            art_brush: true,
            ..keep.clone()
        },
    )?;
    let figures = ExemplarFigures::of(bs);
    let (mut coverage, mut far, mut debris, mut density, mut thickness) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut repeats = Vec::new();
    let ew = crate::brush::ribs::exemplar_width(bs)?;
    for (r, a) in out.queries.iter().zip(&art.queries) {
        let (_, m) = crate::brush::pipeline::matched(bs, &r.spine, &keep, ew)?;
        repeats.push(crate::brush::matching::longest_repeat(&m.segments) as f64);
        let mask = ink(bs, r);
        // Output px per finest exemplar px, where the exemplars' figures
        // are measured.
        let (k, ka) = (out_per_fine(bs, r), out_per_fine(bs, a));
        let f = Fidelity::of(r, &mask);
        coverage.push(f.coverage / figures.coverage.clamp(1e-9, 1.0));
        far.push(f.farthest);
        let smallest = (figures.smallest as f64 * k * k).round() as usize;
        debris.push(f.smallest.min(usize::MAX >> 1) as f64 / smallest.min(f.largest).max(1) as f64);
        density.push((figures.density_of(r, &mask, k) / figures.density.max(1e-9) - 1.0).abs());
        let own = figures.thickness_distance(&mask, k);
        let stretched = figures.thickness_distance(&ink(bs, a), ka);
        thickness.push(own / stretched.max(1e-9));
    }
    let mut checks = vec![
        Check::at_least("coverage", worst(coverage.into_iter(), true, 0.0), 0.95),
        Check::at_most("farthest", worst(far.into_iter(), false, 0.0), 1.5),
        Check::at_least("debris", worst(debris.into_iter(), true, 1.0), 1.0),
        Check::at_most("density", worst(density.into_iter(), false, 0.0), 0.3),
        Check::at_most("thickness", worst(thickness.into_iter(), false, 0.0), 0.5),
    ];
    if bs.exemplars.len() > 1 {
        checks.push(Check::at_most(
            "repeats",
            worst(repeats.into_iter(), false, 0.0),
            2.0,
        ));
    }
    Ok((out.document.to_svg(), checks))
}

/// Ink pixels of an SVG rendered `w` × `h` px (dark or opaque enough:
/// alpha-weighted darkness over ½).
fn rendered_ink(svg: &[u8], w: u32, h: u32) -> crate::Result<Vec<bool>> {
    let tree = crate::read::svg::parse_svg(svg)?;
    let size = tree.size();
    let mut pixmap =
        resvg::tiny_skia::Pixmap::new(w, h).ok_or_else(|| crate::Error::invalid("empty render"))?;
    let t =
        resvg::tiny_skia::Transform::from_scale(w as f32 / size.width(), h as f32 / size.height());
    resvg::render(&tree, t, &mut pixmap.as_mut());
    Ok(pixmap
        .pixels()
        .iter()
        .map(|p| {
            let c = p.demultiply();
            let dark = 1.0 - (c.red() as f32 + c.green() as f32 + c.blue() as f32) / 765.0;
            dark * c.alpha() as f32 / 255.0 > 0.25
        })
        .collect())
}

/// Distinct fill colours of an SVG's text (`fill="#rrggbb"`).
fn fill_colours(svg: &str) -> usize {
    let mut seen: Vec<&str> = svg
        .split("fill=\"#")
        .skip(1)
        .filter_map(|r| r.get(..6))
        .collect();
    seen.sort_unstable();
    seen.dedup();
    seen.len()
}

/// The F-measure of ink `a` against ink `b` (`w` px wide) with a 1 px
/// tolerance, as document binarization is scored: a pixel of one counts
/// as matched when the other has ink within its 3 × 3 neighbourhood.
fn tolerant_f(a: &[bool], b: &[bool], w: usize) -> f64 {
    let h = a.len() / w.max(1);
    let near = |m: &[bool], x: usize, y: usize| {
        (y.saturating_sub(1)..(y + 2).min(h))
            .any(|yy| (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| m[yy * w + xx]))
    };
    let matched = |p: &[bool], q: &[bool]| {
        let (mut hit, mut all) = (0usize, 0usize);
        for y in 0..h {
            for x in 0..w {
                if p[y * w + x] {
                    all += 1;
                    hit += usize::from(near(q, x, y));
                }
            }
        }
        hit as f64 / all.max(1) as f64
    };
    let (precision, recall) = (matched(a, b), matched(b, a));
    if precision + recall == 0.0 {
        0.0
    } else {
        2.0 * precision * recall / (precision + recall)
    }
}

/// The segments (lines and curves) potrace's SVG backend (`potrace -s`)
/// makes of the bitmap `input`, read as potrace reads a picture turned
/// into a PBM: ink where the luminance is under one half; speck size 3
/// (`-t 3`, what flourish's default `--min-area 4` drops). `None` when the
/// bitmap cannot be read or potrace does not run.
fn potrace_segments(input: &Path) -> Option<usize> {
    let grey = image::open(input).ok()?.to_luma8();
    let (w, h) = (grey.width() as usize, grey.height() as usize);
    let stride = w.div_ceil(8);
    let mut pbm = format!("P4\n{w} {h}\n").into_bytes();
    for row in grey.as_raw().chunks_exact(w.max(1)) {
        let mut bits = vec![0u8; stride];
        for (x, &v) in row.iter().enumerate() {
            if v < 128 {
                bits[x / 8] |= 0x80 >> (x % 8);
            }
        }
        pbm.extend_from_slice(&bits);
    }
    let dir = tempfile::tempdir().ok()?;
    let (inp, out) = (dir.path().join("in.pbm"), dir.path().join("out.svg"));
    std::fs::write(&inp, pbm).ok()?;
    let ran = std::process::Command::new("potrace")
        .args(["-s", "-t", "3", "-o"])
        .arg(&out)
        .arg(&inp)
        .status()
        .ok()?;
    if !ran.success() {
        return None;
    }
    let svg = std::fs::read(&out).ok()?;
    let tree = resvg::usvg::Tree::from_data(&svg, &resvg::usvg::Options::default()).ok()?;
    fn count(g: &resvg::usvg::Group) -> usize {
        g.children()
            .iter()
            .map(|n| match n {
                resvg::usvg::Node::Group(g) => count(g),
                resvg::usvg::Node::Path(p) => p
                    .data()
                    .segments()
                    .filter(|s| {
                        !matches!(
                            s,
                            resvg::tiny_skia::PathSegment::MoveTo(_)
                                | resvg::tiny_skia::PathSegment::Close
                        )
                    })
                    .count(),
                _ => 0,
            })
            .sum()
    }
    Some(count(tree.root()))
}

fn trace(input: &Path) -> Outcome {
    let bytes = crate::io::read_file(input)?;
    let truth = std::fs::read_to_string(input.with_extension("svg"))
        .map_err(|e| crate::Error::io(input.with_extension("svg"), e))?;
    // A drawing in several inks is traced a layer per colour.
    let read = crate::ImageOptions {
        layers: fill_colours(&truth) > 1,
        ..crate::ImageOptions::default()
    };
    let image = crate::Image::from_bytes(&bytes, &read)?;
    let out = crate::trace(&image, &crate::TraceOptions::default())?;
    let svg = out.to_svg();
    let (w, h) = image::image_dimensions(input).map_err(|e| crate::Error::Image(e.to_string()))?;
    let (a, b) = (
        rendered_ink(svg.as_bytes(), w, h)?,
        rendered_ink(truth.as_bytes(), w, h)?,
    );
    let f = tolerant_f(&a, &b, w as usize);
    let segments = out.document.segment_count() as f64;
    let mut checks = vec![Check {
        name: "segments".into(),
        value: Some(segments),
        ok: true,
        higher_is_better: false,
        wanted: "(recorded)".into(),
        limit: None,
    }];
    // A scan turned by hand does not line up with its drawing.
    let aligned = !input.to_string_lossy().contains("scanned");
    checks.push(if aligned {
        Check::at_least("ink", f, 0.98)
    } else {
        Check {
            name: "ink".into(),
            value: Some(f),
            ok: true,
            higher_is_better: true,
            wanted: "(recorded: the scan is turned)".into(),
            limit: None,
        }
    });
    // Segments against potrace's on the same bitmap: flourish's default
    // trace (one layer of every ink, as the issue compares them).
    let own = if read.layers {
        let one = crate::Image::from_bytes(&bytes, &crate::ImageOptions::default())?;
        crate::trace(&one, &crate::TraceOptions::default())?
            .document
            .segment_count() as f64
    } else {
        segments
    };
    checks.push(match potrace_segments(input) {
        Some(p) => Check::at_most("segments-vs-potrace", own / p.max(1) as f64, 0.8),
        None => Check {
            name: "segments-vs-potrace".into(),
            value: None,
            ok: false,
            higher_is_better: false,
            wanted: "potrace installed (make deps)".into(),
            limit: None,
        },
    });
    if read.layers {
        // The same colours cut out: rendered at 4x without anti-aliasing,
        // no pixel left uncovered and none covered twice.
        let cut = crate::Image::regions_from_bytes(&bytes, &read)?;
        let cut = crate::trace(&cut, &crate::TraceOptions::default())?;
        let (gaps, overlaps) = crate::trace::cutout::measure::gaps_and_overlaps(&cut.document, 4.0);
        checks.push(Check::at_most("cutout-gaps", gaps as f64, 0.0));
        checks.push(Check::at_most("cutout-overlaps", overlaps as f64, 0.0));
        // Each colour's IoU with the drawing's (pixels nearest the colour,
        // both rendered at the bitmap's size) cut out against stacked: the
        // worst difference.
        let palette: Vec<crate::svg_out::Color> = cut
            .document
            .groups
            .iter()
            .filter_map(|g| g.shapes.first().and_then(|s| s.fill))
            .collect();
        let cut_ious =
            crate::trace::cutout::measure::colour_ious(&cut.to_svg(), &truth, &palette, w, h);
        let stacked_ious = crate::trace::cutout::measure::colour_ious(&svg, &truth, &palette, w, h);
        let worst = cut_ious
            .iter()
            .zip(&stacked_ious)
            .map(|(c, s)| c - s)
            .fold(f64::INFINITY, f64::min);
        checks.push(Check::at_least("cutout-iou", worst, 0.0));
    }
    Ok((svg, checks))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::{PatternStyle, PlacedElement};
    use kurbo::Affine;

    /// Two copies of one element: none of the ink is shared when they
    /// stand apart, all of it when they stand on each other, part of it
    /// when they half overlap.
    #[test]
    fn overlap_counts_ink_drawn_twice() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("styles/flowers");
        let style = PatternStyle::load(&dir).unwrap();
        let size = kurbo::Shape::bounding_box(&style.element_shapes(0).next().unwrap().path);
        let at = |dx: f64| PlacedElement {
            element: 0,
            transform: Affine::translate((dx, 0.0)),
            centre: kurbo::Point::new(dx, 0.0),
        };
        let measure = |dx: f64| {
            let pair = [at(0.0), at(dx)];
            overlapping_ink(pair.iter().map(|e| (&style, e))).unwrap()
        };
        assert_eq!(measure(3.0 * size.width()), 0.0);
        assert!((measure(0.0) - 1.0).abs() < 1e-9);
        let half = measure(0.5 * size.width());
        assert!(half > 0.05 && half < 0.6, "{half}");
    }
}
