//! `protect_inputs` is process-wide (and files are compared by device and inode, which a
//! deleted temporary directory hands on to the next test's files), so it runs in its own test
//! process, apart from the unit tests.

use glassdb_io::{OutputError, StagedOutput, write_bytes_atomic};

#[cfg(unix)]
#[test]
fn after_protect_inputs_no_write_replaces_a_file_read() {
    glassdb_io::protect_inputs();
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.txt");
    std::fs::write(&a, b"input").unwrap();
    let link = dir.path().join("link.txt");
    std::os::unix::fs::symlink(&a, &link).unwrap();
    glassdb_io::read_input(&link, glassdb_io::limits::JSON).unwrap();
    let hard = dir.path().join("hard.txt");
    std::fs::hard_link(&a, &hard).unwrap();
    for out in [&a, &hard, &link] {
        let e = write_bytes_atomic(out, b"output").unwrap_err();
        assert!(matches!(e, OutputError::OutputIsInput { .. }), "{e:?}");
        let mut staged = StagedOutput::new();
        assert!(staged.write_bytes(out, b"output").is_err());
    }
    assert_eq!(std::fs::read(&a).unwrap(), b"input");
    write_bytes_atomic(&dir.path().join("other.txt"), b"output").unwrap();
    // A declared input, which a library will read, and one it names that does not exist (a
    // missing MTL): no output replaces or creates either.
    let named = dir.path().join("named.json");
    std::fs::write(&named, b"input").unwrap();
    let missing = dir.path().join("missing.mtl");
    glassdb_io::declare_inputs([named.as_path(), missing.as_path()]);
    for out in [&named, &missing] {
        let e = glassdb_io::refuse_input_as_output(out).unwrap_err();
        assert!(matches!(e, OutputError::OutputIsInput { .. }), "{e:?}");
        assert!(write_bytes_atomic(out, b"output").is_err());
    }
    assert_eq!(std::fs::read(&named).unwrap(), b"input");
    assert!(!missing.exists());
    glassdb_io::refuse_input_as_output(&dir.path().join("other.json")).unwrap();
}
