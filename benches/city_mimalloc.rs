//! The whole-city benchmarks of `benches/city.rs` with mimalloc as the global allocator,
//! as the `city` example uses it:
//!
//! ```text
//! cargo bench --bench city_mimalloc [-- lod1 | metropolis | all]
//! ```
//!
//! The pipeline allocates millions of small meshes and polygons from several threads;
//! BENCHMARKS.md compares the two allocators.

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "city.rs"]
mod city;

fn main() {
    city::main();
}
