//! The digest of what a sweep runs: the tree file, every file it includes and the scene file,
//! recorded with every result line (`tree_digest`) so that `--resume` refuses a tree, an include
//! or a scene edited since the interruption; and the per-line checksum (`crc32`) that makes an
//! edited line (anywhere in the file) refused too.

use std::path::Path;

use sha1::{Digest, Sha1};

/// The SHA-1 (40 hex digits) of the contents of `files`, in order (each preceded by its length,
/// so that moving bytes from one file to the next changes it). A file that cannot be read
/// counts as empty with a marker (the loaders have refused it already).
pub fn files_digest(files: &[&Path]) -> String {
    let mut h = Sha1::new();
    h.update(b"macrotree tree digest v1");
    for f in files {
        match std::fs::read(f) {
            Ok(bytes) => {
                h.update((bytes.len() as u64).to_le_bytes());
                h.update(&bytes);
            }
            Err(_) => h.update(u64::MAX.to_le_bytes()),
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The key that introduces the checksum at the end of a line.
const CRC_KEY: &str = ",\"crc32\":\"";

/// `json` (one JSON object) with its checksum added as its last field: the CRC-32 of the text
/// before it, as 8 hex digits.
pub fn with_checksum(json: &str) -> String {
    let body = json.strip_suffix('}').unwrap_or(json);
    format!("{body}{CRC_KEY}{:08x}\"}}", crc32fast::hash(body.as_bytes()))
}

/// The line without its checksum, when it has one and it matches; `Ok(None)` for a line without
/// one, `Err` for a checksum that does not match.
pub fn strip_checksum(line: &str) -> Result<Option<String>, String> {
    let Some(at) = line.rfind(CRC_KEY) else {
        return Ok(None);
    };
    let (body, tail) = line.split_at(at);
    let hex = tail[CRC_KEY.len()..]
        .strip_suffix("\"}")
        .filter(|h| h.len() == 8)
        .ok_or("its `crc32` is not 8 hex digits at the end of the line")?;
    let want = u32::from_str_radix(hex, 16).map_err(|_| "its `crc32` is not hex".to_string())?;
    if crc32fast::hash(body.as_bytes()) != want {
        return Err("its checksum does not match its content (the line was edited or damaged)".into());
    }
    Ok(Some(format!("{body}}}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksums_round_trip_and_catch_edits() {
        let line = with_checksum(r#"{"a":1,"b":"x"}"#);
        assert_eq!(
            strip_checksum(&line).unwrap().as_deref(),
            Some(r#"{"a":1,"b":"x"}"#)
        );
        let edited = line.replace("\"a\":1", "\"a\":2");
        assert!(strip_checksum(&edited).is_err());
        assert_eq!(strip_checksum(r#"{"a":1}"#).unwrap(), None);
    }
}
