//! Progress of long work, reported by the libraries and shown (or not) by the binaries: a
//! library calls a [`Progress`] observer at each stage and step; it never prints. The command
//! line shows a spinner or bar on a terminal; tests record the calls; [`NoProgress`] ignores
//! them.

/// An observer of long work. Calls come in order from one thread at a time, or from several
/// (hence `Sync`): an implementation keeps no assumptions about which.
pub trait Progress: Sync {
    /// A new stage begins, e.g. `decode`, `composite`, `encode`, or a report's section.
    fn stage(&self, name: &str);

    /// Within the current stage, `done` of `total` steps are finished (frames, sections).
    fn step(&self, done: u64, total: u64) {
        let _ = (done, total);
    }
}

/// Reports nothing: for callers that show no progress.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn stage(&self, _name: &str) {}
}

/// Records the stages in order (for tests of what a library reports).
#[derive(Debug, Default)]
pub struct StageLog {
    stages: std::sync::Mutex<Vec<String>>,
}

impl StageLog {
    /// The stages reported so far, in order.
    pub fn stages(&self) -> Vec<String> {
        self.stages.lock().map(|s| s.clone()).unwrap_or_default()
    }
}

impl Progress for StageLog {
    fn stage(&self, name: &str) {
        if let Ok(mut s) = self.stages.lock() {
            s.push(name.to_string());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_log_keeps_stages_in_order_and_steps_are_optional() {
        let log = StageLog::default();
        let observer: &dyn Progress = &log;
        observer.stage("decode");
        observer.step(1, 2);
        observer.stage("encode");
        assert_eq!(log.stages(), ["decode", "encode"]);
        NoProgress.stage("anything");
    }
}
