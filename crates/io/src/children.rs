//! Programs a glassdb process starts and waits for (Blender) run as the leaders of process
//! groups of their own, recorded while they run: stopping one stops everything it started
//! (its own children too), and a stop of glassdb by a signal
//! ([`crate::exit_removing_temporaries`]) stops every recorded group before exiting, so no
//! Blender is left rendering after `glassdb blender render` was stopped. (A group of its own
//! also means that a terminal's Ctrl-C reaches glassdb, which stops the group, rather than
//! each program separately.) SIGKILL of glassdb itself cannot be handled; its groups are then
//! left running.

use std::io;
use std::process::{Child, Command, ExitStatus};

use crate::registry::{self, state};

/// A running program that leads a process group of its own, recorded until it is reaped.
#[derive(Debug)]
pub struct ChildGroup {
    child: Child,
    reaped: bool,
}

impl ChildGroup {
    /// Starts `command` as the leader of a new process group and records the group (refused
    /// once a stop is under way).
    pub fn spawn(command: &mut Command) -> io::Result<ChildGroup> {
        #[cfg(unix)]
        {
            use std::os::unix::process::CommandExt;
            command.process_group(0);
        }
        let mut s = state();
        if s.refuses() {
            return Err(registry::stopping_error());
        }
        let child = command.spawn()?;
        s.child_groups.insert(child.id());
        Ok(ChildGroup {
            child,
            reaped: false,
        })
    }

    /// The running program (its pipes, its id).
    pub fn child(&mut self) -> &mut Child {
        &mut self.child
    }

    /// Its exit status if it has exited (reaped then), else `None`; under the lock a stop
    /// takes, so that a stop never signals a group whose leader was reaped (its id may be
    /// another process's by then).
    pub fn try_wait(&mut self) -> io::Result<Option<ExitStatus>> {
        let mut s = state();
        let status = self.child.try_wait()?;
        if status.is_some() {
            self.reaped = true;
            s.child_groups.remove(&self.child.id());
        }
        Ok(status)
    }

    /// Kills every process of the group (the program and whatever it started that stayed in
    /// its group) and reaps the program.
    pub fn kill(&mut self) {
        if !self.reaped {
            let mut s = state();
            kill_group(self.child.id());
            let _ = self.child.kill();
            let _ = self.child.wait();
            self.reaped = true;
            s.child_groups.remove(&self.child.id());
        }
    }
}

impl Drop for ChildGroup {
    /// A group dropped while running (an error while waiting for it) is killed, not left.
    fn drop(&mut self) {
        self.kill();
    }
}

/// Sends SIGKILL to every process of group `id` (Unix; elsewhere nothing: the program itself
/// is killed by its handle).
pub(crate) fn kill_group(id: u32) {
    #[cfg(unix)]
    if let Some(pid) = i32::try_from(id)
        .ok()
        .and_then(rustix::process::Pid::from_raw)
    {
        let _ = rustix::process::kill_process_group(pid, rustix::process::Signal::KILL);
    }
    #[cfg(not(unix))]
    let _ = id;
}
