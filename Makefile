# sunshade: the two commands of the README are `make render` and `make test`; both install what is missing first.
CARGO ?= cargo
SUNSHADE := target/release/sunshade

.PHONY: setup build render test lint models bench clean

setup:
	@./scripts/setup.sh

build: setup
	$(CARGO) build --release

# Renders the default scene, models/teapot.glb, to teapot.png.
render: build
	$(SUNSHADE) render models/teapot.glb -o teapot.png -v

# Every test (unit, GPU on lavapipe with validation layers, CPU reference, CLI).
test: setup
	$(CARGO) test --release

lint:
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings

# Regenerates the measured figures in README.md and docs/accuracy.md (on this machine; the tables name it).
bench: build
	$(SUNSHADE) bench --repeat 5 --process-runs 5 --process-scene models/teapot.glb --update README.md
	$(SUNSHADE) bench --repeat 5 --interpolation f64,f32,device --update docs/accuracy.md

# Regenerates the generated scenes in models/.
models:
	$(CARGO) run --release --example make_models

clean:
	$(CARGO) clean
