//! Runs a fixed sample of real drawings through every command of the
//! `flourish` program, as a user would, and checks that each run either
//! succeeds with an SVG that parses and has a size, or fails cleanly (exit
//! 1, one line on stderr): no panic, no abort, no hang, no invalid output.
//! Prints a table per command (ok, clean errors, other, slowest run, peak
//! resident memory) and exits 1 when any run is "other".
//!
//! ```text
//! cargo run --release -p flourish-tools --bin corpus -- \
//!     [--dir /usr/share/openclipart/svg] [--count 200] [--hang-after 300] \
//!     [--flourish target/release/flourish] [--out out/corpus]
//! ```
//!
//! The sample: every `.svg` under `--dir` (the Debian package
//! `openclipart-svg`), one per file name, sorted by name, then `--count`
//! of them evenly spaced; the same package version gives the same sample.
//! Runs go two at a time (the machine's cores); each is a child process
//! with the default memory budget, killed and counted as a hang after
//! `--hang-after` seconds.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// What one run came to.
#[derive(Clone, Debug)]
enum Outcome {
    /// Exit 0 and a valid SVG.
    Ok,
    /// Exit 1 and one line on stderr.
    CleanError(String),
    /// Anything else, in words.
    Other(String),
}

/// One run: the command, the drawing, the outcome, seconds, peak KB.
struct Run {
    command: &'static str,
    drawing: PathBuf,
    outcome: Outcome,
    seconds: f64,
    peak_kb: i64,
}

/// The commands, each with the arguments before the input.
const COMMANDS: [(&str, &[&str]); 5] = [
    ("trace", &["-q", "trace"]),
    ("brush", &["-q", "brush", "--style", "vine"]),
    ("fill", &["-q", "fill", "--style", "knot"]),
    ("pattern", &["-q", "pattern", "--style", "stipple"]),
    (
        "decorate",
        &["-q", "decorate", "--strokes", "vine", "--regions", "knot"],
    ),
];

fn main() {
    let mut dir = PathBuf::from("/usr/share/openclipart/svg");
    let mut count = 200usize;
    let mut hang_after = 300.0f64;
    let mut flourish = PathBuf::from("target/release/flourish");
    let mut out = PathBuf::from("out/corpus");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| usage(&a));
        match a.as_str() {
            "--dir" => dir = value().into(),
            "--count" => count = value().parse().unwrap_or_else(|_| usage("--count")),
            "--hang-after" => {
                hang_after = value().parse().unwrap_or_else(|_| usage("--hang-after"))
            }
            "--flourish" => flourish = value().into(),
            "--out" => out = value().into(),
            _ => usage(&a),
        }
    }
    let drawings = sample(&dir, count);
    if drawings.is_empty() {
        eprintln!(
            "corpus: no .svg under {} (apt-get install openclipart-svg)",
            dir.display()
        );
        std::process::exit(1);
    }
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(out.join("svg")).expect("the output folder");
    let cache = out.join("cache");
    let jobs: Vec<(usize, &'static str, &'static [&'static str], &PathBuf)> = drawings
        .iter()
        .enumerate()
        .flat_map(|(i, d)| COMMANDS.iter().map(move |(name, a)| (i, *name, *a, d)))
        .collect();
    let next = Mutex::new(0usize);
    let runs = Mutex::new(Vec::new());
    let started = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let k = {
                    let mut n = next.lock().expect("the job counter");
                    let k = *n;
                    *n += 1;
                    k
                };
                let Some(&(i, name, pre, drawing)) = jobs.get(k) else {
                    break;
                };
                let target = out.join("svg").join(format!("{i:03}-{name}.svg"));
                let errors = out.join("svg").join(format!("{i:03}-{name}.err"));
                let mut cmd = Command::new(&flourish);
                cmd.args(pre)
                    .arg(drawing)
                    .arg("-o")
                    .arg(&target)
                    .env("FLOURISH_CACHE_DIR", &cache);
                let run = run_one(cmd, &errors, &target, hang_after);
                let _ = std::fs::remove_file(&target);
                runs.lock().expect("the runs").push(Run {
                    command: name,
                    drawing: drawing.clone(),
                    ..run
                });
            });
        }
    });
    let runs = runs.into_inner().expect("the runs");
    let report = report(&runs, drawings.len(), started.elapsed());
    print!("{report}");
    let _ = std::fs::write(out.join("report.md"), &report);
    if runs.iter().any(|r| matches!(r.outcome, Outcome::Other(_))) {
        std::process::exit(1);
    }
}

fn usage(arg: &str) -> ! {
    eprintln!(
        "corpus: bad argument {arg:?}; usage: corpus [--dir DIR] [--count N] \
         [--hang-after SECONDS] [--flourish BIN] [--out DIR]"
    );
    std::process::exit(2)
}

/// `count` drawings evenly spaced over the sorted, one-per-name `.svg`
/// files under `dir`.
fn sample(dir: &Path, count: usize) -> Vec<PathBuf> {
    let mut by_name: BTreeMap<String, PathBuf> = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "svg") {
                let name = e.file_name().to_string_lossy().into_owned();
                by_name
                    .entry(name)
                    .and_modify(|q| {
                        if p < *q {
                            *q = p.clone();
                        }
                    })
                    .or_insert(p);
            }
        }
    }
    let all: Vec<PathBuf> = by_name.into_values().collect();
    let n = all.len();
    if n <= count {
        return all;
    }
    (0..count).map(|i| all[i * n / count].clone()).collect()
}

