# sunshade: the two commands of the README are `make render` and `make test`; both install what is missing first.
CARGO ?= cargo
SUNSHADE := target/release/sunshade

.PHONY: setup build render test lint models bench images clean

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

# Regenerates the pictures in README.md: one scene per kind of light.
images: build
	mkdir -p docs/images
	for m in teapot.glb room.gltf overcast.glb sunset.glb; do \
		$(SUNSHADE) render models/$$m -o docs/images/$${m%.*}.png --width 640 --height 480 || exit 1; \
	done

# Regenerates the generated scenes in models/.
models:
	$(CARGO) run --release --example make_models

clean:
	$(CARGO) clean
