//! wavg's timing scripts and experiments, one binary each in `src/bin/`; run one with
//! `cargo run --release -p wavg-bench --bin NAME -- ARGS` or `cargo xtask bench NAME ARGS`.
//! Not published; the figures they produce are in `BENCHMARKS.md`.

#![forbid(unsafe_code)]
