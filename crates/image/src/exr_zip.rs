//! OpenEXR ZIP / ZIPS output with a chosen deflate level, compressed by libdeflate.
//!
//! ZIP output is the compositor's largest single cost (docs/performance.md). The `exr` crate
//! compresses ZIP blocks with miniz_oxide at a fixed level 4; this module prepares each block
//! exactly as OpenEXR does (little-endian samples line by line and channel by channel, bytes
//! split into even and odd halves, then a byte-delta predictor, then zlib) and deflates it with
//! libdeflate at the level asked for, as OpenEXR ≥ 3.2 does (its default level is 4). Headers,
//! offset table and chunk layout stay `exr`'s own (`exr::block::write`), so the file is what
//! `exr` would write with a different deflate stream; any EXR reader decodes it.

use std::collections::BTreeMap;
use std::io::{Seek, Write};
use std::sync::{Condvar, Mutex, mpsc};

use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
use exr::block::writer::{ChunkWriter, ChunksWriter};
use exr::compression::Compression;
use exr::image::write::layers::WritableLayers;
use exr::meta::header::ImageAttributes;
use exr::prelude::{AnyChannels, FlatSamples, Layer, SmallVec};
use rayon::prelude::*;

/// OpenEXR's default zlib level for ZIP and ZIPS (`Imf::getDefaultZipCompressionLevel`).
pub const DEFAULT_ZIP_LEVEL: u32 = 4;

/// Lines per ZIP block, or `None` for a compression this module does not write.
pub fn zip_block_lines(compression: Compression) -> Option<usize> {
    match compression {
        Compression::ZIP16 => Some(16),
        Compression::ZIP1 => Some(1),
        _ => None,
    }
}

/// Writes scan-line layers (one part each) whose encoding is ZIP or ZIPS, deflating at
/// `level` (0–9). Blocks are compressed in parallel while a writer thread writes them in order,
/// with at most a window of blocks (four per thread) compressed ahead of the file.
pub fn write_zip_layers<W: Write + Seek + Send>(
    attributes: &ImageAttributes,
    layers: &[Layer<AnyChannels<FlatSamples>>],
    level: u32,
    out: W,
) -> exr::error::UnitResult {
    let mut headers: exr::meta::Headers = SmallVec::new();
    for layer in layers {
        if zip_block_lines(layer.encoding.compression).is_none() {
            return Err(exr::error::Error::NotSupported(
                "write_zip_layers needs ZIP or ZIPS compression".into(),
            ));
        }
        headers.extend(layer.infer_headers(attributes));
    }
    exr::block::write(out, headers, true, |_meta, writer| {
        for (layer_index, layer) in layers.iter().enumerate() {
            write_layer_blocks(layer_index, layer, level, writer)?;
        }
        Ok(())
    })
}

/// Compresses the blocks of one layer on the rayon pool and writes them, in order, from a
/// scoped thread: the file's writing overlaps the compression instead of stopping it.
fn write_layer_blocks<W: Write + Seek + Send>(
    layer_index: usize,
    layer: &Layer<AnyChannels<FlatSamples>>,
    level: u32,
    writer: &mut ChunkWriter<W>,
) -> exr::error::UnitResult {
    let lines_per_block = zip_block_lines(layer.encoding.compression).unwrap_or(16);
    let height = layer.size.height();
    let blocks = height.div_ceil(lines_per_block);
    let window = BlockWindow::new((rayon::current_num_threads() * 4).max(2));
    let (sender, receiver) = mpsc::channel::<(usize, exr::error::Result<Chunk>)>();
    std::thread::scope(|scope| {
        let writing = scope.spawn(|| {
            // Whatever happens, even a panic, no compressor may wait for this writer afterwards.
            let _stop = StopOnDrop(&window);
            write_in_order(writer, receiver, blocks, &window)
        });
        window
            .indices(blocks)
            .par_bridge()
            .for_each_with(sender, |sender, block| {
                let chunk = compress_block(layer_index, layer, lines_per_block, block, level);
                // A closed channel means the writer has stopped on an error it reports.
                let _ = sender.send((block, chunk));
            });
        writing.join().unwrap_or_else(|_| {
            Err(exr::error::Error::Io(std::io::Error::other(
                "the EXR block writer stopped unexpectedly",
            )))
        })
    })
}

