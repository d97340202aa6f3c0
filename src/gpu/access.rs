//! Barriers derived from declared access. Every command the recorder records states what it
//! reads and writes — a dispatch through its pipeline's reflected binding access, a copy or
//! fill through its source and destination — and the recorder places a barrier only before a
//! command that reads or writes what an earlier command since the last barrier wrote, or
//! writes what one read (read-after-write, write-after-write, write-after-read). Independent
//! commands are left free to overlap on the GPU.

use ash::vk;

use super::buffer::Buffer;
use super::image::Image;
use super::pipeline::{Binding, Slot};

/// A region of device memory one command touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Resource {
    /// Bytes `start..end` of a buffer.
    Buffer { raw: u64, start: u64, end: u64 },
    /// A whole image (ocular never touches part of one).
    Image(u64),
}

impl Resource {
    pub(crate) fn buffer(b: &Buffer) -> Resource {
        Resource::buffer_range(b, 0, b.size_bytes())
    }

    pub(crate) fn buffer_range(b: &Buffer, offset: u64, size: u64) -> Resource {
        Resource::Buffer {
            raw: vk::Handle::as_raw(b.raw()),
            start: offset,
            end: offset + size,
        }
    }

    pub(crate) fn image(i: &Image) -> Resource {
        Resource::Image(vk::Handle::as_raw(i.raw()))
    }

    pub(crate) fn of_binding(binding: &Binding<'_>) -> Resource {
        match *binding {
            Binding::Buffer(b) => Resource::buffer(b),
            Binding::BufferRange(b, offset, size) => Resource::buffer_range(b, offset, size),
            Binding::Sampled(i, _) | Binding::Storage(i) => Resource::image(i),
        }
    }

    fn overlaps(&self, other: &Resource) -> bool {
        match (self, other) {
            (
                Resource::Buffer { raw, start, end },
                Resource::Buffer {
                    raw: r2,
                    start: s2,
                    end: e2,
                },
            ) => raw == r2 && start < e2 && s2 < end,
            (Resource::Image(a), Resource::Image(b)) => a == b,
            _ => false,
        }
    }
}

/// The reads and writes of the commands recorded since the last barrier.
#[derive(Default)]
pub(crate) struct Hazards {
    reads: Vec<Resource>,
    writes: Vec<Resource>,
    /// Barriers placed and commands recorded, for tests and reports.
    pub(crate) barriers: u32,
    pub(crate) commands: u32,
}

impl Hazards {
    /// Whether a command with these accesses must wait for the earlier ones.
    pub(crate) fn conflicts(&self, reads: &[Resource], writes: &[Resource]) -> bool {
        let hits = |mine: &[Resource], theirs: &[Resource]| {
            mine.iter().any(|m| theirs.iter().any(|t| m.overlaps(t)))
        };
        hits(reads, &self.writes) || hits(writes, &self.writes) || hits(writes, &self.reads)
    }

    pub(crate) fn add(&mut self, reads: &[Resource], writes: &[Resource]) {
        self.reads.extend_from_slice(reads);
        self.writes.extend_from_slice(writes);
        self.commands += 1;
    }

    /// Whether anything was recorded since the last barrier.
    pub(crate) fn pending(&self) -> bool {
        !self.reads.is_empty() || !self.writes.is_empty()
    }

    pub(crate) fn clear(&mut self) {
        self.reads.clear();
        self.writes.clear();
    }
}

/// The reads and writes of a dispatch or draw: each binding with its reflected access.
pub(crate) fn binding_access(
    bindings: &[Binding<'_>],
    slots: &[Slot],
) -> (Vec<Resource>, Vec<Resource>) {
    let (mut reads, mut writes) = (Vec::new(), Vec::new());
    for (b, slot) in bindings.iter().zip(slots) {
        let r = Resource::of_binding(b);
        if slot.access.reads() {
            reads.push(r);
        }
        if slot.access.writes() {
            writes.push(r);
        }
    }
    (reads, writes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn buf(raw: u64, start: u64, end: u64) -> Resource {
        Resource::Buffer { raw, start, end }
    }

    #[test]
    fn only_dependent_commands_wait() {
        let mut h = Hazards::default();
        h.add(&[buf(1, 0, 100)], &[buf(2, 0, 64)]);
        // Reading what the first only read, writing elsewhere: independent.
        assert!(!h.conflicts(&[buf(1, 0, 100)], &[buf(3, 0, 8)]));
        // Another range of the written buffer: independent.
        assert!(!h.conflicts(&[buf(2, 64, 128)], &[]));
        // Read after write, write after write, write after read.
        assert!(h.conflicts(&[buf(2, 32, 40)], &[]));
        assert!(h.conflicts(&[], &[buf(2, 0, 4)]));
        assert!(h.conflicts(&[], &[buf(1, 99, 200)]));
        h.add(&[], &[Resource::Image(7)]);
        assert!(h.conflicts(&[Resource::Image(7)], &[]));
        assert!(!h.conflicts(&[Resource::Image(8)], &[buf(7, 0, 1)]));
        h.clear();
        assert!(!h.pending() && !h.conflicts(&[buf(2, 0, 64)], &[buf(2, 0, 64)]));
    }
}
