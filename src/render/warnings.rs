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

/// Prints a warning on stderr unless `-q` was given.
pub fn warn(message: &str) {
    if !quiet() {
        eprintln!("sunshade: warning: {message}");
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
