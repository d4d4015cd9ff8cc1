# Verbs for a newcomer. `make test` is the README's test command.
.PHONY: help install test lint bench paper docs readme-figure
help:
	@echo "make install  - pip install the package with its test tools"
	@echo "make test     - every test, Rust and Python (what .ci/run runs)"
	@echo "make lint     - cargo fmt/clippy, ruff, mypy, stubtest"
	@echo "make bench    - throughput and call overhead benchmarks"
	@echo "make paper    - reproduce the founding paper into paper-results/"
	@echo "make docs     - the documentation site into docs/_build/html (warnings are errors)"
	@echo "make readme-figure - the README's figure, docs/_static/frf_impact_damper.png"

install:
	pip install ".[test]"

test:
	pip install ".[test]" && cargo test --workspace && python -m pytest

lint:
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	ruff format --check python tests benchmarks
	ruff check python tests benchmarks
	mypy
	python -m mypy.stubtest vibroimpact._core

bench:
	python benchmarks/bench_system.py
	cargo run --release -p vibroimpact-core --example system_throughput
	python benchmarks/bench_steps.py
	python benchmarks/bench_scipy.py
	cargo run --release -p vibroimpact-core --example throughput

paper:
	vibroimpact paper

docs:
	python -m sphinx -W --keep-going -b html docs docs/_build/html

# The README's figure: the frequency response its example draws, kept small in the repository.
readme-figure:
	vibroimpact sweep examples/frf_impact_damper.toml --plot docs/_static/frf_impact_damper.png
