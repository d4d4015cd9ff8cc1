//! A time limit for tests: `cargo test` has none, and a hung test would
//! otherwise wait for CI's limit. Used by the unit tests here and by the
//! integration tests (`tests/common`); not part of the engine.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::thread;
use std::time::Duration;

/// Runs `body` on its own thread and fails the test if it has not finished
/// within `seconds` (a panic in `body` fails the test as usual). A timed-out
/// body is left running detached: the test binary exits when its last test
/// ends, which stops it.
pub fn timeout<F>(seconds: u64, body: F)
where
    F: FnOnce() + Send + 'static,
{
    let name = thread::current().name().unwrap_or("test").to_string();
    let (done, finished) = mpsc::channel();
    let worker = thread::Builder::new()
        .name(name.clone())
        .spawn(move || {
            body();
            // The receiver is gone only after a timeout, already reported.
            let _ = done.send(());
        })
        .expect("spawn the test thread");
    match finished.recv_timeout(Duration::from_secs(seconds)) {
        Ok(()) => worker.join().expect("the test body finished"),
        // The body panicked (its sender dropped): re-raise its failure.
        Err(RecvTimeoutError::Disconnected) => {
            if let Err(failure) = worker.join() {
                std::panic::resume_unwind(failure);
            }
        }
        Err(RecvTimeoutError::Timeout) => {
            panic!("{name}: timed out after {seconds} s (a hang or a runaway loop)")
        }
    }
}
