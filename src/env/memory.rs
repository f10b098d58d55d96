//! What an environment holds in memory, and the check that a vector environment's fits.

use crate::error::Error;

/// Memory one more environment holds once its leaves plan motions, bytes: measured 2.0 MB per
/// `VectorEnv` sub-environment with its collision checker (`examples/python/memory.py`), with
/// headroom for its episode's records.
pub const ENV_MEMORY_BYTES: u64 = 4 << 20;

/// The most of the memory the system reports available (`MemAvailable`) that `n`
/// environments may ask for, as a fraction.
const AVAILABLE_SHARE: f64 = 0.5;

/// Refuses `n` environments ([`ENV_MEMORY_BYTES`] each) when they would need more than half of
/// `available` bytes; `None` (not known, as off Linux) accepts.
///
/// # Errors
/// [`Error::Config`] with both figures.
pub fn check_fits(n: usize, available: Option<u64>) -> Result<(), Error> {
    let Some(available) = available else {
        return Ok(());
    };
    let need = n as u64 * ENV_MEMORY_BYTES;
    if need as f64 <= AVAILABLE_SHARE * available as f64 {
        return Ok(());
    }
    let mb = |b: u64| b / (1 << 20);
    Err(Error::Config {
        message: format!(
            "{n} environments need about {} MB ({} MB each once they plan), more than half of the {} MB this machine has available: use fewer environments, or several processes on several machines",
            mb(need),
            mb(ENV_MEMORY_BYTES),
            mb(available)
        ),
    })
}

/// The memory the system reports available to new work (`MemAvailable` of `/proc/meminfo`),
/// bytes; `None` where it cannot be read.
pub fn available_memory() -> Option<u64> {
    use std::io::Read;
    let mut text = String::new();
    // The file is a few kilobytes; read at most 64 KiB of it.
    std::fs::File::open("/proc/meminfo")
        .ok()?
        .take(64 << 10)
        .read_to_string(&mut text)
        .ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let kib: u64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then_some(kib.checked_mul(1024)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn environments_that_would_need_more_than_half_the_available_memory_are_refused_with_the_figures() {
        let gib = 1u64 << 30;
        assert!(check_fits(1024, Some(16 * gib)).is_ok());
        assert!(check_fits(1024, None).is_ok());
        let e = check_fits(1024, Some(2 * gib)).unwrap_err();
        assert_eq!(e.kind(), "config");
        let text = e.to_string();
        assert!(
            text.contains("4096 MB") && text.contains("2048 MB this machine has available"),
            "{text}"
        );
        assert!(check_fits(256, Some(2 * gib)).is_ok(), "1 GiB of 2 fits");
        assert!(check_fits(257, Some(2 * gib)).is_err());
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn the_available_memory_is_read_on_linux() {
        let bytes = available_memory().expect("MemAvailable");
        assert!(bytes > 16 << 20, "{bytes} bytes");
    }
}
