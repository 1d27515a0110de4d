//! A whole mixed sketch decorated in one go (`flourish decorate`), and the
//! single modes' `--keep-sketch`: every element that is not decorated stays
//! (by id, in drawing order), every query is decorated in place of its
//! element, and the ornament lands where the mode alone puts it.

use flourish::{DecorateOptions, Decoration, Library, PatternOptions, Sketch, StyleOptions};
use resvg::usvg;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;

fn flourish() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flourish"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("decorate");
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    dir.join(name)
}

/// A card: a title, an embedded picture, a plain frame (no paint), a
/// stroke inside a rotated group, a stroke and a filled shape that name
/// their styles, and a filled circle that takes the default.
const CARD: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="320" height="200">
  <text id="title" x="160" y="20" font-size="14" fill="#333">Greetings</text>
  <image id="photo" x="280" y="160" width="4" height="4" href="data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg=="/>
  <rect id="frame" x="4" y="4" width="312" height="192" fill="none" stroke="none"/>
  <g id="tilted" transform="translate(30 40) rotate(8)" stroke="#000" stroke-width="10" fill="none">
    <path id="swoosh" d="M0 0 C 60 -30 120 30 180 0"/>
  </g>
  <path id="vine-line" d="M30 170 C 90 140 150 190 200 160" stroke="#000" stroke-width="14" fill="none" data-style="vine"/>
  <circle id="sun" cx="250" cy="90" r="34" fill="#000"/>
  <ellipse id="leaf" cx="90" cy="110" rx="40" ry="18" fill="#000" data-style="stipple"/>
</svg>"##;

/// Every element id of an SVG text, with its tag name.
fn ids(svg: &str) -> BTreeMap<String, String> {
    let doc = usvg::roxmltree::Document::parse(svg).expect("well-formed output");
    doc.descendants()
        .filter_map(|n| {
            Some((
                n.attribute("id")?.to_string(),
                n.tag_name().name().to_string(),
            ))
        })
        .collect()
}

fn decorate_card() -> (Sketch, flourish::Output) {
    let lib = Library::shipped();
    let sketch = Sketch::from_svg(CARD.as_bytes()).expect("the card parses");
    let load = StyleOptions::default();
    let stipple = lib.load("stipple", &load).expect("stipple");
    let knot = lib.load("knot", &load).expect("knot");
    let named = lib.load_every_named(&sketch, &load).expect("named styles");
    assert_eq!(named.keys().collect::<Vec<_>>(), ["stipple", "vine"]);
    let styles = Decoration {
        strokes: Some(&stipple),
        regions: Some(&knot),
        named: &named,
    };
    let out = flourish::decorate(&sketch, styles, &DecorateOptions::default())
        .expect("the card decorates");
    (sketch, out)
}

#[test]
fn decorate_keeps_every_other_element_and_decorates_every_query() {
    let (sketch, out) = decorate_card();
    let svg = out.to_svg();
    let before = ids(CARD);
    let after = ids(&svg);
    // Each query's element became a group of ornament under the same id.
    let queries: Vec<&str> = sketch.queries.iter().map(|q| q.id.as_str()).collect();
    assert_eq!(queries, ["swoosh", "vine-line", "sun", "leaf"]);
    for q in &queries {
        assert_eq!(after.get(*q).map(String::as_str), Some("g"), "{q} in {svg}");
    }
    for g in &out.document.groups {
        assert!(!g.shapes.is_empty(), "{} is decorated", g.id);
    }
    // Everything else is kept as it was.
    for (id, tag) in &before {
        if !queries.contains(&id.as_str()) {
            assert_eq!(after.get(id), Some(tag), "{id} kept");
        }
    }
    // In drawing order: the title before the ornament, the circle's
    // pattern before the leaf's.
    let at = |id: &str| svg.find(&format!("id=\"{id}\"")).expect(id);
    assert!(at("title") < at("swoosh") && at("swoosh") < at("vine-line"));
    assert!(at("sun") < at("leaf"));
    // The text the output keeps is not reported as left out.
    assert!(
        out.warnings.iter().all(|w| !w.contains("text")),
        "{:?}",
        out.warnings
    );
    // The result renders.
    flourish::preview_png(&svg).expect("the decorated card renders");
}

