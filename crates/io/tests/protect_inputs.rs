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
}
