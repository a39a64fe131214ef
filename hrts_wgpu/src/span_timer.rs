//! GPU milliseconds between two points of a device's command stream, frame after frame: a timestamp
//! written into a command encoder at each point, the pair read back a few frames later.

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

/// Spans whose timestamps may be in flight at once.
const SLOTS: usize = 8;
/// Bytes between two slots of the resolve buffer (`QUERY_RESOLVE_BUFFER_ALIGNMENT`).
const SLOT_BYTES: u64 = 256;

const FREE: u8 = 0;
const MAPPING: u8 = 1;
const MAPPED: u8 = 2;

/// Times one span a frame: [`SpanTimer::begin`] and [`SpanTimer::end`] record its two timestamps (in
/// command buffers submitted in that order), [`SpanTimer::submitted`] follows their submission, and a later
/// `begin` collects the spans the GPU completed. A frame whose slot is still being read back goes untimed.
pub struct SpanTimer {
    /// Two timestamps a slot.
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    slots: Vec<Slot>,
    next: usize,
    /// The slot of the span being recorded, if one was free.
    current: Option<usize>,
    /// Whether the span being recorded has both timestamps.
    ended: bool,
    period_ns: f64,
    /// Completed spans not taken yet, in milliseconds, oldest first.
    completed: Vec<f64>,
}

struct Slot {
    readback: wgpu::Buffer,
    state: Arc<AtomicU8>,
}

impl SpanTimer {
    /// The timer, on a device that writes timestamps inside command encoders (`None` otherwise).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        let needed =
            wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        if !device.features().contains(needed) {
            return None;
        }
        Some(Self {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("span timer"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * SLOTS as u32,
            }),
            resolved: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("span timer resolved"),
                size: SLOT_BYTES * SLOTS as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            slots: (0..SLOTS)
                .map(|_| Slot {
                    readback: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("span timer read-back"),
                        size: 16,
                        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    }),
                    state: Arc::new(AtomicU8::new(FREE)),
                })
                .collect(),
            next: 0,
            current: None,
            ended: false,
            period_ns: f64::from(queue.get_timestamp_period()),
            completed: Vec::new(),
        })
    }

    /// Collects the spans the GPU completed, then writes the span's first timestamp into `encoder`.
    pub fn begin(&mut self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder) {
        let _ = device.poll(wgpu::PollType::Poll);
        // Oldest first: `next` is the oldest slot that may be in flight.
        for i in 0..SLOTS {
            let slot = &self.slots[(self.next + i) % SLOTS];
            if slot.state.load(Ordering::Acquire) != MAPPED {
                continue;
            }
            let ticks: Vec<u64> = slot
                .readback
                .get_mapped_range(..)
                .chunks_exact(8)
                .map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
                .collect();
            slot.readback.unmap();
            slot.state.store(FREE, Ordering::Release);
            self.completed
                .push(ticks[1].saturating_sub(ticks[0]) as f64 * self.period_ns / 1e6);
        }
        let slot = self.next;
        self.ended = false;
        self.current = (self.slots[slot].state.load(Ordering::Acquire) == FREE).then_some(slot);
        if self.current.is_some() {
            encoder.write_timestamp(&self.queries, 2 * slot as u32);
        }
    }

    /// Waits for the GPU if the next span's slot is still being read back, so that the next span is timed
    /// (the host then runs at most 8 spans ahead of the GPU).
    pub fn wait_for_slot(&self, device: &wgpu::Device) {
        if self.slots[self.next].state.load(Ordering::Acquire) == MAPPING {
            let _ = device.poll(wgpu::PollType::wait_indefinitely());
        }
    }

    /// Writes the span's last timestamp into `encoder`, and copies the pair where it can be read back.
    pub fn end(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let Some(slot) = self.current else {
            return;
        };
        self.ended = true;
        let first = 2 * slot as u32;
        let offset = SLOT_BYTES * slot as u64;
        encoder.write_timestamp(&self.queries, first + 1);
        encoder.resolve_query_set(&self.queries, first..first + 2, &self.resolved, offset);
        encoder.copy_buffer_to_buffer(&self.resolved, offset, &self.slots[slot].readback, 0, 16);
    }

    /// After the span's command buffers were submitted: reads it back once the GPU completed it (a span
    /// that was not ended is dropped).
    pub fn submitted(&mut self) {
        let Some(slot) = self.current.take().filter(|_| self.ended) else {
            return;
        };
        self.next = (slot + 1) % SLOTS;
        let state = self.slots[slot].state.clone();
        state.store(MAPPING, Ordering::Release);
        self.slots[slot]
            .readback
            .map_async(wgpu::MapMode::Read, .., move |result| {
                state.store(
                    if result.is_ok() { MAPPED } else { FREE },
                    Ordering::Release,
                );
            });
    }

    /// The spans completed since the last call, in milliseconds, oldest first.
    pub fn take(&mut self) -> Vec<f64> {
        std::mem::take(&mut self.completed)
    }
}
