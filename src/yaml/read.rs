//! Reading an input file with hard limits: only regular files, never more than
//! [`MAX_FILE_BYTES`], so a device, a FIFO or a huge file is refused before it is read.

use std::io::Read;
use std::path::Path;

use super::value::MAX_FILE_BYTES;

/// Read a tree file of at most [`MAX_FILE_BYTES`]. Only regular files are read, and never more
/// than the limit: a device (`/dev/zero`), a FIFO or a `/proc` file whose size is reported as 0
/// would otherwise be read forever, or block.
pub fn read_limited(path: &Path) -> Result<Vec<u8>, (String, String)> {
    let meta = std::fs::metadata(path).map_err(|e| {
        (
            format!("cannot read `{}`: {e}", path.display()),
            "check the path (include paths are relative to the including file)".to_string(),
        )
    })?;
    if meta.is_dir() {
        return Err((
            format!("`{}` is a folder, not a tree file", path.display()),
            "give the path of a `.yaml` file".to_string(),
        ));
    }
    if !meta.is_file() {
        return Err((
            format!("`{}` is not a regular file", path.display()),
            "give the path of a `.yaml` file (devices, pipes and sockets are not read)".to_string(),
        ));
    }
    let too_large = |size: String| {
        (
            format!("file is too large: {size} bytes (limit {MAX_FILE_BYTES} bytes)"),
            "a behavior tree file is a few kilobytes; is this the right file?".to_string(),
        )
    };
    if meta.len() > MAX_FILE_BYTES as u64 {
        return Err(too_large(meta.len().to_string()));
    }
    let cannot = |e: std::io::Error| {
        (
            format!("cannot read `{}`: {e}", path.display()),
            "check the path and permissions".to_string(),
        )
    };
    let file = std::fs::File::open(path).map_err(cannot)?;
    let mut bytes = Vec::new();
    // One byte past the limit tells "too large" from "exactly at the limit".
    file.take(MAX_FILE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(too_large(format!("more than {MAX_FILE_BYTES}")));
    }
    Ok(bytes)
}
