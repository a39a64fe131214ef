//! Deferred destruction for frames in flight: GPU objects replaced while earlier frames may still use them
//! are held until those frames completed.

/// The most frames in flight a pipeline supports: how many frames' objects may be held at once.
pub const MAX_FRAMES_IN_FLIGHT: u32 = 8;

/// Objects retired at a frame, held until every frame up to that one completed on the GPU.
pub struct RetireQueue<T> {
    held: Vec<(u64, T)>,
}

impl<T> Default for RetireQueue<T> {
    fn default() -> Self {
        Self { held: Vec::new() }
    }
}

impl<T> RetireQueue<T> {
    /// Holds `item`, which the recordings of frames up to `last_used_frame` may use.
    pub fn retire(&mut self, last_used_frame: u64, item: T) {
        self.held.push((last_used_frame, item));
    }

    /// Drops what only frames up to `completed` used (`None`: no frame is known to have completed).
    pub fn release_completed(&mut self, completed: Option<u64>) {
        if let Some(done) = completed {
            self.held.retain(|(last_used, _)| *last_used > done);
        }
    }

    /// How many objects are held.
    pub fn len(&self) -> usize {
        self.held.len()
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.held.is_empty()
    }
}

/// The frames known to have completed when frame `frame` is recorded with at most `frames_in_flight` frames
/// in flight: every frame up to `frame - frames_in_flight` (none while that is negative).
pub fn completed_before(frame: u64, frames_in_flight: u32) -> Option<u64> {
    frame.checked_sub(u64::from(frames_in_flight.max(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_are_held_until_their_frames_completed() {
        let mut q = RetireQueue::default();
        q.retire(4, "a");
        q.retire(6, "b");
        q.release_completed(None);
        assert_eq!(q.len(), 2);
        q.release_completed(completed_before(7, 3)); // frames <= 4 completed
        assert_eq!(q.held, vec![(6, "b")]);
        q.release_completed(completed_before(8, 3)); // frames <= 5
        assert_eq!(q.len(), 1);
        q.release_completed(completed_before(9, 3)); // frames <= 6
        assert!(q.is_empty());
    }

    #[test]
    fn nothing_has_completed_in_the_first_frames() {
        assert_eq!(completed_before(0, 3), None);
        assert_eq!(completed_before(2, 3), None);
        assert_eq!(completed_before(3, 3), Some(0));
        assert_eq!(completed_before(5, 1), Some(4));
        assert_eq!(completed_before(5, 0), Some(4), "0 counts as 1");
    }
}
