# flourish — the project's entry points. See README.md.
CARGO ?= cargo
BIN := target/release/flourish
OUT := out

.PHONY: demo test gallery golden bench lint deps clean fuzz-smoke corpus browser-deps browser-test serve load-test

# Everything the tests need that cargo does not install: potrace, the
# reference tracer the trace tests compare against (Debian package).
deps:
	@if command -v potrace >/dev/null 2>&1; then \
	  echo "potrace: $$(command -v potrace)"; \
	else \
	  echo "installing potrace (Debian package) for the comparison tests"; \
	  (apt-get update -qq && apt-get install -y -qq potrace) || \
	  (sudo apt-get update -qq && sudo apt-get install -y -qq potrace) || \
	  { echo "make: potrace could not be installed: install the Debian package potrace" >&2; exit 1; }; \
	fi

# Brush sketches (the refinement sketch is drawn over s-curve.svg, not brushed).
BRUSH_SKETCHES = $(filter-out %-refine.svg,$(wildcard samples/brush/*.svg))

# The main job on the shipped samples: traces and patterns, with previews, into out/.
demo:
	$(CARGO) build --release
	mkdir -p $(OUT)/trace/png $(OUT)/trace/svg $(OUT)/pattern
	$(BIN) trace samples/trace/*.png --out-dir $(OUT)/trace/png --preview $(OUT)/trace/png
	$(BIN) trace samples/trace/*.svg --out-dir $(OUT)/trace/svg --preview $(OUT)/trace/svg
	$(BIN) trace samples/trace/two-colour.svg --layers -o $(OUT)/trace/two-colour-layers.svg --preview $(OUT)/trace/two-colour-layers.png
	for style in hatching stipple flowers brushmarks; do \
	  for s in samples/pattern/*.svg; do \
	    n=$$(basename $$s .svg); \
	    $(BIN) pattern --style $$style $$s -o $(OUT)/pattern/$$n-$$style.svg --preview $(OUT)/pattern/$$n-$$style.png || exit 1; \
	  done; \
	done
	mkdir -p $(OUT)/fill
	for style in knot scales; do \
	  for s in samples/fill/circle.svg samples/fill/star.svg samples/fill/letter.svg samples/fill/frame.svg samples/fill/combed.svg; do \
	    n=$$(basename $$s .svg); \
	    $(BIN) fill --style $$style $$s -o $(OUT)/fill/$$n-$$style.svg --preview $(OUT)/fill/$$n-$$style.png || exit 1; \
	  done; \
	done
	for style in vine scroll doodle; do \
	  mkdir -p $(OUT)/brush/$$style $(OUT)/brush/$$style-art-brush; \
	  $(BIN) brush --style $$style $(BRUSH_SKETCHES) --out-dir $(OUT)/brush/$$style --preview $(OUT)/brush/$$style || exit 1; \
	  $(BIN) brush --art-brush --style $$style $(BRUSH_SKETCHES) --out-dir $(OUT)/brush/$$style-art-brush --preview $(OUT)/brush/$$style-art-brush || exit 1; \
	done
	$(BIN) brush --style vine samples/brush/s-curve.svg --refine samples/brush/s-curve-refine.svg -o $(OUT)/brush/s-curve-refined.svg --preview $(OUT)/brush/s-curve-refined.png
	mkdir -p $(OUT)/decorate
	$(BIN) decorate --strokes vine --regions knot samples/decorate/card.svg -o $(OUT)/decorate/card.svg --preview $(OUT)/decorate/card.png
	@echo "demo outputs (SVG + preview PNG) are in $(OUT)/"

# The whole test suite, built once with the test profile (optimized: see
# [profile.test]); the examples' binaries are built too, for
# tests/examples.rs.
test: deps browser-deps
	$(CARGO) build --profile test --workspace --all-targets
	$(CARGO) test --workspace --tests
	$(MAKE) browser-test

# What the browser tests of `flourish serve` need: Debian's chromium and
# node, and playwright-core from npm at the version package-lock.json pins.
browser-deps:
	@command -v npm >/dev/null 2>&1 || \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq nodejs npm) || \
	  { echo "make: install the Debian packages nodejs and npm" >&2; exit 1; }
	@[ -x /usr/bin/chromium ] || \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium) || \
	  { echo "make: install the Debian package chromium" >&2; exit 1; }
	cd tests/browser && npm ci --no-audit --no-fund --loglevel=error

# The page of `flourish serve` in headless chromium (tests/browser/): pen
# strokes, results against the command line, undo, another one, erase,
# fill, import and export, a malformed request; prints the latencies.
# UPDATE_SCREENSHOTS=1 rewrites docs/serve-*.png.
browser-test: browser-deps
	$(CARGO) build --profile test --bin flourish
	cd tests/browser && FLOURISH_BIN=$(CURDIR)/target/debug/flourish npm test

# 20 clients drawing brush strokes at once for 30 s against `flourish
# serve` on the loopback interface: fails on an error, a request over 5 s
# or a peak resident memory over 2 GB; prints latencies and memory.
load-test:
	$(CARGO) build --release --bin flourish
	node tests/browser/load.mjs

# The painting page on http://127.0.0.1:8080/ (release build).
serve:
	$(CARGO) build --release --bin flourish
	$(BIN) serve

# Every mode on the third-party art of ../shared/art (and the shipped
# styles), measured against each issue's thresholds, with contact sheets
# and a report in out/gallery/. Fails on a shortfall that is not listed in
# src/gallery/shortfalls.txt, on a listed one that got worse, and on a
# listed one that is now met. FLOURISH_GALLERY=fill (or a style name)
# runs only the matching cases.
gallery:
	@test -d ../shared/art || { echo "gallery: ../shared/art is missing"; exit 1; }
	$(CARGO) test --lib gallery::gallery -- --ignored --nocapture

# Regenerate the golden files; review the diff before committing.
golden:
	UPDATE_GOLDEN=1 $(CARGO) test --test golden
	git status --short golden/

# Criterion benchmarks of every pipeline, then the side-by-side with potrace
# (whole commands, the release binary against potrace, pairwise).
bench: deps
	$(CARGO) bench
	$(CARGO) build --release
	$(CARGO) run --release -p flourish-tools --bin compare_potrace

lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

clean:
	rm -rf $(OUT) golden/.failed

# The readers under libFuzzer (cargo-fuzz on the nightly toolchain, which
# the target installs): the sketch SVG reader, style.toml, exemplar files
# and the picture decoders, FUZZ_SECONDS each (default 60) from the seeds
# in fuzz/seeds/, with a fixed libFuzzer seed. A crash stops here, its
# input in fuzz/artifacts/.
# A fixed sample of CORPUS_COUNT real drawings (default 200; the Debian
# package openclipart-svg, which the target installs) through every
# command: each run succeeds with a valid SVG or fails in one line; a
# panic, an abort, a hang or an invalid output fails the target. The
# table (ok / clean error / other, times, peak memory) is printed and
# written to out/corpus/report.md.
CORPUS_COUNT ?= 200
OPENCLIPART = /usr/share/openclipart/svg
corpus:
	@[ -d $(OPENCLIPART) ] || { command -v apt-get >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -q openclipart-svg >/dev/null; } || \
	  { echo "corpus: install the Debian package openclipart-svg"; exit 1; }
	$(CARGO) build --release -p flourish -p flourish-tools --bin flourish --bin corpus
	target/release/corpus --dir $(OPENCLIPART) --count $(CORPUS_COUNT) --flourish target/release/flourish --out out/corpus

FUZZ_SECONDS ?= 60
FUZZ_TARGETS = sketch_svg style_toml exemplar raster
fuzz-smoke:
	@command -v cargo-fuzz >/dev/null 2>&1 || $(CARGO) install cargo-fuzz --locked
	cd fuzz && $(CARGO) +nightly fuzz build -O
	cd fuzz && for t in $(FUZZ_TARGETS); do \
	  mkdir -p corpus/$$t && \
	  $(CARGO) +nightly fuzz run -O $$t corpus/$$t seeds/$$t -- \
	    -seed=1 -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=2048 -timeout=30 -max_len=65536 || exit 1; \
	done
