//! The `fretsim` command ([`fretsim::cli::main`]).

/// mimalloc instead of the system allocator: the solver makes many small allocations per step
/// (the per-evaluation point lists, maps and batches). Built without transparent huge pages
/// (the crate's `no_thp` feature) to keep the peak memory small. The library itself sets no
/// allocator; the dependency is the default feature `mimalloc`.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    fretsim::cli::main()
}