/// The ornament of a stroke inside a rotated group lands where the mode
/// alone draws it: the group undoes the element's placement.
#[test]
fn ornament_lands_where_the_mode_alone_puts_it() {
    let (_, out) = decorate_card();
    let composed =
        usvg::Tree::from_str(&out.to_svg(), &usvg::Options::default()).expect("the output parses");
    let only = Sketch::from_svg(
        CARD.replace(r#" data-style="vine""#, "")
            .replace(r#" data-style="stipple""#, "")
            .as_bytes(),
    )
    .expect("parses");
    let stipple = Library::shipped()
        .load("stipple", &StyleOptions::default())
        .expect("stipple");
    let alone = flourish::pattern(&only, &stipple, &PatternOptions::default()).expect("pattern");
    let group = alone
        .document
        .groups
        .iter()
        .find(|g| g.id == "swoosh")
        .expect("the swoosh's group");
    let mut want = kurbo::Rect::new(f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for s in &group.shapes {
        want = want.union(kurbo::Shape::bounding_box(&s.path));
    }
    let node = composed.node_by_id("swoosh").expect("the swoosh's group");
    let got = node.abs_bounding_box();
    for (a, b) in [
        (got.left() as f64, want.x0),
        (got.top() as f64, want.y0),
        (got.right() as f64, want.x1),
        (got.bottom() as f64, want.y1),
    ] {
        assert!((a - b).abs() < 0.05, "got {got:?}, want {want:?}");
    }
}

#[test]
fn keep_sketch_lays_a_single_mode_over_its_sketch() {
    let sketch = tmp("card.svg");
    // Pattern decorates every shape; vine is a brush style.
    std::fs::write(&sketch, CARD.replace(r#" data-style="vine""#, "")).expect("write the card");
    let out = tmp("card-pattern.svg");
    let run = flourish()
        .args(["pattern", "--style", "stipple", "--keep-sketch", "-o"])
        .arg(&out)
        .arg(&sketch)
        .output()
        .expect("runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        !String::from_utf8_lossy(&run.stderr).contains("text"),
        "the kept text is not reported as left out"
    );
    let after = ids(&std::fs::read_to_string(&out).expect("written"));
    for id in ["title", "photo", "frame", "tilted", "swoosh", "sun"] {
        assert!(after.contains_key(id), "{id} in {after:?}");
    }
    assert_eq!(after["swoosh"], "g");
    // Without it, only the ornament.
    let run = flourish()
        .args(["pattern", "--style", "stipple", "-o"])
        .arg(&out)
        .arg(&sketch)
        .output()
        .expect("runs");
    assert!(run.status.success());
    let after = ids(&std::fs::read_to_string(&out).expect("written"));
    assert!(!after.contains_key("title") && after.contains_key("swoosh"));
}

#[test]
fn decorate_refuses_a_style_of_the_wrong_kind_as_usage() {
    let sketch = tmp("card-kind.svg");
    std::fs::write(&sketch, CARD).expect("write the card");
    let out = tmp("card-kind-out.svg");
    let run = flourish()
        .args(["decorate", "--strokes", "knot", "-o"])
        .arg(&out)
        .arg(&sketch)
        .output()
        .expect("runs");
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("--strokes") && err.contains("fill style"),
        "{err}"
    );
    assert!(!out.exists(), "no output written");
}

/// A brush style named on a filled shape leaves the shape as drawn, with
/// a warning; a shape whose id is given twice still gets its ornament
/// (after the rest, as it has no one place).
#[test]
fn shapes_without_a_place_or_a_fitting_style() {
    let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100">
      <rect id="box" x="10" y="10" width="50" height="50" fill="#000" data-style="vine"/>
      <path id="twice" d="M10 80 H190" stroke="#000" stroke-width="12" fill="none"/>
      <path id="twice" d="M10 95 H190" stroke="#000" stroke-width="4" fill="none"/>
    </svg>"##;
    let sketch = Sketch::from_svg(svg.as_bytes()).expect("parses");
    let lib = Library::shipped();
    let load = StyleOptions::default();
    let stipple = lib.load("stipple", &load).expect("stipple");
    let named = lib.load_every_named(&sketch, &load).expect("named");
    let styles = Decoration {
        strokes: Some(&stipple),
        regions: None,
        named: &named,
    };
    let out = flourish::decorate(&sketch, styles, &DecorateOptions::default()).expect("decorates");
    assert!(
        out.warnings
            .iter()
            .any(|w| w.contains("box") && w.contains("kept as drawn")),
        "{:?}",
        out.warnings
    );
    let text = out.to_svg();
    assert!(text.contains(r#"<rect id="box""#), "the box is kept");
    // Both originals are kept and both ornaments follow them.
    assert_eq!(text.matches(r#"<path id="twice""#).count(), 2);
    assert_eq!(text.matches(r#"<g id="twice""#).count(), 2, "{text}");
    let last_original = text.rfind(r#"<path id="twice""#).expect("kept");
    assert!(text.find(r#"<g id="twice""#).expect("ornament") > last_original);
}