/// Runs `cmd` with stderr to `errors`, killing it after `hang_after`
/// seconds, and judges its outcome and output `target`. The child is
/// reaped by `wait4` (for its peak memory), not by `Child::wait`.
#[allow(clippy::zombie_processes)]
fn run_one(mut cmd: Command, errors: &Path, target: &Path, hang_after: f64) -> Run {
    let err_file = std::fs::File::create(errors).expect("a stderr file");
    let start = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err_file)
        .spawn()
        .expect("flourish starts (build it first: cargo build --release)");
    let pid = child.id() as libc::pid_t;
    let limit = Duration::from_secs_f64(hang_after);
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let hung = loop {
        // SAFETY: waits for our own child, writing into live locals.
        let r = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        if r == pid {
            break false;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            // SAFETY: as above; blocks until the killed child is reaped.
            unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
            break true;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let seconds = start.elapsed().as_secs_f64();
    let stderr = std::fs::read_to_string(errors).unwrap_or_default();
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let outcome = if hung {
        Outcome::Other(format!("still running after {hang_after} s"))
    } else if libc::WIFSIGNALED(status) {
        Outcome::Other(format!("killed by signal {}", libc::WTERMSIG(status)))
    } else {
        match libc::WEXITSTATUS(status) {
            0 => match valid_svg(target) {
                Ok(()) => Outcome::Ok,
                Err(e) => Outcome::Other(format!("exit 0 but {e}")),
            },
            1 if lines.len() == 1 && lines[0].starts_with("flourish: ") && !target.exists() => {
                Outcome::CleanError(lines[0].to_string())
            }
            1 if target.exists() => Outcome::Other("exit 1 with an output left".into()),
            code => Outcome::Other(format!(
                "exit {code}, {} stderr lines: {}",
                lines.len(),
                lines.first().copied().unwrap_or("")
            )),
        }
    };
    Run {
        command: "",
        drawing: PathBuf::new(),
        outcome,
        seconds,
        peak_kb: usage.ru_maxrss,
    }
}

/// An SVG that parses and has a size.
fn valid_svg(path: &Path) -> Result<(), String> {
    let data = std::fs::read(path).map_err(|e| format!("no output ({e})"))?;
    let tree = resvg::usvg::Tree::from_data(&data, &resvg::usvg::Options::default())
        .map_err(|e| format!("an output that does not parse ({e})"))?;
    let size = tree.size();
    if size.width() > 0.0 && size.height() > 0.0 {
        Ok(())
    } else {
        Err("an output of zero size".into())
    }
}

/// The markdown report: a table per command and every "other" run.
fn report(runs: &[Run], drawings: usize, took: Duration) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{drawings} drawings × {} commands in {:.0} s\n",
        COMMANDS.len(),
        took.as_secs_f64()
    );
    let _ = writeln!(
        s,
        "| command | ok | clean error | other | median s | slowest s | peak MB |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|");
    for (name, _) in COMMANDS {
        let mine: Vec<&Run> = runs.iter().filter(|r| r.command == name).collect();
        let count = |f: fn(&Outcome) -> bool| mine.iter().filter(|r| f(&r.outcome)).count();
        let mut times: Vec<f64> = mine.iter().map(|r| r.seconds).collect();
        times.sort_by(f64::total_cmp);
        let median = times.get(times.len() / 2).copied().unwrap_or(0.0);
        let slowest = mine.iter().max_by(|a, b| a.seconds.total_cmp(&b.seconds));
        let peak = mine.iter().map(|r| r.peak_kb).max().unwrap_or(0);
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {median:.2} | {:.1} ({}) | {} |",
            count(|o| matches!(o, Outcome::Ok)),
            count(|o| matches!(o, Outcome::CleanError(_))),
            count(|o| matches!(o, Outcome::Other(_))),
            slowest.map_or(0.0, |r| r.seconds),
            slowest.map_or(String::new(), |r| file_name(&r.drawing)),
            peak / 1024
        );
    }
    let mut causes: BTreeMap<(String, &str), usize> = BTreeMap::new();
    for r in runs {
        if let Outcome::CleanError(line) = &r.outcome {
            *causes.entry((cause(line), r.command)).or_default() += 1;
        }
    }
    if !causes.is_empty() {
        let _ = writeln!(s, "\nClean errors by cause:\n");
        for ((c, command), n) in &causes {
            let _ = writeln!(s, "- {command}: {n} × {c}");
        }
    }
    let others: Vec<&Run> = runs
        .iter()
        .filter(|r| matches!(r.outcome, Outcome::Other(_)))
        .collect();
    if !others.is_empty() {
        let _ = writeln!(s, "\nOther outcomes:\n");
        for r in others {
            if let Outcome::Other(why) = &r.outcome {
                let _ = writeln!(s, "- {} {}: {why}", r.command, r.drawing.display());
            }
        }
    }
    s
}

/// A clean error's cause with the file name and numbers taken out, to
/// group alike errors.
fn cause(line: &str) -> String {
    let rest = line.strip_prefix("flourish: ").unwrap_or(line);
    let rest = match rest.find(".svg: ") {
        Some(i) => &rest[i + 6..],
        None => rest,
    };
    let mut out: String = rest
        .chars()
        .map(|c| if c.is_ascii_digit() { '#' } else { c })
        .collect();
    while out.contains("##") {
        out = out.replace("##", "#");
    }
    out.chars().take(120).collect()
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}
