//! The `flourish` command line: parses arguments, calls the library,
//! reports. Exit status: 0 success, 1 failure, 2 usage error.

use clap::{Args, Parser, Subcommand};
use flourish::{
    io, BrushOptions, DecorateOptions, Decoration, Error, FillOptions, Image, ImageOptions,
    Library, Output, PatternOptions, Refinement, Sketch, StyleKind, StyleOptions, Styles,
    TraceOptions,
};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod serve;

#[derive(Parser)]
#[command(
    name = "flourish",
    version,
    about = "Decorative SVGs from sketches, by example; bitmaps and SDFs to Bézier outlines."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print nothing but errors.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// Print notes about what was read and skipped.
    #[arg(short, long, global = true)]
    verbose: bool,
    /// Worker threads, 1..=1024 (default: one per core); output does not depend on it.
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
    /// End the run after this many seconds: exit 1, no output file left half-written.
    #[arg(long, global = true, value_name = "SECONDS")]
    timeout: Option<f64>,
    /// Most memory the run may hold, in MB or with a unit (512M, 2G); default 1G.
    /// Resolution is lowered to fit where a mode can, else the run ends with one line.
    #[arg(long, global = true, value_name = "SIZE")]
    max_memory: Option<String>,
}

#[derive(Subcommand)]
enum Command {
    /// Trace bitmaps or SVGs into compact filled Bézier outlines.
    Trace(TraceArgs),
    /// Arrange hand-drawn stroke elements along open paths and inside filled shapes.
    Pattern(PatternArgs),
    /// Fill closed shapes with an art pattern synthesized from a style's swatches.
    Fill(FillArgs),
    /// Grow structured ornament of a brush style along open paths (DecoBrush).
    Brush(BrushArgs),
    /// Decorate a whole sketch: strokes and shapes each by its style, everything else kept.
    Decorate(DecorateArgs),
    /// Compare two SVGs by rendering: exit 0 alike, 1 different beyond --tolerance, 2 trouble.
    Diff(DiffArgs),
    /// Style libraries: analyse, report and draw diagnostics.
    Style(StyleArgs),
    /// Paint ornament live in a browser page: serve the page and its API locally.
    Serve(ServeArgs),
}

#[derive(Args)]
struct ServeArgs {
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Address to listen on (default: this machine only).
    #[arg(long, default_value = "127.0.0.1")]
    host: std::net::IpAddr,
    /// A folder of styles offered first (then $FLOURISH_STYLES and the shipped styles).
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
    /// Open the page in the desktop's browser.
    #[arg(long)]
    open: bool,
}

#[derive(Args)]
struct StyleArgs {
    #[command(subcommand)]
    command: StyleCommand,
}

#[derive(Subcommand)]
enum StyleCommand {
    /// Analyse a style: a report per exemplar, warnings, and (brush) a diagnostics sheet.
    Check(StyleCheckArgs),
    /// List every style that --styles, $FLOURISH_STYLES and the shipped styles hold.
    List(StyleListArgs),
    /// Make a folder of exemplar drawings a brush library: write its style.toml, each
    /// exemplar's start and end found automatically.
    Init(StyleInitArgs),
}

#[derive(Args)]
struct StyleListArgs {
    /// A folder of styles searched first.
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
}

#[derive(Args)]
struct StyleInitArgs {
    /// Folder of exemplar drawings (SVG, PNG, JPEG, ...); style.toml is written there.
    #[arg(value_name = "DIR")]
    dir: PathBuf,
    /// Finest exemplar resolution in px (64..=1024; default 256).
    #[arg(long, value_name = "PX")]
    resolution: Option<u32>,
    /// Replace an existing style.toml.
    #[arg(long)]
    force: bool,
}

#[derive(Args)]
struct StyleCheckArgs {
    /// Style: a folder holding style.toml, or a name in --styles.
    #[arg(value_name = "STYLE")]
    style: String,
    /// Write the diagnostics sheet (spine, ribs, orientation field) to this PNG.
    #[arg(long, value_name = "OUT.png")]
    sheet: Option<PathBuf>,
    /// Folder of named styles (default: the styles shipped with flourish).
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
    /// Cache folder for the analysis (default: $FLOURISH_CACHE_DIR, else the platform cache).
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,
    /// Analyse afresh: neither read nor write the cache.
    #[arg(long)]
    no_cache: bool,
    /// Exit 1 when there are warnings.
    #[arg(long)]
    strict: bool,
}

/// Where a command writes, shared by every mode that converts files.
#[derive(Args)]
struct Outputs {
    /// Output SVG (`-` for standard output, DIR/ for DIR/NAME.svg); one input only.
    #[arg(short = 'o', long = "output", value_name = "OUT.svg")]
    output: Option<PathBuf>,
    /// Output folder for a batch (made if missing): NAME.svg per input.
    #[arg(long, value_name = "DIR", conflicts_with = "output")]
    out_dir: Option<PathBuf>,
    /// Render the result to a PNG (with --out-dir: a folder for NAME.png).
    #[arg(long, value_name = "PNG")]
    preview: Option<PathBuf>,
    /// Random seed: the same inputs and seed give the same output at any
    /// thread count (tracing has no randomness and ignores it).
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Args)]
struct FillArgs {
    /// Sketch SVGs: filled shapes get the pattern; open paths inside them comb its direction.
    #[arg(required = true, value_name = "SKETCH.svg")]
    sketches: Vec<PathBuf>,
    /// Fill style: a folder holding style.toml, or a name in --styles.
    #[arg(long, default_value = "knot")]
    style: String,
    /// Folder of named styles (default: the styles shipped with flourish).
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
    #[command(flatten)]
    out: Outputs,
    /// Keep the sketch: the ornament replaces the shapes it decorates, the rest stays.
    #[arg(long)]
    keep_sketch: bool,
    /// An SVG of open stroked paths that comb the pattern's direction in every region.
    #[arg(long, value_name = "D.svg")]
    direction: Option<PathBuf>,
    /// Draw the pattern this many times larger (multiplies the style's scale), 0.01..=100.
    #[arg(long, default_value_t = 1.0, value_name = "F")]
    scale: f64,
    /// Swatch raster size in pixels (longest side), overriding the style's.
    #[arg(long, value_name = "PX")]
    resolution: Option<u32>,
    /// Synthesize every shape from this one swatch of the style (a file
    /// that style.toml lists) instead of from all of them; a shape's
    /// data-exemplar="FILE" pins its own.
    #[arg(long, value_name = "FILE")]
    exemplar: Option<String>,
}

