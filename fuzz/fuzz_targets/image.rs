//! PNG and OpenEXR through the one reader: headers, every channel of every part, the exact
//! read used to carry channels over, and the text attributes. Pixel limit kept small so that a
//! valid huge header is refused rather than allocated.
#![no_main]
use glassdb_image::{ImageFile, open_image, read_exr_exact, read_exr_text_attributes};
use libfuzzer_sys::fuzz_target;

const MAX_PIXELS: u64 = 1 << 20;

fuzz_target!(|data: &[u8]| {
    if let Ok(ImageFile::Exr(exr)) = open_image(data, MAX_PIXELS) {
        for (k, part) in exr.parts().iter().enumerate() {
            let all: Vec<usize> = (0..part.channels.len()).collect();
            let _ = exr.read_channels(k, &all);
        }
        let _ = glassdb_image::choose_rgb_layer(exr.parts(), None);
        let _ = read_exr_exact(data, MAX_PIXELS);
        let _ = read_exr_text_attributes(data);
    }
});
