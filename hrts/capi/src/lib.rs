//! The plugin's shared and static C libraries: every `hrts_*` function of the `hrts` crate, with the plugin's
//! counting allocator as the global allocator, so that `hrts_get_memory_stats` counts the plugin's host
//! memory and `hrts_set_allocation_callbacks` can route it. A Rust program linking the `hrts` rlib
//! keeps its own allocator.

pub use hrts::*;

#[global_allocator]
static ALLOCATOR: hrts::CountingAllocator = hrts::CountingAllocator;
