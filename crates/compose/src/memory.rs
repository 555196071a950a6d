//! The memory a frame holds, estimated from the inputs' headers before any pixel is decoded,
//! and the limit it must stay under: one frame above the limit is refused (naming the estimate,
//! the limit and the largest shares); frames of a sequence take their estimate from one
//! shared budget, so frames in flight together never add up to more than the limit.
//!
//! What is counted, per frame (docs/compose.md, "Memory"):
//! - decoding: what every input's read keeps (passes as `f32` planes, the mask as ids,
//!   planes, cos θ and coverage), and what a read holds only while it runs for the
//!   transmission pass, the mask and as many reflection passes as are decoded at once
//!   ([`decoding_at_once`], the largest counted): the transmission pass's and the mask's file,
//!   read whole, and an EXR's compressed blocks copied out of it, or a PNG's decoding buffer
//!   (an upper bound for a transmission EXR whose other channels are not carried: it is read
//!   by seeking, one block per decoding thread at a time); a reflection EXR is read by
//!   seeking, counted as its compressed blocks (at most its file);
//!   the transmission file's other channels in their own sample types when they are carried
//!   over. A reflection pass counts the planes of its whole data window (a crop: its
//!   rectangle), an upper bound: decoding keeps only the blocks of its plane's glass rows,
//!   known once the mask is decoded, after the frame's memory is reserved;
//! - compositing: the decoded inputs, and the mask placed in the frame when its data window
//!   differs from the transmission pass's;
//! - encoding: the composite and the carried channels, a half-float copy of one plane (half
//!   EXR), the compressor's window of blocks, or the PNG samples and file.
//!
//! The frame's estimate is the largest of the three stages, plus an eighth for what the
//! allocator keeps and [`PROCESS_OVERHEAD`] for the program itself ([`with_overhead`]).

use std::path::Path;
use std::sync::{Condvar, Mutex};

/// What the program holds besides the frame: its code and libraries, the threads' stacks and
/// the registry's tables (7 MiB in all for a tiny frame), with room to spare.
pub const PROCESS_OVERHEAD: u64 = 32 << 20;

/// What the allocator keeps besides the frame's buffers, as a share of them (1/8): freed
/// blocks it has not given back (glibc's malloc, raising its mmap threshold after large frees,
/// serves later blocks from its heap and keeps them; a 4K half-float frame peaked 11 % above
/// its counted buffers, 1 % with a fixed threshold; docs/performance.md).
pub const ALLOCATOR_SHARE: u64 = 8;

/// The estimate of a frame whose largest stage holds `buffers` bytes.
pub fn with_overhead(buffers: u64) -> u64 {
    buffers
        .saturating_add(buffers / ALLOCATOR_SHARE)
        .saturating_add(PROCESS_OVERHEAD)
}

/// How many reflection passes are decoded at once: one per thread of the pool (at least 1).
pub fn decoding_at_once() -> usize {
    rayon::current_num_threads().max(1)
}

/// The default limit of the library, 8 GiB (the `compose` binary lowers it to half the
/// machine's memory where that is less).
pub const DEFAULT_MAX_MEMORY: u64 = 8 << 30;

/// One share of a frame's memory, for messages: what it is and its bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemoryItem {
    /// What it is.
    pub what: String,
    /// Its bytes.
    pub bytes: u64,
}

/// A frame's estimated memory.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct MemoryEstimate {
    /// The most the frame holds at once (the largest stage).
    pub total: u64,
    /// The shares, largest first: each input's decoding (file, buffers, decoded planes), the
    /// carried channels, the mask placed in the frame, the output's encoding buffers.
    pub items: Vec<MemoryItem>,
    /// Of which the transmission file's other channels, carried over into an EXR output.
    pub carried: u64,
}

/// Bytes as people read them: `812 B`, `3.4 KiB`, `512 MiB`, `1.5 GiB` (powers of 1024).
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
    if bytes < 1024 {
        return format!("{bytes} B");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    let text = if value >= 100.0 {
        format!("{value:.0}")
    } else {
        format!("{value:.1}")
    };
    format!("{} {}", text.trim_end_matches(".0"), UNITS[unit])
}

/// `path`'s file name (the whole path when it has none), for short messages.
pub(crate) fn file_label(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

/// The frames' shared memory: a frame reserves its estimate before decoding and gives it back
/// when it is done; a reservation that does not fit beside those held waits for them.
#[derive(Debug)]
pub struct MemoryBudget {
    limit: u64,
    held: Mutex<u64>,
    released: Condvar,
}

/// Bytes reserved from a [`MemoryBudget`], given back when dropped.
#[derive(Debug)]
pub struct Reservation<'a> {
    budget: &'a MemoryBudget,
    bytes: u64,
}

impl MemoryBudget {
    /// A budget of `limit` bytes, none held.
    pub fn new(limit: u64) -> MemoryBudget {
        MemoryBudget {
            limit,
            held: Mutex::new(0),
            released: Condvar::new(),
        }
    }

    /// The limit.
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// Reserves `bytes`, waiting while other reservations leave too little. A reservation of
    /// more than the whole limit is granted when nothing else is held (callers refuse those
    /// first).
    pub fn reserve(&self, bytes: u64) -> Reservation<'_> {
        let mut held = self.held.lock().unwrap_or_else(|e| e.into_inner());
        while *held > 0 && held.saturating_add(bytes) > self.limit {
            held = self.released.wait(held).unwrap_or_else(|e| e.into_inner());
        }
        *held = held.saturating_add(bytes);
        Reservation {
            budget: self,
            bytes,
        }
    }

    /// Bytes reserved now.
    pub fn held(&self) -> u64 {
        *self.held.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Drop for Reservation<'_> {
    fn drop(&mut self) {
        let mut held = self.budget.held.lock().unwrap_or_else(|e| e.into_inner());
        *held = held.saturating_sub(self.bytes);
        self.budget.released.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_read_as_people_read_them() {
        assert_eq!(format_bytes(812), "812 B");
        assert_eq!(format_bytes(3 * 1024 + 400), "3.4 KiB");
        assert_eq!(format_bytes(512 << 20), "512 MiB");
        assert_eq!(format_bytes(3 << 29), "1.5 GiB");
        assert_eq!(format_bytes(8 << 30), "8 GiB");
        assert_eq!(format_bytes((32 << 20) + 5), "32 MiB");
        assert_eq!(format_bytes(100 << 20), "100 MiB");
    }

    #[test]
    fn reservations_wait_for_room_and_never_exceed_the_limit() {
        let budget = MemoryBudget::new(100);
        let peak = std::sync::atomic::AtomicU64::new(0);
        std::thread::scope(|s| {
            for bytes in [60, 60, 30, 100, 10] {
                let (budget, peak) = (&budget, &peak);
                s.spawn(move || {
                    let _r = budget.reserve(bytes);
                    peak.fetch_max(budget.held(), std::sync::atomic::Ordering::SeqCst);
                    std::thread::sleep(std::time::Duration::from_millis(5));
                });
            }
        });
        assert!(peak.into_inner() <= 100);
        assert_eq!(budget.held(), 0);
        // Alone, a reservation of more than the limit is granted (callers refuse it first).
        drop(budget.reserve(150));
    }
}
