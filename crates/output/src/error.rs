//! Why writing a run's outputs (or the run itself) failed. The command
//! line maps each variant to its exit status (`fbd_cli::error::exit_code`).

use crate::config::{ConfigError, os_message};

/// Why a run, a sweep or the writing of their files failed. Displays as
/// one line (without the `error: ` prefix the binary adds).
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// A configuration file is unreadable or invalid (exit 2, or 4 for an
    /// operating-system read failure).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The request cannot be served (exit 2), e.g. `fbd run` of a hexapod.
    #[error("{0}")]
    Usage(String),
    /// The simulation stopped with an error; what was computed is written
    /// (exit 3).
    #[error("{0}")]
    Simulation(String),
    /// SIGINT or SIGTERM stopped the command; what was computed is written
    /// (exit 130).
    #[error("{0}")]
    Interrupted(String),
    /// Reading or writing a file failed (exit 4).
    #[error("{0}")]
    Io(String),
    /// Writing to stdout failed because the reader went away (exit 4,
    /// nothing printed).
    #[error("broken pipe")]
    BrokenPipe,
}

impl OutputError {
    /// `true` when stdout was closed by its reader (no message is printed).
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, OutputError::BrokenPipe)
    }

    /// Wraps an I/O error on `what` (a path or "stdout"):
    /// `out/summary.json: permission denied`.
    pub fn io(what: impl std::fmt::Display, e: &std::io::Error) -> Self {
        OutputError::Io(format!("{what}: {}", os_message(e)))
    }

    /// Maps a failed write to stdout.
    pub fn stdout(e: std::io::Error) -> Self {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            OutputError::BrokenPipe
        } else {
            OutputError::io("stdout", &e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn os_messages_read_like_the_others() {
        let e = std::io::Error::from_raw_os_error(2);
        assert_eq!(os_message(&e), "no such file or directory");
        let e = std::io::Error::other("Broken thing");
        assert_eq!(os_message(&e), "broken thing");
        assert_eq!(
            OutputError::io("out/x", &std::io::Error::from_raw_os_error(13)).to_string(),
            "out/x: permission denied"
        );
    }
}
