//! `flourish serve` without a browser: the binary started on a free port,
//! requests sent over the loopback interface, results compared with the
//! library's face for the same sketch and seed, and malformed, oversized
//! and hostile requests answered with a 4xx while the server goes on.

use flourish::{BrushOptions, FillOptions, Library, Sketch, StyleOptions};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// A running `flourish serve --port 0`, killed when dropped.
struct Server {
    child: Child,
    addr: SocketAddr,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start() -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_flourish"))
        .args(["serve", "--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("flourish serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("the address line");
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap_or_else(|| panic!("no address in {line:?}"));
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .parse()
        .expect("an address");
    Server { child, addr }
}

/// One HTTP/1.1 exchange: (status, body).
fn exchange(addr: SocketAddr, head: &str, body: &[u8]) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(Duration::from_secs(120)))
        .expect("timeout");
    s.write_all(head.as_bytes()).expect("writes head");
    // A server may answer (413) before the whole body is sent.
    let _ = s.write_all(body);
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    let text = String::from_utf8_lossy(&reply);
    let status = text
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:?}"));
    let at = reply
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .map_or(reply.len(), |i| i + 4);
    (status, reply[at..].to_vec())
}

fn get(server: &Server, path: &str) -> (u16, Vec<u8>) {
    let head = format!(
        "GET {path} HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
        server.addr
    );
    exchange(server.addr, &head, b"")
}

fn post(server: &Server, path: &str, body: &[u8]) -> (u16, Vec<u8>) {
    let head = format!(
        "POST {path} HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        server.addr,
        body.len()
    );
    exchange(server.addr, &head, body)
}

fn json(bytes: &[u8]) -> serde_json::Value {
    serde_json::from_slice(bytes)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(bytes)))
}

const STROKES: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="400" height="240" viewBox="0 0 400 240">
  <path id="s-1" data-style="vine" d="M20 80 L100 40 L200 90 L300 50 L380 80" fill="none" stroke="black" stroke-width="20"/>
  <path id="s-2" data-style="vine" d="M20 180 L120 200 L220 160 L380 190" fill="none" stroke="black" stroke-width="24"/>
</svg>"#;

const SHAPE: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">
  <path id="s-1" data-style="knot" d="M100 20 L180 100 L100 180 L20 100 Z" fill="black"/>
</svg>"#;

#[test]
fn the_page_and_styles_are_served() {
    let server = start();
    let (status, page) = get(&server, "/");
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&page).contains("<svg id=\"board\""));
    for path in ["/app.js", "/app.css"] {
        assert_eq!(get(&server, path).0, 200, "{path}");
    }
    let (status, body) = get(&server, "/api/styles");
    assert_eq!(status, 200);
    let styles = json(&body);
    let list = styles["styles"].as_array().expect("a list");
    let shipped = Library::shipped().styles();
    assert_eq!(list.len(), shipped.len());
    let vine = list
        .iter()
        .find(|s| s["name"] == "vine")
        .expect("vine is listed");
    assert_eq!(vine["kind"], "brush");
    let n = vine["exemplars"].as_u64().expect("a count");
    assert!(n > 0);
    let (status, bytes) = get(&server, "/api/styles/vine/exemplars/0");
    assert_eq!(status, 200);
    assert!(bytes.starts_with(b"<") || bytes.starts_with(b"\x89PNG"));
    assert_eq!(
        get(&server, &format!("/api/styles/vine/exemplars/{n}")).0,
        404
    );
}

