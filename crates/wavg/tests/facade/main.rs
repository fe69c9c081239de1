//! The integration tests of the `wavg` facade as one test binary: each file here is a module
//! (a test's name is `FILE::TEST`), so the library is linked once for all of them
//! and their tests run in parallel with one another.

mod anchors;
mod cache;
mod errors;
mod extreme_coords;
mod readme;
mod surface;
