//! Where the text for people goes: stdout normally, stderr with `--json`, so that stdout then
//! holds exactly one JSON document (`macrotree sweep … --json | jq` works).

/// Prints one line for people: on stdout, or on stderr when `to_stderr` (the command's `--json`).
macro_rules! say {
    ($to_stderr:expr, $($arg:tt)*) => {
        if $to_stderr {
            eprintln!($($arg)*)
        } else {
            println!($($arg)*)
        }
    };
}

/// Prints text for people without adding a newline: on stdout, or on stderr when `to_stderr`.
macro_rules! say_text {
    ($to_stderr:expr, $text:expr) => {
        if $to_stderr {
            eprint!("{}", $text)
        } else {
            print!("{}", $text)
        }
    };
}

pub(super) use {say, say_text};
