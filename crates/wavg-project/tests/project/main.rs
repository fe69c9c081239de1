//! The integration tests of `wavg-project` as one test binary: each file here is a module
//! (a test's name is `FILE::TEST`), so the library is linked once for all of them
//! and their tests run in parallel with one another.

mod common;
mod fallback;
mod frames;
mod properties;
mod real_meshes;
mod thin_plate;
