# edo-city: the two commands a fresh machine needs are `make run` and `make test`.

CARGO ?= cargo

.PHONY: cityjson-deps faketime-deps run test test-cluster test-future lint bench crowd-fd real real-cut textures fixtures clean pictures bad-input viewer-deps gis-deps blender-deps

## Build the tool and the city of the bundled example data into out/.
run:
	$(CARGO) run --release -- build fixtures/kyoto-small --out out

## Unit, property, end-to-end and doc tests; the glTF validator and the browser test need
## the viewer's npm packages, the GeoPackage tests GDAL, the crowd's clip Blender, the city
## model's test cjio (each installed first when missing). Every test binary runs once, under
## faketime on the first 29 February a year or more ahead, so a test that passes only on
## the day it was written fails (doc tests need rustc, which hangs under faketime: they run
## on today's date).
test: viewer-deps gis-deps blender-deps cityjson-deps faketime-deps
	bash scripts/test-future.sh
	$(CARGO) test --doc

## The viewer's npm packages (three.js, 3d-tiles-renderer, gltf-validator, playwright-core),
## exactly as viewer/package-lock.json pins them, and Debian's chromium for the browser test.
viewer-deps:
	bash scripts/viewer-deps.sh

## cjio (PyPI) in target/cjio-venv, with which tests/cityjson.rs reads the city model.
cityjson-deps:
	bash scripts/cityjson-deps.sh

## Debian's blender, whose glTF importer tests/crowd_clip.rs runs on the walkers' clip.
blender-deps:
	bash scripts/blender-deps.sh

## Debian's gdal-bin and python3-gdal, with which tests/gpkg.rs reads plan.gpkg.
gis-deps:
	bash scripts/gis-deps.sh

## Debian's faketime, under which `make test` runs the suite.
faketime-deps:
	bash scripts/faketime-deps.sh

## The test binaries alone under faketime, as `make test` runs them (without the doc tests).
test-future: faketime-deps
	bash scripts/test-future.sh

## Formatting and lints, as CI runs them.
lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --all-targets -- -D warnings

REAL ?= ../shared/data/real
# The release binary, wherever cargo puts it (CARGO_TARGET_DIR is honoured).
BIN ?= $(or $(CARGO_TARGET_DIR),target)/release/edo-city

## Build every real data set of $(REAL) with its example parameter file into out/real/.
real:
	$(CARGO) build --release
	$(BIN) build $(REAL)/chino_plateau_devpermit --params params/examples/chino.toml --out out/real/chino
	$(BIN) build $(REAL)/osaka_plateau --params params/examples/osaka.toml --out out/real/osaka
	$(BIN) build $(REAL)/osaka_plateau --params params/examples/osaka-lonlat.toml --out out/real/osaka-lonlat
	$(BIN) build $(REAL)/kyoto_plateau_related --params params/examples/kyoto.toml --out out/real/kyoto
	$(BIN) build $(REAL)/swellendam_osm --params params/examples/swellendam.toml --out out/real/swellendam

## Cut fixtures/real from the full sets of $(REAL) (pyshp in target/cut-venv): the real data
## the tests read in a clone with nothing beside it (fixtures/real/README.md).
real-cut:
	python3 -m venv target/cut-venv
	target/cut-venv/bin/pip install --quiet pyshp==3.1.9
	rm -rf fixtures/real/*/
	target/cut-venv/bin/python scripts/cut_real.py $(REAL) fixtures/real

## Whole-Kyoto scale: 30,052 synthetic lots, three builds, per-stage timings.
bench:
	bash scripts/bench.sh

## Our crowd's speed against density, next to JuPedSim and Weidmann (1993): the tables of
## docs/crowds.md and docs/pictures/crowd-fd.png (JuPedSim and PedPy in a venv it makes).
crowd-fd:
	bash scripts/crowd_fd.sh

## The cluster path on a real Slurm: a throw-away single-node cluster (installs Debian's
## slurm-wlm and munge when missing; needs root), the sbatch array of deploy/slurm/ and its
## merge, checked byte for byte against a full build; every daemon stopped after.
test-cluster:
	bash scripts/test-cluster.sh

## Redraw the texture library (the PNGs are committed).
textures:
	$(CARGO) run --release --example make_textures

## Render every template alone into docs/templates/ and the people of a street into
## docs/people.png (needs f3d and xvfb-run).
pictures:
	scripts/render_templates.sh

## Rewrite the corpus of broken inputs tests/bad_input/ from tests/common/corpus.rs.
bad-input:
	EDO_CITY_WRITE_CORPUS=1 $(CARGO) test --test bad_input the_committed_corpus_is_what_its_script_makes

## Regenerate the example data (lots.csv is written by hand on top of it).
fixtures:
	$(CARGO) run --release -- synth fixtures/kyoto-small --lots 400 --seed 9 --force

clean:
	rm -rf out target
