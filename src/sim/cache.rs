//! A cache of compiled models: MuJoCo's binary model format (MJB) on disk, so that a command
//! starts in a few milliseconds instead of compiling the Menagerie meshes again (≈ 0.85 s).
//!
//! The cache is keyed by a SHA-1 of everything that goes into the compiled model: the generated
//! scene MJCF (our `assets/scene.xml` with the scene file's objects), the bytes and relative
//! path of every file in the Menagerie model folders (XML and meshes), the source of the code
//! that composes the model (this folder's `scene.rs` and `mjcf.rs`), the MuJoCo version and
//! macrotree's version. A file is used only when its header names exactly this key and the CRC-32
//! of its payload matches; anything else (a stale key, a truncated or corrupt file, an MJB that
//! MuJoCo refuses) is ignored and the model is compiled again. A new file is written to a
//! temporary file created exclusively and then renamed into place ([`crate::output`]), so a
//! reader never sees half a file and concurrent writers do not clash.
//!
//! Where: `$MACROTREE_CACHE_DIR` when set (`off` turns the cache off), else
//! `$XDG_CACHE_HOME/macrotree`, else `~/.cache/macrotree`.

use std::path::{Path, PathBuf};

use mujoco_rs::prelude::*;
use sha1::{Digest, Sha1};

/// Environment variable naming the cache folder (`off` disables the cache).
pub const CACHE_ENV: &str = "MACROTREE_CACHE_DIR";

/// First bytes of a cache file (format version 1).
const MAGIC: &[u8; 16] = b"MACROTREE-MJB-1\n";

/// Bytes of a cache file before the MJB payload: magic, key (SHA-1), payload length, payload
/// CRC-32.
const HEADER_LEN: usize = 16 + 20 + 8 + 4;

/// The code that composes the model, hashed into the key so that a change to it is never served
/// an old model.
const COMPOSER_SOURCES: [&str; 2] = [include_str!("scene.rs"), include_str!("mjcf.rs")];

/// The Menagerie folders whose files go into the model.
pub const MENAGERIE_MODELS: [&str; 2] = ["universal_robots_ur5e", "robotiq_2f85"];

/// The cache folder, or `None` when the cache is off (`MACROTREE_CACHE_DIR=off`) or no folder
/// can be named (no `HOME`).
pub fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os(CACHE_ENV) {
        Some(v) if v == "off" => None,
        Some(v) if !v.is_empty() => Some(PathBuf::from(v)),
        _ => match std::env::var_os("XDG_CACHE_HOME") {
            Some(x) if Path::new(&x).is_absolute() => Some(PathBuf::from(x).join("macrotree")),
            _ => std::env::var_os("HOME")
                .filter(|h| !h.is_empty())
                .map(|h| PathBuf::from(h).join(".cache/macrotree")),
        },
    }
}

/// The cache key (40 hex digits) of the model composed from `scene_mjcf` and the Menagerie
/// models in `menagerie`. Reads every file of the model folders.
pub fn model_key(scene_mjcf: &str, menagerie: &Path) -> std::io::Result<String> {
    let mut h = Sha1::new();
    let field = |h: &mut Sha1, bytes: &[u8]| {
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(bytes);
    };
    field(&mut h, b"macrotree compiled model v1");
    field(&mut h, env!("CARGO_PKG_VERSION").as_bytes());
    field(&mut h, mujoco_rs::mujoco_version().as_bytes());
    for src in COMPOSER_SOURCES {
        field(&mut h, src.as_bytes());
    }
    field(&mut h, scene_mjcf.as_bytes());
    for model in MENAGERIE_MODELS {
        let root = menagerie.join(model);
        let mut files = Vec::new();
        list_files(&root, &root, &mut files)?;
        files.sort();
        for rel in files {
            let bytes = std::fs::read(root.join(&rel))?;
            field(&mut h, model.as_bytes());
            field(&mut h, rel.to_string_lossy().as_bytes());
            field(&mut h, &bytes);
        }
    }
    Ok(hex(&h.finalize()))
}

