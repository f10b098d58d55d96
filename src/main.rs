//! The `macrotree` command-line tool. See [`macrotree::cli`].

fn main() -> std::process::ExitCode {
    macrotree::cli::main()
}