/// Receives compressed blocks in any order and writes them in increasing order.
fn write_in_order<W: Write + Seek>(
    writer: &mut ChunkWriter<W>,
    receiver: mpsc::Receiver<(usize, exr::error::Result<Chunk>)>,
    blocks: usize,
    window: &BlockWindow,
) -> exr::error::UnitResult {
    let mut pending = BTreeMap::new();
    let mut next = 0;
    while next < blocks {
        let (block, chunk) = receiver.recv().map_err(|_| {
            exr::error::Error::Io(std::io::Error::other("a block compressor stopped"))
        })?;
        pending.insert(block, chunk?);
        while let Some(chunk) = pending.remove(&next) {
            writer.write_chunk(next, chunk)?;
            next += 1;
            window.written(next);
        }
    }
    Ok(())
}

/// How far the writer has come, so that compression runs at most `ahead` blocks before it.
struct BlockWindow {
    /// Blocks written, and whether the writer has stopped.
    state: Mutex<(usize, bool)>,
    advanced: Condvar,
    ahead: usize,
}

impl BlockWindow {
    fn new(ahead: usize) -> Self {
        Self {
            state: Mutex::new((0, false)),
            advanced: Condvar::new(),
            ahead,
        }
    }

    fn written(&self, count: usize) {
        if let Ok(mut state) = self.state.lock() {
            state.0 = count;
        }
        self.advanced.notify_all();
    }

    fn stop(&self) {
        if let Ok(mut state) = self.state.lock() {
            state.1 = true;
        }
        self.advanced.notify_all();
    }

    /// Block indices `0..blocks`, each handed out once it is within the window; none once
    /// the writer has stopped.
    fn indices(&self, blocks: usize) -> impl Iterator<Item = usize> + Send + '_ {
        (0..blocks).map_while(move |block| {
            let mut state = self.state.lock().ok()?;
            while !state.1 && block >= state.0 + self.ahead {
                state = self.advanced.wait(state).ok()?;
            }
            (!state.1).then_some(block)
        })
    }
}

/// Stops a [`BlockWindow`] when dropped.
struct StopOnDrop<'a>(&'a BlockWindow);

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        self.0.stop();
    }
}

/// One block of a layer as a chunk: its lines' bytes, OpenEXR's ZIP transform, deflated.
fn compress_block(
    layer_index: usize,
    layer: &Layer<AnyChannels<FlatSamples>>,
    lines_per_block: usize,
    block: usize,
    level: u32,
) -> exr::error::Result<Chunk> {
    let (width, height) = (layer.size.width(), layer.size.height());
    let y0 = block * lines_per_block;
    let y1 = (y0 + lines_per_block).min(height);
    let compressed_pixels_le = SCRATCH.with(|cell| {
        let scratch = &mut *cell.borrow_mut();
        block_bytes_le(&layer.channel_data.list, width, y0..y1, &mut scratch.raw);
        let raw_len = scratch.raw.len();
        let packed = deflate_block(scratch, level)?;
        // OpenEXR stores a block raw when deflate does not make it smaller.
        Ok::<_, exr::error::Error>(if packed.len() < raw_len {
            packed.to_vec()
        } else {
            scratch.raw.clone()
        })
    })?;
    Ok(Chunk {
        layer_index,
        compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
            y_coordinate: layer.attributes.layer_position.y() + y0 as i32,
            compressed_pixels_le,
        }),
    })
}