#[derive(Args)]
struct BrushArgs {
    /// Sketch SVGs whose stroked open paths are the queries.
    #[arg(required = true, value_name = "SKETCH.svg")]
    sketches: Vec<PathBuf>,
    /// Brush style name (a folder of the styles directory) or folder path.
    #[arg(long, default_value = "vine")]
    style: String,
    /// Styles directory (default: the shipped styles).
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
    /// Style analysis cache folder.
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,
    #[command(flatten)]
    out: Outputs,
    /// Keep the sketch: the ornament replaces the shapes it decorates, the rest stays.
    #[arg(long)]
    keep_sketch: bool,
    /// Write N alternatives OUT-1.svg … OUT-N.svg, or NAME-v1.svg … NAME-vN.svg
    /// with --out-dir (seeds seed … seed+N−1).
    #[arg(long, default_value_t = 1, value_name = "N")]
    variations: u32,
    /// Draw the art-brush baseline instead (one exemplar stretched along the path).
    #[arg(long)]
    art_brush: bool,
    /// Refinement sketch: black strokes add ornament, white ones erase it (DecoBrush §5.5).
    #[arg(long, value_name = "REFINE.svg")]
    refine: Option<PathBuf>,
    /// Correction iterations per synthesis level, 0..=100 (0: graph cut upsampled only).
    #[arg(long, default_value_t = 1, value_name = "N")]
    iterations: usize,
    /// For a PNG or JPEG drawing: every traced line this wide, in pixels (default: the lines'
    /// widths scaled up together until the median is a 24th of the page's shorter side).
    #[arg(long, value_name = "PX")]
    width: Option<f64>,
}

#[derive(Args)]
struct PatternArgs {
    /// Sketch SVGs: stroked paths get patterns along them, filled shapes inside them.
    #[arg(required = true, value_name = "SKETCH.svg")]
    sketches: Vec<PathBuf>,
    /// Pattern style: a folder holding style.toml, or a name in --styles.
    #[arg(long, default_value = "stipple")]
    style: String,
    /// Folder of named styles (default: the styles shipped with flourish).
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
    #[command(flatten)]
    out: Outputs,
    /// Keep the sketch: the ornament replaces the shapes it decorates, the rest stays.
    #[arg(long)]
    keep_sketch: bool,
    /// How much repeated elements vary in place and turn (Barla et al. §3.3), 0..1.
    #[arg(long, alias = "variation", default_value_t = 0.0, value_name = "0..1")]
    jitter: f64,
    /// Draw the elements and their spacing this many times larger, 0.01..=100.
    #[arg(long, default_value_t = 1.0, value_name = "F")]
    scale: f64,
    /// For a PNG or JPEG drawing: every traced line this wide, in pixels (default: the lines'
    /// widths scaled up together until the median is a 24th of the page's shorter side).
    #[arg(long, value_name = "PX")]
    width: Option<f64>,
}

#[derive(Args)]
struct DecorateArgs {
    /// Sketch SVGs: a shape's data-style names its style; others take --strokes or --regions.
    #[arg(required = true, value_name = "SKETCH.svg")]
    sketches: Vec<PathBuf>,
    /// Style of stroked paths without data-style: a brush or pattern style.
    #[arg(long, value_name = "STYLE")]
    strokes: Option<String>,
    /// Style of filled shapes without data-style: a fill or pattern style.
    #[arg(long, value_name = "STYLE")]
    regions: Option<String>,
    /// Folder of named styles searched first.
    #[arg(long, value_name = "DIR")]
    styles: Option<PathBuf>,
    /// Brush analysis cache folder.
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,
    #[command(flatten)]
    out: Outputs,
}

#[derive(Args)]
struct TraceArgs {
    /// Input files: PNG, JPEG, BMP, GIF, TIFF, WebP or SVG.
    #[arg(required = true, value_name = "IN")]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    out: Outputs,
    /// Largest distance of the curves from the outline, in pixels.
    #[arg(long, default_value_t = 0.25, value_name = "PX")]
    tolerance: f64,
    /// Drop islands and holes smaller than this, in square pixels.
    #[arg(long, default_value_t = 4.0, value_name = "PX2")]
    min_area: f64,
    /// Longest side in pixels at which SVG input is rasterized.
    #[arg(long, default_value_t = 1024, value_name = "PX")]
    resolution: u32,
    /// Trace the paper instead of the ink.
    #[arg(long)]
    invert: bool,
    /// Trace each fill colour separately and stack the layers.
    #[arg(long)]
    layers: bool,
    /// With --layers: each colour's region (the paper's too) a shape of
    /// its own, neighbours sharing exactly the same boundary curves, so
    /// nothing overlaps and no seam shows (cutting plotters, embroidery).
    #[arg(long, requires = "layers", conflicts_with = "invert")]
    cutout: bool,
    /// Trace a drawing of lines along their centres: open stroked paths,
    /// crossings continued straight through, as wide as the lines.
    #[arg(long, conflicts_with_all = ["layers", "invert"])]
    centerline: bool,
    /// With --centerline: every stroke this wide instead of its line's
    /// measured width, in pixels.
    #[arg(long, requires = "centerline", value_name = "PX")]
    width: Option<f64>,
}

