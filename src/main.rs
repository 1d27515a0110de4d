//! The `flourish` command line: parses arguments, calls the library,
//! reports. Exit status: 0 success, 1 failure, 2 usage error.

use clap::{Args, Parser, Subcommand};
use flourish::raster::input::InputOptions;
use flourish::trace::TraceOptions;
use flourish::{diff, io, render, trace, Error};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "flourish", version, about = "Decorative SVGs from sketches, by example; bitmaps and SDFs to Bézier outlines.")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print nothing but errors.
    #[arg(long, global = true)]
    quiet: bool,
    /// Print notes about what was read and skipped.
    #[arg(long, global = true)]
    verbose: bool,
    /// Worker threads (default: one per core); output does not depend on it.
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Trace bitmaps or SVGs into compact filled Bézier outlines.
    Trace(TraceArgs),
    /// Compare two SVGs by rendering; exit 1 when they differ beyond --tolerance.
    Diff(DiffArgs),
}

#[derive(Args)]
struct TraceArgs {
    /// Input files: PNG, JPEG, BMP, GIF, TIFF, WebP or SVG.
    #[arg(required = true, value_name = "IN")]
    inputs: Vec<PathBuf>,
    /// Output SVG (`-` for standard output); one input only.
    #[arg(short = 'o', long = "output", value_name = "OUT.svg")]
    output: Option<PathBuf>,
    /// Output folder for a batch: NAME.svg per input.
    #[arg(long, value_name = "DIR", conflicts_with = "output")]
    out_dir: Option<PathBuf>,
    /// Render the result to a PNG (with --out-dir: a folder for NAME.png).
    #[arg(long, value_name = "PNG")]
    preview: Option<PathBuf>,
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
    /// Accepted for uniformity with the other modes; tracing has no randomness.
    #[arg(long, default_value_t = 0)]
    seed: u64,
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

/// A failure and the exit status it maps to.
enum Failure {
    Usage(String),
    Run(Error),
    Differ,
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure::Run(e)
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match run(cli) {
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
    }
}

fn run(cli: Cli) -> Result<(), Failure> {
    if let Some(n) = cli.threads {
        if n == 0 {
            return Err(Failure::Usage("--threads must be at least 1".into()));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Failure::Usage(format!("--threads: {e}")))?;
    }
    match cli.command {
        Command::Trace(args) => run_trace(args, cli.quiet),
        Command::Diff(args) => run_diff(args, cli.quiet),
    }
}

fn run_trace(args: TraceArgs, quiet: bool) -> Result<(), Failure> {
    let input = InputOptions {
        resolution: args.resolution,
        invert: args.invert,
        layers: args.layers,
    };
    let opts = TraceOptions {
        tolerance: args.tolerance,
        min_area: args.min_area,
    };
    opts.validate().map_err(|e| Failure::Usage(e.to_string()))?;
    if args.resolution == 0 {
        return Err(Failure::Usage("--resolution must be at least 1 px".into()));
    }
    match (&args.output, &args.out_dir) {
        (Some(out), None) => {
            if args.inputs.len() != 1 {
                return Err(Failure::Usage("-o takes one input; use --out-dir for several".into()));
            }
            let inp = &args.inputs[0];
            check_not_input(inp, out)?;
            if let Some(p) = &args.preview {
                check_not_input(inp, p)?;
            }
            let doc = trace::trace_file(inp, &input, &opts)?;
            let svg = doc.to_svg();
            io::write_atomic(out, svg.as_bytes())?;
            if let Some(p) = &args.preview {
                render::write_preview(&svg, p)?;
            }
            Ok(())
        }
        (None, Some(dir)) => {
            if !dir.is_dir() {
                return Err(Failure::Run(Error::invalid(dir, "output folder does not exist")));
            }
            let mut names = std::collections::BTreeSet::new();
            for inp in &args.inputs {
                let stem = inp.file_stem().unwrap_or_default().to_os_string();
                if !names.insert(stem) {
                    return Err(Failure::Usage(format!(
                        "two inputs would both write {}.svg",
                        Path::new(inp.file_stem().unwrap_or_default()).display()
                    )));
                }
                check_not_input(inp, &dir.join(svg_name(inp)))?;
            }
            let bar = if quiet {
                ProgressBar::hidden()
            } else {
                let b = ProgressBar::new(args.inputs.len() as u64);
                if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} {msg}") {
                    b.set_style(style);
                }
                b
            };
            let results: Vec<Result<(), Error>> = args
                .inputs
                .par_iter()
                .map(|inp| {
                    let r = (|| {
                        let doc = trace::trace_file(inp, &input, &opts)?;
                        let svg = doc.to_svg();
                        io::write_atomic(&dir.join(svg_name(inp)), svg.as_bytes())?;
                        if let Some(pdir) = &args.preview {
                            let png = pdir.join(Path::new(inp.file_stem().unwrap_or_default()).with_extension("png"));
                            render::write_preview(&svg, &png)?;
                        }
                        Ok(())
                    })();
                    bar.inc(1);
                    r
                })
                .collect();
            bar.finish_and_clear();
            let mut failed = 0;
            for e in results.into_iter().filter_map(|r| r.err()) {
                eprintln!("flourish: {e}");
                failed += 1;
            }
            if failed > 0 {
                return Err(Failure::Differ);
            }
            Ok(())
        }
        _ => Err(Failure::Usage("give -o OUT.svg or --out-dir DIR".into())),
    }
}

fn svg_name(inp: &Path) -> PathBuf {
    Path::new(inp.file_stem().unwrap_or_default()).with_extension("svg")
}

fn check_not_input(input: &Path, output: &Path) -> Result<(), Failure> {
    if output.as_os_str() != "-" && io::same_file(input, output) {
        return Err(Failure::Run(Error::invalid(output, "output would overwrite the input")));
    }
    Ok(())
}

fn run_diff(args: DiffArgs, quiet: bool) -> Result<(), Failure> {
    if !(args.tolerance.is_finite() && (0.0..=1.0).contains(&args.tolerance)) {
        return Err(Failure::Usage(format!("--tolerance {} is not a fraction in 0..=1", args.tolerance)));
    }
    let report = diff::diff_files(&args.expected, &args.actual)?;
    if let Some(out) = &args.out {
        diff::write_panels(&report, out)?;
    }
    if !quiet {
        println!(
            "changed: {:.6} ({} of {} px)",
            report.fraction(),
            report.changed,
            report.total
        );
    }
    if report.fraction() > args.tolerance {
        return Err(Failure::Differ);
    }
    Ok(())
}
