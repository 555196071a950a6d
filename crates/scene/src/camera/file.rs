//! Camera files: one camera (`camera.json`), one file per frame of an animation
//! (`camera.####.json`, the `#` run replaced by the zero-padded frame number as in `compose`),
//! or one file holding every frame (`{"frames": {"1": {…camera…}, "2": {…}}}`). A frame's
//! camera is validated when it is asked for, so that one bad frame does not stop the others.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::de::{Deserializer, MapAccess, Visitor};
use serde::{Deserialize, de};
use serde_json::Value;

use super::{Camera, CameraSpec, bad_camera};
use crate::error::SceneError;

/// Largest camera file read (a camera is a few hundred bytes; an animation file of ten
/// thousand frames a few megabytes).
pub const CAMERA_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::mib(16, "a camera file");

/// Largest camera file read, in bytes ([`CAMERA_FILE`]).
pub const MAX_CAMERA_FILE_BYTES: u64 = CAMERA_FILE.bytes;

/// Where the camera of each frame comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraSource {
    /// One camera, the same for every frame.
    One {
        /// The camera file.
        path: PathBuf,
        /// Its camera.
        camera: Camera,
    },
    /// One file per frame: `pattern` has a `#` run that the frame number replaces.
    PerFrame {
        /// The file pattern.
        pattern: PathBuf,
    },
    /// One file with a `frames` object: each frame's camera JSON, validated when asked for.
    Animation {
        /// The animation file.
        path: PathBuf,
        /// Each frame's camera JSON.
        frames: BTreeMap<u32, Value>,
    },
}

impl CameraSource {
    /// Opens `path`: a path with a `#` run is one file per frame (nothing is read until a frame
    /// is asked for); any other file is read now, and is one camera (validated now) or an
    /// animation (`{"frames": …}`; each frame validated when asked for).
    pub fn open(path: &Path) -> Result<CameraSource, SceneError> {
        if glassdb_io::is_frame_pattern(path) {
            return Ok(CameraSource::PerFrame {
                pattern: path.to_path_buf(),
            });
        }
        let text = read_camera_text(path, None)?;
        Ok(match parse_camera_json(&text, path, None)? {
            CameraJson::One(spec) => CameraSource::One {
                path: path.to_path_buf(),
                camera: Camera::from_spec(&spec, path, None)?,
            },
            CameraJson::Frames(frames) => CameraSource::Animation {
                path: path.to_path_buf(),
                frames,
            },
        })
    }

    /// The frames an animation file holds, in order; `None` for the other sources.
    pub fn frames(&self) -> Option<Vec<u32>> {
        match self {
            CameraSource::Animation { frames, .. } => Some(frames.keys().copied().collect()),
            _ => None,
        }
    }

    /// Whether each frame may have its own camera (per-frame files or an animation file).
    pub fn is_animated(&self) -> bool {
        !matches!(self, CameraSource::One { .. })
    }

    /// The file the camera of `frame` is read from (the pattern itself without a frame).
    pub fn path(&self, frame: Option<u32>) -> PathBuf {
        match (self, frame) {
            (CameraSource::One { path, .. } | CameraSource::Animation { path, .. }, _) => {
                path.clone()
            }
            (CameraSource::PerFrame { pattern }, Some(f)) => {
                glassdb_io::expand_frame_pattern(pattern, f).unwrap_or_else(|_| pattern.clone())
            }
            (CameraSource::PerFrame { pattern }, None) => pattern.clone(),
        }
    }

    /// The validated camera of `frame`; `None` asks for the one camera of a single-camera file
    /// (an error for per-frame files and animation files).
    pub fn camera(&self, frame: Option<u32>) -> Result<Camera, SceneError> {
        match (self, frame) {
            (CameraSource::One { camera, .. }, _) => Ok(*camera),
            (CameraSource::PerFrame { pattern }, None) => Err(SceneError::CameraNeedsFrame {
                path: pattern.clone(),
                what: "names one file per frame (a # run for the frame number)".into(),
            }),
            (CameraSource::Animation { path, frames }, None) => Err(SceneError::CameraNeedsFrame {
                path: path.clone(),
                what: format!(
                    "holds the cameras of frames {}",
                    frame_ranges(frames.keys())
                ),
            }),
            (CameraSource::PerFrame { .. }, Some(f)) => {
                let path = self.path(Some(f));
                let text = read_camera_text(&path, Some(f))?;
                match parse_camera_json(&text, &path, Some(f))? {
                    CameraJson::One(spec) => Camera::from_spec(&spec, &path, Some(f)),
                    CameraJson::Frames(_) => Err(bad_camera(&path, Some(f))(
                        "holds a \"frames\" object, but a per-frame file holds one camera".into(),
                    )),
                }
            }
            (CameraSource::Animation { path, frames }, Some(f)) => {
                let value = frames
                    .get(&f)
                    .ok_or_else(|| SceneError::MissingCameraFrame {
                        path: path.clone(),
                        frame: f,
                        why: format!(
                            "has no frame {f} (its frames: {})",
                            frame_ranges(frames.keys())
                        ),
                    })?;
                let spec = CameraSpec::deserialize(value).map_err(|e| {
                    bad_camera(path, Some(f))(glassdb_io::bounded_message(&e.to_string()))
                })?;
                Camera::from_spec(&spec, path, Some(f))
            }
        }
    }
}