#[derive(Args)]
struct DiffArgs {
    /// Expected SVG (e.g. the golden file).
    expected: PathBuf,
    /// Actual SVG.
    actual: PathBuf,
    /// Largest fraction of changed pixels still accepted (0..1).
    #[arg(long, default_value_t = 0.0, value_name = "FRACTION")]
    tolerance: f64,
    /// Write an expected | mask | actual image.
    #[arg(long = "out", value_name = "DIFF.png")]
    out: Option<PathBuf>,
}

/// The argument parser's message on one line: its lines up to the usage
/// summary, without tips, joined.
fn one_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let words: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("Usage:"))
        .filter(|l| !l.trim_start().starts_with("tip:"))
        .flat_map(str::split_whitespace)
        .collect();
    words.join(" ").trim_start_matches("error: ").to_string()
}

/// A failure and the exit status it maps to.
enum Failure {
    /// `diff` could not compare (as `cmp` and `diff` do): exit 2.
    Trouble(Error),
    Usage(String),
    Run(Error),
    Differ,
}

impl From<Error> for Failure {
    /// An option the library refuses is a usage error, named by its flag.
    fn from(e: Error) -> Self {
        match e {
            Error::Option { name, reason } => Failure::Usage(format!(
                "invalid option --{}: {reason}",
                name.replace('_', "-")
            )),
            e => Failure::Run(e),
        }
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if e.use_stderr() => {
            eprintln!("flourish: {} (see flourish --help)", one_line(&e));
            return ExitCode::from(2);
        }
        Err(e) => {
            // --help and --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
    };
    let verbose = cli.verbose;
    let result = run(cli);
    if verbose {
        eprintln!(
            "flourish: peak memory {} of the {} budget",
            flourish::memory::in_words(flourish::memory::peak()),
            flourish::memory::in_words(flourish::memory::budget())
        );
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Usage(msg)) => {
            eprintln!("flourish: {msg}");
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("flourish: {e}");
            ExitCode::from(1)
        }
        Err(Failure::Differ) => ExitCode::from(1),
        Err(Failure::Trouble(e)) => {
            eprintln!("flourish: {e}");
            ExitCode::from(2)
        }
    }
}

/// Most worker threads `--threads` may ask for (each is an OS thread
/// started up front; a million of them never finish starting).
const MAX_THREADS: usize = 1024;

fn run(cli: Cli) -> Result<(), Failure> {
    let budget = match &cli.max_memory {
        Some(text) => parse_size(text).ok_or_else(|| {
            Failure::Usage(format!(
                "--max-memory {text:?} is not a size (a number of MB, or with a unit: 512M, 2G)"
            ))
        })?,
        None => flourish::memory::DEFAULT_BUDGET,
    };
    if budget < MIN_BUDGET {
        return Err(Failure::Usage(format!(
            "--max-memory must be at least {}",
            flourish::memory::in_words(MIN_BUDGET)
        )));
    }
    flourish::memory::set_budget(budget);
    if let Some(t) = cli.timeout {
        if !(t.is_finite() && t > 0.0 && t <= 1e6) {
            return Err(Failure::Usage(format!(
                "--timeout {t} is not a number of seconds in (0, 1000000]"
            )));
        }
        std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_secs_f64(t));
            let stage = io::stage();
            let during = if stage.is_empty() {
                String::new()
            } else {
                format!(", during {stage}")
            };
            eprintln!("flourish: timed out after {t} s{during} (--timeout)");
            io::exit_between_writes(1)
        });
    }
    if let Some(n) = cli.threads {
        if n == 0 {
            return Err(Failure::Usage("--threads must be at least 1".into()));
        }
        if n > MAX_THREADS {
            return Err(Failure::Usage(format!(
                "--threads {n} is more than the limit of {MAX_THREADS}"
            )));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Failure::Usage(format!("--threads: {e}")))?;
    }
    match cli.command {
        Command::Trace(args) => run_trace(args, cli.quiet, cli.verbose),
        Command::Pattern(args) => run_pattern(args, cli.quiet, cli.verbose),
        Command::Fill(args) => run_fill(args, cli.quiet, cli.verbose),
        Command::Brush(args) => run_brush(args, cli.quiet, cli.verbose),
        Command::Decorate(args) => run_decorate(args, cli.quiet, cli.verbose),
        Command::Diff(args) => run_diff(args, cli.quiet),
        Command::Style(StyleArgs {
            command: StyleCommand::Check(args),
        }) => run_style_check(args, cli.quiet),
        Command::Style(StyleArgs {
            command: StyleCommand::List(args),
        }) => run_style_list(args),
        Command::Style(StyleArgs {
            command: StyleCommand::Init(args),
        }) => run_style_init(args, cli.quiet),
        Command::Serve(args) => serve::serve(serve::ServeOptions {
            host: args.host,
            port: args.port,
            library: library(&args.styles),
            open: args.open,
        })
        .map_err(|e| Failure::Run(Error::invalid(e))),
    }
}

fn run_trace(args: TraceArgs, quiet: bool, verbose: bool) -> Result<(), Failure> {
    let input = ImageOptions {
        resolution: args.resolution,
        invert: args.invert,
        layers: args.layers,
    };
    let opts = TraceOptions {
        tolerance: args.tolerance,
        min_area: args.min_area,
    };
    opts.validate()?;
    input.validate()?;
    let job = |inp: &Path| -> Result<String, Error> {
        let bytes = io::read_input(inp)?;
        let image = if args.centerline {
            Image::lines_from_bytes(&bytes, &input, args.width)
        } else if args.cutout {
            Image::regions_from_bytes(&bytes, &input)
        } else {
            Image::from_bytes(&bytes, &input)
        };
        let out = image
            .and_then(|image| flourish::trace(&image, &opts))
            .map_err(|e| e.in_file(shown(inp)))?;
        Ok(report(inp, out, quiet, verbose))
    };
    run_batch(&args.inputs, &args.out, quiet, &job)
}

