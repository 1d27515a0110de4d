//! The server's state and its API: the styles offered (loaded once, by
//! exact name from the library's listing), and syntheses through the
//! library's face, one per request, at most [`slots`] at once, a stale
//! one (superseded by a newer generation of the same lane) dropped before
//! it starts or cancelled while it runs (the modes' [`Cancel`] handle,
//! checked between their stages and queries): 409 either way.

use super::Reply;
use flourish::{
    BrushOptions, Cancel, DecorateOptions, Decoration, FillOptions, Library, Output,
    PatternOptions, QueryKind, Refinement, Sketch, Style, StyleEntry, StyleKind, StyleOptions,
    Styles,
};
use serde::Deserialize;
use serde_json::json;
use std::collections::{BTreeMap, HashMap};
use std::net::SocketAddr;
use std::sync::{Condvar, Mutex};
use std::time::Instant;

/// Most lanes remembered for superseding; past it the memory of lanes
/// starts afresh (a stale request may then run, which is harmless).
const MAX_LANES: usize = 10_000;

/// Longest lane name accepted, in bytes.
const MAX_LANE: usize = 128;

/// Syntheses run at once: one per core, at least two (each also uses the
/// rayon pool, so more would only queue there and hold memory).
pub fn slots() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(2)
        .max(2)
}

/// A synthesis request, as the page sends it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SynthRequest {
    /// The sketch SVG text.
    sketch: String,
    /// `brush`, `fill`, `pattern` (with `style`) or `decorate` (each
    /// shape's `data-style`).
    mode: String,
    /// The style's name (the library's listing), for every mode but
    /// `decorate`.
    #[serde(default)]
    style: Option<String>,
    /// The seed of the command line's `--seed` (default 0).
    #[serde(default)]
    seed: u64,
    /// A refinement sketch for mode `brush` (DecoBrush §5.5; the command
    /// line's `--refine`): SVG text of the sketch's size whose black
    /// strokes add ornament and white ones erase it.
    #[serde(default)]
    refine: Option<String>,
    /// What the request draws (a stroke's id): a later generation of the
    /// same lane makes this one stale.
    #[serde(default)]
    lane: Option<String>,
    /// This request's generation in its lane (larger is newer).
    #[serde(default)]
    generation: u64,
}

/// Everything the workers share.
pub struct State {
    /// Where styles are found.
    library: Library,
    /// The address the server is bound to (for the `Host` check).
    bound: SocketAddr,
    /// Styles loaded so far, by name.
    styles: Mutex<HashMap<String, Style>>,
    /// The newest generation seen per lane and its running syntheses.
    lanes: Mutex<HashMap<String, Lane>>,
    /// Styles made on the page from dropped exemplars.
    pub uploads: super::upload::Uploads,
    /// The listing entries of those styles, in the order they were made.
    made: Mutex<Vec<serde_json::Value>>,
    /// Synthesis slots handed out first come, first served, and the
    /// condition to wait for one's turn on.
    queue: (Mutex<Queue>, Condvar),
}

/// One lane's generations: the newest seen, and the syntheses running
/// with their cancel handles.
#[derive(Default)]
struct Lane {
    /// The newest generation seen.
    newest: u64,
    /// (generation, handle) of each synthesis running in this lane.
    running: Vec<(u64, Cancel)>,
}

/// A synthesis registered in its lane; taken out when dropped.
struct Running<'a> {
    state: &'a State,
    lane: &'a str,
    cancel: Cancel,
}

impl Drop for Running<'_> {
    fn drop(&mut self) {
        if let Ok(mut lanes) = self.state.lanes.lock() {
            if let Some(l) = lanes.get_mut(self.lane) {
                l.running.retain(|(_, c)| *c != self.cancel);
            }
        }
    }
}

/// The body of `POST /api/cancel`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CancelRequest {
    /// The lane whose older syntheses end.
    lane: String,
    /// The generation that supersedes them.
    generation: u64,
}

/// The tickets of the synthesis queue.
struct Queue {
    /// The ticket the next request to arrive takes.
    next: u64,
    /// The ticket whose turn it is.
    turn: u64,
    /// Syntheses running now.
    running: usize,
    /// Most syntheses at once ([`slots`]).
    slots: usize,
}

/// Holds a synthesis slot; gives it back when dropped.
struct Slot<'a>(&'a State);

