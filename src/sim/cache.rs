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
//! Hashing the Menagerie meshes (33 MB) on every start would cost more than the episode, so their
//! digest is remembered next to the models with each file's size, times, inode and device
//! ([`model_key_stamped`]); a file whose metadata changed is read again.
//!
//! A model derived from a cached one (the cell's collision model, compiled from the cell's model:
//! `super::collision_model`) is cached beside it under a key of its own ([`derived_key`]): the
//! key of the model it derives from, what it is, and the source of the code that derives it.
//!
//! The cache is bounded: it keeps at most [`MAX_MODELS`] models (each scene variant is two: its
//! model, about 43 MB, and its collision model, under 1 MB) and at most [`MAX_BYTES`] of them;
//! writing a new one removes the least recently used beyond that (a model's modification time is
//! set on each use). Temporary files left by a
//! process that stopped while writing one (any way, `kill -9` included) are removed by the next
//! write (see [`crate::cleanup`]).
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

/// Most models the cache keeps (least recently used out): 16 scene variants, each a model and
/// its collision model.
pub const MAX_MODELS: usize = 32;
/// Most bytes of models the cache keeps (least recently used out): 1 GiB.
pub const MAX_BYTES: u64 = 1 << 30;

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
/// models in `menagerie`. Reads and hashes every file of the model folders.
pub fn model_key(scene_mjcf: &str, menagerie: &Path) -> std::io::Result<String> {
    Ok(key_from(scene_mjcf, &menagerie_digest(menagerie)?))
}

/// [`model_key`], reading the Menagerie files only when they changed since the last time: their
/// digest is remembered in `dir` with each file's size, modification and status-change times,
/// inode and device (what `git` trusts to tell a file changed; writing a file always updates its
/// status-change time). Any difference, or no remembered digest, hashes the files again.
pub fn model_key_stamped(scene_mjcf: &str, menagerie: &Path, dir: &Path) -> std::io::Result<String> {
    let files = model_files(menagerie)?;
    let mut stamp = String::new();
    for (model, rel) in &files {
        let meta = std::fs::metadata(menagerie.join(model).join(rel))?;
        stamp += &format!(
            "{model}/{}\t{}\t{}\n",
            rel.display(),
            meta.len(),
            file_times(&meta)
        );
    }
    let stamp_path = dir.join(format!(
        "menagerie-{}.stamp",
        &hex(&Sha1::digest(menagerie.as_os_str().as_encoded_bytes()))[..16]
    ));
    if let Ok(saved) = std::fs::read_to_string(&stamp_path)
        && let Some((listing, digest)) = saved.rsplit_once("digest ")
        && listing == stamp
        && let Some(d) = unhex(digest.trim())
    {
        return Ok(key_from(scene_mjcf, &d));
    }
    let digest = menagerie_digest(menagerie)?;
    // Only files unchanged while they were hashed are remembered.
    let mut after = String::new();
    for (model, rel) in &files {
        let meta = std::fs::metadata(menagerie.join(model).join(rel))?;
        after += &format!(
            "{model}/{}\t{}\t{}\n",
            rel.display(),
            meta.len(),
            file_times(&meta)
        );
    }
    if after == stamp {
        let text = format!("{stamp}digest {}\n", hex(&digest));
        let _ = std::fs::create_dir_all(dir);
        if let Ok(out) = crate::output::OutputFile::check(&stamp_path, &[]) {
            let _ = out.write_all(text.as_bytes());
        }
    }
    Ok(key_from(scene_mjcf, &digest))
}

#[cfg(unix)]
fn file_times(meta: &std::fs::Metadata) -> String {
    use std::os::unix::fs::MetadataExt;
    format!(
        "{}.{:09}\t{}.{:09}\t{}\t{}",
        meta.mtime(),
        meta.mtime_nsec(),
        meta.ctime(),
        meta.ctime_nsec(),
        meta.ino(),
        meta.dev()
    )
}

#[cfg(not(unix))]
fn file_times(_: &std::fs::Metadata) -> String {
    // Without status-change times a stamp cannot be trusted: never match.
    format!("{:?}", std::time::SystemTime::now())
}

/// Hashes one length-prefixed field (so that no two lists of fields hash alike).
fn field(h: &mut Sha1, bytes: &[u8]) {
    h.update((bytes.len() as u64).to_le_bytes());
    h.update(bytes);
}

