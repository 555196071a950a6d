//! Running third-party decoders on untrusted bytes: a panic inside a decoder (a bug in the
//! dependency, reached by a corrupt file) becomes an error instead of killing the process, and
//! its message is not printed as if the program itself had crashed.

use std::cell::Cell;
use std::panic::{self, AssertUnwindSafe};
use std::sync::Once;

use crate::{Codec, ImageError};

thread_local! {
    /// Depth of nested [`catch_codec_panic`] calls on this thread.
    static IN_DECODER: Cell<u32> = const { Cell::new(0) };
}

static INSTALL_HOOK: Once = Once::new();

/// Wraps the process panic hook once: panics raised while this thread is inside
/// [`catch_codec_panic`] are silenced (they are reported as errors by the caller); every other
/// panic goes to the previous hook unchanged.
fn install_quiet_hook() {
    INSTALL_HOOK.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if IN_DECODER.with(|d| d.get()) == 0 {
                previous(info);
            }
        }));
    });
}

/// Runs `decode`, turning a panic into [`ImageError::CodecPanic`] (class `Internal`: a bug in the
/// codec, never reported as a property of the file). Use it around every call into a codec that
/// sees file bytes (png, exr), on the thread that runs it.
pub fn catch_codec_panic<T>(codec: Codec, decode: impl FnOnce() -> T) -> Result<T, ImageError> {
    install_quiet_hook();
    IN_DECODER.with(|d| d.set(d.get() + 1));
    let result = panic::catch_unwind(AssertUnwindSafe(decode));
    IN_DECODER.with(|d| d.set(d.get().saturating_sub(1)));
    result.map_err(|payload| {
        let message = if let Some(s) = payload.downcast_ref::<&str>() {
            (*s).to_string()
        } else if let Some(s) = payload.downcast_ref::<String>() {
            s.clone()
        } else {
            "unknown panic".to_string()
        };
        ImageError::CodecPanic { codec, message }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::ImageErrorKind;

    #[test]
    fn panic_becomes_error_with_message() {
        let r: Result<(), ImageError> = catch_codec_panic(Codec::Exr, || panic!("corrupt block 7"));
        let err = r.unwrap_err();
        assert!(
            matches!(&err, ImageError::CodecPanic { codec: Codec::Exr, message } if message == "corrupt block 7"),
            "{err:?}"
        );
        assert_eq!(err.kind(), ImageErrorKind::Internal);
        assert_eq!(catch_codec_panic(Codec::Png, || 5).unwrap(), 5);
    }
}