/// A camera file's content: one camera, or an animation's frames.
enum CameraJson {
    One(Box<CameraSpec>),
    Frames(BTreeMap<u32, Value>),
}

/// Reads a camera file of at most [`MAX_CAMERA_FILE_BYTES`]; a per-frame file that does not
/// exist is a missing frame.
fn read_camera_text(path: &Path, frame: Option<u32>) -> Result<String, SceneError> {
    let read_err = |source: glassdb_io::InputError| match frame {
        Some(f)
            if matches!(&source, glassdb_io::InputError::Io(e)
                if e.kind() == std::io::ErrorKind::NotFound) =>
        {
            SceneError::MissingCameraFrame {
                path: path.to_path_buf(),
                frame: f,
                why: "does not exist".into(),
            }
        }
        _ => SceneError::Read {
            path: path.to_path_buf(),
            source,
        },
    };
    glassdb_io::read_input_string(path, CAMERA_FILE).map_err(read_err)
}

/// Parses a camera file: an object with a `frames` key is an animation, anything else one
/// camera. Malformed JSON is named by line and column.
fn parse_camera_json(
    text: &str,
    path: &Path,
    frame: Option<u32>,
) -> Result<CameraJson, SceneError> {
    let bad = bad_camera(path, frame);
    let json_err = |e: serde_json::Error| {
        bad(glassdb_io::bounded_message(&format!(
            "line {}, column {}: {e}",
            e.line(),
            e.column()
        )))
    };
    let value: Value = serde_json::from_str(text).map_err(json_err)?;
    let animated = matches!(&value, Value::Object(m) if m.contains_key("frames"));
    drop(value);
    if !animated {
        return serde_json::from_str(text)
            .map(|spec| CameraJson::One(Box::new(spec)))
            .map_err(json_err);
    }
    let file: AnimationFile = serde_json::from_str(text).map_err(json_err)?;
    if file.frames.0.is_empty() {
        return Err(bad(
            "\"frames\" is empty: an animation needs at least one frame".into(),
        ));
    }
    let mut frames: BTreeMap<u32, Value> = BTreeMap::new();
    let mut keys: BTreeMap<u32, String> = BTreeMap::new();
    for (key, value) in file.frames.0 {
        let number = (!key.is_empty() && key.bytes().all(|b| b.is_ascii_digit()))
            .then(|| key.parse::<u32>().ok())
            .flatten()
            .ok_or_else(|| {
                bad(format!(
                    "\"frames\" key {} is not a frame number (0 to {})",
                    glassdb_io::quoted(&key),
                    u32::MAX
                ))
            })?;
        if let Some(first) = keys.get(&number) {
            return Err(bad(format!(
                "frame {number} is given twice in \"frames\" (keys {} and {})",
                glassdb_io::quoted(first),
                glassdb_io::quoted(&key)
            )));
        }
        keys.insert(number, key);
        frames.insert(number, value);
    }
    Ok(CameraJson::Frames(frames))
}

/// `{"frames": {…}}`, nothing else.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnimationFile {
    frames: FrameEntries,
}

/// The `frames` object in file order, keys kept as written so that duplicates are caught.
struct FrameEntries(Vec<(String, Value)>);

impl<'de> Deserialize<'de> for FrameEntries {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<FrameEntries, D::Error> {
        struct Entries;
        impl<'de> Visitor<'de> for Entries {
            type Value = FrameEntries;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an object of frame number → camera")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<FrameEntries, A::Error> {
                let mut out = Vec::new();
                while let Some(key) = map.next_key::<String>()? {
                    if out.len() as u64 >= glassdb_io::frames::MAX_FRAMES {
                        return Err(de::Error::custom("more than a million frames"));
                    }
                    let value = map.next_value::<Value>()?;
                    out.push((key, value));
                }
                Ok(FrameEntries(out))
            }
        }
        d.deserialize_map(Entries)
    }
}

/// Frames as ranges, `1-3, 7, 9-12`, the first few only.
pub(crate) fn frame_ranges<'a>(frames: impl IntoIterator<Item = &'a u32>) -> String {
    const SHOWN: usize = 8;
    let mut ranges: Vec<(u32, u32)> = Vec::new();
    for &f in frames {
        match ranges.last_mut() {
            Some((_, end)) if end.checked_add(1) == Some(f) => *end = f,
            _ => ranges.push((f, f)),
        }
    }
    let mut parts: Vec<String> = ranges
        .iter()
        .take(SHOWN)
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}-{b}")
            }
        })
        .collect();
    if ranges.len() > SHOWN {
        parts.push("…".into());
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_compress() {
        assert_eq!(frame_ranges(&[1, 2, 3, 7, 9, 10]), "1-3, 7, 9-10");
        assert_eq!(frame_ranges(&[]), "");
        let many: Vec<u32> = (0..40).map(|k| 2 * k).collect();
        assert!(frame_ranges(&many).ends_with(", …"));
    }
}
