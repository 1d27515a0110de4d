//! `flourish serve`: a local web page to paint ornament with. A small
//! HTTP/1.1 server (tiny_http) serves the page, whose files travel inside
//! the binary, and a JSON API that runs the library's modes on the sketch
//! the page sends: the same calls as the command line, so a result equals
//! `flourish MODE --style S --seed N` on the exported sketch byte for byte.
//!
//! | method and path | what |
//! |---|---|
//! | `GET /`, `/app.js`, `/app.css` | the page |
//! | `GET /api/styles` | every style of the library: name, kind, exemplar count |
//! | `GET /api/styles/NAME/exemplars/I` | exemplar I of style NAME (SVG or PNG bytes) |
//! | `POST /api/synthesize` | a sketch, a mode, a style and a seed → the result SVG |
//! | `POST /api/cancel` | a lane and a generation: the lane's older syntheses end (409) |
//! | `POST /api/uploads` | a new upload of exemplars → its id |
//! | `POST /api/uploads/ID/files` | one exemplar file (SVG, PNG or JPEG) |
//! | `POST /api/uploads/ID/style/KIND` | the upload made a style `mine-ID` of KIND, with its check's warnings |
//! | `GET /api/uploads/ID/zip` | that style as a zip of its folder |
//!
//! Nothing a client sends is used as a file path: a style is found by
//! exact name among the styles the library lists, an exemplar by its index
//! in the style's own file list. Bodies are capped at [`MAX_BODY`] bytes;
//! a malformed request gets a 4xx and a one-line message, and the server
//! goes on serving. Requests are taken by [`WORKERS`] threads; at most
//! [`synth::slots`] syntheses run at once (each on the rayon pool the modes
//! use), and a synthesis superseded by a newer one for the same stroke
//! while it waited is dropped with 409.

mod synth;
mod upload;

use flourish::Library;
use std::io::Read;
use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;
use tiny_http::{Header, Method, Request, Response, Server};

/// Largest request body accepted, in bytes (a sketch of thousands of
/// strokes fits; a bigger one gets 413).
pub const MAX_BODY: usize = 4 << 20;

/// Threads taking requests: enough that page files and style listings are
/// served while syntheses wait for a slot.
pub const WORKERS: usize = 16;

/// What `flourish serve` was asked for.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// Address to bind (default 127.0.0.1: this machine only).
    pub host: IpAddr,
    /// Port to bind; 0 takes a free one (the address is printed).
    pub port: u16,
    /// The styles offered: the library searched, as the command line's.
    pub library: Library,
    /// Open the page in the desktop's browser once listening.
    pub open: bool,
}

/// The page's files, embedded at build time: (path, content type, bytes).
const PAGE: [(&str, &str, &[u8]); 3] = [
    (
        "/",
        "text/html; charset=utf-8",
        include_bytes!("../../web/index.html"),
    ),
    (
        "/app.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../web/app.js"),
    ),
    (
        "/app.css",
        "text/css; charset=utf-8",
        include_bytes!("../../web/app.css"),
    ),
];

/// A reply: status code, content type and body.
pub(crate) struct Reply {
    /// HTTP status code.
    pub status: u16,
    /// Content-Type header value.
    pub content_type: &'static str,
    /// Body bytes.
    pub body: Vec<u8>,
}

impl Reply {
    /// A JSON reply with `status`.
    pub fn json(status: u16, value: &serde_json::Value) -> Reply {
        Reply {
            status,
            content_type: "application/json",
            body: value.to_string().into_bytes(),
        }
    }

    /// A JSON `{"error": message}` reply with a 4xx or 5xx `status`.
    pub fn error(status: u16, message: impl Into<String>) -> Reply {
        Reply::json(status, &serde_json::json!({ "error": message.into() }))
    }
}

/// Binds the address and serves until the process ends; prints
/// `flourish serve: http://HOST:PORT/` on standard output once listening.
pub fn serve(opts: ServeOptions) -> Result<(), String> {
    let addr = SocketAddr::new(opts.host, opts.port);
    let server = Server::http(addr).map_err(|e| format!("cannot listen on {addr}: {e}"))?;
    let bound = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| format!("cannot listen on {addr}: not an IP address"))?;
    let url = match bound.ip() {
        IpAddr::V6(ip) => format!("http://[{ip}]:{}/", bound.port()),
        IpAddr::V4(ip) => format!("http://{ip}:{}/", bound.port()),
    };
    println!("flourish serve: {url} (Ctrl-C stops)");
    use std::io::Write;
    let _ = std::io::stdout().flush();
    if opts.open {
        open_browser(&url);
    }
    let state = Arc::new(synth::State::new(opts.library, bound));
    state.warm_up();
    let server = Arc::new(server);
    let workers: Vec<_> = (0..WORKERS)
        .map(|_| {
            let (server, state) = (server.clone(), state.clone());
            std::thread::spawn(move || {
                while let Ok(request) = server.recv() {
                    handle(&state, request);
                }
            })
        })
        .collect();
    for w in workers {
        let _ = w.join();
    }
    Ok(())
}

