//! The `flexmech` command line with the built-in joint kinds (see
//! `flexmech::cli` for a binary with more).

use flexmech::model::JointRegistry;

/// mimalloc keeps the pages a run frees for its next allocations: with the
/// system's allocator a 100-step run of the 512-element cantilever took
/// 5 300 page faults, 2 400 with it, before the result files' write path
/// left out HDF5's chunk cache (docs/book/performance.md).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    flexmech::cli::main_with(JointRegistry::builtin())
}
