# sunshade: the two commands of the README are `make render` and `make test`; both install what is missing first.
CARGO ?= cargo
SUNSHADE := target/release/sunshade

.PHONY: setup build render test lint models bench bench-batch bench-startup bench-shadow-cost bench-daylight docs images clean

setup:
	@./scripts/setup.sh

build: setup
	$(CARGO) build --release

# Renders the default scene, models/teapot.glb, to teapot.png.
render: build
	$(SUNSHADE) render models/teapot.glb -o teapot.png -v

# Every test (unit, GPU on lavapipe with validation layers, CPU reference, CLI), then the GPU shadow-ray tests
# on Mesa 25's lavapipe (ray queries; scripts/lavapipe-rt.sh installs it into .lavapipe-rt/ without touching the
# system). Where it cannot be installed those tests are skipped with a message, never silently.
test: setup
	@./scripts/machine.sh
	CARGO=$(CARGO) ./scripts/cargo-test-or-backtrace.sh --release --workspace
	@if rt="$$(./scripts/lavapipe-rt.sh)"; then \
		eval "$$rt"; echo "make test: the ray-query tests on $$VK_ICD_FILENAMES"; \
		SUNSHADE_REQUIRE_RAY_QUERIES=1 SUNSHADE_RAY_QUERIES=1 CARGO=$(CARGO) ./scripts/cargo-test-or-backtrace.sh --release --test shadows \
			--test cli --test measured --test startup -- gpu_ ray_quer; \
	else \
		echo "make test: SKIPPED the ray-query tests: scripts/lavapipe-rt.sh could not install Mesa 25's lavapipe (above)"; \
	fi

lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps

# Regenerates the measured figures in docs/speed.md and docs/accuracy.md (on this machine; the tables name it).
bench: build
	$(SUNSHADE) bench --repeat 5 --process-runs 5 --process-scene models/teapot.glb --update docs/speed.md
	$(SUNSHADE) bench --startup --repeat 5 --update docs/speed.md
	$(SUNSHADE) bench --shadow-cost --repeat 5 --update docs/accuracy.md
	$(SUNSHADE) bench --repeat 5 --interpolation f64,f32,device --update docs/accuracy.md
	$(SUNSHADE) bench --brdf-chart --repeat 5 --update docs/accuracy.md
	$(SUNSHADE) bench --textures --repeat 5 --update docs/textures.md
	$(SUNSHADE) bench --measured --repeat 5 --update docs/measured.md
	$(SUNSHADE) bench --pareto --repeat 5 --update docs/accuracy.md --plot docs/images/pareto.png
	eval "$$(scripts/lavapipe-rt.sh)" && $(SUNSHADE) bench --pareto models/brdfs.glb --repeat 5 --plot docs/images/pareto-brdfs.png

# Start-up: every model's whole render process, 5 processes each, with each pipeline's size and creation time
# (docs/speed.md, "Start-up").
bench-startup: build
	$(SUNSHADE) bench --startup --repeat 5 --update docs/speed.md

# What the default shadows cost against an unshadowed frame (docs/accuracy.md, "What the shadows cost").
bench-shadow-cost: build
	$(SUNSHADE) bench --shadow-cost --repeat 5 --update docs/accuracy.md

# Throughput: 30 renders as processes against one batch, and a whole render process against its frame phases.
bench-batch: build
	./scripts/bench-batch.sh 5

# A year of hourly daylight (4380 steps with the sun up) on a 100k-triangle city block at 512², in one process,
# against single frames of it (docs/daylight.md; about 40 minutes with lavapipe on 2 threads). Writes
# docs/images/district-year.png.
DISTRICT := /tmp/sunshade-district.glb
DISTRICT_VIEW := --eye 90,70,110 --target 0,0,0 --width 512 --height 512 --location 47.37,8.54,408
bench-daylight: build
	$(CARGO) run --release --example make_district -- $(DISTRICT)
	for i in 1 2 3; do $(SUNSHADE) render $(DISTRICT) $(DISTRICT_VIEW) --time 2026-06-21T15:00:00+02:00 \
		--quantity irradiance -o /tmp/sunshade-district-E.exr -v 2>&1 | grep -E '^  (render|readback)'; done
	$(SUNSHADE) render $(DISTRICT) $(DISTRICT_VIEW) --quantity irradiation --from 2026-01-01T00:00:00+01:00 \
		--to 2027-01-01T00:00:00+01:00 --step 1h -o /tmp/sunshade-district-year.exr \
		--false-color docs/images/district-year.png -v

# Regenerates docs/cli.md (the whole flag reference, from the parser) and the BRDF tables in docs/brdf.md
# (directional albedo, convergence of the sampled light integrals).
docs: build
	$(SUNSHADE) man --markdown > docs/cli.md.tmp && mv docs/cli.md.tmp docs/cli.md
	$(SUNSHADE) albedo --update docs/brdf.md

# Regenerates the pictures in README.md and docs/: one scene per kind of light, and the BRDF spheres under each light; with
# shadows where Mesa 25's lavapipe (ray queries) can be installed (scripts/lavapipe-rt.sh), else without.
images: build
	mkdir -p docs/images
	@if rt="$$(./scripts/lavapipe-rt.sh)"; then eval "$$rt"; else echo "make images: no ray queries: shadow maps"; fi; \
	for m in teapot.glb room.gltf overcast.glb sunset.glb; do \
		$(SUNSHADE) render models/$$m -o docs/images/$${m%.*}.png --width 640 --height 480 || exit 1; \
	done; \
	$(SUNSHADE) render models/room.gltf -o /tmp/sunshade-room-irradiance.exr --width 320 --height 240 \
		--quantity irradiance --false-color docs/images/room-irradiance.png -q && \
	$(SUNSHADE) render models/brdfs.glb -o docs/images/brdfs-sun.png --width 640 --height 300 \
		--sun-elevation 35 --sun-azimuth 20 && \
	$(SUNSHADE) render models/brdfs.glb -o docs/images/brdfs-disk.png --width 640 --height 300 \
		--disk-light 0,3,2:0,-1,0:0.8:2000 && \
	$(SUNSHADE) render models/brdfs.glb -o docs/images/brdfs-sky.png --width 640 --height 300 --sky-radiance 300 && \
	for m in BoxTextured/BoxTextured.glb TextureTransformTest/TextureTransformTest.gltf \
		NormalTangentMirrorTest/NormalTangentMirrorTest.glb CesiumMan/CesiumMan.glb \
		VertexColorTest/VertexColorTest.glb; do \
		n=$$(basename $${m%.*}); \
		$(SUNSHADE) render models/gltf-samples/$$m -o docs/images/sample-$$n.png --width 320 --height 240 \
			--sun-dir -1,1.2,1.5 --sky-radiance 100 -q || exit 1; \
	done; \
	$(SUNSHADE) render models/gltf-samples/AlphaBlendModeTest/AlphaBlendModeTest.glb \
		-o docs/images/sample-AlphaBlendModeTest.png --width 320 --height 240 --sun-dir -1,1.2,1.5 \
		--sky-radiance 100 --eye 0,1.6,7.5 --target 0,0.9,0 -q

# Regenerates the generated scenes in models/.
models:
	$(CARGO) run --release --example make_models

clean:
	$(CARGO) clean
