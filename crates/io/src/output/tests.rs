//! Atomic and staged outputs against the file system: failures, links, devices, signals.

use super::*;
use crate::ErrorChain;

/// A file larger than [`SyncingFile::SYNC_EVERY`], with a seek back over written bytes
/// (as an EXR's offset table is written last), lands exactly as written.
#[test]
fn a_large_file_written_with_syncs_and_a_seek_back_is_exact() {
    use std::io::{Seek, SeekFrom};
    let (dir, [path]) = scratch(["big.bin"]);
    let len = SyncingFile::SYNC_EVERY as usize * 2 + 12_345;
    let expected: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
    write_atomic(&path, |w| {
        w.write_all(&[0; 8])?;
        w.write_all(&expected[8..])?;
        w.seek(SeekFrom::Start(0))?;
        w.write_all(&expected[..8])
    })
    .unwrap();
    assert!(std::fs::read(&path).unwrap() == expected);
    assert_eq!(names(dir.path()), ["big.bin"]);
}

/// A new temporary directory and the paths of `names` in it (not created).
fn scratch<const N: usize>(names: [&str; N]) -> (tempfile::TempDir, [PathBuf; N]) {
    let dir = tempfile::tempdir().unwrap();
    let paths = names.map(|name| dir.path().join(name));
    (dir, paths)
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn failed_producer_leaves_target_untouched() {
    let (dir, [target]) = scratch(["out.txt"]);
    std::fs::write(&target, b"old").unwrap();
    let r = write_atomic(&target, |w| {
        w.write_all(b"partial")?;
        Err(std::io::Error::other("producer failed"))
    });
    assert!(matches!(r, Err(OutputError::Write { .. })));
    assert_eq!(std::fs::read(&target).unwrap(), b"old");
    assert_eq!(names(dir.path()), ["out.txt"], "temporary file left");
    assert!(
        !registry::live_temporaries()
            .iter()
            .any(|p| p.starts_with(dir.path())),
        "a removed temporary file is still recorded"
    );
}

#[test]
fn missing_or_unusable_directory_is_named_and_each_cause_printed_once() {
    let err = write_bytes_atomic(Path::new("/nonexistent-dir-glassdb/x.json"), b"{}").unwrap_err();
    assert!(
        matches!(err, OutputError::MissingDirectory { .. }),
        "{err:?}"
    );
    // A directory that exists but takes no new files (even for root): the OS reason once.
    let target = Path::new("/proc/self/x.json");
    if target.parent().is_some_and(Path::is_dir) {
        let err = write_bytes_atomic(target, b"{}").unwrap_err();
        let text = ErrorChain(&err).to_string();
        assert!(
            text.starts_with("cannot create a temporary file beside /proc/self/x.json: "),
            "{text}"
        );
        assert_eq!(text.matches("(os error").count(), 1, "{text}");
    }
}

#[test]
fn success_replaces_target() {
    let (dir, [target]) = scratch(["out.txt"]);
    write_bytes_atomic(&target, b"new").unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), b"new");
    assert_eq!(names(dir.path()), ["out.txt"]);
}

#[cfg(unix)]
#[test]
fn new_output_is_not_private_and_replaced_output_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt;
    let (dir, [fresh]) = scratch(["fresh.txt"]);
    write_bytes_atomic(&fresh, b"x").unwrap();
    let mode = std::fs::metadata(&fresh).unwrap().permissions().mode() & 0o777;
    // Any usual umask (022, 002, 077 aside) leaves the owner read+write; the private
    // temporary-file mode 0600 must not leak unless the umask itself asks for it.
    assert_eq!(mode & 0o600, 0o600, "mode {mode:o}");
    let kept = dir.path().join("kept.txt");
    std::fs::write(&kept, b"old").unwrap();
    std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
    write_bytes_atomic(&kept, b"new").unwrap();
    let mode = std::fs::metadata(&kept).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o640, "mode {mode:o}");
}

#[test]
fn missing_directory_is_an_error_naming_the_path() {
    let r = write_bytes_atomic(Path::new("/nonexistent-dir-glassdb/x.json"), b"{}");
    let msg = r.unwrap_err().to_string();
    assert!(msg.contains("/nonexistent-dir-glassdb/x.json"), "{msg}");
}

#[test]
fn output_equal_to_input_is_refused() {
    let (dir, [a]) = scratch(["a.exr"]);
    std::fs::write(&a, b"x").unwrap();
    let dotted = dir.path().join(".").join("a.exr");
    assert!(same_file_as(&dotted, &[a.as_path()]).is_some());
    let b = dir.path().join("b.exr");
    assert!(same_file_as(&b, &[a.as_path()]).is_none());
}