#[test]
fn results_equal_the_library_for_the_same_sketch_and_seed() {
    let server = start();
    let lib = Library::shipped();
    let vine = lib.load("vine", &StyleOptions::default()).expect("vine");
    let knot = lib.load("knot", &StyleOptions::default()).expect("knot");
    for seed in [0u64, 7] {
        let req =
            serde_json::json!({"sketch": STROKES, "mode": "brush", "style": "vine", "seed": seed});
        let (status, body) = post(&server, "/api/synthesize", req.to_string().as_bytes());
        assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
        let sketch = Sketch::from_svg(STROKES.as_bytes()).expect("sketch");
        let want = flourish::brush(
            &sketch,
            &vine,
            &BrushOptions {
                seed,
                ..BrushOptions::default()
            },
        )
        .expect("brushes")
        .to_svg();
        assert_eq!(
            json(&body)["svg"].as_str(),
            Some(want.as_str()),
            "seed {seed}"
        );
    }
    let req = serde_json::json!({"sketch": SHAPE, "mode": "fill", "style": "knot", "seed": 3});
    let (status, body) = post(&server, "/api/synthesize", req.to_string().as_bytes());
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
    let sketch = Sketch::from_svg(SHAPE.as_bytes()).expect("sketch");
    let named = lib
        .load_named(&sketch, flourish::StyleKind::Fill, &StyleOptions::default())
        .expect("named");
    let want = flourish::fill(
        &sketch,
        flourish::Styles::new(&knot, &named),
        &FillOptions {
            seed: 3,
            ..FillOptions::default()
        },
    )
    .expect("fills")
    .to_svg();
    assert_eq!(json(&body)["svg"].as_str(), Some(want.as_str()));
}

#[test]
fn one_stroke_alone_gives_its_group_of_the_whole_sketch() {
    // The page shows each stroke's own synthesis until the drawing
    // settles: the ornament is the same. (A stroke alone may be written
    // with fewer decimals than in a drawing with finer strokes, so the
    // strokes here are of one width.)
    let server = start();
    let strokes = STROKES.replace("stroke-width=\"24\"", "stroke-width=\"20\"");
    let whole = serde_json::json!({"sketch": strokes, "mode": "brush", "style": "vine", "seed": 2});
    let (_, body) = post(&server, "/api/synthesize", whole.to_string().as_bytes());
    let whole = json(&body)["svg"].as_str().expect("svg").to_string();
    let lines: Vec<&str> = strokes.lines().collect();
    for keep in [1, 2] {
        let one = format!("{}\n{}\n{}", lines[0], lines[keep], lines[3]);
        let req = serde_json::json!({"sketch": one, "mode": "brush", "style": "vine", "seed": 2});
        let (status, body) = post(&server, "/api/synthesize", req.to_string().as_bytes());
        assert_eq!(status, 200);
        let svg = json(&body)["svg"].as_str().expect("svg").to_string();
        let start = svg.find("<g id=").expect("a group");
        let end = svg.rfind("</g>").expect("its end") + 4;
        assert!(whole.contains(&svg[start..end]), "stroke {keep}");
    }
}

#[test]
fn malformed_requests_get_a_4xx_and_the_server_goes_on() {
    let server = start();
    let bad: Vec<(u16, String)> = vec![
        (400, "{not json".into()),
        (
            400,
            r#"{"sketch": "<svg/>", "mode": "paint", "style": "vine"}"#.into(),
        ),
        (400, r#"{"sketch": "<svg/>", "mode": "brush"}"#.into()),
        (
            400,
            r#"{"sketch": 5, "mode": "brush", "style": "vine"}"#.into(),
        ),
        (
            400,
            r#"{"sketch": "", "mode": "brush", "style": "vine", "extra": 1}"#.into(),
        ),
        (
            422,
            r#"{"sketch": "<svg", "mode": "brush", "style": "vine"}"#.into(),
        ),
        (
            404,
            r#"{"sketch": "<svg/>", "mode": "brush", "style": "../../etc"}"#.into(),
        ),
        (
            404,
            r#"{"sketch": "<svg/>", "mode": "brush", "style": "/etc/passwd"}"#.into(),
        ),
        (
            422,
            r#"{"sketch": "<svg/>", "mode": "brush", "style": "knot"}"#.into(),
        ),
    ];
    for (want, body) in &bad {
        let (status, reply) = post(&server, "/api/synthesize", body.as_bytes());
        assert_eq!(status, *want, "{body}");
        let msg = json(&reply)["error"]
            .as_str()
            .expect("a message")
            .to_string();
        assert!(!msg.is_empty() && !msg.contains('\n'), "{msg}");
    }
    // A data-style that is a path is refused, never read.
    let sketch = STROKES.replace("data-style=\"vine\"", "data-style=\"../../../etc\"");
    let req = serde_json::json!({"sketch": sketch, "mode": "pattern", "style": "flowers"});
    assert_eq!(
        post(&server, "/api/synthesize", req.to_string().as_bytes()).0,
        422
    );
    assert_eq!(get(&server, "/api/styles/..%2F..%2Fetc/exemplars/0").0, 404);
    assert_eq!(get(&server, "/api/styles/vine/exemplars/x").0, 400);
    assert_eq!(get(&server, "/nowhere").0, 404);
    assert_eq!(get(&server, "/api/synthesize").0, 405);
    // A request to another host name (DNS rebinding) is refused.
    let head = "GET /api/styles HTTP/1.1\r\nHost: evil.example:80\r\nConnection: close\r\n\r\n";
    assert_eq!(exchange(server.addr, head, b"").0, 421);
    // Garbage instead of HTTP.
    let _ = exchange_raw(server.addr, b"\x00\x01garbage\r\n\r\n");
    // Still serving.
    assert_eq!(get(&server, "/api/styles").0, 200);
}

/// Sends raw bytes and reads whatever comes back.
fn exchange_raw(addr: SocketAddr, bytes: &[u8]) -> Vec<u8> {
    let mut s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(Duration::from_secs(5)))
        .expect("timeout");
    let _ = s.write_all(bytes);
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    reply
}