fn list_files(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        // Follows symbolic links, as MuJoCo does when it reads the files.
        if std::fs::metadata(&path)?.is_dir() {
            list_files(root, &path, out)?;
        } else if let Ok(rel) = path.strip_prefix(root) {
            out.push(rel.to_path_buf());
        }
    }
    Ok(())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The cache file of `key` in `dir`.
pub fn model_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("model-{key}.mjb"))
}

/// The model cached under `key` in `dir`, if a valid file is there.
pub fn load(dir: &Path, key: &str) -> Option<MjModel> {
    let bytes = std::fs::read(model_path(dir, key)).ok()?;
    let payload = check(&bytes, key)?;
    MjModel::from_buffer(payload).ok()
}

/// The MJB payload of a cache file's `bytes` when its header is intact, names `key` and the
/// payload's CRC-32 matches; `None` otherwise.
fn check<'a>(bytes: &'a [u8], key: &str) -> Option<&'a [u8]> {
    if bytes.len() < HEADER_LEN || &bytes[..16] != MAGIC {
        return None;
    }
    if hex(&bytes[16..36]) != key {
        return None;
    }
    let len = u64::from_le_bytes(bytes[36..44].try_into().ok()?);
    let payload = &bytes[HEADER_LEN..];
    if payload.len() as u64 != len || crc32fast::hash(payload).to_le_bytes() != bytes[44..48] {
        return None;
    }
    Some(payload)
}

/// Writes `model` under `key` into `dir` (created if missing). Errors are returned for the
/// caller to log; the cache is an optimisation, never required.
pub fn store(dir: &Path, key: &str, model: &MjModel) -> Result<PathBuf, String> {
    let mut payload = vec![0u8; model.size()];
    model
        .save_to_buffer(&mut payload)
        .map_err(|e| format!("cannot save the model: {e:?}"))?;
    let key_bytes: Vec<u8> = (0..key.len() / 2)
        .map(|i| u8::from_str_radix(&key[2 * i..2 * i + 2], 16))
        .collect::<Result<_, _>>()
        .map_err(|_| format!("bad key {key}"))?;
    if key_bytes.len() != 20 {
        return Err(format!("bad key {key}"));
    }
    let mut bytes = Vec::with_capacity(HEADER_LEN + payload.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&key_bytes);
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    bytes.extend_from_slice(&payload);
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = model_path(dir, key);
    let out = crate::output::OutputFile::check(&path, &[]).map_err(|e| e.to_string())?;
    out.write_all(&bytes).map_err(|e| e.to_string())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_used_only_with_its_key_and_an_intact_payload() {
        let key = "00112233445566778899aabbccddeeff00112233";
        let payload = b"not really an mjb";
        let mut bytes = MAGIC.to_vec();
        bytes.extend((0..20).map(|i| u8::from_str_radix(&key[2 * i..2 * i + 2], 16).unwrap()));
        bytes.extend((payload.len() as u64).to_le_bytes());
        bytes.extend(crc32fast::hash(payload).to_le_bytes());
        bytes.extend(payload);
        assert_eq!(check(&bytes, key), Some(&payload[..]));
        let other = "10112233445566778899aabbccddeeff00112233";
        assert_eq!(check(&bytes, other), None, "another key");
        let mut flipped = bytes.clone();
        *flipped.last_mut().unwrap() ^= 1;
        assert_eq!(check(&flipped, key), None, "a corrupt payload");
        assert_eq!(check(&bytes[..bytes.len() - 1], key), None, "a truncated file");
        assert_eq!(check(&bytes[..10], key), None, "a truncated header");
        let mut magic = bytes.clone();
        magic[0] = b'X';
        assert_eq!(check(&magic, key), None, "another format");
    }
}
