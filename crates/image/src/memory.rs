//! What reading an image costs in memory, estimated from its header before any pixel is
//! decoded, so that a caller can refuse a frame that would not fit before allocating it.

use crate::PngHeader;

/// Bytes held while an image is read: `transient` only during the read (the file's bytes,
/// decoding buffers), `kept` by what the read returns.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReadMemory {
    /// Bytes held only while reading (the file, the decoder's buffers).
    pub transient: u64,
    /// Bytes kept after reading (the decoded planes).
    pub kept: u64,
}

impl ReadMemory {
    /// The most held at once.
    pub fn peak(&self) -> u64 {
        self.transient.saturating_add(self.kept)
    }

    /// Reading `channels` `f32` planes of `pixels` pixels each with
    /// [`read_exr_channels`](crate::read_exr_channels) from a file of `file_len` bytes held in
    /// memory: the file, the part's compressed blocks copied out of it (at most the file
    /// again), and the planes.
    pub fn exr_planes(file_len: u64, pixels: u64, channels: usize) -> ReadMemory {
        ReadMemory {
            transient: file_len.saturating_mul(2),
            kept: pixels.saturating_mul(4 * channels as u64),
        }
    }

    /// Reading `channels` `f32` planes of `pixels` pixels each with
    /// [`read_exr_channel_rows_from`](crate::read_exr_channel_rows_from) from a file of
    /// `file_len` bytes: the file is not held, only the part's compressed blocks (at most the
    /// file), and the planes (`pixels`: the rows decoded, at most the data window).
    pub fn exr_planes_from_file(file_len: u64, pixels: u64, channels: usize) -> ReadMemory {
        ReadMemory {
            transient: file_len,
            kept: pixels.saturating_mul(4 * channels as u64),
        }
    }

    /// Decoding a PNG of `file_len` bytes held in memory with [`decode_png`](crate::decode_png):
    /// the file and the decoder's buffers; what the caller makes of the samples is added with
    /// [`ReadMemory::keeping`].
    pub fn png(file_len: u64, header: &PngHeader) -> ReadMemory {
        ReadMemory {
            transient: file_len.saturating_add(header.decode_bytes()),
            kept: 0,
        }
    }

    /// `self` with `bytes` more kept.
    pub fn keeping(self, bytes: u64) -> ReadMemory {
        ReadMemory {
            kept: self.kept.saturating_add(bytes),
            ..self
        }
    }

    /// `self` with `bytes` more held while reading.
    pub fn with_transient(self, bytes: u64) -> ReadMemory {
        ReadMemory {
            transient: self.transient.saturating_add(bytes),
            ..self
        }
    }
}
