# Convenience wrappers over cargo (install just with `cargo install just`).
# The two commands a fresh machine needs are plain cargo: see README.md.

# The seed case: full model, 24 V, 50 Hz, 0.2 s → out/demo
run:
    cargo run --release -p hd-cli -- simulate --out out/demo

test:
    cargo test --workspace

# Solver and sweep benchmarks (criterion), then the scaling script
bench:
    cargo bench -p hd-model
    cargo bench -p hd-sweep
    benches/sweep_scaling.sh

lint:
    cargo fmt --all -- --check
    cargo clippy --workspace --all-targets -- -D warnings

fmt:
    cargo fmt --all

# Every shipped study in studies/ → out/studies/<name>
studies:
    cargo build --release -p hd-cli
    for f in studies/*.toml; do n=$(basename "$f" .toml); rm -rf "out/studies/$n"; ./target/release/hdw study "$f" --out "out/studies/$n" || exit 1; done

# End-to-end test of deploy/slurm on a one-node Slurm cluster (root; installs slurm-wlm and
# munge if missing). HDW=path/to/hdw skips the release build: `HDW=target/debug/hdw just slurm-test`
slurm-test:
    tests/slurm/run.sh