/// The uncompressed bytes of lines `lines` into `out`: per line, per channel (sorted by name,
/// as in the header), the samples in little-endian order.
fn block_bytes_le(
    channels: &[exr::prelude::AnyChannel<FlatSamples>],
    width: usize,
    lines: std::ops::Range<usize>,
    out: &mut Vec<u8>,
) {
    out.clear();
    for y in lines {
        let row = y * width..(y + 1) * width;
        for c in channels {
            match &c.sample_data {
                FlatSamples::F16(v) => {
                    for s in &v[row.clone()] {
                        out.extend_from_slice(&s.to_bits().to_le_bytes());
                    }
                }
                FlatSamples::F32(v) => {
                    for s in &v[row.clone()] {
                        out.extend_from_slice(&s.to_le_bytes());
                    }
                }
                FlatSamples::U32(v) => {
                    for s in &v[row.clone()] {
                        out.extend_from_slice(&s.to_le_bytes());
                    }
                }
            }
        }
    }
}

/// OpenEXR's ZIP transform of `scratch.raw`: even bytes then odd bytes, a byte-delta
/// predictor (`d[i] = s[i] − s[i−1] + 128`), then a zlib stream at `level` (libdeflate).
/// Returns the stream, in `scratch.packed`.
fn deflate_block(scratch: &mut BlockScratch, level: u32) -> exr::error::Result<&[u8]> {
    let BlockScratch {
        raw,
        split,
        packed,
        compressor,
    } = scratch;
    let half = raw.len().div_ceil(2);
    split.clear();
    split.extend(raw.iter().step_by(2));
    split.extend(raw.iter().skip(1).step_by(2));
    debug_assert_eq!(split.len() - split.len() / 2, half);
    let mut previous = split.first().copied().unwrap_or(0);
    for b in split.iter_mut().skip(1) {
        let current = *b;
        *b = current.wrapping_sub(previous).wrapping_add(128);
        previous = current;
    }
    let compressor = match compressor {
        Some((l, c)) if *l == level => c,
        _ => {
            let lvl = libdeflater::CompressionLvl::new(level as i32).map_err(|_| {
                exr::error::Error::NotSupported(format!("zip level {level}").into())
            })?;
            &mut compressor
                .insert((level, libdeflater::Compressor::new(lvl)))
                .1
        }
    };
    packed.resize(compressor.zlib_compress_bound(split.len()), 0);
    let n = compressor
        .zlib_compress(split, packed)
        .map_err(|e| exr::error::Error::Io(std::io::Error::other(e.to_string())))?;
    Ok(&packed[..n])
}

/// One thread's buffers for compressing blocks, reused from block to block.
#[derive(Default)]
struct BlockScratch {
    raw: Vec<u8>,
    split: Vec<u8>,
    packed: Vec<u8>,
    /// The libdeflate compressor (with its level): about 1 MB of tables, too much to
    /// allocate per block.
    compressor: Option<(u32, libdeflater::Compressor)>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<BlockScratch> = std::cell::RefCell::new(BlockScratch::default());
}

#[cfg(test)]
mod tests {
    use std::io::Cursor;

    use exr::prelude::{
        AnyChannel, Encoding, LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec,
        WritableImage, read,
    };
    use half::f16;

    use super::*;
    use exr::prelude::Image;

    /// Writes a single-layer scan-line image whose encoding is ZIP or ZIPS, deflating at `level`
    /// (0–9); see [`write_zip_layers`].
    pub fn write_zip_image<W: Write + Seek + Send>(
        image: &Image<Layer<AnyChannels<FlatSamples>>>,
        level: u32,
        out: W,
    ) -> exr::error::UnitResult {
        write_zip_layers(
            &image.attributes,
            std::slice::from_ref(&image.layer_data),
            level,
            out,
        )
    }

    /// A deterministic mix of smooth and noisy samples (noise defeats deflate in places, so
    /// both the compressed and the stored-raw block paths run).
    fn samples(n: usize, seed: u32, noisy: bool) -> Vec<f32> {
        (0..n)
            .map(|i| {
                let h = (i as u32 ^ seed).wrapping_mul(0x9e37_79b9).rotate_left(13);
                let smooth = (i % 97) as f32 / 97.0;
                if noisy {
                    f32::from_bits(h & 0x3fff_ffff)
                } else {
                    smooth + (h >> 24) as f32 / 4096.0
                }
            })
            .collect()
    }

