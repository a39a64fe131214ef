//! The plugin's shared and static C libraries: every `hrts_*` function of `plugin_api`, with the plugin's
//! counting allocator as the global allocator, so that `hrts_get_memory_stats` counts the plugin's host
//! memory and `hrts_set_allocation_callbacks` can route it. A Rust program linking `plugin_api`'s rlib
//! keeps its own allocator.

pub use hrts_plugin::*;

#[global_allocator]
static ALLOCATOR: hrts_plugin::CountingAllocator = hrts_plugin::CountingAllocator;
