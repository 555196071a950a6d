//! The process-wide records behind [`crate::write_atomic`] and [`crate::read_input`]: the
//! temporary files being written, which [`exit_removing_temporaries`] removes when the process
//! is stopped by a signal, and (after [`protect_inputs`]) the files read, which no output of the
//! process may replace.
//!
//! One lock guards both. A temporary file is created and recorded under it, and renamed into
//! place under it, so a stop that takes the lock sees every temporary file there is and lets
//! no output land after it.

use std::collections::{BTreeMap, BTreeSet};
use std::fs::{File, Metadata, Permissions};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::thread::ThreadId;

use tempfile::TempPath;

/// The prefix of every temporary file (`.glassdb-tmp-XXXXXX` beside its target).
pub const TEMP_PREFIX: &str = ".glassdb-tmp-";

/// What identifies a file: its device and inode where it exists (so that hard links, symbolic
/// links and spellings such as `./a/../a` match), else its canonical directory and name.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum FileId {
    Inode { dev: u64, ino: u64 },
    Path(PathBuf),
}

impl FileId {
    /// The identity of the file whose metadata (links followed) is `meta`.
    #[cfg_attr(unix, allow(unused_variables))]
    pub(crate) fn of_meta(meta: &Metadata, path: &Path) -> FileId {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            FileId::Inode {
                dev: meta.dev(),
                ino: meta.ino(),
            }
        }
        #[cfg(not(unix))]
        {
            FileId::Path(path.canonicalize().unwrap_or_else(|_| path.to_path_buf()))
        }
    }

    /// The identity of `path`: of the file it names (links followed), or, where nothing is
    /// there yet, its canonical directory joined with its name (`None` when even the directory
    /// cannot be resolved).
    pub(crate) fn of_path(path: &Path) -> Option<FileId> {
        if let Ok(meta) = std::fs::metadata(path) {
            return Some(FileId::of_meta(&meta, path));
        }
        let name = path.file_name()?;
        Some(FileId::Path(
            parent_dir(path).canonicalize().ok()?.join(name),
        ))
    }
}

pub(crate) struct State {
    /// A stop is under way: no temporary file may be created or renamed into place, no
    /// program started.
    pub(crate) stopping: bool,
    /// The temporary files that exist now (absolute paths).
    temporaries: BTreeSet<PathBuf>,
    /// Whether the files read are recorded (see [`protect_inputs`]).
    protect_inputs: bool,
    /// The files read, by identity, with the name each was first read by.
    inputs: BTreeMap<FileId, PathBuf>,
    /// The process groups of the programs started and not yet reaped (`crate::ChildGroup`).
    pub(crate) child_groups: BTreeSet<u32>,
    /// What a stop still writes ([`on_stop`]), with the id of its registration.
    on_stop: Option<(u64, StopHook)>,
    /// The registrations made so far (ids of [`OnStop`]).
    on_stop_count: u64,
    /// The thread running the [`on_stop`] hook: the one that may still write while stopping.
    stop_writer: Option<ThreadId>,
}

/// What a stop by a signal still writes, given the exit code (128 + the signal's number).
type StopHook = Box<dyn FnOnce(i32) + Send>;

impl State {
    /// Whether this thread may no longer create, rename or start anything: a stop is under
    /// way and this is not the thread writing the stop's last output.
    pub(crate) fn refuses(&self) -> bool {
        self.stopping && self.stop_writer != Some(std::thread::current().id())
    }
}

static STATE: Mutex<State> = Mutex::new(State {
    stopping: false,
    temporaries: BTreeSet::new(),
    protect_inputs: false,
    inputs: BTreeMap::new(),
    child_groups: BTreeSet::new(),
    on_stop: None,
    on_stop_count: 0,
    stop_writer: None,
});

/// The lock (a panic elsewhere does not make the records unusable).
pub(crate) fn state() -> MutexGuard<'static, State> {
    STATE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// From now on, every file read through [`crate::read_input`] is an input that no output of
/// this process may replace: [`crate::write_atomic`] and [`crate::refuse_input_as_output`]
/// refuse an output that is (by device and inode) a file read or declared ([`declare_inputs`])
/// before. This record is glassdb's one protection of inputs. The binaries call this first
/// thing; a library never does, so that library users and tests are not affected (the record
/// is process-wide, and a deleted file's inode is handed on).
pub fn protect_inputs() {
    state().protect_inputs = true;
}

/// Declares `paths` as inputs of this process (when [`protect_inputs`] was called): files it
/// will read, or names it reads from but that may not exist (a material library an OBJ names).
/// No output may then replace or create one ([`crate::refuse_input_as_output`]). A library
/// declares its inputs before its first output, so that a run refuses an output that is one of
/// them before it does any work; reading a file through [`crate::read_input`] records it too.
pub fn declare_inputs<'a>(paths: impl IntoIterator<Item = &'a Path>) {
    let mut s = state();
    if s.protect_inputs {
        for path in paths {
            if let Some(id) = FileId::of_path(path) {
                s.inputs.entry(id).or_insert_with(|| path.to_path_buf());
            }
        }
    }
}

