//! The integration tests of `wavg-apps` as one test binary: each file here is a module
//! (a test's name is `FILE::TEST`), so the library is linked once for all of them
//! and their tests run in parallel with one another.

mod figure_correspond;
mod remesh;
mod render_scale;
mod transfer;