#[test]
fn bodies_over_the_limit_get_413() {
    let server = start();
    let big = vec![b' '; 5 << 20];
    let (status, _) = post(&server, "/api/synthesize", &big);
    assert_eq!(status, 413);
    // Chunked, with no length announced.
    let head = format!(
        "POST /api/synthesize HTTP/1.1\r\nHost: {}\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n",
        server.addr
    );
    let mut body = Vec::new();
    for _ in 0..6 {
        body.extend_from_slice(format!("{:x}\r\n", 1 << 20).as_bytes());
        body.extend(std::iter::repeat_n(b' ', 1 << 20));
        body.extend_from_slice(b"\r\n");
    }
    body.extend_from_slice(b"0\r\n\r\n");
    assert_eq!(exchange(server.addr, &head, &body).0, 413);
    assert_eq!(get(&server, "/api/styles").0, 200);
}

#[test]
fn a_stale_generation_is_superseded() {
    let server = start();
    let newer = serde_json::json!({"sketch": STROKES, "mode": "brush", "style": "vine", "lane": "s-1", "generation": 5});
    assert_eq!(
        post(&server, "/api/synthesize", newer.to_string().as_bytes()).0,
        200
    );
    let older = serde_json::json!({"sketch": STROKES, "mode": "brush", "style": "vine", "lane": "s-1", "generation": 4});
    assert_eq!(
        post(&server, "/api/synthesize", older.to_string().as_bytes()).0,
        409
    );
}

#[test]
fn several_clients_at_once_are_served() {
    let server = start();
    let addr = server.addr;
    let handles: Vec<_> = (0..6)
        .map(|i| {
            std::thread::spawn(move || {
                let req = serde_json::json!({"sketch": STROKES, "mode": "brush", "style": "vine", "seed": i % 2});
                let body = req.to_string();
                let head = format!(
                    "POST /api/synthesize HTTP/1.1\r\nHost: {addr}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
                    body.len()
                );
                let (status, reply) = exchange(addr, &head, body.as_bytes());
                assert_eq!(status, 200);
                json(&reply)["svg"].as_str().expect("svg").to_string()
            })
        })
        .collect();
    let svgs: Vec<String> = handles
        .into_iter()
        .map(|h| h.join().expect("a client"))
        .collect();
    for (i, svg) in svgs.iter().enumerate() {
        assert_eq!(svg, &svgs[i % 2], "same seed, same result");
    }
    assert_ne!(svgs[0], svgs[1]);
}