/// Prints what a run has to tell about input `inp` (warnings unless
/// `quiet`, notes under `verbose`) and gives its SVG.
fn report(inp: &Path, out: Output, quiet: bool, verbose: bool) -> String {
    let inp = shown(inp);
    if !quiet {
        for w in &out.warnings {
            eprintln!("flourish: warning: {}: {w}", inp.display());
        }
    }
    if verbose {
        for note in &out.notes {
            eprintln!("flourish: {}: {note}", inp.display());
        }
    }
    out.to_svg()
}

/// Reads a sketch and reports what it skipped: warnings unless `quiet`,
/// notes under `verbose`.
fn load_sketch(path: &Path, quiet: bool, verbose: bool) -> Result<Sketch, Error> {
    load_drawn(path, None, quiet, verbose)
}

/// [`load_sketch`], a raster drawing's lines `width` px wide when given.
fn load_drawn(
    path: &Path,
    width: Option<f64>,
    quiet: bool,
    verbose: bool,
) -> Result<Sketch, Error> {
    let sk = read_drawn(path, width)?;
    let path = shown(path);
    if !quiet {
        for w in &sk.warnings {
            eprintln!("flourish: warning: {}: {w}", path.display());
        }
    }
    if verbose {
        for note in &sk.notes {
            eprintln!("flourish: {}: {note}", path.display());
        }
    }
    Ok(sk)
}

/// Reads and parses a sketch file (`-`: standard input); errors name it.
/// A raster drawing's lines, traced along their centres, are its
/// queries.
fn read_sketch(path: &Path) -> Result<Sketch, Error> {
    read_drawn(path, None)
}

/// [`read_sketch`], a raster drawing's lines `width` px wide when given.
fn read_drawn(path: &Path, width: Option<f64>) -> Result<Sketch, Error> {
    let bytes = io::read_input(path)?;
    if flourish::looks_like_svg(&bytes) {
        Sketch::from_svg(&bytes)
    } else {
        flourish::sketch_from_drawing(&bytes, width)
    }
    .map_err(|e| e.in_file(shown(path)))
}

/// How an input is named in messages: `-` as `<stdin>`.
fn shown(path: &Path) -> &Path {
    if path.as_os_str() == "-" {
        Path::new("<stdin>")
    } else {
        path
    }
}

