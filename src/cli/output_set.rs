//! Rules across the outputs of one command: no two outputs are the same file (`run --record x
//! --frames x`), and no output lies inside a folder the command replaces (`sweep --dataset DIR
//! --overwrite --out DIR/results.jsonl`). Checked before any work starts (bad input, exit 2).

use std::os::unix::fs::MetadataExt;
use std::path::{Component, Path, PathBuf};

use super::CliError;

/// Where `path` resolves to: standard output or error, or the absolute path of its folder
/// (symbolic links resolved) joined with its name, plus the (device, inode) of the file there.
#[derive(Debug, PartialEq, Eq)]
struct Resolved {
    stream: Option<u8>,
    path: PathBuf,
    file: Option<(u64, u64)>,
}

fn resolve(path: &Path) -> Resolved {
    let stream = match path.as_os_str().as_encoded_bytes() {
        b"-" | b"/dev/stdout" => Some(1),
        b"/dev/stderr" => Some(2),
        _ => None,
    };
    let file = std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()));
    Resolved {
        stream,
        path: absolute(path),
        file,
    }
}

/// `path` made absolute with its folder's symbolic links resolved (as far as the folder
/// exists), and `.`/`..` removed lexically for the rest.
pub(super) fn absolute(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    // The longest existing ancestor, canonicalized, then the remaining components.
    let mut head = abs.clone();
    let mut tail: Vec<std::ffi::OsString> = Vec::new();
    loop {
        if let Ok(mut out) = head.canonicalize() {
            for part in tail.iter().rev() {
                match Path::new(part).components().next() {
                    Some(Component::ParentDir) => {
                        out.pop();
                    }
                    Some(Component::CurDir) | None => {}
                    Some(_) => out.push(part),
                }
            }
            return out;
        }
        let last = head.components().next_back();
        match (last, head.parent()) {
            (Some(c), Some(parent)) => {
                tail.push(c.as_os_str().to_owned());
                head = parent.to_path_buf();
            }
            _ => return abs,
        }
    }
}

/// Refuses two outputs (`(option, path)`) that name the same file: the same path, another
/// spelling of it, a link to it, or the same standard stream.
pub(super) fn refuse_same_outputs(outputs: &[(&str, Option<&Path>)]) -> Result<(), CliError> {
    let given: Vec<(&str, &Path, Resolved)> = outputs
        .iter()
        .filter_map(|(opt, p)| p.map(|p| (*opt, p, resolve(p))))
        .collect();
    for (i, (a_opt, a_path, a)) in given.iter().enumerate() {
        for (b_opt, b_path, b) in &given[i + 1..] {
            let same = match (a.stream, b.stream) {
                (Some(x), Some(y)) => x == y,
                (None, None) => a.path == b.path || (a.file.is_some() && a.file == b.file),
                _ => false,
            };
            if same {
                return Err(CliError::Input(format!(
                    "error: {a_opt} {} and {b_opt} {} name the same file; one would overwrite the \
                     other: give each output its own path",
                    a_path.display(),
                    b_path.display()
                )));
            }
        }
    }
    Ok(())
}

/// Refuses an output (`option`, `path`) inside the folder `dir` that `dir_opt` writes (and
/// replaces as a whole).
pub(super) fn refuse_output_inside(
    option: &str,
    path: &Path,
    dir_opt: &str,
    dir: &Path,
) -> Result<(), CliError> {
    if resolve(path).stream.is_some() {
        return Ok(());
    }
    let (p, d) = (absolute(path), absolute(dir));
    if p.starts_with(&d) {
        return Err(CliError::Input(format!(
            "error: {option} {} is inside {dir_opt} {}, which this command replaces as a whole: the \
             file would be lost; write it outside that folder",
            path.display(),
            dir.display()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_one_path_resolve_alike() {
        let dir = std::env::temp_dir();
        let a = absolute(&dir.join("x/../y.txt"));
        let b = absolute(&dir.join("./y.txt"));
        assert_eq!(a, b);
        assert!(refuse_same_outputs(&[("--a", Some(&dir.join("y.txt"))), ("--b", Some(&b))]).is_err());
        assert!(
            refuse_same_outputs(&[
                ("--a", Some(Path::new("-"))),
                ("--b", Some(Path::new("/dev/stdout")))
            ])
            .is_err()
        );
        assert!(
            refuse_same_outputs(&[
                ("--a", Some(&dir.join("y.txt"))),
                ("--b", Some(&dir.join("z.txt")))
            ])
            .is_ok()
        );
    }
}