/// The key (40 hex digits) of a model derived from the model cached under `base`: `what` names
/// the derived model and `sources` are the code that derives it, so that a change to either is
/// never served an old model.
pub fn derived_key(base: &str, what: &str, sources: &[&str]) -> String {
    let mut h = Sha1::new();
    field(&mut h, b"macrotree derived model v1");
    field(&mut h, base.as_bytes());
    field(&mut h, what.as_bytes());
    for src in sources {
        field(&mut h, src.as_bytes());
    }
    hex(&h.finalize())
}

/// The key of `scene_mjcf` with the Menagerie files whose digest is `menagerie`.
fn key_from(scene_mjcf: &str, menagerie: &[u8]) -> String {
    let mut h = Sha1::new();
    field(&mut h, b"macrotree compiled model v1");
    field(&mut h, env!("CARGO_PKG_VERSION").as_bytes());
    field(&mut h, mujoco_rs::mujoco_version().as_bytes());
    for src in COMPOSER_SOURCES {
        field(&mut h, src.as_bytes());
    }
    field(&mut h, scene_mjcf.as_bytes());
    field(&mut h, menagerie);
    hex(&h.finalize())
}

/// Every file of the Menagerie model folders: (model folder, path inside it), sorted.
fn model_files(menagerie: &Path) -> std::io::Result<Vec<(&'static str, PathBuf)>> {
    let mut out = Vec::new();
    for model in MENAGERIE_MODELS {
        let root = menagerie.join(model);
        let mut files = Vec::new();
        list_files(&root, &root, &mut files)?;
        files.sort();
        out.extend(files.into_iter().map(|f| (model, f)));
    }
    Ok(out)
}

/// SHA-1 over the relative path and bytes of every file of the Menagerie model folders.
fn menagerie_digest(menagerie: &Path) -> std::io::Result<Vec<u8>> {
    let mut h = Sha1::new();
    for (model, rel) in model_files(menagerie)? {
        let bytes = std::fs::read(menagerie.join(model).join(&rel))?;
        field(&mut h, model.as_bytes());
        field(&mut h, rel.to_string_lossy().as_bytes());
        field(&mut h, &bytes);
    }
    Ok(h.finalize().to_vec())
}

fn unhex(s: &str) -> Option<Vec<u8>> {
    if !s.len().is_multiple_of(2) {
        return None;
    }
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(s.get(2 * i..2 * i + 2)?, 16).ok())
        .collect()
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
    let path = model_path(dir, key);
    let bytes = std::fs::read(&path).ok()?;
    let payload = check(&bytes, key)?;
    let model = MjModel::from_buffer(payload).ok()?;
    // Used now: the last to be evicted.
    if let Ok(f) = std::fs::File::open(&path) {
        let _ = f.set_modified(std::time::SystemTime::now());
    }
    Some(model)
}

/// Removes the least recently used models of `dir` beyond [`MAX_MODELS`] and `MAX_BYTES`
/// (never `keep`), and temporary files whose writer is gone. Returns the models removed.
pub fn evict(dir: &Path, keep: &Path) -> Vec<PathBuf> {
    crate::cleanup::reclaim(dir, std::ffi::OsStr::new(".model-"), ".tmp", false);
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut models: Vec<(std::time::SystemTime, u64, PathBuf)> = entries
        .flatten()
        .take(100_000)
        .filter_map(|e| {
            let name = e.file_name();
            let name = name.to_str()?;
            if !(name.starts_with("model-") && name.ends_with(".mjb")) {
                return None;
            }
            let meta = std::fs::symlink_metadata(e.path()).ok()?;
            if !meta.is_file() {
                return None;
            }
            Some((meta.modified().ok()?, meta.len(), e.path()))
        })
        .collect();
    // Most recently used first; `keep` (just written) counts as the most recent.
    models.sort_by(|a, b| (b.2 == keep).cmp(&(a.2 == keep)).then(b.0.cmp(&a.0)));
    let mut removed = Vec::new();
    let mut bytes = 0u64;
    for (i, (_, len, path)) in models.into_iter().enumerate() {
        bytes = bytes.saturating_add(len);
        if path != keep && (i >= MAX_MODELS || bytes > MAX_BYTES) && std::fs::remove_file(&path).is_ok() {
            removed.push(path);
        }
    }
    removed
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
    let key_bytes = unhex(key).ok_or_else(|| format!("bad key {key}"))?;
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
    for old in evict(dir, &path) {
        tracing::debug!(path = %old.display(), "model cache: evicted the least recently used model");
    }
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
