# Quick start: `make run` renders the default scene to umbrage.png; `make test` runs every test
# with Vulkan validation on. Both install what is missing first (scripts/deps.sh).
export PATH := $(HOME)/.cargo/bin:$(PATH)
CARGO ?= cargo

.PHONY: deps deps-tests drivers lint run view test bench conform conform-docs conform-matrix deqp-ci doc clean fuzz

# The loader, a driver and the tools; then Mesa lavapipe 25.0.7 in .drivers/ (ray query,
# Vulkan 1.4) beside the system's driver, for `--method rayquery` (a warning if it cannot be had).
deps:
	@./scripts/deps.sh
	@./scripts/drivers.sh install 25.0.7 >/dev/null || echo "warning: Mesa lavapipe 25.0.7 not installed (scripts/drivers.sh install 25.0.7): no --method rayquery here" >&2

# What the tests and the conformance runs need as well (off Debian: the validation layer too),
# lavapipe 25.0.7, which tests/engine/rayquery.rs and tests/engine/mesh.rs run on when the system's driver has
# no ray query or mesh shaders, lavapipe 22.3.6, a known driver without mesh shaders for
# tests/cli/cli.rs (and the quick matrix's), and SwiftShader, which tests/engine/hard_cases.rs, the quick
# matrix and the minimal example run on.
deps-tests:
	@./scripts/deps.sh --tests
	./scripts/drivers.sh install 22.3.6 25.0.7 swiftshader

# Three Mesa lavapipe versions (Vulkan 1.0, 1.3, 1.4) and SwiftShader in .drivers/, beside the
# system's; select one with eval "$$(scripts/drivers.sh env 25.0.7)" (scripts/drivers.sh --help).
drivers:
	./scripts/drivers.sh install 20.3.5 22.3.6 25.0.7 swiftshader

run: deps
	$(CARGO) run -- render

# The interactive window (needs a display; docs/view.md): the animated stress scene.
view: deps
	$(CARGO) run --release -- view --scene stress

# Every test of the workspace with validation on, the quick conformance matrix on three Mesa
# lavapipes (scripts/drivers.sh installs them into .drivers/), the doc examples, and the engine
# crate an engine embeds built alone, documented with warnings denied, and run as
# examples/minimal.rs (crates/umbrage-minimal: the engine and nothing else).
test: deps-tests lint
	./scripts/fetch-assets.sh || true
	UMBRAGE_VALIDATION=1 $(CARGO) test --workspace --all-targets
	./scripts/conform-matrix.sh --quick
	$(CARGO) test --workspace --doc
	$(CARGO) build -p umbrage --lib
	UMBRAGE_VALIDATION=1 $(CARGO) run -p umbrage-minimal --example minimal
	eval "$$(./scripts/drivers.sh env swiftshader)" && UMBRAGE_VALIDATION=1 $(CARGO) run -p umbrage-minimal --example minimal
	$(MAKE) doc

# Formatting and lints of every crate (Cargo.toml's [workspace.lints]: every unsafe block and
# unsafe fn documented), warnings denied.
lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

doc:
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc -p umbrage --no-deps --no-default-features

bench: deps
	$(CARGO) bench

# The fuzz generators of tests/fuzz/ in release, FUZZ_CASES cases each (4 generators plus
# 1/20 as many raw-byte OBJ files: >= 1,000,000 cases in all), the counts printed per generator.
FUZZ_CASES ?= 250000
fuzz: deps
	UMBRAGE_FUZZ_CASES=$(FUZZ_CASES) $(CARGO) test -p umbrage --release --test fuzz -- --nocapture

conform: deps-tests
	UMBRAGE_VALIDATION=1 $(CARGO) run -- conform --out conform-report --junit conform-report/junit.xml

# deqp-runner (crates.io, pinned) drives the suite on lavapipe 22.3.6 and SwiftShader against
# conform/'s baselines, with an injected crash, an injected hang and three shards
# (docs/conform/driver-ci.md).
deqp-ci: deps-tests
	./scripts/deqp-ci.sh

# Regenerates this device's report in docs/conform/ (DEVICE_DOC names it: lavapipe, or a GPU's name).
DEVICE_DOC ?= lavapipe
conform-docs: deps-tests
	UMBRAGE_VALIDATION=1 $(CARGO) run -- conform --out target/conform-docs --junit target/conform-docs/junit.xml \
	  || [ -f target/conform-docs/conform.md ]  # a driver's failures are part of its report
	cp target/conform-docs/conform.md docs/conform/$(DEVICE_DOC).md

# The driver matrix: the full suite on lavapipe 20.3.5 / 22.3.6 / 25.0.7 and llvmpipe's
# switches, side by side in docs/conform/drivers.md (explanations: docs/conform/drivers-notes.md).
conform-matrix: deps-tests
	./scripts/conform-matrix.sh

clean:
	$(CARGO) clean
