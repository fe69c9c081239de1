//! The integration tests of `wavg-serve` as one test binary: each file here is a module
//! (a test's name is `FILE::TEST`), so the library is linked once for all of them
//! and their tests run in parallel with one another.

mod api;
mod body_limits;
mod common;
mod malformed;
mod stop;
