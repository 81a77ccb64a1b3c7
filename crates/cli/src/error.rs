//! The top-level error of a command ([`CliError`], the runs' own
//! [`fbd_output::OutputError`]) and its exit status.

pub use fbd_output::OutputError as CliError;

/// Exit status for an internal error (a caught panic).
pub const INTERNAL: u8 = 70;

/// The process exit status of an error: 2 usage or configuration,
/// 3 simulation, 4 input/output, 130 interrupted.
pub fn exit_code(e: &CliError) -> u8 {
    match e {
        CliError::Config(c) if c.is_io() => 4,
        CliError::Config(_) | CliError::Usage(_) => 2,
        CliError::Simulation(_) => 3,
        CliError::Io(_) | CliError::BrokenPipe => 4,
        CliError::Interrupted(_) => fbd_output::interrupt::EXIT,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fbd_output::config::ConfigError;

    #[test]
    fn exit_codes() {
        assert_eq!(exit_code(&CliError::Usage(String::new())), 2);
        assert_eq!(exit_code(&CliError::Simulation(String::new())), 3);
        assert_eq!(exit_code(&CliError::Io(String::new())), 4);
        assert_eq!(exit_code(&CliError::BrokenPipe), 4);
        assert_eq!(exit_code(&CliError::Interrupted(String::new())), 130);
        let io = ConfigError::Io {
            file: "x.toml".into(),
            what: "permission denied".into(),
        };
        assert_eq!(exit_code(&CliError::Config(io)), 4);
    }
}
