//! SIGINT / SIGTERM (Ctrl-C): one process-wide stop flag.
//!
//! The first signal sets the flag: the stepping loop of every run stops
//! before its next step ([`fbd_sim::run_until`]), the steps computed so far
//! and every file are written, `summary.json` says `"interrupted"`, no
//! temporary file is left, and the command exits with status 130. A second
//! signal while stopping exits at once.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

/// Exit status of an interrupted command (128 + SIGINT).
pub const EXIT: u8 = 130;

/// Installs the signal handler (once; later calls do nothing). Called by
/// the binary's entry point only, so that library users keep their own
/// signal handling.
pub fn install() {
    static INSTALLED: AtomicBool = AtomicBool::new(false);
    if INSTALLED.swap(true, Ordering::SeqCst) {
        return;
    }
    // Failing to install (another handler exists) leaves the default
    // behaviour: the signal ends the process.
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(EXIT));
        }
        eprintln!("\ninterrupted: writing what was computed (press Ctrl-C again to quit now)");
    });
}

/// The stop flag the stepping loops check.
pub fn flag() -> &'static AtomicBool {
    &STOP
}

/// `true` once a signal arrived.
pub fn requested() -> bool {
    STOP.load(Ordering::SeqCst)
}
