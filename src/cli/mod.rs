//! Command-line interface (under construction).

/// Entry point of the `macrotree` binary.
pub fn main() -> std::process::ExitCode {
    std::process::ExitCode::SUCCESS
}