#[cfg(unix)]
#[test]
fn inputs_are_matched_through_links_and_spellings() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let a = dir.path().join("sub/a.dat");
    std::fs::write(&a, b"x").unwrap();
    let hard = dir.path().join("hard.dat");
    std::fs::hard_link(&a, &hard).unwrap();
    let soft = dir.path().join("soft.dat");
    std::os::unix::fs::symlink(&a, &soft).unwrap();
    let dotted = dir.path().join("sub/../sub/./a.dat");
    for out in [&hard, &soft, &dotted] {
        let input = same_file_as(out, &[a.as_path()]).unwrap();
        let e = OutputError::OutputIsInput {
            path: out.to_path_buf(),
            input: input.to_path_buf(),
        };
        assert!(
            e.to_string().starts_with(&format!(
                "refusing to overwrite the input file {}",
                a.display()
            )),
            "{e}"
        );
    }
    // A new name beside an input that does not exist yet either: compared by path.
    let new = dir.path().join("sub/new.dat");
    let new_dotted = dir.path().join("sub/../sub/new.dat");
    assert!(same_file_as(&new_dotted, &[new.as_path()]).is_some());
}

#[cfg(unix)]
#[test]
fn outputs_that_are_not_regular_files_are_refused_and_kept() {
    use std::os::unix::fs::FileTypeExt;
    let e = write_bytes_atomic(Path::new("/dev/null"), b"x").unwrap_err();
    assert_eq!(
        e.to_string(),
        "cannot write /dev/null: it is a character device; an output must be a regular \
         file or a new name"
    );
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );
    let (dir, [sub]) = scratch(["sub"]);
    std::fs::create_dir(&sub).unwrap();
    let e = write_bytes_atomic(&sub, b"x").unwrap_err();
    assert!(
        matches!(
            e,
            OutputError::NotAFile {
                kind: FileKind::Directory,
                ..
            }
        ),
        "{e:?}"
    );
    let e = write_bytes_atomic(Path::new("/dev/stdout"), b"x").unwrap_err();
    assert!(
        matches!(
            e,
            OutputError::NotAFile {
                kind: FileKind::DescriptorLink,
                ..
            }
        ),
        "{e:?}"
    );
    let fifo = dir.path().join("pipe");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let e = write_bytes_atomic(&fifo, b"x").unwrap_err();
        assert!(e.to_string().contains("a FIFO"), "{e}");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    }
    assert!(
        !names(dir.path()).iter().any(|n| n.starts_with(TEMP_PREFIX)),
        "{:?}",
        names(dir.path())
    );
}

#[cfg(unix)]
#[test]
fn a_link_replaced_is_never_followed() {
    let (dir, [outside]) = scratch(["outside.txt"]);
    std::fs::write(&outside, b"kept").unwrap();
    let inside = dir.path().join("folder");
    std::fs::create_dir(&inside).unwrap();
    let link = inside.join("viewer.css");
    std::os::unix::fs::symlink(&outside, &link).unwrap();
    let dangling = inside.join("index.html");
    std::os::unix::fs::symlink(dir.path().join("made-outside.html"), &dangling).unwrap();
    let mut staged = StagedOutput::new();
    staged.write_bytes_replacing_link(&link, b"css").unwrap();
    staged
        .write_bytes_replacing_link(&dangling, b"html")
        .unwrap();
    staged.commit().unwrap();
    assert_eq!(std::fs::read(&outside).unwrap(), b"kept");
    assert!(!dir.path().join("made-outside.html").exists());
    for (path, bytes) in [(&link, &b"css"[..]), (&dangling, &b"html"[..])] {
        let meta = std::fs::symlink_metadata(path).unwrap();
        assert!(meta.is_file(), "{path:?} is still a link");
        assert_eq!(std::fs::read(path).unwrap(), bytes);
    }
    // A folder in the way is still refused.
    let mut staged = StagedOutput::new();
    let e = staged
        .write_bytes_replacing_link(dir.path(), b"x")
        .unwrap_err();
    assert!(matches!(e, OutputError::NotAFile { .. }), "{e:?}");
}

