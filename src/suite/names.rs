//! The names of scenario files in reports (`<testcase name>` of JUnit): the path relative to the
//! suite folder, with `/` separators, so that the same suite has the same test names in every
//! checkout (CI keeps test history by name).

use std::path::{Path, PathBuf};

/// The report name of each of `files`, as found from `roots` (the paths given to `macrotree
/// test`): a file found under a folder is named relative to that folder (`flagship.yaml`,
/// `slip/flagship.yaml` for `scenarios/slip/flagship.yaml` found from `scenarios/`); a file
/// given by itself is named by its file name.
pub fn case_names(roots: &[PathBuf], files: &[PathBuf]) -> Vec<String> {
    files
        .iter()
        .map(|f| {
            roots
                .iter()
                .filter(|r| r.is_dir())
                .filter_map(|r| f.strip_prefix(r).ok())
                .find(|rel| !rel.as_os_str().is_empty())
                .map_or_else(|| file_name(f), slash_path)
        })
        .collect()
}

/// The report names of `files` that a merged report (`macrotree report`) reads back from the
/// results: relative to the folder all of them share (one file: its file name). For the files
/// of one suite folder that has a file at its top, or files in two of its sub-folders, these
/// are the names `macrotree test` gave.
pub fn shared_folder_names(files: &[PathBuf]) -> Vec<String> {
    let parent = |f: &PathBuf| f.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut shared: Option<PathBuf> = None;
    for f in files {
        let p = parent(f);
        shared = Some(match shared {
            None => p,
            Some(s) => common_prefix(&s, &p),
        });
    }
    let shared = shared.unwrap_or_default();
    files
        .iter()
        .map(|f| match f.strip_prefix(&shared) {
            Ok(rel) if !rel.as_os_str().is_empty() => slash_path(rel),
            _ => file_name(f),
        })
        .collect()
}

fn common_prefix(a: &Path, b: &Path) -> PathBuf {
    a.components()
        .zip(b.components())
        .take_while(|(x, y)| x == y)
        .map(|(x, _)| x)
        .collect()
}

fn file_name(f: &Path) -> String {
    f.file_name()
        .map_or_else(|| f.display().to_string(), |n| n.to_string_lossy().into_owned())
}

fn slash_path(p: &Path) -> String {
    p.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn junit_names_do_not_depend_on_the_checkout_folder() {
        let dir = std::env::temp_dir().join(format!("macrotree-names-{}", std::process::id()));
        let sub = dir.join("scenarios/slip");
        std::fs::create_dir_all(&sub).unwrap();
        let a = dir.join("scenarios/a.yaml");
        let b = sub.join("b.yaml");
        let names = case_names(&[dir.join("scenarios")], &[a.clone(), b.clone()]);
        assert_eq!(names, ["a.yaml", "slip/b.yaml"]);
        // A file given by itself: its name, wherever the checkout is.
        assert_eq!(
            case_names(std::slice::from_ref(&b), std::slice::from_ref(&b)),
            ["b.yaml"]
        );
        assert_eq!(shared_folder_names(&[a, b.clone()]), ["a.yaml", "slip/b.yaml"]);
        assert_eq!(shared_folder_names(&[b]), ["b.yaml"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