impl Drop for Slot<'_> {
    fn drop(&mut self) {
        let (lock, cv) = &self.0.queue;
        if let Ok(mut q) = lock.lock() {
            q.running -= 1;
            cv.notify_all();
        }
    }
}

impl State {
    /// A fresh state serving `library`'s styles on `bound`.
    pub fn new(library: Library, bound: SocketAddr) -> State {
        State {
            library,
            bound,
            styles: Mutex::new(HashMap::new()),
            lanes: Mutex::new(HashMap::new()),
            uploads: super::upload::Uploads::new(),
            made: Mutex::new(Vec::new()),
            queue: (
                Mutex::new(Queue {
                    next: 0,
                    turn: 0,
                    running: 0,
                    slots: slots(),
                }),
                Condvar::new(),
            ),
        }
    }

    /// Loads every listed style on a thread of its own, so that the first
    /// stroke finds its style analysed.
    pub fn warm_up(self: &std::sync::Arc<Self>) {
        let state = self.clone();
        std::thread::spawn(move || {
            for entry in state.library.styles() {
                let _ = state.style(&entry.name, None);
            }
        });
    }

    /// Whether a request with `Host: host` is for this server: on a
    /// loopback address only `localhost` and loopback addresses with this
    /// port are (a page elsewhere cannot reach it by renaming a host).
    pub fn host_allowed(&self, host: Option<&str>) -> bool {
        if !self.bound.ip().is_loopback() {
            return true;
        }
        let Some(host) = host else { return false };
        let port = self.bound.port();
        ["127.0.0.1", "localhost", "[::1]"]
            .iter()
            .any(|name| host == format!("{name}:{port}"))
    }

    /// The library's styles as JSON: name, kind and exemplar count each;
    /// then the styles made on the page.
    pub fn styles(&self) -> Reply {
        let mut list: Vec<_> = self
            .library
            .styles()
            .into_iter()
            .filter_map(|e| {
                let kind = e.kind?;
                Some(json!({
                    "name": e.name,
                    "kind": kind.name(),
                    "exemplars": e.exemplars,
                }))
            })
            .collect();
        if let Ok(made) = self.made.lock() {
            list.extend(made.iter().cloned());
        }
        Reply::json(200, &json!({ "styles": list }))
    }

    /// Exemplar `index` (from 0) of style `name`: its file's bytes, read
    /// from the path the style itself lists.
    pub fn exemplar(&self, name: &str, index: usize) -> Reply {
        let style = match self.style(name, None) {
            Ok(s) => s,
            Err(reply) => return reply,
        };
        let Some(path) = style.files().get(index + 1) else {
            return Reply::error(404, format!("style {name} has no exemplar {index}"));
        };
        let content_type = match path.extension().and_then(|e| e.to_str()) {
            Some("svg") => "image/svg+xml",
            Some("png") => "image/png",
            Some("jpg" | "jpeg") => "image/jpeg",
            Some("gif") => "image/gif",
            Some("webp") => "image/webp",
            _ => "application/octet-stream",
        };
        match std::fs::read(path) {
            Ok(body) => Reply {
                status: 200,
                content_type,
                body,
            },
            Err(e) => Reply::error(500, format!("style {name}: exemplar {index}: {e}")),
        }
    }

    /// `POST /api/uploads/ID/style/KIND`: makes upload ID a style named
    /// `mine-ID`, offered from then on like the library's.
    pub fn make_style(&self, id: u64, kind: &str) -> Reply {
        let name = format!("mine-{id}");
        match self.uploads.make_style(id, kind, &name) {
            Ok((style, reply)) => {
                if let Ok(mut m) = self.styles.lock() {
                    m.insert(name.clone(), style.clone());
                }
                if let Ok(mut made) = self.made.lock() {
                    made.retain(|e| e["name"] != name.as_str());
                    made.push(json!({
                        "name": name,
                        "kind": style.kind().name(),
                        "exemplars": style.files().len().saturating_sub(1),
                    }));
                }
                reply
            }
            Err(reply) => reply,
        }
    }