#[test]
fn a_refinement_sketch_is_the_command_lines_refine() {
    let server = start();
    let refine = r#"<svg xmlns="http://www.w3.org/2000/svg" width="400" height="240" viewBox="0 0 400 240">
  <path d="M200 20 L200 120" fill="none" stroke="white" stroke-width="30"/>
</svg>"#;
    let req =
        serde_json::json!({"sketch": STROKES, "mode": "brush", "style": "vine", "refine": refine});
    let (status, body) = post(&server, "/api/synthesize", req.to_string().as_bytes());
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
    let vine = Library::shipped()
        .load("vine", &StyleOptions::default())
        .expect("vine");
    let sketch = Sketch::from_svg(STROKES.as_bytes()).expect("sketch");
    let opts = BrushOptions {
        refine: Some(flourish::Refinement::from_svg(refine.as_bytes()).expect("refine")),
        ..BrushOptions::default()
    };
    let want = flourish::brush(&sketch, &vine, &opts)
        .expect("brushes")
        .to_svg();
    assert_eq!(json(&body)["svg"].as_str(), Some(want.as_str()));
    for (want, req) in [
        (
            400,
            serde_json::json!({"sketch": SHAPE, "mode": "fill", "style": "knot", "refine": refine}),
        ),
        (
            422,
            serde_json::json!({"sketch": STROKES, "mode": "brush", "style": "vine", "refine": "<svg"}),
        ),
    ] {
        assert_eq!(
            post(&server, "/api/synthesize", req.to_string().as_bytes()).0,
            want
        );
    }
}

#[test]
fn uploads_become_styles_and_bad_uploads_get_a_4xx() {
    let server = start();
    let (status, body) = post(&server, "/api/uploads", b"");
    assert_eq!(status, 200);
    let id = json(&body)["id"].as_u64().expect("an id");
    let files = format!("/api/uploads/{id}/files");
    // Nothing to make a style of yet; a file that is no drawing.
    assert_eq!(
        post(&server, &format!("/api/uploads/{id}/style/pattern"), b"").0,
        400
    );
    assert_eq!(post(&server, &files, b"#!/bin/sh\nrm -rf /\n").0, 415);
    let example = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("styles/flowers/example.svg"),
    )
    .expect("the flowers example");
    assert_eq!(post(&server, &files, &example).0, 200);
    assert_eq!(
        post(&server, &format!("/api/uploads/{id}/style/paint"), b"").0,
        400
    );
    assert_eq!(post(&server, "/api/uploads/999/files", &example).0, 404);
    assert_eq!(post(&server, "/api/uploads/x/files", &example).0, 400);
    let (status, body) = post(&server, &format!("/api/uploads/{id}/style/pattern"), b"");
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
    let made = json(&body);
    let name = made["name"].as_str().expect("a name").to_string();
    assert_eq!(made["kind"], "pattern");
    // Offered and usable like a shipped style.
    let (_, list) = get(&server, "/api/styles");
    assert!(json(&list)["styles"]
        .as_array()
        .expect("a list")
        .iter()
        .any(|s| s["name"] == name.as_str()));
    assert_eq!(
        get(&server, &format!("/api/styles/{name}/exemplars/0")).1,
        example
    );
    let sketch = STROKES.replace("data-style=\"vine\" ", "");
    let req = serde_json::json!({"sketch": sketch, "mode": "pattern", "style": name});
    let (status, body) = post(&server, "/api/synthesize", req.to_string().as_bytes());
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
}

#[test]
fn a_made_style_downloads_as_a_zip_of_its_folder() {
    let server = start();
    let (_, body) = post(&server, "/api/uploads", b"");
    let id = json(&body)["id"].as_u64().expect("an id");
    assert_eq!(get(&server, &format!("/api/uploads/{id}/zip")).0, 409);
    assert_eq!(get(&server, "/api/uploads/999/zip").0, 404);
    let example = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("styles/flowers/example.svg"),
    )
    .expect("the flowers example");
    post(&server, &format!("/api/uploads/{id}/files"), &example);
    post(&server, &format!("/api/uploads/{id}/style/pattern"), b"");
    let (status, zip) = get(&server, &format!("/api/uploads/{id}/zip"));
    assert_eq!(status, 200);
    assert!(zip.starts_with(b"PK\x03\x04"));
    // Its folder and files are named, in order.
    let text = String::from_utf8_lossy(&zip);
    let a = text
        .find(&format!("mine-{id}/exemplar-01.svg"))
        .expect("the exemplar");
    let b = text
        .find(&format!("mine-{id}/style.toml"))
        .expect("style.toml");
    assert!(a < b);
}