    fn image(
        w: usize,
        h: usize,
        half: bool,
        alpha: bool,
        compression: Compression,
        noisy: bool,
    ) -> Image<Layer<AnyChannels<FlatSamples>>> {
        let data = |seed| {
            let v = samples(w * h, seed, noisy);
            if half {
                FlatSamples::F16(v.into_iter().map(f16::from_f32).collect())
            } else {
                FlatSamples::F32(v)
            }
        };
        let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
        for (k, name) in ["R", "G", "B"].iter().enumerate() {
            list.push(AnyChannel::new(*name, data(k as u32 * 7919)));
        }
        if alpha {
            list.push(AnyChannel::new("A", data(31)));
        }
        let encoding = Encoding {
            compression,
            blocks: exr::prelude::Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        Image::from_layer(Layer::new(
            (w, h),
            LayerAttributes::default(),
            encoding,
            AnyChannels::sort(list),
        ))
    }

    fn decode(bytes: Vec<u8>) -> Vec<(String, FlatSamples)> {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .expect("an EXR reader decodes the file");
        image
            .layer_data
            .channel_data
            .list
            .into_iter()
            .map(|c| (c.name.to_string(), c.sample_data))
            .collect()
    }

    #[test]
    fn every_level_type_and_block_size_round_trips_bit_exactly() {
        // 37 × 21: a last ZIP block of 5 lines; noisy data exercises the stored-raw blocks.
        for compression in [Compression::ZIP16, Compression::ZIP1] {
            for (half, alpha, noisy) in [
                (true, false, false),
                (false, true, false),
                (true, true, true),
                (false, false, true),
            ] {
                let img = image(37, 21, half, alpha, compression, noisy);
                let expected: Vec<(String, FlatSamples)> = img
                    .layer_data
                    .channel_data
                    .list
                    .iter()
                    .map(|c| (c.name.to_string(), c.sample_data.clone()))
                    .collect();
                for level in [0, 1, 4, 9] {
                    let mut out = Cursor::new(Vec::new());
                    write_zip_image(&img, level, &mut out).unwrap();
                    let got = decode(out.into_inner());
                    assert_eq!(
                        got, expected,
                        "{compression:?}, half {half}, alpha {alpha}, noisy {noisy}, level {level}"
                    );
                }
                // Same pixels as the exr crate's own ZIP writer.
                let mut theirs = Cursor::new(Vec::new());
                img.write().to_buffered(&mut theirs).unwrap();
                assert_eq!(decode(theirs.into_inner()), expected);
            }
        }
    }

    /// A file that takes `room` bytes, then fails every write.
    struct FullDisk {
        written: Cursor<Vec<u8>>,
        room: usize,
    }

    impl Write for FullDisk {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if self.written.get_ref().len() + buf.len() > self.room {
                return Err(std::io::Error::other("no space left on device"));
            }
            self.written.write(buf)
        }

        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    impl Seek for FullDisk {
        fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
            self.written.seek(pos)
        }
    }

    #[test]
    fn a_failing_write_stops_every_compressor_and_is_reported() {
        // 300 one-line blocks: far more than the window compressed ahead of the writer.
        let img = image(64, 300, false, false, Compression::ZIP1, true);
        for room in [0, 2_000, 40_000] {
            let out = FullDisk {
                written: Cursor::new(Vec::new()),
                room,
            };
            let err = write_zip_image(&img, 1, out).unwrap_err();
            assert!(err.to_string().contains("no space left"), "{room}: {err}");
        }
    }

    #[test]
    fn higher_levels_are_not_larger_and_other_compressions_are_refused() {
        let img = image(64, 48, true, false, Compression::ZIP16, false);
        let size = |level| {
            let mut out = Cursor::new(Vec::new());
            write_zip_image(&img, level, &mut out).unwrap();
            out.into_inner().len()
        };
        let (stored, fast, default, best) = (size(0), size(1), size(4), size(9));
        assert!(
            stored > fast && fast >= default && default >= best,
            "{stored} {fast} {default} {best}"
        );
        let piz = image(8, 8, true, false, Compression::PIZ, false);
        let err = write_zip_image(&piz, 4, Cursor::new(Vec::new())).unwrap_err();
        assert!(err.to_string().contains("ZIP"), "{err}");
    }
}
