//! The integration tests of `wavg-mesh` as one test binary: each file here is a module
//! (a test's name is `FILE::TEST`), so the library is linked once for all of them
//! and their tests run in parallel with one another.

mod analyze_bruteforce;
mod data_bad;
mod data_meshes;
mod deprecated_names;
mod gltf_hostile;
mod gltf_read;
mod gltf_write;
mod hostile;
mod io_formats;
mod odd_inputs;
mod ply_layouts;
mod properties;
mod repair;
mod topology_basic;