/// Makes output folder `dir` (and its parents) unless it exists; a file
/// in its place is an error.
fn make_folder(dir: &Path) -> Result<(), Failure> {
    if dir.is_dir() {
        return Ok(());
    }
    if dir.exists() {
        return Err(Failure::Run(
            Error::invalid("is not a folder (--out-dir and, with it, --preview name folders)")
                .in_file(dir),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Run(Error::invalid(format!("cannot make the output folder: {e}")).in_file(dir))
    })
}

/// The search path for style names: `--styles DIR`, then
/// `$FLOURISH_STYLES`, then the shipped styles.
fn library(arg: &Option<PathBuf>) -> Library {
    Library::search(arg.iter().cloned())
}

fn run_pattern(args: PatternArgs, quiet: bool, verbose: bool) -> Result<(), Failure> {
    let opts = PatternOptions {
        seed: args.out.seed,
        variation: args.jitter,
        scale: args.scale,
        ..PatternOptions::default()
    };
    opts.validate()?;
    let lib = library(&args.styles);
    let load = StyleOptions {
        kind: Some(StyleKind::Pattern),
        ..StyleOptions::default()
    };
    let style = lib.load(&args.style, &load)?;
    let job = |sketch: &Path| -> Result<String, Error> {
        let sk = load_drawn(sketch, args.width, quiet, verbose)?;
        let out = lib
            .load_named(&sk, StyleKind::Pattern, &load)
            .and_then(|named| flourish::pattern(&sk, Styles::new(&style, &named), &opts))
            .map_err(|e| e.in_file(shown(sketch)))?;
        let out = kept(out, &sk, args.keep_sketch);
        Ok(report(sketch, out, quiet, verbose))
    };
    run_batch(&args.sketches, &args.out, quiet, &job)
}

fn run_fill(args: FillArgs, quiet: bool, verbose: bool) -> Result<(), Failure> {
    let load = StyleOptions {
        kind: Some(StyleKind::Fill),
        resolution: args.resolution,
        ..StyleOptions::default()
    };
    load.validate()?;
    let direction = match &args.direction {
        Some(d) => {
            let sk = read_sketch(d)?;
            let probe = FillOptions {
                direction: Some(sk.clone()),
                ..FillOptions::default()
            };
            // A direction sketch that combs nothing is a fault of that file.
            if let Err(Error::Option { reason, .. }) = probe.validate() {
                return Err(Failure::Run(Error::invalid(reason).in_file(d)));
            }
            Some(sk)
        }
        None => None,
    };
    let opts = FillOptions {
        seed: args.out.seed,
        direction,
        scale: args.scale,
        exemplar: args.exemplar.clone(),
        ..FillOptions::default()
    };
    opts.validate()?;
    let lib = library(&args.styles);
    let style = lib.load(&args.style, &load)?;
    let job = |sketch: &Path| -> Result<String, Error> {
        let sk = load_sketch(sketch, quiet, verbose)?;
        let out = lib
            .load_named(&sk, StyleKind::Fill, &load)
            .and_then(|named| flourish::fill(&sk, Styles::new(&style, &named), &opts))
            .map_err(|e| e.in_file(shown(sketch)))?;
        let out = kept(out, &sk, args.keep_sketch);
        Ok(report(sketch, out, quiet, verbose))
    };
    run_batch(&args.sketches, &args.out, quiet, &job)
}

fn run_brush(args: BrushArgs, quiet: bool, verbose: bool) -> Result<(), Failure> {
    if args.variations == 0 || args.variations > 100 {
        return Err(Failure::Usage("--variations must be in 1..=100".into()));
    }
    BrushOptions {
        iterations: args.iterations,
        ..BrushOptions::default()
    }
    .validate()?;
    if args.variations > 1
        && args.out.out_dir.is_none()
        && (args.out.output.is_none() || args.out.output.as_deref() == Some(Path::new("-")))
    {
        return Err(Failure::Usage(
            "--variations needs -o OUT.svg (a file) or --out-dir DIR".into(),
        ));
    }
    let refine = match &args.refine {
        Some(path) => {
            Some(Refinement::from_svg(&io::read_input(path)?).map_err(|e| e.in_file(shown(path)))?)
        }
        None => None,
    };
    let style = library(&args.styles).load(
        &args.style,
        &StyleOptions {
            kind: Some(StyleKind::Brush),
            cache_dir: args.cache.clone(),
            ..StyleOptions::default()
        },
    )?;
    for k in 0..args.variations {
        let opts = BrushOptions {
            seed: args.out.seed.wrapping_add(k as u64),
            art_brush: args.art_brush,
            iterations: args.iterations,
            refine: refine.clone(),
            // Only --verbose prints each query's energy.
            measure: verbose,
            cancel: None,
        };
        let job = |sketch: &Path| -> Result<String, Error> {
            let sk = load_drawn(sketch, args.width, quiet, verbose)?;
            let out = flourish::brush(&sk, &style, &opts).map_err(|e| e.in_file(shown(sketch)))?;
            let out = kept(out, &sk, args.keep_sketch);
            Ok(report(sketch, out, quiet, verbose))
        };
        let suffixed = |p: &Path| -> PathBuf {
            if args.variations == 1 {
                return p.to_path_buf();
            }
            let stem = p.file_stem().unwrap_or_default().to_string_lossy();
            let ext = p
                .extension()
                .map(|e| format!(".{}", e.to_string_lossy()))
                .unwrap_or_default();
            p.with_file_name(format!("{stem}-{}{ext}", k + 1))
        };
        let output = args.out.output.as_deref().map(suffixed);
        let preview = args.out.preview.as_deref().map(|p| {
            if args.out.out_dir.is_some() {
                p.to_path_buf()
            } else {
                suffixed(p)
            }
        });
        run_jobs(
            &args.sketches,
            output.as_deref(),
            args.out.out_dir.as_deref(),
            preview.as_deref(),
            quiet,
            &job,
            (args.variations > 1).then_some(k + 1),
        )?;
    }
    Ok(())
}

/// `out` laid over its sketch when `keep` (`--keep-sketch`).
fn kept(out: Output, sketch: &Sketch, keep: bool) -> Output {
    if keep {
        out.over(sketch)
    } else {
        out
    }
}

fn run_decorate(args: DecorateArgs, quiet: bool, verbose: bool) -> Result<(), Failure> {
    let opts = DecorateOptions {
        brush: BrushOptions {
            seed: args.out.seed,
            measure: verbose,
            ..BrushOptions::default()
        },
        fill: FillOptions {
            seed: args.out.seed,
            ..FillOptions::default()
        },
        pattern: PatternOptions {
            seed: args.out.seed,
            ..PatternOptions::default()
        },
    };
    opts.validate()?;
    let lib = library(&args.styles);
    let load = StyleOptions {
        cache_dir: args.cache.clone(),
        ..StyleOptions::default()
    };
    let strokes = args
        .strokes
        .as_deref()
        .map(|s| lib.load(s, &load))
        .transpose()?;
    let regions = args
        .regions
        .as_deref()
        .map(|s| lib.load(s, &load))
        .transpose()?;
    let none = Default::default();
    Decoration {
        strokes: strokes.as_ref(),
        regions: regions.as_ref(),
        named: &none,
    }
    .validate()?;
    let job = |sketch: &Path| -> Result<String, Error> {
        let sk = load_sketch(sketch, quiet, verbose)?;
        let out = lib
            .load_every_named(&sk, &load)
            .and_then(|named| {
                let styles = Decoration {
                    strokes: strokes.as_ref(),
                    regions: regions.as_ref(),
                    named: &named,
                };
                flourish::decorate(&sk, styles, &opts)
            })
            .map_err(|e| e.in_file(shown(sketch)))?;
        Ok(report(sketch, out, quiet, verbose))
    };
    run_batch(&args.sketches, &args.out, quiet, &job)
}

/// [`run_jobs`] with the output options as given (no variation suffix).
fn run_batch(
    inputs: &[PathBuf],
    out: &Outputs,
    quiet: bool,
    job: &(dyn Fn(&Path) -> Result<String, Error> + Sync),
) -> Result<(), Failure> {
    run_jobs(
        inputs,
        out.output.as_deref(),
        out.out_dir.as_deref(),
        out.preview.as_deref(),
        quiet,
        job,
        None,
    )
}

/// Runs `job` on every input and writes its SVG (and preview) where the
/// output options say, in parallel with a progress bar. For one variation
/// `k` (1-based) of several, `--out-dir` files are named `NAME-vK.svg` /
/// `NAME-vK.png`.
fn run_jobs(
    inputs: &[PathBuf],
    output: Option<&Path>,
    out_dir: Option<&Path>,
    preview: Option<&Path>,
    quiet: bool,
    job: &(dyn Fn(&Path) -> Result<String, Error> + Sync),
    variant: Option<u32>,
) -> Result<(), Failure> {
    let svg_name = |p: &Path| named(p, variant, "svg");
    let png_name = |p: &Path| named(p, variant, "png");
    match (output, out_dir) {
        (Some(out), None) => {
            if inputs.len() != 1 {
                return Err(Failure::Usage(
                    "-o takes one input; use --out-dir for several".into(),
                ));
            }
            let inp = &inputs[0];
            budget::running_on(shown(inp));
            let _ticker = Ticker::start(shown(inp), quiet);
            // `-o DIR/` (or an existing folder) writes NAME.svg into it.
            let into = |p: &Path, name: PathBuf| -> Result<PathBuf, Failure> {
                if names_folder(p) {
                    make_folder(p)?;
                    Ok(p.join(name))
                } else {
                    Ok(p.to_path_buf())
                }
            };
            let out = &into(out, svg_name(inp))?;
            let preview = match preview {
                Some(p) => Some(into(p, png_name(inp))?),
                None => None,
            };
            let preview = preview.as_deref();
            check_not_input(inp, out)?;
            if let Some(p) = preview {
                check_not_input(inp, p)?;
                if out.as_os_str() == "-" && p.as_os_str() == "-" {
                    // The SVG and the PNG would run together on stdout.
                    return Err(Failure::Usage(
                        "--preview - and -o - both name standard output".into(),
                    ));
                }
                if out.as_os_str() != "-" && io::same_file(out, p) {
                    return Err(Failure::Usage("--preview and -o name the same file".into()));
                }
            }
            let svg = job(inp)?;
            write_outputs(out, &svg, preview)?;
            Ok(())
        }
        (None, Some(dir)) => {
            // Output folders are made as needed, like `mkdir -p`. A preview
            // that names a PNG file serves a batch of one.
            make_folder(dir)?;
            let preview_file = preview.filter(|p| !names_folder(p) && is_png_name(p));
            match (preview_file, inputs.len()) {
                (Some(p), 1) => {
                    check_not_input(&inputs[0], p)?;
                    let svg = job(&inputs[0])?;
                    let out = dir.join(svg_name(&inputs[0]));
                    check_not_input(&inputs[0], &out)?;
                    write_outputs(&out, &svg, Some(p))?;
                    return Ok(());
                }
                (Some(p), _) => {
                    return Err(Failure::Usage(format!(
                        "--preview {} names a file; with several inputs it names a folder",
                        p.display()
                    )))
                }
                (None, _) => {}
            }
            if let Some(p) = preview {
                make_folder(p)?;
            }
            let mut names = std::collections::BTreeSet::new();
            for inp in inputs {
                let stem = inp.file_stem().unwrap_or_default().to_os_string();
                if !names.insert(stem) {
                    return Err(Failure::Usage(format!(
                        "two inputs would both write {}",
                        svg_name(inp).display()
                    )));
                }
                check_not_input(inp, &dir.join(svg_name(inp)))?;
                if let Some(p) = preview {
                    check_not_input(inp, &p.join(png_name(inp)))?;
                }
            }
            let bar = if quiet {
                ProgressBar::hidden()
            } else {
                let b = ProgressBar::new(inputs.len() as u64);
                if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} {msg}") {
                    b.set_style(style);
                }
                b
            };
            let results: Vec<Result<(), Error>> = inputs
                .par_iter()
                .map(|inp| {
                    let r = (|| {
                        let svg = job(inp)?;
                        let png = preview.map(|pdir| pdir.join(png_name(inp)));
                        write_outputs(&dir.join(svg_name(inp)), &svg, png.as_deref())
                    })();
                    bar.inc(1);
                    r
                })
                .collect();
            bar.finish_and_clear();
            let mut failed = false;
            for e in results.into_iter().filter_map(|r| r.err()) {
                eprintln!("flourish: {e}");
                failed = true;
            }
            if failed {
                return Err(Failure::Differ);
            }
            Ok(())
        }
        _ => Err(Failure::Usage("give -o OUT.svg or --out-dir DIR".into())),
    }
}