    /// Style `name` of the listing (of `kind`, when given), loaded once;
    /// a name the listing lacks is 404, a style of another kind 422.
    fn style(&self, name: &str, kind: Option<StyleKind>) -> Result<Style, Reply> {
        let cached = self.styles.lock().ok().and_then(|m| m.get(name).cloned());
        let style = match cached {
            Some(s) => s,
            None => {
                let listed: Vec<StyleEntry> = self.library.styles();
                if !listed.iter().any(|e| e.name == name) {
                    return Err(Reply::error(404, format!("no style named {name:?}")));
                }
                let s = self
                    .library
                    .load(name, &StyleOptions::default())
                    .map_err(|e| Reply::error(422, format!("style {name}: {e}")))?;
                if let Ok(mut m) = self.styles.lock() {
                    m.insert(name.to_string(), s.clone());
                }
                s
            }
        };
        match kind {
            Some(k) if style.kind() != k => Err(Reply::error(
                422,
                format!(
                    "{name} is a {} style, not a {} style",
                    style.kind().name(),
                    k.name()
                ),
            )),
            _ => Ok(style),
        }
    }

    /// The styles the queries `decorated` accepts name with `data-style`,
    /// by name, as [`Library::load_named`] gives them.
    fn named(
        &self,
        sketch: &Sketch,
        decorated: impl Fn(&QueryKind) -> bool,
    ) -> Result<BTreeMap<String, Style>, Reply> {
        let mut named = BTreeMap::new();
        for q in &sketch.queries {
            let Some(name) = q.style.as_ref().filter(|_| decorated(&q.kind)) else {
                continue;
            };
            if !named.contains_key(name) {
                let style = self.style(name, None).map_err(|r| {
                    if r.status == 404 {
                        Reply::error(422, format!("{}: data-style {name:?} is not a style", q.id))
                    } else {
                        r
                    }
                })?;
                named.insert(name.clone(), style);
            }
        }
        Ok(named)
    }