/// Records a file read (when [`protect_inputs`] was called).
pub(crate) fn record_input(path: &Path, meta: &Metadata) {
    let mut s = state();
    if s.protect_inputs {
        let id = FileId::of_meta(meta, path);
        s.inputs.entry(id).or_insert_with(|| path.to_path_buf());
    }
}

/// The file read before whose identity is `id`, if any.
pub(crate) fn input_matching(id: &FileId) -> Option<PathBuf> {
    state().inputs.get(id).cloned()
}

pub(crate) fn stopping_error() -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::Interrupted,
        "the process is being stopped",
    )
}

/// A temporary file beside an output, recorded while it exists; dropping it removes it.
#[derive(Debug)]
pub(crate) struct LiveTemp {
    path: Option<TempPath>,
}

impl LiveTemp {
    /// Creates a new temporary file in `dir` with `permissions`, recorded before anyone can
    /// see it; fails once a stop is under way.
    pub(crate) fn create(dir: &Path, permissions: Permissions) -> std::io::Result<(File, Self)> {
        let tmp = tempfile::Builder::new()
            .prefix(TEMP_PREFIX)
            .make_in(dir, |path| {
                let mut s = state();
                if s.refuses() {
                    return Err(stopping_error());
                }
                let mut options = std::fs::OpenOptions::new();
                options.read(true).write(true).create_new(true);
                #[cfg(unix)]
                {
                    use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
                    options.mode(permissions.mode());
                }
                let file = options.open(path)?;
                s.temporaries.insert(path.to_path_buf());
                Ok(file)
            })?;
        let (file, path) = tmp.into_parts();
        #[cfg(not(unix))]
        {
            let _ = file.set_permissions(permissions);
        }
        Ok((file, LiveTemp { path: Some(path) }))
    }

    /// Renames it over `target` (taking the lock).
    pub(crate) fn persist(mut self, target: &Path) -> std::io::Result<()> {
        let mut s = state();
        self.persist_locked(target, &mut s)
    }

    /// Renames it over `target` with the lock held by the caller. On failure it is removed.
    pub(crate) fn persist_locked(&mut self, target: &Path, s: &mut State) -> std::io::Result<()> {
        let Some(path) = self.path.take() else {
            return Err(std::io::Error::other("the temporary file is gone"));
        };
        let key = path.to_path_buf();
        if s.refuses() {
            drop(path);
            s.temporaries.remove(&key);
            return Err(stopping_error());
        }
        let result = path.persist(target).map_err(|e| e.error);
        // Renamed, or removed by the failed persist's TempPath drop: no longer there either way.
        s.temporaries.remove(&key);
        result
    }
}

impl Drop for LiveTemp {
    fn drop(&mut self) {
        if let Some(path) = self.path.take() {
            let mut s = state();
            let key = path.to_path_buf();
            drop(path); // removes the file
            s.temporaries.remove(&key);
        }
    }
}

/// Removes every temporary file this process is writing, kills the process groups of the
/// programs it started ([`crate::ChildGroup`]), runs the [`on_stop`] hook if one is registered,
/// and exits with `code` (128 + the signal number, by convention: 130 for SIGINT, 143 for
/// SIGTERM). From the stop on, no other thread creates a temporary file, renames one into
/// place or starts a program: the outputs that were finished before stay, the unfinished leave
/// nothing behind, and the hook's output (written by this thread) is the only one that lands.
pub fn exit_removing_temporaries(code: i32) -> ! {
    let hook = {
        let mut s = state();
        s.stopping = true;
        for group in std::mem::take(&mut s.child_groups) {
            crate::children::kill_group(group);
        }
        for path in std::mem::take(&mut s.temporaries) {
            let _ = std::fs::remove_file(path);
        }
        s.stop_writer = Some(std::thread::current().id());
        s.on_stop.take()
    };
    if let Some((_, hook)) = hook {
        hook(code);
    }
    // Held to the end: nothing is created or renamed while the process exits.
    let _s = state();
    std::process::exit(code)
}

/// Registers what a stop by a signal still writes before the process exits: compose's frames
/// report, saying which frames were finished and which the stop interrupted. `hook` runs once,
/// with the exit code, on the thread of [`exit_removing_temporaries`] after the unfinished
/// outputs are removed; it may write outputs ([`crate::write_atomic`]), which no other thread
/// can then. One hook at a time: a later registration replaces an earlier one. Dropping the
/// returned [`OnStop`] unregisters it.
#[must_use = "the hook is unregistered when the guard is dropped"]
pub fn on_stop(hook: impl FnOnce(i32) + Send + 'static) -> OnStop {
    let mut s = state();
    s.on_stop_count += 1;
    let id = s.on_stop_count;
    s.on_stop = Some((id, Box::new(hook)));
    OnStop { id }
}

/// The registration of an [`on_stop`] hook; dropping it unregisters the hook.
#[derive(Debug)]
pub struct OnStop {
    id: u64,
}

impl Drop for OnStop {
    fn drop(&mut self) {
        let mut s = state();
        if s.on_stop.as_ref().is_some_and(|(id, _)| *id == self.id) {
            s.on_stop = None;
        }
    }
}

/// The folder `path` is in: its parent, or `.` for a bare file name.
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The temporary files that exist now (for tests).
#[cfg(test)]
pub(crate) fn live_temporaries() -> Vec<PathBuf> {
    state().temporaries.iter().cloned().collect()
}