/// Progress on stderr for a run that lasts: after [`Ticker::after`], the
/// library's stage ([`io::stage`]) as a spinner on a terminal, else a line
/// each time the stage changes. Stops (and clears the spinner) when
/// dropped.
struct Ticker {
    done: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Ticker {
    /// How long a run goes before it shows progress: 2 s, or the seconds
    /// in `$FLOURISH_PROGRESS_AFTER` (the tests set 0).
    fn after() -> std::time::Duration {
        std::env::var("FLOURISH_PROGRESS_AFTER")
            .ok()
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|v| v.is_finite() && *v >= 0.0 && *v < 1e6)
            .map_or(
                std::time::Duration::from_secs(2),
                std::time::Duration::from_secs_f64,
            )
    }

    /// Starts watching the run on `input`; shows nothing when `quiet`.
    fn start(input: &Path, quiet: bool) -> Ticker {
        use std::io::IsTerminal as _;
        use std::sync::atomic::Ordering;
        let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        if quiet {
            return Ticker { done, thread: None };
        }
        let input = input.display().to_string();
        let stop = done.clone();
        let thread = std::thread::spawn(move || {
            let tick = std::time::Duration::from_millis(100);
            let start = std::time::Instant::now();
            let after = Ticker::after();
            // Parked, not asleep: dropping the ticker unparks it, so a
            // run that ends early does not wait out a tick.
            while start.elapsed() < after {
                if stop.load(Ordering::Relaxed) {
                    return;
                }
                std::thread::park_timeout(tick.min(after.saturating_sub(start.elapsed())));
            }
            let terminal = std::io::stderr().is_terminal();
            let spinner = terminal.then(|| {
                let s = ProgressBar::new_spinner();
                s.enable_steady_tick(tick);
                s
            });
            let mut shown = String::new();
            let mut printed = std::time::Instant::now();
            // A log gets a line when the stage changes, and for a count
            // that moves ("brush: strokes synthesized: K of N") a line
            // every few seconds.
            let label = |s: &str| s.replace(|c: char| c.is_ascii_digit(), "");
            let every = std::time::Duration::from_secs(5);
            while !stop.load(Ordering::Relaxed) {
                let stage = io::stage();
                if stage != shown {
                    let show = match &spinner {
                        Some(s) => {
                            s.set_message(format!("{input}: {stage}"));
                            true
                        }
                        None => label(&stage) != label(&shown) || printed.elapsed() >= every,
                    };
                    if show && spinner.is_none() {
                        eprintln!("flourish: {input}: {stage}");
                        printed = std::time::Instant::now();
                    }
                    if show {
                        shown = stage;
                    }
                }
                std::thread::park_timeout(tick);
            }
            if let Some(s) = spinner {
                s.finish_and_clear();
            }
        });
        Ticker {
            done,
            thread: Some(thread),
        }
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        self.done.store(true, std::sync::atomic::Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}

/// Writes the SVG and its optional preview, both or neither.
fn write_outputs(out: &Path, svg: &str, preview: Option<&Path>) -> Result<(), Error> {
    match preview {
        Some(p) => {
            let png = flourish::preview_png(svg).map_err(|e| e.in_file(p))?;
            io::write_all_atomic(&[(out, svg.as_bytes()), (p, &png)])
        }
        None => io::write_atomic(out, svg.as_bytes()),
    }
}

/// Whether an output path names a folder: it ends in a separator or is
/// one already.
fn names_folder(p: &Path) -> bool {
    p.as_os_str() != "-" && (p.as_os_str().to_string_lossy().ends_with('/') || p.is_dir())
}

/// Whether a path's extension is `.png`.
fn is_png_name(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// The output file name of an input in an `--out-dir`: its stem (`stdin`
/// for `-`), `-vK` for variation K, and the extension.
fn named(inp: &Path, variant: Option<u32>, ext: &str) -> PathBuf {
    let mut stem = if inp.as_os_str() == "-" {
        std::ffi::OsString::from("stdin")
    } else {
        inp.file_stem().unwrap_or_default().to_os_string()
    };
    if let Some(k) = variant {
        stem.push(format!("-v{k}"));
    }
    Path::new(&stem).with_extension(ext)
}

fn check_not_input(input: &Path, output: &Path) -> Result<(), Failure> {
    if output.as_os_str() != "-" && input.as_os_str() != "-" && io::same_file(input, output) {
        return Err(Failure::Run(
            Error::invalid("output would overwrite the input").in_file(output),
        ));
    }
    Ok(())
}

fn run_diff(args: DiffArgs, quiet: bool) -> Result<(), Failure> {
    if !(args.tolerance.is_finite() && (0.0..=1.0).contains(&args.tolerance)) {
        return Err(Failure::Usage(format!(
            "--tolerance {} is not a fraction in 0..=1",
            args.tolerance
        )));
    }
    let trouble = |f: Failure| match f {
        Failure::Run(e) => Failure::Trouble(e),
        f => f,
    };
    if let Some(out) = &args.out {
        check_not_input(&args.expected, out).map_err(trouble)?;
        check_not_input(&args.actual, out).map_err(trouble)?;
    }
    let report = flourish::diff(&args.expected, &args.actual).map_err(Failure::Trouble)?;
    if let Some(out) = &args.out {
        report
            .panels_png()
            .map_err(|e| e.in_file(out))
            .and_then(|png| io::write_atomic(out, &png))
            .map_err(Failure::Trouble)?;
    }
    if !quiet {
        let line = format!(
            "changed: {:.6} ({} of {} px)",
            report.fraction(),
            report.changed,
            report.total
        );
        // The image alone goes to standard output when it is asked for there.
        if args.out.as_deref() == Some(Path::new("-")) {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    }
    if report.fraction() > args.tolerance {
        return Err(Failure::Differ);
    }
    Ok(())
}

fn run_style_init(args: StyleInitArgs, quiet: bool) -> Result<(), Failure> {
    let toml = args.dir.join("style.toml");
    if toml.exists() && !args.force {
        return Err(Failure::Usage(format!(
            "{} exists; --force replaces it",
            toml.display()
        )));
    }
    let report = flourish::init_style(&args.dir, args.resolution)?;
    io::write_atomic(&toml, report.to_toml().as_bytes())?;
    for why in &report.skipped {
        eprintln!("flourish: passed over {why}");
    }
    for e in report.exemplars.iter().filter(|e| e.fallback) {
        eprintln!(
            "flourish: {}: no clear main branch (a dot or a ring?): its ends run across its longer side; move them in {}",
            args.dir.join(&e.file).display(),
            toml.display()
        );
    }
    if !quiet {
        println!(
            "{}: {} exemplar{}, ends found automatically; check them with `flourish style check {} --sheet sheet.png`",
            toml.display(),
            report.exemplars.len(),
            if report.exemplars.len() == 1 { "" } else { "s" },
            args.dir.display()
        );
    }
    Ok(())
}

fn run_style_check(args: StyleCheckArgs, quiet: bool) -> Result<(), Failure> {
    let style = library(&args.styles).load(
        &args.style,
        &StyleOptions {
            cache_dir: args.cache,
            use_cache: !args.no_cache,
            ..StyleOptions::default()
        },
    )?;
    if args.sheet.is_some() && style.kind() != StyleKind::Brush {
        return Err(Failure::Usage(format!(
            "--sheet draws brush exemplars; {} is a {} style",
            args.style,
            style.kind().name()
        )));
    }
    if let Some(sheet) = &args.sheet {
        // The sheet must not replace the style's own files.
        for file in style.files() {
            check_not_input(file, sheet)?;
        }
    }
    let report = flourish::check_style(&style)?;
    if let Some(sheet) = &args.sheet {
        let png = flourish::style_sheet(&style).map_err(|e| e.in_file(sheet))?;
        io::write_atomic(sheet, &png)?;
    }
    if !quiet {
        print!("{}", report.to_text());
    } else {
        for (file, w) in report.warnings() {
            eprintln!("flourish: {}: {w}", style.dir().join(file).display());
        }
    }
    if args.strict && report.warning_count() > 0 {
        return Err(Failure::Differ);
    }
    Ok(())
}

fn run_style_list(args: StyleListArgs) -> Result<(), Failure> {
    let styles = library(&args.styles).styles();
    let width = styles
        .iter()
        .map(|s| s.name.len())
        .max()
        .unwrap_or(4)
        .max(4);
    println!(
        "{:width$}  {:7}  {:>9}  folder",
        "name", "kind", "exemplars"
    );
    for s in &styles {
        let kind = s.kind.map_or("?", StyleKind::name);
        println!(
            "{:width$}  {kind:7}  {:>9}  {}",
            s.name,
            s.exemplars,
            s.dir.display()
        );
    }
    Ok(())
}

/// Smallest `--max-memory`: what reading a small sketch and a style takes.
const MIN_BUDGET: u64 = 16 << 20;

/// A size of `--max-memory`: a number of MB, or a number with a unit
/// K, M, G (optionally followed by B or iB), in bytes.
fn parse_size(text: &str) -> Option<u64> {
    let t = text.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix("B"))
        .or_else(|| t.strip_suffix('b'))
        .unwrap_or(t);
    let (number, scale) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let scale: u64 = match c.to_ascii_uppercase() {
                'K' => 1 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                _ => return None,
            };
            (&t[..i], scale)
        }
        _ => (t, 1 << 20),
    };
    let n: f64 = number.trim().parse().ok()?;
    let bytes = n * scale as f64;
    (n.is_finite() && n > 0.0 && bytes < 2f64.powi(62)).then_some(bytes as u64)
}

/// The budget's last resort: every heap allocation of the program is
/// counted ([`flourish::memory::reserve`]); one that would cross
/// `--max-memory` ends the run with one line and exit 1 instead of an
/// allocation abort. The modes check their large canvases against the
/// budget before allocating them, so this is reached only by what no
/// estimate covered.
mod budget {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::sync::Mutex;