    /// Takes a synthesis slot, waiting for it in order of arrival (so no
    /// request waits behind later ones); `None` if the lock broke.
    fn slot(&self) -> Option<Slot<'_>> {
        let (lock, cv) = &self.queue;
        let mut q = lock.lock().ok()?;
        let ticket = q.next;
        q.next += 1;
        while q.turn != ticket || q.running >= q.slots {
            q = cv.wait(q).ok()?;
        }
        q.turn += 1;
        q.running += 1;
        cv.notify_all();
        Some(Slot(self))
    }

    /// Records `generation` for `lane` and cancels the lane's running
    /// syntheses of older generations; whether it is the newest so far.
    fn newest(&self, lane: &str, generation: u64) -> bool {
        let Ok(mut lanes) = self.lanes.lock() else {
            return true;
        };
        if lanes.len() >= MAX_LANES && !lanes.contains_key(lane) {
            lanes.clear();
        }
        let l = lanes.entry(lane.to_string()).or_insert(Lane {
            newest: generation,
            running: Vec::new(),
        });
        l.newest = l.newest.max(generation);
        for (g, c) in &l.running {
            if *g < l.newest {
                c.cancel();
            }
        }
        l.newest == generation
    }

    /// Registers a synthesis of `generation` in `lane` with its handle,
    /// so a newer generation cancels it.
    fn register<'a>(&'a self, lane: &'a str, generation: u64, cancel: &Cancel) -> Running<'a> {
        if let Ok(mut lanes) = self.lanes.lock() {
            lanes
                .entry(lane.to_string())
                .or_default()
                .running
                .push((generation, cancel.clone()));
        }
        Running {
            state: self,
            lane,
            cancel: cancel.clone(),
        }
    }

    /// `POST /api/cancel`: `{"lane", "generation"}` supersedes the lane's
    /// older requests, queued or running (the page sends it when the
    /// drawing changes under a synthesis of the whole of it).
    pub fn cancel(&self, body: &[u8]) -> Reply {
        let req: CancelRequest = match serde_json::from_slice(body) {
            Ok(r) => r,
            Err(e) => return Reply::error(400, format!("malformed request: {e}")),
        };
        if req.lane.len() > MAX_LANE {
            return Reply::error(400, format!("lane is longer than {MAX_LANE} bytes"));
        }
        self.newest(&req.lane, req.generation);
        Reply::json(
            200,
            &json!({ "lane": req.lane, "generation": req.generation }),
        )
    }

    /// `POST /api/synthesize`: parses the request, waits for a slot,
    /// drops it if a newer generation of its lane came meanwhile, and runs
    /// the mode through the library's face with the command line's
    /// options for that seed.
    pub fn synthesize(&self, body: &[u8]) -> Reply {
        let req: SynthRequest = match serde_json::from_slice(body) {
            Ok(r) => r,
            Err(e) => return Reply::error(400, format!("malformed request: {e}")),
        };
        if let Some(lane) = &req.lane {
            if lane.len() > MAX_LANE {
                return Reply::error(400, format!("lane is longer than {MAX_LANE} bytes"));
            }
            if !self.newest(lane, req.generation) {
                return Reply::error(409, "superseded by a newer request for the same stroke");
            }
        }
        let Some(_slot) = self.slot() else {
            return Reply::error(503, "the server is shutting down");
        };
        let cancel = Cancel::new();
        let _running = req
            .lane
            .as_deref()
            .map(|lane| self.register(lane, req.generation, &cancel));
        if let Some(lane) = &req.lane {
            if !self.newest(lane, req.generation) {
                return Reply::error(409, "superseded by a newer request for the same stroke");
            }
        }
        let started = Instant::now();
        let sketch = match Sketch::from_svg(req.sketch.as_bytes()) {
            Ok(s) => s,
            Err(e) => return Reply::error(422, format!("sketch: {e}")),
        };
        let out = match self.run(&req, &sketch, &cancel) {
            Ok(out) => out,
            Err(reply) => return reply,
        };
        Reply::json(
            200,
            &json!({
                "svg": out.to_svg(),
                "warnings": out.warnings,
                "notes": out.notes,
                "ms": started.elapsed().as_secs_f64() * 1e3,
            }),
        )
    }

    /// Runs the request's mode on `sketch`.
    fn run(&self, req: &SynthRequest, sketch: &Sketch, cancel: &Cancel) -> Result<Output, Reply> {
        let fail = |e: flourish::Error| match e.cause() {
            flourish::Error::Cancelled => Reply::error(
                409,
                "cancelled: superseded by a newer request for the same stroke",
            ),
            _ => Reply::error(422, e.to_string()),
        };
        let cancel = Some(cancel.clone());
        let style_of = |kind: StyleKind| -> Result<Style, Reply> {
            let name = req
                .style
                .as_deref()
                .ok_or_else(|| Reply::error(400, format!("mode {} needs a style", req.mode)))?;
            self.style(name, Some(kind))
        };
        let seed = req.seed;
        if req.refine.is_some() && req.mode != "brush" {
            return Err(Reply::error(400, "refine goes with mode brush only"));
        }
        match req.mode.as_str() {
            "brush" => {
                let style = style_of(StyleKind::Brush)?;
                let refine = match &req.refine {
                    Some(svg) => Some(
                        Refinement::from_svg(svg.as_bytes())
                            .map_err(|e| Reply::error(422, format!("refine: {e}")))?,
                    ),
                    None => None,
                };
                let opts = BrushOptions {
                    seed,
                    refine,
                    cancel,
                    ..BrushOptions::default()
                };
                flourish::brush(sketch, &style, &opts).map_err(fail)
            }
            "fill" => {
                let style = style_of(StyleKind::Fill)?;
                let named = self.named(sketch, |k| matches!(k, QueryKind::Region { .. }))?;
                let opts = FillOptions {
                    seed,
                    cancel,
                    ..FillOptions::default()
                };
                flourish::fill(sketch, Styles::new(&style, &named), &opts).map_err(fail)
            }
            "pattern" => {
                let style = style_of(StyleKind::Pattern)?;
                let named = self.named(sketch, |_| true)?;
                let opts = PatternOptions {
                    seed,
                    ..PatternOptions::default()
                };
                flourish::pattern(sketch, Styles::new(&style, &named), &opts).map_err(fail)
            }
            "decorate" => {
                let named = self.named(sketch, |_| true)?;
                let opts = DecorateOptions {
                    brush: BrushOptions {
                        seed,
                        cancel: cancel.clone(),
                        ..BrushOptions::default()
                    },
                    fill: FillOptions {
                        seed,
                        cancel,
                        ..FillOptions::default()
                    },
                    pattern: PatternOptions {
                        seed,
                        ..PatternOptions::default()
                    },
                };
                let styles = Decoration {
                    strokes: None,
                    regions: None,
                    named: &named,
                };
                flourish::decorate(sketch, styles, &opts).map_err(fail)
            }
            other => Err(Reply::error(
                400,
                format!("mode {other:?} is not brush, fill, pattern or decorate"),
            )),
        }
    }
}
