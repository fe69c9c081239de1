//! Build support, not published, with no code: its `Cargo.toml` names the features the
//! whole workspace turns on in its dependencies. The crates built apart from the workspace
//! (`wavg-py` by maturin, `wavg-fuzz`, the quickstart outside the workspace) depend on it,
//! so cargo resolves their dependencies as for `cargo test --workspace` and reuses that
//! build's artifacts instead of compiling faer and the numeric crates again.

#![forbid(unsafe_code)]
