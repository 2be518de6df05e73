# The two commands of the README. Both run the set-up first; it is quick once done.
#   make demo   set up, build, and run the main job on the shipped defaults
#   make test   set up, build, and run every test (the Rust crates', then the Python package's)
# Extra arguments for the demo: make demo ARGS="--distance 9 --seed 4"

CARGO ?= cargo
ARGS ?=

.PHONY: demo test lint setup

demo: setup
	$(CARGO) run --release -p dexcube-cli -- demo $(ARGS)

test: setup
	$(CARGO) test --release --workspace
	./scripts/test-python

lint: setup
	$(CARGO) fmt --all --check
	$(CARGO) clippy --release --workspace --all-targets -- -D warnings

setup:
	@./scripts/setup