/// A cancel handle set before the run ends it at its first check with
/// the typed error, for brush and fill alike; a fresh handle changes
/// nothing.
#[test]
fn a_cancelled_run_ends_with_the_cancelled_error() {
    let vine = Library::shipped()
        .load("vine", &StyleOptions::default())
        .expect("vine");
    let knot = Library::shipped()
        .load("knot", &StyleOptions::default())
        .expect("knot");
    let cancel = flourish::Cancel::new();
    cancel.cancel();
    let strokes = Sketch::from_svg(STROKES.as_bytes()).expect("sketch");
    let shape = Sketch::from_svg(SHAPE.as_bytes()).expect("sketch");
    let brushed = flourish::brush(
        &strokes,
        &vine,
        &BrushOptions {
            cancel: Some(cancel.clone()),
            ..BrushOptions::default()
        },
    );
    assert!(
        matches!(
            brushed.as_ref().map_err(|e| e.cause()),
            Err(flourish::Error::Cancelled)
        ),
        "{:?}",
        brushed.err()
    );
    let filled = flourish::fill(
        &shape,
        &knot,
        &FillOptions {
            cancel: Some(cancel),
            ..FillOptions::default()
        },
    );
    assert!(
        matches!(
            filled.as_ref().map_err(|e| e.cause()),
            Err(flourish::Error::Cancelled)
        ),
        "{:?}",
        filled.err()
    );
    let fresh = BrushOptions {
        cancel: Some(flourish::Cancel::new()),
        ..BrushOptions::default()
    };
    assert_eq!(
        flourish::brush(&strokes, &vine, &fresh)
            .expect("brushes")
            .to_svg(),
        flourish::brush(&strokes, &vine, &BrushOptions::default())
            .expect("brushes")
            .to_svg()
    );
}

/// A synthesis of many strokes superseded through `POST /api/cancel`
/// while it runs gets 409 well before it would have finished, and the
/// next request is served.
#[test]
fn a_running_synthesis_is_cancelled_by_a_newer_generation() {
    let server = start();
    let addr = server.addr;
    let mut body = String::from(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="800" height="1600" viewBox="0 0 800 1600">"#,
    );
    for i in 0..24 {
        let y = 40 + 64 * i;
        body.push_str(&format!(
            r#"<path d="M40 {y} C 240 {a}, 520 {b}, 760 {y}" fill="none" stroke="black" stroke-width="20"/>"#,
            a = y - 30,
            b = y + 30
        ));
    }
    body.push_str("</svg>");
    let req = serde_json::json!({"sketch": body, "mode": "brush", "style": "vine", "lane": "drawing", "generation": 1});
    let started = std::time::Instant::now();
    let big = std::thread::spawn(move || {
        let body = req.to_string();
        let head = format!(
            "POST /api/synthesize HTTP/1.1\r\nHost: {addr}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
            body.len()
        );
        let (status, reply) = exchange(addr, &head, body.as_bytes());
        (status, reply, started.elapsed())
    });
    std::thread::sleep(Duration::from_millis(300));
    let cancelled_at = started.elapsed();
    let cancel = serde_json::json!({"lane": "drawing", "generation": 2});
    assert_eq!(
        post(&server, "/api/cancel", cancel.to_string().as_bytes()).0,
        200
    );
    let (status, reply, ended) = big.join().expect("the big request");
    assert_eq!(status, 409, "{}", String::from_utf8_lossy(&reply));
    println!(
        "cancelled at {} ms, the reply came {} ms later",
        cancelled_at.as_millis(),
        (ended - cancelled_at).as_millis()
    );
    // The whole drawing, uncancelled, for comparison.
    let t = std::time::Instant::now();
    let whole = serde_json::json!({"sketch": body, "mode": "brush", "style": "vine"});
    assert_eq!(
        post(&server, "/api/synthesize", whole.to_string().as_bytes()).0,
        200
    );
    println!(
        "the same drawing uncancelled: {} ms",
        t.elapsed().as_millis()
    );
    for (want, bad) in [(400, "{\"lane\": 3}"), (400, "not json"), (405, "")] {
        let (status, _) = if want == 405 {
            get(&server, "/api/cancel")
        } else {
            post(&server, "/api/cancel", bad.as_bytes())
        };
        assert_eq!(status, want, "{bad}");
    }
}
