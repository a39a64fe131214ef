//! The registry of live contexts. A handle names a slot and the generation of the context created in it,
//! so the handle of a destroyed context never matches a later context that reuses the slot (an address
//! could be reused by the allocator and pass as live).

use crate::context::Context;
use crate::types::HrtsContext;
use std::ffi::CString;
use std::sync::{Arc, Mutex, MutexGuard};

/// A live context and the message of the last call on it.
pub(crate) struct Entry {
    /// The context, used by one thread at a time.
    pub(crate) context: Mutex<Context>,
    /// The message of the last call on the context if it failed. Locked only to set it or copy it out, so
    /// that any thread can read it while another uses the context.
    last_error: Mutex<Option<CString>>,
}

impl Entry {
    fn last_error_slot(&self) -> MutexGuard<'_, Option<CString>> {
        self.last_error
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// A copy of the message of the last call on the context (empty if it succeeded).
    pub(crate) fn last_error(&self) -> CString {
        self.last_error_slot().clone().unwrap_or_default()
    }

    /// Keeps the outcome of a call on the context: its message if it failed, `None` if it succeeded.
    pub(crate) fn set_last_error(&self, message: Option<CString>) {
        *self.last_error_slot() = message;
    }
}

/// One slot: its current generation and the context created with it, if live.
struct Slot {
    generation: u32,
    context: Option<Arc<Entry>>,
}

static SLOTS: Mutex<Vec<Slot>> = Mutex::new(Vec::new());

// A handle carries a 32-bit generation and a 32-bit slot number in one pointer-sized value.
const _: () = assert!(usize::BITS >= 64, "handles need 64-bit pointers");

/// The first slot free for a new context: empty, with a generation left. A slot whose generation is
/// exhausted is retired, never reused, so that no handle ever names two contexts.
fn free_slot(slots: &[Slot]) -> Option<usize> {
    slots
        .iter()
        .position(|s| s.context.is_none() && s.generation < u32::MAX)
}

/// The handle of slot `index` at `generation`: `generation << 32 | (index + 1)`, never NULL and never
/// dereferenced.
fn handle(index: usize, generation: u32) -> *mut HrtsContext {
    ((u64::from(generation) << 32) | (index as u64 + 1)) as usize as *mut HrtsContext
}

/// The slot index and generation a handle names.
fn parts(handle: *const HrtsContext) -> Option<(usize, u32)> {
    let raw = handle as usize as u64;
    let index = (raw & 0xFFFF_FFFF).checked_sub(1)?;
    Some((index as usize, (raw >> 32) as u32))
}

fn slots() -> MutexGuard<'static, Vec<Slot>> {
    SLOTS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Registers a new context and returns its handle.
pub(crate) fn register(context: Context) -> *mut HrtsContext {
    let mut slots = slots();
    let context = Some(Arc::new(Entry {
        context: Mutex::new(context),
        last_error: Mutex::new(None),
    }));
    match free_slot(&slots) {
        Some(i) => {
            let slot = &mut slots[i];
            slot.generation += 1;
            slot.context = context;
            handle(i, slot.generation)
        }
        None => {
            slots.push(Slot {
                generation: 0,
                context,
            });
            handle(slots.len() - 1, 0)
        }
    }
}

/// The live context a handle names.
pub(crate) fn lookup(handle: *const HrtsContext) -> Option<Arc<Entry>> {
    let (index, generation) = parts(handle)?;
    let slots = slots();
    let slot = slots.get(index).filter(|s| s.generation == generation)?;
    slot.context.clone()
}

/// Unregisters the context a handle names; returns it if it was live.
pub(crate) fn unregister(handle: *const HrtsContext) -> Option<Arc<Entry>> {
    let (index, generation) = parts(handle)?;
    let mut slots = slots();
    let slot = slots
        .get_mut(index)
        .filter(|s| s.generation == generation)?;
    slot.context.take()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_name_slot_and_generation() {
        for (index, generation) in [(0, 0), (5, 1), (70_000, u32::MAX)] {
            let h = handle(index, generation);
            assert!(!h.is_null());
            assert_eq!(parts(h), Some((index, generation)));
        }
        assert_eq!(parts(std::ptr::null()), None);
        assert_eq!(parts(0x1_0000_0000usize as *const HrtsContext), None);
    }

    #[test]
    fn a_slot_whose_generation_is_exhausted_is_never_reused() {
        let empty = |generation| Slot {
            generation,
            context: None,
        };
        assert_eq!(free_slot(&[empty(u32::MAX), empty(7)]), Some(1));
        assert_eq!(free_slot(&[empty(u32::MAX - 1)]), Some(0));
        assert_eq!(free_slot(&[empty(u32::MAX)]), None);
    }
}
