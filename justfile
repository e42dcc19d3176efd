# Convenience wrappers over cargo (install just with `cargo install just`).
# The two commands a fresh machine needs are plain cargo: see README.md.

# The seed case: full model, 24 V, 50 Hz, 0.2 s → out/demo
run:
    cargo run --release -p hd-cli -- simulate --out out/demo

test:
    cargo test --workspace

bench:
    cargo bench -p hd-model

lint:
    cargo fmt --all -- --check
    cargo clippy --workspace --all-targets -- -D warnings

fmt:
    cargo fmt --all

# Every shipped study in studies/ → out/studies/<name>
studies:
    cargo build --release -p hd-cli
    for f in studies/*.toml; do ./target/release/hdw study "$f" --out "out/studies/$(basename "$f" .toml)"; done
