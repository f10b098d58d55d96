//! Who may talk to the live server: the `Host` of every request and the `Origin` of every
//! websocket upgrade must name this server by a loopback name and its port.
//!
//! * `Host` stops DNS rebinding: a page of `evil.example` whose name was made to resolve to
//!   127.0.0.1 still sends `Host: evil.example:PORT`.
//! * `Origin` stops other pages: any page the user visits may open `ws://127.0.0.1:PORT/`, but
//!   the browser then sends that page's own origin, which it cannot forge.

use std::net::IpAddr;

/// Host names this server answers to besides the address it is bound to.
const LOOPBACK_NAMES: [&str; 3] = ["127.0.0.1", "localhost", "[::1]"];

/// The names (host and port) this server answers to.
#[derive(Debug, Clone)]
pub(crate) struct Authority {
    port: u16,
    /// The bound address when it is a specific one (not 0.0.0.0 or ::), as written in a URL.
    bound: Option<String>,
}

impl Authority {
    /// The authority of a server bound to `ip`:`port`.
    pub fn new(ip: IpAddr, port: u16) -> Self {
        let bound = match ip {
            _ if ip.is_unspecified() => None,
            IpAddr::V4(v4) => Some(v4.to_string()),
            IpAddr::V6(v6) => Some(format!("[{v6}]")),
        };
        Self { port, bound }
    }

    /// Whether a `Host` header value (`name:port`, or `name` alone on port 80) names us.
    pub fn host_allowed(&self, host: &str) -> bool {
        let (name, port) = split_port(host);
        let port_ok = match port {
            Some(p) => p.parse::<u16>() == Ok(self.port) && !p.starts_with(['+', '-']),
            None => self.port == 80,
        };
        port_ok && self.name_allowed(name)
    }

    /// Whether an `Origin` header value is one of our own pages' origins (`http://` and an
    /// allowed host).
    pub fn origin_allowed(&self, origin: &str) -> bool {
        origin
            .strip_prefix("http://")
            .is_some_and(|host| !host.contains('/') && self.host_allowed(host))
    }

    fn name_allowed(&self, name: &str) -> bool {
        LOOPBACK_NAMES.iter().any(|n| n.eq_ignore_ascii_case(name))
            || self
                .bound
                .as_deref()
                .is_some_and(|b| b.eq_ignore_ascii_case(name))
    }
}

/// `name:port` → (`name`, `Some(port)`); a bracketed IPv6 literal keeps its brackets.
fn split_port(host: &str) -> (&str, Option<&str>) {
    let after_name = if host.starts_with('[') {
        host.find(']').map_or(host.len(), |i| i + 1)
    } else {
        0
    };
    match host[after_name..].rfind(':') {
        Some(i) => (&host[..after_name + i], Some(&host[after_name + i + 1..])),
        None => (host, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_names_with_our_port_only() {
        let a = Authority::new([127, 0, 0, 1].into(), 7000);
        for ok in ["127.0.0.1:7000", "localhost:7000", "LOCALHOST:7000", "[::1]:7000"] {
            assert!(a.host_allowed(ok), "{ok}");
            assert!(a.origin_allowed(&format!("http://{ok}")), "{ok}");
        }
        for bad in [
            "evil.example:7000",
            "127.0.0.1:7001",
            "127.0.0.1",
            "127.0.0.1:+7000",
            "localhost.:7000",
            "[::1]",
            "127.0.0.2:7000",
            "",
            ":7000",
        ] {
            assert!(!a.host_allowed(bad), "{bad}");
        }
        for bad in [
            "null",
            "https://127.0.0.1:7000",
            "http://127.0.0.1:7000/",
            "http://evil.example:7000",
            "http://localhost:7001",
            "",
        ] {
            assert!(!a.origin_allowed(bad), "{bad}");
        }
    }

    #[test]
    fn the_bound_address_and_port_80() {
        let a = Authority::new("192.168.1.5".parse().unwrap(), 80);
        assert!(a.host_allowed("192.168.1.5"));
        assert!(a.host_allowed("localhost:80"));
        assert!(a.origin_allowed("http://192.168.1.5"));
        assert!(!a.host_allowed("192.168.1.6"));
        let any = Authority::new("0.0.0.0".parse().unwrap(), 7000);
        assert!(!any.host_allowed("0.0.0.0:7000"));
        let v6 = Authority::new("::1".parse().unwrap(), 7000);
        assert!(v6.host_allowed("[::1]:7000"));
    }
}
