//! `fbd`: the command-line simulator (see the `fbd_cli` library).

fn main() -> std::process::ExitCode {
    fbd_cli::main_with_args(std::env::args_os())
}
