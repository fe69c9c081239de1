//! The integration tests of the `wavg` command (`wavg-cli`) as one test binary: each file here is a module
//! (a test's name is `FILE::TEST`), so the library is linked once for all of them
//! and their tests run in parallel with one another.

mod anchors;
mod bench_load;
mod bench_project;
mod cache;
mod cli_docs;
mod common;
mod completions;
mod demo;
mod doc_sizes;
mod docs_blocks;
mod exit_codes;
mod forward_inverse;
mod gltf;
mod gltf_blender;
mod gltf_outputs;
mod info;
mod interrupted;
mod json_keys;
mod maps;
mod mesh_arg;
mod missing_answers;
mod morph;
mod npy_stream;
mod outputs;
mod pipes;
mod precompute;
mod remesh;
mod render;
mod repair;
mod serve;
mod spline;
mod subdivide;
mod threads;
mod transfer_texture;
mod version;