/// Opens `url` with the desktop's opener; says so when there is none.
fn open_browser(url: &str) {
    let opened = std::process::Command::new("xdg-open")
        .arg(url)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .is_ok();
    if !opened {
        eprintln!("flourish serve: no browser opener (xdg-open) found; open {url} yourself");
    }
}

/// Answers one request; a failure to send the reply (the client left) is
/// the client's business.
fn handle(state: &synth::State, mut request: Request) {
    let reply = route(state, &mut request);
    // A Content-Length rather than chunks, whatever the size: every
    // client reads that.
    let mut response = Response::from_data(reply.body)
        .with_status_code(reply.status)
        .with_chunked_threshold(usize::MAX);
    for (name, value) in [
        ("Content-Type", reply.content_type),
        ("Cache-Control", "no-store"),
        ("X-Content-Type-Options", "nosniff"),
    ] {
        if let Ok(h) = Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(h);
        }
    }
    let _ = request.respond(response);
}

/// The reply to `request`.
fn route(state: &synth::State, request: &mut Request) -> Reply {
    if !state.host_allowed(host_header(request).as_deref()) {
        return Reply::error(421, "this server answers requests to its own address only");
    }
    let path = request.url().split('?').next().unwrap_or("").to_string();
    let method = request.method().clone();
    if let Some((_, ty, bytes)) = PAGE.iter().find(|(p, _, _)| *p == path) {
        return match method {
            Method::Get | Method::Head => Reply {
                status: 200,
                content_type: ty,
                body: bytes.to_vec(),
            },
            _ => Reply::error(405, format!("{path} takes GET")),
        };
    }
    let parts: Vec<&str> = path.trim_start_matches('/').split('/').collect();
    match (method, parts.as_slice()) {
        (Method::Get, ["api", "styles"]) => state.styles(),
        (Method::Get, ["api", "styles", name, "exemplars", index]) => {
            match index.parse::<usize>() {
                Ok(i) => state.exemplar(&percent_decoded(name), i),
                Err(_) => Reply::error(400, format!("exemplar index {index:?} is not a number")),
            }
        }
        (Method::Post, ["api", "synthesize"]) => match body(request) {
            Ok(bytes) => state.synthesize(&bytes),
            Err(reply) => reply,
        },
        (Method::Post, ["api", "cancel"]) => match body(request) {
            Ok(bytes) => state.cancel(&bytes),
            Err(reply) => reply,
        },
        (Method::Post, ["api", "uploads"]) => state.uploads.create(),
        (Method::Get, ["api", "uploads", id, "zip"]) => match id.parse() {
            Ok(id) => state.uploads.zip(id),
            Err(_) => Reply::error(400, format!("upload id {id:?} is not a number")),
        },
        (Method::Post, ["api", "uploads", id, "files"]) => match (id.parse(), body(request)) {
            (Ok(id), Ok(bytes)) => state.uploads.add_file(id, &bytes),
            (Err(_), _) => Reply::error(400, format!("upload id {id:?} is not a number")),
            (_, Err(reply)) => reply,
        },
        (Method::Post, ["api", "uploads", id, "style", kind]) => match id.parse() {
            Ok(id) => state.make_style(id, kind),
            Err(_) => Reply::error(400, format!("upload id {id:?} is not a number")),
        },
        (_, ["api", "styles", ..])
        | (_, ["api", "synthesize"])
        | (_, ["api", "cancel"])
        | (_, ["api", "uploads", ..]) => Reply::error(405, format!("{path}: wrong method")),
        _ => Reply::error(404, format!("{path}: no such page")),
    }
}

/// The request's `Host` header, if any.
fn host_header(request: &Request) -> Option<String> {
    request
        .headers()
        .iter()
        .find(|h| h.field.equiv("Host"))
        .map(|h| h.value.as_str().to_string())
}

/// The request body, at most [`MAX_BODY`] bytes, or the 4xx reply.
fn body(request: &mut Request) -> Result<Vec<u8>, Reply> {
    let too_large = || {
        Reply::error(
            413,
            format!("the request is larger than {} bytes", MAX_BODY),
        )
    };
    if request.body_length().is_some_and(|n| n > MAX_BODY) {
        return Err(too_large());
    }
    let mut bytes = Vec::new();
    request
        .as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Reply::error(400, format!("the request body could not be read: {e}")))?;
    if bytes.len() > MAX_BODY {
        return Err(too_large());
    }
    Ok(bytes)
}

/// `text` with `%XX` escapes decoded (invalid escapes kept as they are).
fn percent_decoded(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|&c| hex(c)),
            b.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}