#[cfg(unix)]
#[test]
fn symbolic_links_are_written_through() {
    let (dir, [real]) = scratch(["real.txt"]);
    std::fs::write(&real, b"old").unwrap();
    let link = dir.path().join("link.txt");
    std::os::unix::fs::symlink("real.txt", &link).unwrap();
    write_bytes_atomic(&link, b"new").unwrap();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read(&real).unwrap(), b"new");
    // A dangling link: its target is created.
    let dangling = dir.path().join("dangling.txt");
    std::os::unix::fs::symlink("made.txt", &dangling).unwrap();
    write_bytes_atomic(&dangling, b"made").unwrap();
    assert_eq!(std::fs::read(dir.path().join("made.txt")).unwrap(), b"made");
    // A link to a device: refused, the device kept.
    let null = dir.path().join("null");
    std::os::unix::fs::symlink("/dev/null", &null).unwrap();
    assert!(matches!(
        write_bytes_atomic(&null, b"x"),
        Err(OutputError::NotAFile {
            kind: FileKind::CharDevice,
            ..
        })
    ));
    // A loop.
    let a = dir.path().join("loop_a");
    let b = dir.path().join("loop_b");
    std::os::unix::fs::symlink(&b, &a).unwrap();
    std::os::unix::fs::symlink(&a, &b).unwrap();
    assert!(write_bytes_atomic(&a, b"x").is_err());
}

#[test]
fn staged_outputs_land_together() {
    let (dir, [a, b]) = scratch(["a.txt", "b.txt"]);
    std::fs::write(&a, b"old a").unwrap();
    let mut staged = StagedOutput::new();
    staged.write_bytes(&a, b"new a").unwrap();
    staged.write_bytes(&b, b"new b").unwrap();
    assert_eq!(
        std::fs::read(&a).unwrap(),
        b"old a",
        "renamed before the commit"
    );
    assert!(!b.exists());
    staged.commit().unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), b"new a");
    assert_eq!(std::fs::read(&b).unwrap(), b"new b");
    assert_eq!(names(dir.path()), ["a.txt", "b.txt"]);
}

#[test]
fn a_failing_staged_file_leaves_nothing() {
    let (dir, [a, b]) = scratch(["a.txt", "b"]);
    std::fs::create_dir(&b).unwrap();
    let mut staged = StagedOutput::new();
    staged.write_bytes(&a, b"a").unwrap();
    assert!(staged.write_bytes(&b, b"b").is_err());
    drop(staged);
    assert_eq!(names(dir.path()), ["b"]);
}

#[cfg(unix)]
#[test]
fn a_failing_rename_puts_back_the_files_renamed_before() {
    let (dir, [a, b, c]) = scratch(["a.txt", "b.txt", "c.txt"]);
    std::fs::write(&a, b"old a").unwrap();
    let mut staged = StagedOutput::new();
    staged.write_bytes(&a, b"new a").unwrap();
    staged.write_bytes(&c, b"new c").unwrap();
    staged.write_bytes(&b, b"new b").unwrap();
    // After staging, b becomes a non-empty directory: its rename fails.
    std::fs::create_dir(&b).unwrap();
    std::fs::write(b.join("x"), b"").unwrap();
    let e = staged.commit().unwrap_err();
    assert!(matches!(e, OutputError::Persist { .. }), "{e:?}");
    assert_eq!(std::fs::read(&a).unwrap(), b"old a");
    assert!(!c.exists());
    assert_eq!(names(dir.path()), ["a.txt", "b.txt"]);
}

/// The first of `inputs` that is (by identity, as [`refuse_input_as_output`] compares) the
/// file `output` names.
fn same_file_as<'a>(output: &Path, inputs: &[&'a Path]) -> Option<&'a Path> {
    let out = FileId::of_path(output)?;
    inputs
        .iter()
        .copied()
        .find(|input| FileId::of_path(input).as_ref() == Some(&out))
}

/// An output folder is created with the folders above it, an existing one is kept, and one
/// that cannot be made (a file stands where a folder above it should be) is an I/O error
/// naming the folder and what it is for.
#[test]
fn an_output_folder_is_made_with_its_parents_or_named_in_the_error() {
    let (dir, [file]) = scratch(["a-file"]);
    let nested = dir.path().join("renders").join("frames");
    create_output_folder(&nested, "output directory").unwrap();
    assert!(nested.is_dir());
    create_output_folder(&nested, "output directory").unwrap();

    std::fs::write(&file, b"not a folder").unwrap();
    let under_file = file.join("figures");
    let err = create_output_folder(&under_file, "figures directory").unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "cannot create the figures directory {}",
            under_file.display()
        )
    );
    assert_eq!(err.kind(), ErrorKind::Io);
    assert_eq!(std::fs::read(&file).unwrap(), b"not a folder");
}
