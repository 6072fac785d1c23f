//! Warnings on stderr, once per process for a repeated one, and `-q`, which silences them.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// `-q`: warnings and notes are not printed (errors still are, and the exit code says the rest).
static QUIET: AtomicBool = AtomicBool::new(false);

pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Where warnings go while something else owns the terminal's last line (a progress bar): a function that prints
/// a line without breaking it (indicatif's `suspend`). `None`: straight to stderr.
type Sink = Box<dyn Fn(&str) + Send>;
static SINK: Mutex<Option<Sink>> = Mutex::new(None);

/// Sends warnings through `sink` until the returned guard is dropped (then to stderr again).
pub fn print_through(sink: impl Fn(&str) + Send + 'static) -> SinkGuard {
    if let Ok(mut s) = SINK.lock() {
        *s = Some(Box::new(sink));
    }
    SinkGuard(())
}

/// While alive, warnings go through the sink [`print_through`] set.
pub struct SinkGuard(());

impl Drop for SinkGuard {
    fn drop(&mut self) {
        if let Ok(mut s) = SINK.lock() {
            *s = None;
        }
    }
}

/// Prints a warning on stderr (through the sink a progress bar set, if any) unless `-q` was given.
pub fn warn(message: &str) {
    if quiet() {
        return;
    }
    let line = format!("sunshade: warning: {message}");
    match SINK.lock().as_deref() {
        Ok(Some(sink)) => sink(&line),
        _ => eprintln!("{line}"),
    }
}

/// [`warn`], once per process for each distinct message (a batch of many jobs repeats the same ones).
pub fn warn_once(message: &str) {
    static SEEN: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let first = SEEN.lock().map_or(true, |mut seen| {
        let new = !seen.iter().any(|m| m == message);
        if new {
            seen.push(message.to_string());
        }
        new
    });
    if first {
        warn(message);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn warnings_go_through_the_sink_while_its_guard_lives() {
        let seen = Arc::new(Mutex::new(Vec::<String>::new()));
        let into = Arc::clone(&seen);
        let guard = print_through(move |line| into.lock().unwrap().push(line.to_string()));
        warn("through the sink");
        drop(guard);
        warn("to stderr again");
        let seen = seen.lock().unwrap();
        assert!(seen.iter().any(|l| l == "sunshade: warning: through the sink"), "{seen:?}");
        assert!(!seen.iter().any(|l| l.contains("to stderr again")), "{seen:?}");
    }
}