    /// The input being worked on, for the last-resort message.
    static INPUT: Mutex<String> = Mutex::new(String::new());

    /// Names the input the run is working on.
    pub fn running_on(input: &std::path::Path) {
        let name = input.display().to_string();
        if let Ok(mut i) = INPUT.lock() {
            *i = name;
        }
    }

    /// The system allocator, counted against the budget.
    pub struct Counting;

    // SAFETY: every call is forwarded to `System` with the same layout and
    // pointer; the counting around it neither allocates nor locks.
    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            // SAFETY: forwarded with the caller's layout.
            counted(layout.size(), || unsafe { System.alloc(layout) })
        }

        unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
            // SAFETY: forwarded with the caller's layout.
            counted(layout.size(), || unsafe { System.alloc_zeroed(layout) })
        }

        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            // SAFETY: `ptr` was allocated by `System` with `layout`.
            unsafe { System.dealloc(ptr, layout) };
            flourish::memory::release(layout.size());
        }

        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            let old = layout.size();
            if new_size > old && !flourish::memory::reserve(new_size - old) {
                over_budget(new_size - old);
            }
            // SAFETY: `ptr` was allocated by `System` with `layout`.
            let p = unsafe { System.realloc(ptr, layout, new_size) };
            if p.is_null() {
                if new_size > old {
                    flourish::memory::release(new_size - old);
                }
            } else if new_size < old {
                flourish::memory::release(old - new_size);
            }
            p
        }
    }

    /// Counts `size` bytes against the budget (ending the run when they do
    /// not fit), then allocates them; a failed allocation counts nothing.
    fn counted(size: usize, allocate: impl FnOnce() -> *mut u8) -> *mut u8 {
        if !flourish::memory::reserve(size) {
            over_budget(size);
        }
        let p = allocate();
        if p.is_null() {
            flourish::memory::release(size);
        }
        p
    }

    /// A fixed buffer that formats without allocating.
    struct Line {
        bytes: [u8; 512],
        len: usize,
    }

    impl std::fmt::Write for Line {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            let room = self.bytes.len() - self.len;
            let n = s.len().min(room);
            self.bytes[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
            self.len += n;
            Ok(())
        }
    }

    /// Writes one line naming the input, the stage and the budget to
    /// stderr and ends the process with exit 1, allocating nothing and
    /// waiting for no lock.
    #[cold]
    fn over_budget(asked: usize) -> ! {
        use std::fmt::Write as _;
        let mut line = Line {
            bytes: [0; 512],
            len: 0,
        };
        let _ = line.write_str("flourish: ");
        if let Ok(input) = INPUT.try_lock() {
            if !input.is_empty() {
                let _ = write!(line, "{input}: ");
            }
        }
        let budget = flourish::memory::budget();
        let _ = write!(
            line,
            "out of memory: {} more would pass the memory budget of {}",
            flourish::memory::Size(asked as u64),
            flourish::memory::Size(budget)
        );
        flourish::io::with_stage(|stage| {
            if !stage.is_empty() {
                let _ = write!(line, " during {stage}");
            }
        });
        let _ = line.write_str(" (--max-memory to change it)\n");
        end(&line.bytes[..line.len])
    }

    #[cfg(unix)]
    fn end(line: &[u8]) -> ! {
        // SAFETY: `line` is a valid buffer of its length; `_exit` ends the
        // process without running anything that could allocate.
        unsafe {
            libc::write(2, line.as_ptr().cast(), line.len());
            libc::_exit(1)
        }
    }

    #[cfg(not(unix))]
    fn end(line: &[u8]) -> ! {
        use std::io::Write as _;
        let _ = std::io::stderr().write_all(line);
        std::process::exit(1)
    }
}

#[global_allocator]
static ALLOCATOR: budget::Counting = budget::Counting;
